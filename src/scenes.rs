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
/// base (cut at course-0 joints into fixed slabs of at most 20 m when it is too long for the
/// sub-contact spacing, [`crate::geometry::MAX_SUBCONTACTS_PER_EDGE`]: from about 6,500 blocks
/// on; the base blocks come first), dry Coulomb joints (kn 1 GPa/m, ks 0.4 GPa/m, φ 30°), sub-contacts at most
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
    wall_and_base(blocks, spacing).map(|(model, _)| model)
}

/// [`benchmark_wall_with_spacing`] and its number of base blocks.
fn wall_and_base(blocks: usize, spacing: Real) -> Result<(crate::Model, usize)> {
    use crate::block::{Block, Fixity, RigidBlock};
    use crate::build::{running_bond_wall, WallSpec};
    use crate::math::Vector;
    positive("spacing", spacing)?;
    let mut model: crate::Model = crate::Model::new(params_for(spacing))?;
    model.set_joint_law(
        MaterialId(0),
        MaterialId(0),
        crate::law::CoulombSlip::dry(1e9, 4e8, 30.0)?,
    )?;
    let spec = WallSpec::with_blocks(blocks);
    let mut wall = running_bond_wall(&spec)?;
    // The base spans x ∈ [−l/2, n l + l/2]; too long for the spacing, it is cut at every
    // `per_slab`-th joint of course 0 (the same bed joints, the same fixity and material).
    let (l, w, h) = (spec.brick.x, spec.brick.y, spec.brick.z);
    let length = l * spec.bricks_per_course as Real;
    let radius = 0.5 * Vector::new(length + l, 3.0 * w, h).length();
    let mut bases = 1;
    if params_for(spacing).contact.check_block(radius, "base").is_err() {
        let per_slab = ((20.0 / l).floor() as usize).max(1);
        let mut cuts: Vec<Real> = vec![-0.5 * l];
        cuts.extend(
            (1..)
                .map(|k| (k * per_slab) as Real * l)
                .take_while(|&x| x < length - 0.5 * l),
        );
        cuts.push(length + 0.5 * l);
        let material = wall[0].material();
        let slabs = cuts
            .windows(2)
            .enumerate()
            .map(|(k, x)| {
                let name = if k == 0 { "base".to_owned() } else { format!("base {k}") };
                Ok(RigidBlock::cuboid(
                    &name,
                    Vector::new(x[0], -w, -h),
                    Vector::new(x[1], 2.0 * w, 0.0),
                    spec.density,
                )?
                .with_fixity(Fixity::FIXED)
                .with_material(material))
            })
            .collect::<Result<Vec<_>>>()?;
        bases = slabs.len();
        wall.splice(0..1, slabs);
    }
    for b in wall {
        model.add_block(b)?;
    }
    Ok((model, bases))
}

/// [`benchmark_wall_with_spacing`] on a shaking table, undamped ([`crate::integrate::Damping::None`]):
/// from its first step the base (every base block) moves across the wall (along y, out of its plane) with
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
/// use voussoir::block::Block;
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
    use crate::signal::{BaseMotion, MotionKind, TimeHistory};
    let (mut model, bases) = wall_and_base(blocks, spacing)?;
    model.set_damping(crate::integrate::Damping::None)?;
    let omega = 2.0 * core::f64::consts::PI * SHAKE_FREQUENCY;
    let velocity = TimeHistory::sine(SHAKE_ACCELERATION / omega, SHAKE_FREQUENCY, SHAKE_DURATION, 200)?;
    let motion = BaseMotion::new(MotionKind::Velocity, [None, Some(velocity), None])?;
    for k in 0..bases {
        model.set_base_motion(crate::BlockId(k as u32), Some(motion.clone()))?;
    }
    Ok(model)
}

/// The model parameters of the benchmark walls: defaults, sub-contacts at most `spacing` apart.
fn params_for(spacing: Real) -> crate::ModelParameters {
    use crate::geometry::{ContactParameters, SubContactDensity};
    crate::ModelParameters {
        contact: ContactParameters {
            density: SubContactDensity::Spacing(spacing),
            ..ContactParameters::default()
        },
        ..crate::ModelParameters::default()
    }
}
