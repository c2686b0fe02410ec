//! Barrel vaults of radial-jointed voussoirs on fixed supports.
//!
//! Coordinates: `y` up; a barrel vault spans along `x` and runs along `z`.

use serde::{Deserialize, Serialize};

use crate::block::{Fixity, RigidBlock};
use crate::constitutive::MaterialId;
use crate::error::{positive, Error, Result};
use crate::math::{Real, Vector};

/// A semicircular barrel vault: `rings` arch rings side by side along `z`, each of `voussoirs`
/// equal-angle voussoirs, on two fixed springer beams. Alternate rings are shifted by half a
/// voussoir (a bonded vault), closed at the springings with half voussoirs.
#[derive(Debug, Clone, Copy, PartialEq, Serialize, Deserialize)]
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
