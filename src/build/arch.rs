//! Segmental and semicircular arches of radial-jointed voussoirs between two abutments.
//!
//! Coordinates: `x` along the span (origin at midspan on the springing line), `y` up, `z` across
//! the width (`0 ≤ z ≤ width`). Gravity must be set along `−y` for these models.

#[cfg(feature = "serde")]
use serde::{Deserialize, Serialize};

use crate::block::{Fixity, RigidBlock};
use crate::error::{positive, Error, Result};
use crate::law::MaterialId;
use crate::math::{Real, Vector};

/// The shape of the two (mirrored) abutment blocks.
#[derive(Debug, Clone, Copy, PartialEq)]
#[cfg_attr(feature = "serde", derive(Serialize, Deserialize))]
pub struct AbutmentShape {
    /// Horizontal extent beyond the springing extrados point (m).
    pub outer_width: Real,
    /// Depth of the abutment below the springing line (m, positive).
    pub depth: Real,
}

impl Default for AbutmentShape {
    /// 0.20 m beyond the extrados springing, 0.30 m deep: the outline of the reference arch (`docs/benchmarks/arch-static.md`, Model).
    fn default() -> Self {
        Self {
            outer_width: 0.20,
            depth: 0.30,
        }
    }
}

/// Geometry of an arch ring. Intrados dimensions, as surveyed.
#[derive(Debug, Clone, Copy, PartialEq)]
#[cfg_attr(feature = "serde", derive(Serialize, Deserialize))]
pub struct ArchSpec {
    /// Clear span at the intrados (m).
    pub span: Real,
    /// Rise at the intrados (m); `span / 2` gives a semicircle.
    pub rise: Real,
    /// Radial ring thickness (m).
    pub thickness: Real,
    /// Out-of-plane width (m).
    pub width: Real,
    /// Number of voussoirs (equal angles).
    pub voussoirs: usize,
    /// Density of the stones (kg/m³).
    pub density: Real,
    /// Abutment outline.
    pub abutment: AbutmentShape,
    /// Material of the voussoirs.
    pub voussoir_material: MaterialId,
    /// Material of the abutments.
    pub abutment_material: MaterialId,
}

impl ArchSpec {
    /// The arch of the reference paper (Pulatsu et al. 2021): span 1.2 m, rise 0.4 m, ring 0.2 m,
    /// 13 voussoirs, unit weight 24 kN/m³ (2446.5 kg/m³ with g = 9.81), at the given width.
    pub fn reference(width: Real) -> Self {
        Self {
            span: 1.2,
            rise: 0.4,
            thickness: 0.2,
            width,
            voussoirs: 13,
            density: 24_000.0 / 9.81,
            abutment: AbutmentShape::default(),
            voussoir_material: MaterialId(0),
            abutment_material: MaterialId(0),
        }
    }

    /// Intrados radius `R_i = (L²/4 + f²)/(2f)` (m).
    pub fn intrados_radius(&self) -> Real {
        (self.span * self.span / 4.0 + self.rise * self.rise) / (2.0 * self.rise)
    }

    /// Height of the circle centre above the springing line (m, negative for a segment).
    pub fn centre_height(&self) -> Real {
        self.rise - self.intrados_radius()
    }

    /// Half-embrace angle `θ0` (rad) from the vertical.
    pub fn half_angle(&self) -> Real {
        (0.5 * self.span / self.intrados_radius()).clamp(-1.0, 1.0).asin()
    }

    /// Angle from the vertical of joint `j` (`0..=voussoirs`), rad.
    pub fn joint_angle(&self, j: usize) -> Real {
        let t0 = self.half_angle();
        -t0 + 2.0 * t0 * j as Real / self.voussoirs as Real
    }

    /// Intrados and extrados points `(x, y)` of joint `j` (z = 0).
    pub fn joint_points(&self, j: usize) -> (Vector, Vector) {
        let phi = self.joint_angle(j);
        let (ri, re, yc) = (
            self.intrados_radius(),
            self.intrados_radius() + self.thickness,
            self.centre_height(),
        );
        (
            Vector::new(ri * phi.sin(), yc + ri * phi.cos(), 0.0),
            Vector::new(re * phi.sin(), yc + re * phi.cos(), 0.0),
        )
    }

    fn validate(&self) -> Result<()> {
        positive("arch.span", self.span)?;
        positive("arch.rise", self.rise)?;
        positive("arch.thickness", self.thickness)?;
        positive("arch.width", self.width)?;
        positive("arch.density", self.density)?;
        positive("arch.abutment.outer_width", self.abutment.outer_width)?;
        positive("arch.abutment.depth", self.abutment.depth)?;
        super::check_block_count("arch.voussoirs", &[self.voussoirs as u128])?;
        if self.voussoirs < 2 {
            return Err(Error::InvalidParameter {
                name: "arch.voussoirs".into(),
                value: self.voussoirs as Real,
                expected: "at least 2",
            });
        }
        if self.rise > 0.5 * self.span + 1e-12 {
            return Err(Error::InvalidParameter {
                name: "arch.rise".into(),
                value: self.rise,
                expected: "at most span / 2 (segmental or semicircular arches)",
            });
        }
        Ok(())
    }
}

/// A joint of the ring: its index, the blocks on either side (as indices into [`Arch::blocks`])
/// and its intrados and extrados points at mid-width.
#[derive(Debug, Clone, Copy, PartialEq)]
#[cfg_attr(feature = "serde", derive(Serialize, Deserialize))]
pub struct ArchJoint {
    /// Joint number `j` (0 = left springing).
    pub index: usize,
    /// Block on the left (lower `x`).
    pub left: usize,
    /// Block on the right.
    pub right: usize,
    /// Intrados point, mid-width (m).
    pub intrados: Vector,
    /// Extrados point, mid-width (m).
    pub extrados: Vector,
}

/// An arch: its blocks and the names a user can address.
///
/// Block order: left abutment, voussoirs 1…n (left to right), right abutment. Added to an empty
/// model in this order, block `i` becomes `BlockId(i)`.
///
/// ```
/// use voussoir::build::arch::{Arch, ArchSpec};
/// let arch = Arch::new(&ArchSpec::reference(0.15))?;
/// assert_eq!(arch.blocks.len(), 15);
/// let p = arch.extrados_midpoint(5);
/// assert!((p.x + 0.29967).abs() < 5e-5 && (p.y - 0.54171).abs() < 5e-5);
/// # Ok::<(), voussoir::Error>(())
/// ```
#[derive(Debug, Clone)]
pub struct Arch {
    /// The geometry it was built from.
    pub spec: ArchSpec,
    /// All blocks: left abutment, voussoirs, right abutment.
    pub blocks: Vec<RigidBlock>,
    /// The joints `0..=n`.
    pub joints: Vec<ArchJoint>,
}

impl Arch {
    /// Builds the blocks. Abutments are fixed.
    ///
    /// # Errors
    /// [`Error::InvalidParameter`] naming the bad dimension; [`Error::TooLarge`] for more than
    /// [`super::MAX_GENERATED_BLOCKS`] voussoirs.
    pub fn new(spec: &ArchSpec) -> Result<Self> {
        spec.validate()?;
        let n = spec.voussoirs;
        let b = spec.width;
        let pts: Vec<(Vector, Vector)> = (0..=n).map(|j| spec.joint_points(j)).collect();
        let extrude = |outline: &[Vector]| -> Vec<Vector> {
            outline
                .iter()
                .flat_map(|p| [Vector::new(p.x, p.y, 0.0), Vector::new(p.x, p.y, b)])
                .collect()
        };
        let mut blocks = Vec::with_capacity(n + 2);
        let abutment = |sign: Real, (i0, e0): (Vector, Vector)| -> Vec<Vector> {
            let outer = e0.x + sign * spec.abutment.outer_width;
            vec![
                i0,
                e0,
                Vector::new(outer, e0.y, 0.0),
                Vector::new(outer, -spec.abutment.depth, 0.0),
                Vector::new(i0.x, -spec.abutment.depth, 0.0),
            ]
        };
        blocks.push(
            RigidBlock::from_vertices("left abutment", &extrude(&abutment(-1.0, pts[0])), spec.density)?
                .with_fixity(Fixity::FIXED)
                .with_material(spec.abutment_material),
        );
        for k in 1..=n {
            let (i0, e0) = pts[k - 1];
            let (i1, e1) = pts[k];
            blocks.push(
                RigidBlock::from_vertices(&format!("voussoir {k}"), &extrude(&[i0, i1, e1, e0]), spec.density)?
                    .with_material(spec.voussoir_material),
            );
        }
        blocks.push(
            RigidBlock::from_vertices("right abutment", &extrude(&abutment(1.0, pts[n])), spec.density)?
                .with_fixity(Fixity::FIXED)
                .with_material(spec.abutment_material),
        );
        let mid = Vector::new(0.0, 0.0, 0.5 * b);
        let joints = (0..=n)
            .map(|j| ArchJoint {
                index: j,
                left: j,
                right: j + 1,
                intrados: pts[j].0 + mid,
                extrados: pts[j].1 + mid,
            })
            .collect();
        Ok(Self {
            spec: *spec,
            blocks,
            joints,
        })
    }

    /// Index in [`Arch::blocks`] of voussoir `k` (1-based from the left).
    pub fn voussoir(&self, k: usize) -> usize {
        k.clamp(1, self.spec.voussoirs)
    }

    /// Indices of the left and right abutments.
    pub fn abutments(&self) -> [usize; 2] {
        [0, self.spec.voussoirs + 1]
    }

    /// The [`BlockId`](crate::block::BlockId) of voussoir `k` (1-based from the left) in a model
    /// the arch's blocks were added to first, in [`Arch::blocks`] order (as
    /// [`Arch::joint_refs`] assumes): the id that `Model::block`, `Model::set_load` and the
    /// loading drivers take, without converting [`Arch::voussoir`]'s index by hand.
    ///
    /// ```
    /// use voussoir::build::arch::{Arch, ArchSpec};
    /// use voussoir::prelude::*;
    ///
    /// let arch = Arch::new(&ArchSpec::reference(0.15))?;
    /// let mut model: Model = Model::new(ModelParameters::default())?;
    /// for b in arch.blocks.iter().cloned() {
    ///     model.add_block(b)?;
    /// }
    /// let key = arch.voussoir_id(7);
    /// assert_eq!(model.block(key)?.name(), arch.blocks[arch.voussoir(7)].name());
    /// assert_eq!(arch.abutment_ids()[0], BlockId(0));
    /// # Ok::<(), voussoir::Error>(())
    /// ```
    pub fn voussoir_id(&self, k: usize) -> crate::block::BlockId {
        crate::block::BlockId(self.voussoir(k) as u32)
    }

    /// The [`BlockId`](crate::block::BlockId)s of the left and right abutments, as
    /// [`Arch::voussoir_id`].
    pub fn abutment_ids(&self) -> [crate::block::BlockId; 2] {
        self.abutments().map(|i| crate::block::BlockId(i as u32))
    }

    /// Midpoint of the extrados chord of voussoir `k` at mid-width (m).
    pub fn extrados_midpoint(&self, k: usize) -> Vector {
        let k = self.voussoir(k);
        0.5 * (self.joints[k - 1].extrados + self.joints[k].extrados)
    }

    /// The joints as [`crate::analysis::JointRef`]s for the mechanism classifier, assuming the
    /// blocks were added to an empty model in [`Arch::blocks`] order.
    pub fn joint_refs(&self) -> Vec<crate::analysis::JointRef> {
        self.joints
            .iter()
            .map(|j| crate::analysis::JointRef {
                index: j.index,
                blocks: (
                    crate::block::BlockId(j.left as u32),
                    crate::block::BlockId(j.right as u32),
                ),
                intrados: j.intrados,
                extrados: j.extrados,
            })
            .collect()
    }

    /// Unit outward normal of the extrados face of voussoir `k`.
    pub fn extrados_normal(&self, k: usize) -> Vector {
        let k = self.voussoir(k);
        let chord = self.joints[k].extrados - self.joints[k - 1].extrados;
        Vector::new(-chord.y, chord.x, 0.0).normalize()
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::block::Block;

    /// The reference arch (`docs/benchmarks/arch-static.md`): joint coordinates, section area, load point, extrados slope.
    #[test]
    fn reference_arch_matches_the_benchmark_table() {
        let spec = ArchSpec::reference(0.15);
        assert!((spec.intrados_radius() - 0.65).abs() < 1e-12);
        assert!((spec.half_angle().to_degrees() - 67.3801).abs() < 1e-4);
        let table = [
            (0, -67.3801, (-0.60000, 0.00000), (-0.78462, 0.07692)),
            (4, -25.9154, (-0.28408, 0.33464), (-0.37149, 0.51452)),
            (5, -15.5493, (-0.17424, 0.37621), (-0.22786, 0.56889)),
            (13, 67.3801, (0.60000, 0.00000), (0.78462, 0.07692)),
        ];
        for (j, phi, i, e) in table {
            assert!((spec.joint_angle(j).to_degrees() - phi).abs() < 1e-4, "joint {j}");
            let (pi, pe) = spec.joint_points(j);
            // The table has 5 decimals.
            assert!(
                (pi.x - i.0).abs() < 6e-6 && (pi.y - i.1).abs() < 6e-6,
                "intrados {j}: {pi}"
            );
            assert!(
                (pe.x - e.0).abs() < 6e-6 && (pe.y - e.1).abs() < 6e-6,
                "extrados {j}: {pe}"
            );
        }
        let arch = Arch::new(&spec).unwrap();
        let v5 = &arch.blocks[arch.voussoir(5)];
        let area = v5.shape().volume() / 0.15;
        assert!((area - 0.026991).abs() < 1e-6, "section {area}");
        assert!((v5.mass_properties().mass - 9.905).abs() < 1e-3);
        let ring: f64 = (1..=13)
            .map(|k| arch.blocks[arch.voussoir(k)].mass_properties().mass)
            .sum();
        assert!((ring - 128.8).abs() < 0.05, "ring {ring}");
        let p = arch.extrados_midpoint(5);
        assert!((p.x + 0.29967).abs() < 6e-6 && (p.y - 0.54171).abs() < 6e-6, "{p}");
        assert!((p.x + 0.6 - 0.3003).abs() < 1e-4, "quarter span");
        let n = arch.extrados_normal(5);
        let slope = (-n.x).atan2(n.y).to_degrees();
        assert!((slope - 20.73).abs() < 0.01, "extrados slope {slope}");
        assert_eq!(arch.blocks.len(), 15);
        assert!(arch.blocks[0].fixity().is_fixed() && arch.blocks[14].fixity().is_fixed());
    }

    #[test]
    fn semicircular_arch_and_bad_input() {
        let spec = ArchSpec {
            span: 2.0,
            rise: 1.0,
            ..ArchSpec::reference(0.3)
        };
        assert!((spec.intrados_radius() - 1.0).abs() < 1e-12 && spec.centre_height().abs() < 1e-12);
        let arch = Arch::new(&spec).unwrap();
        let (i0, e0) = spec.joint_points(0);
        assert!((i0.x + 1.0).abs() < 1e-12 && i0.y.abs() < 1e-12 && (e0.x + 1.2).abs() < 1e-12);
        assert_eq!(arch.joints.len(), 14);
        let bad = ArchSpec { rise: 1.5, ..spec };
        assert!(matches!(Arch::new(&bad), Err(Error::InvalidParameter { .. })));
        let bad = ArchSpec { voussoirs: 1, ..spec };
        assert!(Arch::new(&bad).is_err());
    }
}
