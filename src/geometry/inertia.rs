//! The volume, centroid and inertia tensor of a closed triangulated surface, and the principal
//! axes of a symmetric tensor.
//!
//! voussoir computes both itself rather than through parry's `MassProperties`: parry3d-f64
//! 0.31.1 diagonalises the tensor with glamx 0.3.1's `DSymmetricEigen3`, which returns the x axis
//! as an eigenvector when the squared cross products of the tensor's rows fall below an absolute
//! 1e-20 (always so for small blocks' unit-density tensors, m⁵) and assumes the smallest
//! eigenvalue simple (wrong for oblate blocks at any scale). Blocks turned off the world axes got
//! inertia tensors wrong by up to 69 % of their largest moment (`docs/parry-issue-inertia.md`).
//!
//! The equations are in `docs/theory.md` §1.2 (mass properties).

use crate::math::{Matrix, Real, Rotation, Vector};

/// Volume, centroid and inertia per unit density of a closed solid.
#[derive(Debug, Clone, Copy)]
pub(crate) struct VolumeMoments {
    /// Volume (m³), positive.
    pub volume: Real,
    /// Centroid, in the coordinates of the points given.
    pub centroid: Vector,
    /// Inertia tensor per unit density about the centroid (m⁵), in the axes of the points given.
    pub inertia: Matrix,
}

/// The zeroth, first and second moments of the solid bounded by `tris` (outward or inward
/// oriented, consistently) about the point `origin`: each triangle `(a, b, c)` with the origin
/// spans a tetrahedron of signed volume `a·(b×c)/6`, first moment `det/24·(a+b+c)` and
/// covariance `det/120·(aaᵀ + bbᵀ + ccᵀ + ssᵀ)` with `s = a+b+c` (the canonical tetrahedron's
/// covariance mapped by the affine map of the tetrahedron).
fn moments_about(points: &[Vector], tris: &[[u32; 3]], origin: Vector) -> (Real, Vector, Matrix) {
    let mut det_sum = 0.0;
    let mut first = Vector::ZERO;
    let mut covariance = Matrix::ZERO;
    for t in tris {
        let [a, b, c] = t.map(|i| points[i as usize] - origin);
        let det = a.dot(b.cross(c));
        let s = a + b + c;
        det_sum += det;
        first += det * s;
        let outer = |u: Vector| Matrix::from_cols(u * u.x, u * u.y, u * u.z);
        covariance += (outer(a) + outer(b) + outer(c) + outer(s)) * det;
    }
    (det_sum / 6.0, first / 24.0, covariance / 120.0)
}

/// The volume moments of the solid bounded by the triangles `tris` over `points`. The second
/// pass is taken about the centroid found by the first, so that the tensor keeps its digits for
/// a block far from the points' origin.
pub(crate) fn volume_moments(points: &[Vector], tris: &[[u32; 3]]) -> VolumeMoments {
    let reference = points.iter().copied().sum::<Vector>() / points.len().max(1) as Real;
    let (volume, first, _) = moments_about(points, tris, reference);
    let centroid = reference + first / volume;
    let (volume, first, covariance) = moments_about(points, tris, centroid);
    // The residual first moment (round-off) moves the centroid once more, by parallel axes.
    let shift = first / volume;
    let centroid = centroid + shift;
    let covariance = covariance - Matrix::from_cols(shift * shift.x, shift * shift.y, shift * shift.z) * volume;
    // Inward-oriented triangles give all three moments with a negative sign.
    let (volume, covariance) = if volume < 0.0 {
        (-volume, -covariance)
    } else {
        (volume, covariance)
    };
    let trace = covariance.x_axis.x + covariance.y_axis.y + covariance.z_axis.z;
    VolumeMoments {
        volume,
        centroid,
        inertia: Matrix::from_diagonal(Vector::splat(trace)) - covariance,
    }
}

/// The eigenvalues and eigenvectors of the symmetric matrix `a` by cyclic Jacobi rotations:
/// `a = R·diag(λ)·Rᵀ` with `R` a proper rotation (the product of plane rotations, so
/// `det R = +1`) whose columns are the eigenvectors. Exact to round-off at every scale (every
/// test is relative) and for repeated eigenvalues (a multiple eigenvalue needs no rotation in
/// its plane; any orthonormal pair there is right). A diagonal matrix returns the identity.
pub(crate) fn symmetric_eigen(a: Matrix) -> (Vector, Rotation) {
    // Row-major working copy; `a` is symmetric, so rows and columns agree.
    let mut m = a.to_cols_array_2d();
    for (i, j) in [(1, 0), (2, 0), (2, 1)] {
        let mean = 0.5 * (m[i][j] + m[j][i]);
        m[i][j] = mean;
        m[j][i] = mean;
    }
    let mut v = [[1.0, 0.0, 0.0], [0.0, 1.0, 0.0], [0.0, 0.0, 1.0]];
    // Quadratic convergence: a 3×3 matrix needs 4–6 sweeps; the cap only guards NaN input.
    for _sweep in 0..64 {
        if m[0][1] == 0.0 && m[0][2] == 0.0 && m[1][2] == 0.0 {
            break;
        }
        for (p, q) in [(0, 1), (0, 2), (1, 2)] {
            let apq = m[p][q];
            if apq == 0.0 {
                continue;
            }
            let (app, aqq) = (m[p][p], m[q][q]);
            // At the round-off of the tensor's own sums (a few ulps of its diagonal): zero it.
            // Rotating by it would turn the axes of an isotropic or oblate block (a cube's) by an
            // arbitrary angle for nothing; leaving it changes `R·diag(λ)·Rᵀ` by at most
            // 16ε·(|a_pp| + |a_qq|).
            if apq.abs() <= 16.0 * Real::EPSILON * (app.abs() + aqq.abs()) {
                m[p][q] = 0.0;
                m[q][p] = 0.0;
                continue;
            }
            let theta = (aqq - app) / (2.0 * apq);
            // The smaller root of t² + 2θt − 1 = 0 (|rotation| ≤ 45°); 1/(2θ) where θ² overflows.
            let t = if theta.abs() > 1e150 {
                0.5 / theta
            } else {
                theta.signum() / (theta.abs() + (theta * theta + 1.0).sqrt())
            };
            let c = 1.0 / (t * t + 1.0).sqrt();
            let s = t * c;
            // A ← Pᵀ A P with P the rotation in the (p, q) plane: columns, then rows.
            for row in &mut m {
                let (kp, kq) = (row[p], row[q]);
                row[p] = c * kp - s * kq;
                row[q] = s * kp + c * kq;
            }
            let (row_p, row_q) = (m[p], m[q]);
            m[p] = std::array::from_fn(|k| c * row_p[k] - s * row_q[k]);
            m[q] = std::array::from_fn(|k| s * row_p[k] + c * row_q[k]);
            m[p][q] = 0.0;
            m[q][p] = 0.0;
            for row in &mut v {
                let (kp, kq) = (row[p], row[q]);
                row[p] = c * kp - s * kq;
                row[q] = s * kp + c * kq;
            }
        }
    }
    let eigenvalues = Vector::new(m[0][0], m[1][1], m[2][2]);
    let column = |j: usize| Vector::new(v[0][j], v[1][j], v[2][j]);
    let rotation = Rotation::from_mat3(&Matrix::from_cols(column(0), column(1), column(2))).normalize();
    (eigenvalues, rotation)
}

#[cfg(test)]
mod tests {
    use super::*;

    /// `R·diag(λ)·Rᵀ` against `a`, relative to the largest entry of `a`.
    fn reconstruction_error(a: Matrix, lambda: Vector, r: Rotation) -> Real {
        let rm = Matrix::from_quat(r);
        let back = rm * Matrix::from_diagonal(lambda) * rm.transpose();
        let scale = a.to_cols_array().iter().fold(0.0, |s: Real, x| s.max(x.abs()));
        (back - a).to_cols_array().iter().fold(0.0, |s: Real, x| s.max(x.abs())) / scale
    }

    /// A small deterministic generator (no dependency for a unit test).
    fn lcg(state: &mut u64) -> Real {
        *state = state
            .wrapping_mul(6364136223846793005)
            .wrapping_add(1442695040888963407);
        (*state >> 11) as Real / (1u64 << 53) as Real
    }

    fn random_rotation(state: &mut u64) -> Rotation {
        let axis = Vector::new(lcg(state) - 0.5, lcg(state) - 0.5, lcg(state) - 0.5).normalize();
        Rotation::from_axis_angle(axis, 6.0 * lcg(state))
    }

    #[test]
    fn jacobi_reconstructs_tensors_at_every_scale_and_multiplicity() {
        let mut state = 7;
        // Distinct, oblate (two equal), prolate, isotropic and nearly repeated spectra, from the
        // m⁵ tensors of millimetre blocks (1e-15) to those of 10 m blocks (1e5).
        let spectra = [
            Vector::new(1.0, 2.0, 3.0),
            Vector::new(1.0, 1.0, 2.0),
            Vector::new(2.0, 1.0, 1.0),
            Vector::new(1.0, 1.0, 1.0),
            Vector::new(1.0, 1.0 + 1e-9, 1.0 - 1e-9),
            Vector::new(1.0, 1e-6, 1.0),
        ];
        for scale in [1e-18, 1e-15, 1e-9, 1.0, 1e5, 1e12] {
            for lambda in spectra {
                for _ in 0..50 {
                    let r = random_rotation(&mut state);
                    let rm = Matrix::from_quat(r);
                    let a = rm * Matrix::from_diagonal(lambda * scale) * rm.transpose();
                    let (found, frame) = symmetric_eigen(a);
                    let err = reconstruction_error(a, found, frame);
                    assert!(err < 1e-14, "{lambda:?}×{scale:e}: error {err:e}");
                    let mut sorted = found.to_array();
                    sorted.sort_by(Real::total_cmp);
                    let mut expected = (lambda * scale).to_array();
                    expected.sort_by(Real::total_cmp);
                    for k in 0..3 {
                        assert!((sorted[k] - expected[k]).abs() <= 1e-14 * scale * lambda.max_element());
                    }
                }
            }
        }
    }

    #[test]
    fn a_diagonal_tensor_keeps_its_axes() {
        let (lambda, frame) = symmetric_eigen(Matrix::from_diagonal(Vector::new(3.0, 1.0, 2.0)));
        assert_eq!(lambda, Vector::new(3.0, 1.0, 2.0));
        assert_eq!(frame, Rotation::IDENTITY);
    }

    #[test]
    fn a_turned_box_has_the_rotated_closed_form_tensor() {
        // Box a × b × c: I = V/12·diag(b²+c², a²+c², a²+b²), turned and moved far away.
        let (a, b, c) = (0.05, 0.1, 0.15);
        let corners: Vec<Vector> = (0..8)
            .map(|i| {
                Vector::new(
                    ((i & 1) as Real - 0.5) * a,
                    ((i >> 1 & 1) as Real - 0.5) * b,
                    ((i >> 2) as Real - 0.5) * c,
                )
            })
            .collect();
        // Outward triangles of the box (two per face).
        let quads = [
            [0, 2, 3, 1],
            [4, 5, 7, 6],
            [0, 1, 5, 4],
            [2, 6, 7, 3],
            [0, 4, 6, 2],
            [1, 3, 7, 5],
        ];
        let tris: Vec<[u32; 3]> = quads
            .iter()
            .flat_map(|q| [[q[0], q[1], q[2]], [q[0], q[2], q[3]]])
            .collect();
        let r = Rotation::from_axis_angle(Vector::new(0.2, 0.3, 1.0).normalize(), 0.52);
        let offset = Vector::new(1e3, -2e3, 5e2);
        let placed: Vec<Vector> = corners.iter().map(|p| r * *p + offset).collect();
        let vm = volume_moments(&placed, &tris);
        let volume = a * b * c;
        // The placed corners are rounded by ε·|offset| ≈ 2.5e-13 m, 5e-12 of the shortest edge.
        assert!(
            (vm.volume - volume).abs() < 1e-10 * volume,
            "{}",
            vm.volume / volume - 1.0
        );
        assert!((vm.centroid - offset).length() < 1e-12 * offset.length());
        let principal = Vector::new(b * b + c * c, a * a + c * c, a * a + b * b) * volume / 12.0;
        let rm = Matrix::from_quat(r);
        let expected = rm * Matrix::from_diagonal(principal) * rm.transpose();
        let err = (vm.inertia - expected)
            .to_cols_array()
            .iter()
            .fold(0.0, |s: Real, x| s.max(x.abs()));
        assert!(err < 1e-9 * principal.max_element(), "error {err:e}");
    }
}
