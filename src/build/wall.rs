//! Dry-stacked running-bond walls.

#[cfg(feature = "serde")]
use serde::{Deserialize, Serialize};

use crate::block::{Fixity, RigidBlock};
use crate::error::{positive, Result};
use crate::law::MaterialId;
use crate::math::{Pose, Real, Vector};

/// A running-bond wall: courses of bricks along x, stacked in z, one brick thick in y, on a fixed
/// base slab. Odd courses are shifted by half a brick and closed with half bricks at both ends.
#[derive(Debug, Clone, Copy, PartialEq)]
#[cfg_attr(feature = "serde", derive(Serialize, Deserialize))]
pub struct WallSpec {
    /// Bricks per course (full bricks on even courses).
    pub bricks_per_course: usize,
    /// Number of courses.
    pub courses: usize,
    /// Brick size along x, y, z (m).
    pub brick: Vector,
    /// Density (kg/m³).
    pub density: Real,
    /// Material of the bricks; the base gets `MaterialId(base_material)`.
    pub material: MaterialId,
    /// Material of the base.
    pub base_material: MaterialId,
}

impl Default for WallSpec {
    fn default() -> Self {
        Self {
            bricks_per_course: 10,
            courses: 10,
            brick: Vector::new(0.2, 0.1, 0.05),
            density: 2000.0,
            material: MaterialId(0),
            base_material: MaterialId(0),
        }
    }
}

impl WallSpec {
    /// A wall of about `blocks` bricks (default bricks), about ten times as long as high.
    pub fn with_blocks(blocks: usize) -> Self {
        let per_course = ((blocks as Real * 10.0).sqrt().round() as usize).max(2);
        Self {
            bricks_per_course: per_course,
            courses: (blocks / per_course).max(1),
            ..Self::default()
        }
    }
}

/// Builds the blocks of a running-bond wall; the first block is the fixed base.
///
/// ```
/// use voussoir::build::{running_bond_wall, WallSpec};
/// let blocks = running_bond_wall(&WallSpec { bricks_per_course: 4, courses: 3, ..WallSpec::default() })?;
/// // base + 4 + (3 + 2 halves) + 4
/// assert_eq!(blocks.len(), 1 + 4 + 5 + 4);
/// # Ok::<(), voussoir::Error>(())
/// ```
///
/// # Errors
/// [`crate::Error::InvalidParameter`] for non-positive sizes, density or counts;
/// [`crate::Error::TooLarge`] for more than [`super::MAX_GENERATED_BLOCKS`] blocks.
pub fn running_bond_wall(spec: &WallSpec) -> Result<Vec<RigidBlock>> {
    positive("wall.bricks_per_course", spec.bricks_per_course as Real)?;
    positive("wall.courses", spec.courses as Real)?;
    positive("wall.brick.x", spec.brick.x)?;
    positive("wall.brick.y", spec.brick.y)?;
    positive("wall.brick.z", spec.brick.z)?;
    positive("wall.density", spec.density)?;
    super::check_block_count(
        "wall.courses × (wall.bricks_per_course + 1) blocks",
        &[spec.courses as u128, spec.bricks_per_course as u128 + 1],
    )?;
    let (l, w, h) = (spec.brick.x, spec.brick.y, spec.brick.z);
    let length = l * spec.bricks_per_course as Real;
    let mut blocks = Vec::with_capacity(1 + spec.courses * (spec.bricks_per_course + 1));
    blocks.push(
        RigidBlock::cuboid(
            "base",
            Vector::new(-0.5 * l, -w, -h),
            Vector::new(length + 0.5 * l, 2.0 * w, 0.0),
            spec.density,
        )?
        .with_fixity(Fixity::FIXED)
        .with_material(spec.base_material),
    );
    let centred = |length: Real| {
        let half = 0.5 * Vector::new(length, w, h);
        RigidBlock::cuboid("brick", -half, half, spec.density).map(|b| b.with_material(spec.material))
    };
    let (brick, half_brick) = (centred(l)?, centred(0.5 * l)?);
    for c in 0..spec.courses {
        let z0 = c as Real * h;
        let mut edges: Vec<Real> = Vec::with_capacity(spec.bricks_per_course + 2);
        if c % 2 == 0 {
            edges.extend((0..=spec.bricks_per_course).map(|k| k as Real * l));
        } else {
            edges.push(0.0);
            edges.extend((0..spec.bricks_per_course).map(|k| (k as Real + 0.5) * l));
            edges.push(length);
        }
        let last = edges.len() - 2;
        for (k, x) in edges.windows(2).enumerate() {
            // The half bricks that end the odd courses, else whole ones: copies of one brick
            // each, placed at their centres, so that they share one shape.
            let prototype = if c % 2 == 1 && (k == 0 || k == last) {
                &half_brick
            } else {
                &brick
            };
            let centre = Vector::new(0.5 * (x[0] + x[1]), 0.5 * w, z0 + 0.5 * h);
            blocks.push(
                prototype
                    .clone()
                    .transformed(Pose::from_translation(centre))
                    .renamed(&format!("brick c{c} k{k}")),
            );
        }
    }
    Ok(blocks)
}

/// A multi-leaf wall: `leaves` running-bond leaves side by side across the thickness (along `y`),
/// each with its own brick size, on one fixed base; the joints between leaves are plain
/// (collar joints, no through-stones).
#[derive(Debug, Clone, PartialEq)]
#[cfg_attr(feature = "serde", derive(Serialize, Deserialize))]
pub struct MultiLeafSpec {
    /// Length of the wall (m), along `x`.
    pub length: Real,
    /// Height of the wall (m).
    pub height: Real,
    /// Brick size of each leaf, outer to outer (m).
    pub leaves: Vec<Vector>,
    /// Density (kg/m³).
    pub density: Real,
    /// Material of the bricks and the base.
    pub material: MaterialId,
}

impl Default for MultiLeafSpec {
    /// A three-leaf wall: two brick leaves around a core of smaller stones.
    fn default() -> Self {
        Self {
            length: 2.0,
            height: 1.0,
            leaves: vec![
                Vector::new(0.25, 0.12, 0.065),
                Vector::new(0.15, 0.2, 0.1),
                Vector::new(0.25, 0.12, 0.065),
            ],
            density: 2000.0,
            material: MaterialId(0),
        }
    }
}

/// Builds a multi-leaf wall; the first block is the fixed base. Each leaf has as many whole
/// courses as fit the height and as many bricks as fit the length (so its length is rounded to
/// whole bricks).
///
/// ```
/// use voussoir::build::{multi_leaf_wall, MultiLeafSpec};
/// let blocks = multi_leaf_wall(&MultiLeafSpec::default())?;
/// assert!(blocks.len() > 300);
/// # Ok::<(), voussoir::Error>(())
/// ```
///
/// # Errors
/// [`crate::Error::InvalidParameter`] for non-positive sizes.
pub fn multi_leaf_wall(spec: &MultiLeafSpec) -> Result<Vec<RigidBlock>> {
    positive("wall.length", spec.length)?;
    positive("wall.height", spec.height)?;
    positive("wall.leaves", spec.leaves.len() as Real)?;
    let thickness: Real = spec.leaves.iter().map(|b| b.y).sum();
    let mut blocks = vec![RigidBlock::cuboid(
        "base",
        Vector::new(-0.5, -0.5, -0.2),
        Vector::new(spec.length + 0.5, thickness + 0.5, 0.0),
        spec.density,
    )?
    .with_fixity(Fixity::FIXED)
    .with_material(spec.material)];
    let mut y0 = 0.0;
    for brick in &spec.leaves {
        let leaf_spec = WallSpec {
            bricks_per_course: ((spec.length / brick.x).floor() as usize).max(1),
            courses: ((spec.height / brick.z).floor() as usize).max(1),
            brick: *brick,
            density: spec.density,
            material: spec.material,
            base_material: spec.material,
        };
        let shift = crate::math::Pose::from_translation(Vector::new(0.0, y0, 0.0));
        for b in running_bond_wall(&leaf_spec)?.into_iter().skip(1) {
            blocks.push(b.transformed(shift));
        }
        y0 += brick.y;
    }
    Ok(blocks)
}
