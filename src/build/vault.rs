//! Barrel vaults and domes of voussoirs on fixed supports.
//!
//! Coordinates: `y` up; a barrel vault spans along `x` and runs along `z`; a dome is centred on
//! the `y` axis with its springing on `y = 0`.

#[cfg(feature = "serde")]
use serde::{Deserialize, Serialize};

use crate::block::{Fixity, RigidBlock};
use crate::error::{positive, Error, Result};
use crate::law::MaterialId;
use crate::math::{Real, Vector};

/// A semicircular barrel vault: `rings` arch rings side by side along `z`, each of `voussoirs`
/// equal-angle voussoirs, on two fixed springer beams. Alternate rings are shifted by half a
/// voussoir (a bonded vault), closed at the springings with half voussoirs.
#[derive(Debug, Clone, Copy, PartialEq)]
#[cfg_attr(feature = "serde", derive(Serialize, Deserialize))]
pub struct BarrelVaultSpec {
    /// Intrados radius (m).
    pub radius: Real,
    /// Radial thickness (m).
    pub thickness: Real,
    /// Length of one ring along the vault axis (m).
    pub ring_length: Real,
    /// Rings along the axis.
    pub rings: usize,
    /// Voussoirs per ring (full ones on even rings).
    pub voussoirs: usize,
    /// Density (kg/m³).
    pub density: Real,
    /// Material of every block.
    pub material: MaterialId,
}

impl Default for BarrelVaultSpec {
    fn default() -> Self {
        Self {
            radius: 2.0,
            thickness: 0.3,
            ring_length: 0.25,
            rings: 10,
            voussoirs: 25,
            density: 2200.0,
            material: MaterialId(0),
        }
    }
}

/// Builds a barrel vault; the first two blocks are the fixed springer beams.
///
/// ```
/// use voussoir::build::{barrel_vault, BarrelVaultSpec};
/// let blocks = barrel_vault(&BarrelVaultSpec { rings: 4, voussoirs: 9, ..BarrelVaultSpec::default() })?;
/// assert_eq!(blocks.len(), 2 + 2 * 9 + 2 * 10);
/// # Ok::<(), voussoir::Error>(())
/// ```
///
/// # Errors
/// [`Error::InvalidParameter`] for non-positive dimensions or fewer than 3 voussoirs.
pub fn barrel_vault(spec: &BarrelVaultSpec) -> Result<Vec<RigidBlock>> {
    positive("vault.radius", spec.radius)?;
    positive("vault.thickness", spec.thickness)?;
    positive("vault.ring_length", spec.ring_length)?;
    positive("vault.rings", spec.rings as Real)?;
    positive("vault.density", spec.density)?;
    at_least("vault.voussoirs", spec.voussoirs, 3)?;
    super::check_block_count(
        "vault.rings × vault.voussoirs blocks",
        &[spec.rings as u128, spec.voussoirs as u128],
    )?;
    let (ri, re) = (spec.radius, spec.radius + spec.thickness);
    let length = spec.ring_length * spec.rings as Real;
    let mut blocks = Vec::new();
    for (name, sign) in [("left springer", -1.0), ("right springer", 1.0)] {
        let (x0, x1) = if sign < 0.0 { (-re - 0.2, -ri) } else { (ri, re + 0.2) };
        blocks.push(
            RigidBlock::cuboid(
                name,
                Vector::new(x0, -0.3, 0.0),
                Vector::new(x1, 0.0, length),
                spec.density,
            )?
            .with_fixity(Fixity::FIXED)
            .with_material(spec.material),
        );
    }
    let step = std::f64::consts::PI / spec.voussoirs as Real;
    for r in 0..spec.rings {
        let (z0, z1) = (r as Real * spec.ring_length, (r + 1) as Real * spec.ring_length);
        let mut angles: Vec<Real> = Vec::new();
        if r % 2 == 0 {
            angles.extend((0..=spec.voussoirs).map(|k| k as Real * step));
        } else {
            angles.push(0.0);
            angles.extend((0..spec.voussoirs).map(|k| (k as Real + 0.5) * step));
            angles.push(std::f64::consts::PI);
        }
        for (k, a) in angles.windows(2).enumerate() {
            // Angle measured from the right springing (x > 0) counter-clockwise.
            let p = |rad: Real, t: Real, z: Real| Vector::new(rad * t.cos(), rad * t.sin(), z);
            let pts: Vec<Vector> = [z0, z1]
                .iter()
                .flat_map(|&z| [p(ri, a[0], z), p(ri, a[1], z), p(re, a[0], z), p(re, a[1], z)])
                .collect();
            blocks.push(
                RigidBlock::from_vertices(&format!("ring {r} voussoir {k}"), &pts, spec.density)?
                    .with_material(spec.material),
            );
        }
    }
    Ok(blocks)
}

/// A hemispherical dome of horizontal courses with an open oculus, on a fixed ring beam.
///
/// Course `c` holds `per_course[c]` voussoirs between meridian planes; its bed joints are
/// **horizontal planes** (at the heights where the intrados reaches the course's latitudes), so
/// that courses of different voussoir counts share plane bed faces. Alternate courses are
/// staggered by half a voussoir.
#[derive(Debug, Clone, PartialEq)]
#[cfg_attr(feature = "serde", derive(Serialize, Deserialize))]
pub struct DomeSpec {
    /// Intrados radius (m).
    pub radius: Real,
    /// Shell thickness (m).
    pub thickness: Real,
    /// Voussoirs in each course, from the springing up.
    pub per_course: Vec<usize>,
    /// Latitude of the oculus rim on the intrados (rad), in `(0, π/2)`.
    pub oculus_angle: Real,
    /// Density (kg/m³).
    pub density: Real,
    /// Material of every block.
    pub material: MaterialId,
}

impl DomeSpec {
    /// A dome of about `blocks` voussoirs of roughly square stones, oculus at 75°.
    pub fn with_blocks(blocks: usize) -> Self {
        let courses = ((blocks as Real / 4.0).sqrt().round() as usize).max(2);
        let oculus: Real = 75f64.to_radians();
        let weights: Vec<Real> = (0..courses)
            .map(|c| (oculus * (c as Real + 0.5) / courses as Real).cos())
            .collect();
        let total: Real = weights.iter().sum();
        let per_course = weights
            .iter()
            .map(|w| ((blocks as Real * w / total).round() as usize).max(3))
            .collect();
        Self {
            radius: 5.0,
            thickness: 0.4,
            per_course,
            oculus_angle: oculus,
            density: 2200.0,
            material: MaterialId(0),
        }
    }
}

/// Builds a dome; the first `per_course[0]` blocks form the fixed ring beam.
///
/// ```
/// use voussoir::build::{dome, DomeSpec};
/// let spec = DomeSpec { per_course: vec![16, 14, 12], ..DomeSpec::with_blocks(42) };
/// let blocks = dome(&spec)?;
/// assert_eq!(blocks.len(), 16 + 16 + 14 + 12);
/// // Too coarse a course for the 0.4 m shell: its staggered bed faces would not overlap.
/// assert!(dome(&DomeSpec { per_course: vec![16, 8], ..spec }).is_err());
/// # Ok::<(), voussoir::Error>(())
/// ```
///
/// # Errors
/// [`Error::InvalidParameter`] for bad dimensions or a course with fewer than 3 voussoirs.
pub fn dome(spec: &DomeSpec) -> Result<Vec<RigidBlock>> {
    positive("dome.radius", spec.radius)?;
    positive("dome.thickness", spec.thickness)?;
    positive("dome.density", spec.density)?;
    positive("dome.courses", spec.per_course.len() as Real)?;
    crate::error::in_range(
        "dome.oculus_angle",
        spec.oculus_angle,
        1e-3,
        std::f64::consts::FRAC_PI_2,
        "must lie in (0, π/2) rad",
    )?;
    super::check_block_count(
        "dome.per_course (sum) blocks",
        &[spec.per_course.iter().map(|&n| n as u128).sum()],
    )?;
    for (c, &n) in spec.per_course.iter().enumerate() {
        at_least(&format!("dome.per_course[{c}]"), n, 3)?;
        // Staggered chord faces overlap across a bed joint only if the shell is thicker than
        // the chord's sagitta: t > R (1/cos(π/n) − 1).
        let needed = spec.radius * (1.0 / (std::f64::consts::PI / n as Real).cos() - 1.0);
        if spec.thickness <= needed {
            return Err(Error::InvalidParameter {
                name: format!("dome.per_course[{c}]"),
                value: n as Real,
                expected: "too few voussoirs for the shell thickness: staggered bed faces would not overlap",
            });
        }
    }
    let (ri, re) = (spec.radius, spec.radius + spec.thickness);
    let courses = spec.per_course.len();
    // Heights of the bed joints and the horizontal radii of intrados and extrados there.
    let height = |c: usize| ri * (spec.oculus_angle * c as Real / courses as Real).sin();
    let rings = |h: Real| ((ri * ri - h * h).max(0.0).sqrt(), (re * re - h * h).sqrt());
    let point = |rho: Real, lon: Real, h: Real| Vector::new(rho * lon.cos(), h, rho * lon.sin());
    let tau = std::f64::consts::TAU;
    let mut blocks = Vec::new();
    let n0 = spec.per_course[0];
    for k in 0..n0 {
        let (l0, l1) = (tau * k as Real / n0 as Real, tau * (k + 1) as Real / n0 as Real);
        let pts: Vec<Vector> = [l0, l1]
            .iter()
            .flat_map(|&l| {
                [
                    point(ri, l, 0.0),
                    point(re, l, 0.0),
                    point(ri, l, -0.3),
                    point(re, l, -0.3),
                ]
            })
            .collect();
        blocks.push(
            RigidBlock::from_vertices(&format!("ring beam {k}"), &pts, spec.density)?
                .with_fixity(Fixity::FIXED)
                .with_material(spec.material),
        );
    }
    for (c, &n) in spec.per_course.iter().enumerate() {
        let (h0, h1) = (height(c), height(c + 1));
        let ((i0, e0), (i1, e1)) = (rings(h0), rings(h1));
        let shift = if c % 2 == 0 { 0.0 } else { 0.5 };
        for k in 0..n {
            let l0 = tau * (k as Real + shift) / n as Real;
            let l1 = tau * (k as Real + 1.0 + shift) / n as Real;
            let pts: Vec<Vector> = [l0, l1]
                .iter()
                .flat_map(|&l| [point(i0, l, h0), point(e0, l, h0), point(i1, l, h1), point(e1, l, h1)])
                .collect();
            blocks.push(
                RigidBlock::from_vertices(&format!("course {c} voussoir {k}"), &pts, spec.density)?
                    .with_material(spec.material),
            );
        }
    }
    Ok(blocks)
}

fn at_least(name: &str, n: usize, min: usize) -> Result<()> {
    if n < min {
        return Err(Error::InvalidParameter {
            name: name.to_owned(),
            value: n as Real,
            expected: "too few blocks",
        });
    }
    Ok(())
}
