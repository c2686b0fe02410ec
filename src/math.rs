//! The one place where numerical precision is decided.
//!
//! voussoir is 3-D and `f64` throughout; all quantities are SI (m, kg, s, N, Pa).
//! The types are parry's own (which are glam's), so values pass to parry without conversion.

pub use parry3d_f64::math::{Matrix, Pose, Real, Rotation, Vector};

/// A 2-D vector: components in a joint's tangent plane, or coordinates on a contact's anchor plane.
pub type Vector2 = glam::DVec2;

/// Returns `true` when every component of `v` is finite (neither NaN nor infinite).
#[inline]
pub fn is_finite_vector(v: Vector) -> bool {
    v.x.is_finite() && v.y.is_finite() && v.z.is_finite()
}

/// Returns `true` for a pose with a finite translation and a finite unit rotation (to 1e-9,
/// as blocks are checked): what a file may hold.
#[inline]
#[cfg(feature = "serde")]
pub(crate) fn is_unit_pose(p: &Pose) -> bool {
    is_finite_vector(p.translation) && p.rotation.is_finite() && (p.rotation.length() - 1.0).abs() <= 1e-9
}

/// An orthonormal pair `(u, v)` spanning the plane perpendicular to the unit vector `n`,
/// such that `(u, v, n)` is right-handed.
#[inline]
pub fn plane_basis(n: Vector) -> (Vector, Vector) {
    let u = n.any_orthonormal_vector();
    (u, n.cross(u))
}

/// The rotation by the rotation vector `v` (axis × angle in rad), as [`Rotation::from_scaled_axis`]
/// but without trigonometric calls for the small angles of one time step: below 10⁻³ rad the
/// series of `sin(θ/2)/θ` and `cos(θ/2)` to the `θ⁶` term are exact to round-off (the next term is
/// below 10⁻²⁴ relative).
#[inline]
pub fn rotation_from_vector(v: Vector) -> Rotation {
    let theta2 = v.length_squared();
    if theta2 >= 1e-6 {
        return Rotation::from_scaled_axis(v);
    }
    // Reciprocals of the series' denominators: multiplications rather than divisions.
    const SIXTH: Real = 1.0 / 6.0;
    const TWENTIETH: Real = 1.0 / 20.0;
    const FORTY_SECOND: Real = 1.0 / 42.0;
    const TWELFTH: Real = 1.0 / 12.0;
    const THIRTIETH: Real = 1.0 / 30.0;
    let x2 = 0.25 * theta2; // (θ/2)²
    let half_sinc = 0.5 * (1.0 - x2 * SIXTH * (1.0 - x2 * TWENTIETH * (1.0 - x2 * FORTY_SECOND)));
    let cos = 1.0 - x2 * 0.5 * (1.0 - x2 * TWELFTH * (1.0 - x2 * THIRTIETH));
    let xyz = v * half_sinc;
    Rotation::from_xyzw(xyz.x, xyz.y, xyz.z, cos)
}

/// Deterministic pseudo-random numbers in `[0, 1)` for tests: xorshift64 from `seed`.
#[cfg(test)]
pub(crate) fn test_uniform(mut seed: u64) -> impl FnMut() -> Real {
    move || {
        seed ^= seed << 13;
        seed ^= seed >> 7;
        seed ^= seed << 17;
        (seed >> 11) as Real / (1u64 << 53) as Real
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn small_rotations_match_the_trigonometric_form() {
        for &angle in &[0.0, 1e-12, 1e-8, 3e-5, 4e-4, 9.99e-4, 1.01e-3, 0.3] {
            let v = Vector::new(0.3, -0.5, 0.81).normalize() * angle;
            let (a, b) = (rotation_from_vector(v), Rotation::from_scaled_axis(v));
            assert!((a.w - b.w).abs() < 1e-16, "{angle}: {a:?} {b:?}");
            assert!(
                (a.xyz() - b.xyz()).length() < 1e-16 * angle.max(1e-300) + 1e-300,
                "{angle}"
            );
            assert!((a.length() - 1.0).abs() < 2e-16, "{angle}");
        }
    }
}

/// A quantity from a quasi-static run and from the same run refined (half the increment and
/// threshold of a servo, or half the rate of a rate-loaded run): how far the answer is from
/// converged.
#[derive(Debug, Clone, Copy, PartialEq)]
#[cfg_attr(feature = "serde", derive(serde::Serialize, serde::Deserialize))]
pub struct Convergence {
    /// The quantity from the run.
    pub value: Real,
    /// The quantity from the refined run.
    pub refined: Real,
}

impl Convergence {
    /// `|refined − value| / |value|` (infinite for a zero `value` with a non-zero `refined`,
    /// zero when both are zero).
    pub fn relative_change(&self) -> Real {
        let change = (self.refined - self.value).abs();
        if change == 0.0 {
            0.0
        } else {
            change / self.value.abs()
        }
    }

    /// Whether the refinement moved the quantity by at most `tolerance` (relative).
    pub fn converged(&self, tolerance: Real) -> bool {
        self.relative_change() <= tolerance
    }
}
