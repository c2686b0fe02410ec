//! Force moments over a contact's anchor plane: how a contact's sub-contact forces sum to its
//! resultant, moment and work without visiting the sub-contacts again.

use crate::law::{JointAxes, JointForce};
use crate::math::{Real, Vector, Vector2};

/// Three world vectors tied to a contact's anchor plane: a value at the plane origin and its
/// rates along the plane axes — lever arms `R o`, `R u`, `R v` (host rotation `R`), or the
/// displacement increment `w_o`, `w_x`, `w_y` of the anchor `o + x u + y v`.
#[derive(Debug, Clone, Copy)]
pub(crate) struct Lever {
    pub origin: Vector,
    pub u: Vector,
    pub v: Vector,
}

/// Moments of a contact's sub-contact forces `Fᵢ` over the anchors' plane coordinates
/// `(xᵢ, yᵢ)` — world, or in the joint axes while the kernel sums them (see
/// [`ForceMoments::to_world`]): `F = Σ Fᵢ`, `F_x = Σ Fᵢ xᵢ`, `F_y = Σ Fᵢ yᵢ`. With anchors `o + x u + y v` they give
/// the moment about the host centroid, `Σ rᵢ × Fᵢ = R o × F + R u × F_x + R v × F_y`, and the work
/// over a displacement field affine in the plane coordinates,
/// `Σ Fᵢ·(w_o + xᵢ w_x + yᵢ w_y) = F·w_o + F_x·w_x + F_y·w_y`.
#[derive(Debug, Clone, Copy, PartialEq)]
pub(crate) struct ForceMoments {
    pub force: Vector,
    pub per_x: Vector,
    pub per_y: Vector,
}

impl Default for ForceMoments {
    fn default() -> Self {
        Self {
            force: Vector::ZERO,
            per_x: Vector::ZERO,
            per_y: Vector::ZERO,
        }
    }
}

impl ForceMoments {
    /// Adds force `f` at plane coordinates `c`.
    #[inline(always)]
    pub fn add(&mut self, f: Vector, c: Vector2) {
        self.force += f;
        self.per_x += f * c.x;
        self.per_y += f * c.y;
    }

    /// Adds a sub-contact's spring force in the joint axes, `(F_n, F_t₁, F_t₂)`, at plane
    /// coordinates `c` (for moments kept in the joint axes).
    #[inline(always)]
    pub fn add_joint(&mut self, f: &JointForce, c: Vector2) {
        self.add(Vector::new(f.normal, f.shear.x, f.shear.y), c);
    }

    /// These moments, kept in the joint `axes`, in world coordinates: `B = [n t₁ t₂]` applied
    /// to each.
    #[inline]
    pub(crate) fn to_world(self, axes: &JointAxes) -> Self {
        let (n, t1, t2) = (axes.normal, axes.tangent, axes.tangent_2());
        let world = |f: Vector| n * f.x + t1 * f.y + t2 * f.z;
        Self {
            force: world(self.force),
            per_x: world(self.per_x),
            per_y: world(self.per_y),
        }
    }

    /// Whether `self` and `other` agree to round-off (relative 1e-9 of the largest entry):
    /// the same moments summed in another order.
    #[cfg_attr(not(feature = "serde"), allow(dead_code))]
    pub fn matches(&self, other: &Self) -> bool {
        let entries = |m: &Self| [m.force, m.per_x, m.per_y];
        let scale = entries(self)
            .iter()
            .chain(entries(other).iter())
            .map(|v| v.abs().max_element())
            .fold(0.0, Real::max);
        let tolerance = 1e-9 * scale;
        entries(self).iter().all(|v| v.is_finite())
            && entries(self)
                .iter()
                .zip(entries(other).iter())
                .all(|(a, b)| (*a - *b).abs().max_element() <= tolerance)
    }

    pub(crate) fn plus(&self, other: &Self) -> Self {
        Self {
            force: self.force + other.force,
            per_x: self.per_x + other.per_x,
            per_y: self.per_y + other.per_y,
        }
    }

    /// `Σ Fᵢ·(w_o + xᵢ w_x + yᵢ w_y)`.
    #[inline]
    pub(crate) fn work(&self, w: &Lever) -> Real {
        (self.force.dot(w.origin) + self.per_x.dot(w.u)) + self.per_y.dot(w.v)
    }

    /// `Σ rᵢ × Fᵢ` for lever arms `rᵢ = R o + xᵢ R u + yᵢ R v`.
    #[inline]
    pub(crate) fn moment(&self, r: &Lever) -> Vector {
        (r.origin.cross(self.force) + r.u.cross(self.per_x)) + r.v.cross(self.per_y)
    }
}
