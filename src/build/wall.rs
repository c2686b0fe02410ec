//! Dry-stacked running-bond walls.

use serde::{Deserialize, Serialize};

use crate::block::{Fixity, RigidBlock};
use crate::constitutive::MaterialId;
use crate::error::{positive, Result};
use crate::math::{Real, Vector};

/// A running-bond wall: courses of bricks along x, stacked in z, one brick thick in y, on a fixed
/// base slab. Odd courses are shifted by half a brick and closed with half bricks at both ends.
#[derive(Debug, Clone, Copy, PartialEq, Serialize, Deserialize)]
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
/// [`crate::Error::InvalidParameter`] for non-positive sizes, density or counts.
pub fn running_bond_wall(spec: &WallSpec) -> Result<Vec<RigidBlock>> {
    positive("wall.bricks_per_course", spec.bricks_per_course as Real)?;
    positive("wall.courses", spec.courses as Real)?;
    positive("wall.brick.x", spec.brick.x)?;
    positive("wall.brick.y", spec.brick.y)?;
    positive("wall.brick.z", spec.brick.z)?;
    positive("wall.density", spec.density)?;
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
        for (k, x) in edges.windows(2).enumerate() {
            blocks.push(
                RigidBlock::cuboid(
                    &format!("brick c{c} k{k}"),
                    Vector::new(x[0], 0.0, z0),
                    Vector::new(x[1], w, z0 + h),
                    spec.density,
                )?
                .with_material(spec.material),
            );
        }
    }
    Ok(blocks)
}
