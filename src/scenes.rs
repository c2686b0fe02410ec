//! Ready-made models: the settling running-bond wall of the benchmarks and the `scaling`
//! example. (Above `model` and `build` in the house: generators return blocks, and this
//! assembles them into a model.)

use crate::error::{positive, Result};
use crate::law::MaterialId;
use crate::math::Real;

/// Sub-contact spacing of [`benchmark_wall`] (m): 9 × 5 nodes on a 0.2 × 0.1 m bed face.
pub const BENCHMARK_SPACING: Real = 0.025;

/// The wall used by the benchmarks and the `scaling` example: [`crate::build::WallSpec::with_blocks`] on its
/// base, dry Coulomb joints (kn 1 GPa/m, ks 0.4 GPa/m, φ 30°), sub-contacts at most
/// [`BENCHMARK_SPACING`] apart, gravity along −z, local damping. Not yet stepped.
///
/// # Errors
/// As [`crate::build::running_bond_wall`].
pub fn benchmark_wall(blocks: usize) -> Result<crate::Model> {
    benchmark_wall_with_spacing(blocks, BENCHMARK_SPACING)
}

/// [`benchmark_wall`] with sub-contacts at most `spacing` (m) apart, for studies of the cost of
/// sub-contact density.
///
/// ```
/// use voussoir::scenes::{benchmark_wall, benchmark_wall_with_spacing};
/// let (mut coarse, mut fine) = (benchmark_wall_with_spacing(100, 0.1)?, benchmark_wall(100)?);
/// coarse.step()?; // the first step detects the contacts
/// fine.step()?;
/// assert_eq!(coarse.contacts().len(), fine.contacts().len());
/// assert!(4 * coarse.subcontact_count() < fine.subcontact_count());
/// # Ok::<(), voussoir::Error>(())
/// ```
///
/// # Errors
/// As [`crate::build::running_bond_wall`]; [`crate::Error::InvalidParameter`] for a spacing that is not
/// positive and finite.
pub fn benchmark_wall_with_spacing(blocks: usize, spacing: Real) -> Result<crate::Model> {
    use crate::build::{running_bond_wall, WallSpec};
    use crate::geometry::{ContactParameters, SubcontactDensity};
    positive("spacing", spacing)?;
    let params = crate::ModelParameters {
        contact: ContactParameters {
            density: SubcontactDensity::Spacing(spacing),
            ..ContactParameters::default()
        },
        ..crate::ModelParameters::default()
    };
    let mut model: crate::Model = crate::Model::new(params)?;
    model.set_joint_law(
        MaterialId(0),
        MaterialId(0),
        crate::law::CoulombSlip::dry(1e9, 4e8, 30.0)?,
    )?;
    for b in running_bond_wall(&WallSpec::with_blocks(blocks))? {
        model.add_block(b)?;
    }
    Ok(model)
}
