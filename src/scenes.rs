//! Ready-made models: the settling and the shaking running-bond wall of the benchmarks and the
//! `scaling` example. (Above `model` and `build` in the house: generators return blocks, and this
//! assembles them into a model.)

use crate::error::{positive, Result};
use crate::law::MaterialId;
use crate::math::Real;

/// Sub-contact spacing of [`benchmark_wall`] (m): 9 × 5 nodes on a 0.2 × 0.1 m bed face.
pub const BENCHMARK_SPACING: Real = 0.025;

/// Peak base acceleration of [`shaking_wall`] (m/s²): 0.3 g.
pub const SHAKE_ACCELERATION: Real = 0.3 * 9.81;

/// Frequency of [`shaking_wall`]'s base motion (Hz).
pub const SHAKE_FREQUENCY: Real = 3.0;

/// How long [`shaking_wall`]'s base shakes (s); it stands still afterwards.
pub const SHAKE_DURATION: Real = 20.0;

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

/// [`benchmark_wall_with_spacing`] on a shaking table, undamped ([`crate::integrate::Damping::None`]):
/// from its first step the base block moves across the wall (along y, out of its plane) with
/// velocity `(a/ω) sin ωt`, so displacement `(a/ω²)(1 − cos ωt)` (between 0 and 16.6 mm, no
/// drift) and acceleration `a cos ωt`, at `a` = [`SHAKE_ACCELERATION`] (0.3 g) and
/// `ω = 2π` [`SHAKE_FREQUENCY`] (3 Hz), for [`SHAKE_DURATION`]. Across the wall, because the
/// wall is one brick (0.1 m) thick and 0.3 g is well above its rocking threshold (about
/// thickness / height), so the courses rock on their bed joints and the blocks move beyond the
/// re-detection trigger; along it the wall would ride the table almost rigidly (friction
/// tan 30° = 0.58 > 0.3). Shaking starts at once, on the unsettled wall: there is no damping
/// to settle it anyway. Not yet stepped.
///
/// ```
/// use voussoir::scenes::shaking_wall;
/// let mut wall = shaking_wall(100, voussoir::scenes::BENCHMARK_SPACING)?;
/// let start = wall.blocks()[0].state().pose.translation;
/// wall.run_steps(200)?;
/// let moved = wall.blocks()[0].state().pose.translation - start;
/// assert!(moved.y > 0.0 && moved.x == 0.0 && moved.z == 0.0);
/// # Ok::<(), voussoir::Error>(())
/// ```
///
/// # Errors
/// As [`benchmark_wall_with_spacing`].
pub fn shaking_wall(blocks: usize, spacing: Real) -> Result<crate::Model> {
    use crate::loading::{BaseMotion, MotionKind, TimeHistory};
    let mut model = benchmark_wall_with_spacing(blocks, spacing)?;
    model.set_damping(crate::integrate::Damping::None)?;
    let omega = 2.0 * core::f64::consts::PI * SHAKE_FREQUENCY;
    let velocity = TimeHistory::sine(SHAKE_ACCELERATION / omega, SHAKE_FREQUENCY, SHAKE_DURATION, 200)?;
    model.set_base_motion(
        crate::BlockId(0),
        Some(BaseMotion::new(MotionKind::Velocity, [None, Some(velocity), None])?),
    )?;
    Ok(model)
}
