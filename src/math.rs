//! The one place where numerical precision is decided.
//!
//! voussoir is 3-D and `f64` throughout; all quantities are SI (m, kg, s, N, Pa).
//! The types are parry's own (which are glam's), so values pass to parry without conversion.

pub use parry3d_f64::math::{Matrix, Pose, Real, Rotation, Vector};

/// Returns `true` when every component of `v` is finite (neither NaN nor infinite).
#[inline]
pub fn is_finite_vector(v: Vector) -> bool {
    v.x.is_finite() && v.y.is_finite() && v.z.is_finite()
}

/// An orthonormal pair `(u, v)` spanning the plane perpendicular to the unit vector `n`,
/// such that `(u, v, n)` is right-handed.
#[inline]
pub fn plane_basis(n: Vector) -> (Vector, Vector) {
    let u = n.any_orthonormal_vector();
    (u, n.cross(u))
}
