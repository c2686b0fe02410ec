//! The stability limit of central difference on contact springs: each block's bound of its
//! squared natural frequency, assembled from the stiffness of its joints (block Gershgorin), and
//! the bound of a block in free flight. The integrator turns the bounds into its critical step
//! ([`super::Integrator::critical_step`]).

use super::{Stiffness6, StiffnessBound};
use crate::block::{Block, RigidBlock};
use crate::law::JointStiffness;
use crate::math::{Real, Vector};

/// What the stability bound needs of one contact: its blocks, normal, spring stiffness and the
/// area moments of its sub-contact points about `origin` (world).
#[derive(Debug, Clone, Copy)]
pub(crate) struct ContactStiffness {
    pub a: usize,
    pub b: usize,
    pub normal: Vector,
    pub stiffness: JointStiffness,
    pub origin: Vector,
    pub moments: AreaMoments,
}

/// The bound of block `i`, given its contacts in contact order, each with the largest
/// eigenvalues of its mass-normalised stiffness on its two blocks ([`contact_eigenvalues`]:
/// they do not depend on which block asks, so a caller evaluating every block computes them
/// once per contact): for a block in contact, the block Gershgorin bound
/// `λ ≤ λ_max(A_bb) + Σ_c √(λ_b λ_c)` of its mass-normalised contact stiffness; for a block
/// in free flight, that of a contact of stiffness `k_max` (`kn + 2 ks`, the stiffest law's) over
/// its largest face, so that its step is sensible when it lands (the landing contact is detected
/// before it loads, and the step is then re-evaluated from the real contacts); zero for a block
/// whose every degree of freedom is prescribed.
///
/// A block's bound depends only on its own contacts, so that the bounds of the blocks whose
/// contacts changed can be re-evaluated without the others, and all of them in parallel.
pub(crate) fn block_bound(
    blocks: &[RigidBlock],
    i: usize,
    contacts: impl Iterator<Item = (ContactStiffness, [Real; 2])>,
    k_max: Real,
) -> StiffnessBound {
    let b = &blocks[i];
    if all_constrained(b) {
        return StiffnessBound { omega_squared: 0.0 };
    }
    let mut own = Stiffness6::default();
    let mut coupling = 0.0;
    let mut in_contact = false;
    for (c, [la, lb]) in contacts {
        if let Some(m) = side_stiffness(blocks, &c, i) {
            own.add(&m);
        }
        coupling += (la * lb).sqrt();
        in_contact = true;
    }
    StiffnessBound {
        omega_squared: if in_contact {
            own.max_eigenvalue() + coupling
        } else {
            free_flight_bound(b, k_max)
        },
    }
}

/// Block `i`'s side of its contacts (in contact order): each one's largest eigenvalue on `i`
/// written into `eigenvalues` (the entry of [`contact_eigenvalues`] for `i`), and the largest
/// eigenvalue of their sum, the `λ_max(A_bb)` of [`block_bound`]; `None` for a block whose every
/// degree of freedom is prescribed (its eigenvalues zero, no contact assembled). With
/// [`bound_from_sides`], [`block_bound`] to the bit, each contact's side assembled once.
pub(crate) fn block_side(
    blocks: &[RigidBlock],
    i: usize,
    contacts: impl Iterator<Item = ContactStiffness>,
    eigenvalues: &mut [Real],
) -> Option<Real> {
    if all_constrained(&blocks[i]) {
        eigenvalues.fill(0.0);
        return None;
    }
    let mut own = Stiffness6::default();
    // Two sides' eigenvalues at a time ([`Stiffness6::max_eigenvalues`]; four were no faster
    // here), the last one with the block's own.
    let mut pending: Option<(Stiffness6, &mut Real)> = None;
    for (c, eigenvalue) in contacts.zip(eigenvalues) {
        let Some(m) = side_stiffness(blocks, &c, i) else {
            *eigenvalue = 0.0;
            continue;
        };
        own.add(&m);
        match pending.take() {
            Some((first, slot)) => {
                let [l0, l1] = Stiffness6::max_eigenvalues([&first, &m]);
                (*slot, *eigenvalue) = (l0.max(0.0), l1.max(0.0));
            }
            None => pending = Some((m, eigenvalue)),
        }
    }
    if let Some((m, slot)) = pending {
        let [l, own] = Stiffness6::max_eigenvalues([&m, &own]);
        *slot = l.max(0.0);
        return Some(own);
    }
    Some(own.max_eigenvalue())
}

/// The bound of block `i` from its [`block_side`] (`own`) and the eigenvalues of its contacts on
/// their two blocks, in contact order: what [`block_bound`] gives.
pub(crate) fn bound_from_sides(
    blocks: &[RigidBlock],
    i: usize,
    own: Option<Real>,
    contacts: impl Iterator<Item = [Real; 2]>,
    k_max: Real,
) -> StiffnessBound {
    let Some(own) = own else {
        return StiffnessBound { omega_squared: 0.0 };
    };
    let mut coupling = 0.0;
    let mut in_contact = false;
    for [la, lb] in contacts {
        coupling += (la * lb).sqrt();
        in_contact = true;
    }
    StiffnessBound {
        omega_squared: if in_contact {
            own + coupling
        } else {
            free_flight_bound(&blocks[i], k_max)
        },
    }
}

/// The largest eigenvalues of contact `c`'s mass-normalised stiffness on its blocks `a` and
/// `b` (zero on a block whose every degree of freedom is prescribed).
pub(crate) fn contact_eigenvalues(blocks: &[RigidBlock], c: &ContactStiffness) -> [Real; 2] {
    match (side_stiffness(blocks, c, c.a), side_stiffness(blocks, c, c.b)) {
        (Some(a), Some(b)) => Stiffness6::max_eigenvalues([&a, &b]).map(|l| l.max(0.0)),
        (a, b) => [a, b].map(|m| m.map_or(0.0, |m| m.max_eigenvalue().max(0.0))),
    }
}

/// Contact `c`'s mass-normalised stiffness on its block `j`, or `None` when every degree of
/// freedom of that block is prescribed.
fn side_stiffness(blocks: &[RigidBlock], c: &ContactStiffness, j: usize) -> Option<Stiffness6> {
    let block = &blocks[j];
    if all_constrained(block) {
        return None;
    }
    let k = c.stiffness;
    let centre = block.state.pose.translation - c.origin;
    Some(
        c.moments
            .stiffness(centre, c.normal, k.normal, k.shear, &Normalisation::of(block)),
    )
}

/// The bound of a block in free flight: a contact of stiffness `k_max` over its largest face.
fn free_flight_bound(b: &RigidBlock, k_max: Real) -> Real {
    let mp = b.mass_properties();
    let face = b.shape().faces().iter().map(|f| f.area).fold(0.0, Real::max);
    k_max * face * (1.0 / mp.mass + b.shape().radius().powi(2) / mp.principal_inertia.min_element())
}

/// The mass normalisation of one block's stiffness, `K ↦ T K Tᵀ`, restricted to its free
/// degrees of freedom: translations by `1/√m` (zero where prescribed), rotations by
/// `S P` with `S = R I^{-1/2} Rᵀ` and `P` zeroing the prescribed world rotations. The
/// eigenvalues of `S P K P S` are those of `K_FF (I⁻¹)_FF`, the free rotations' dynamics as
/// central difference integrates them (`ω = I⁻¹ L`, then the prescribed components
/// overwritten): a prescribed degree of freedom does not vibrate, and its stiffness must not
/// shorten the step (a loading plate with prescribed rotations would otherwise bound its
/// neighbour's frequency with a rotation that cannot happen).
#[derive(Debug, Clone, Copy)]
pub(crate) struct Normalisation {
    /// `1/√m` on each free world translation, zero on a prescribed one.
    pub translation: Vector,
    /// `S = R I^{-1/2} Rᵀ`.
    pub rotation: crate::math::Matrix,
    /// The diagonal of `P`: one on each free world rotation, zero on a prescribed one.
    pub free_rotations: Vector,
}

impl Normalisation {
    fn of(b: &RigidBlock) -> Self {
        use crate::math::Matrix;
        let mp = b.mass_properties();
        let f = b.fixity();
        let free = |dofs: &[crate::block::Dof; 3]| {
            Vector::from_array(dofs.map(|d| if d.prescribed().is_some() { 0.0 } else { 1.0 }))
        };
        let r = Matrix::from_quat(b.state.pose.rotation);
        let s = r * Matrix::from_diagonal(Vector::ONE / mp.principal_inertia.map(Real::sqrt)) * r.transpose();
        Self {
            translation: free(&f.translation) / mp.mass.sqrt(),
            rotation: s,
            free_rotations: free(&f.rotation),
        }
    }
}

fn all_constrained(b: &RigidBlock) -> bool {
    let f = b.fixity();
    f.translation
        .iter()
        .chain(&f.rotation)
        .all(|d| d.prescribed().is_some())
}

/// Zeroth, first and second area moments of a contact's sub-contact points: enough to assemble
/// the contact's 6×6 stiffness on either block exactly, since all its springs share `kn`, `ks`
/// and the normal.
#[derive(Debug, Clone, Copy)]
pub(crate) struct AreaMoments {
    s0: Real,
    s1: Vector,
    s2: crate::math::Matrix,
}

impl Default for AreaMoments {
    /// All zero (note: glam's `DMat3::default()` is the identity).
    fn default() -> Self {
        Self {
            s0: 0.0,
            s1: Vector::ZERO,
            s2: crate::math::Matrix::ZERO,
        }
    }
}

impl AreaMoments {
    /// The moments about the plane's origin of cells on a plane with world axes `u`, `v`, from
    /// their area moments in the plane's coordinates, `[Σ A, Σ A x, Σ A y, Σ A x², Σ A x y,
    /// Σ A y²]` (a face-face joint's [`crate::contact::CellSummary`]): with `r = x u + y v`,
    /// `Σ A r = u Σ A x + v Σ A y` and `Σ A r rᵀ = u uᵀ Σ A x² + (u vᵀ + v uᵀ) Σ A x y +
    /// v vᵀ Σ A y²`. What [`AreaMoments::add`] gives cell by cell, in a number of operations
    /// that does not depend on the cells (to round-off).
    pub(crate) fn of_plane(plane: [Real; 6], u: Vector, v: Vector) -> Self {
        let [a, ax, ay, axx, axy, ayy] = plane;
        let uv = outer(u, v);
        Self {
            s0: a,
            s1: u * ax + v * ay,
            s2: outer(u, u) * axx + (uv + uv.transpose()) * axy + outer(v, v) * ayy,
        }
    }

    pub(crate) fn add(&mut self, p: Vector, area: Real) {
        self.s0 += area;
        self.s1 += p * area;
        self.s2 += crate::math::Matrix::from_cols(p * (p.x * area), p * (p.y * area), p * (p.z * area));
    }

    /// `T K Tᵀ` of the contact's springs acting on a block with centroid `x`, `T` the block's
    /// [`Normalisation`] (`M^{-1/2}` on its free degrees of freedom): with
    /// `C = ks·I + (kn − ks)·n nᵀ` per unit area and `r = p − x`,
    /// `K = Σ A [C, C[r]ᵀ; [r]C, [r] C [r]ᵀ]` (`[r]` the cross-product matrix).
    pub(crate) fn stiffness(&self, x: Vector, n: Vector, kn: Real, ks: Real, scaling: &Normalisation) -> Stiffness6 {
        use crate::math::Matrix;
        let c = Matrix::from_diagonal(Vector::splat(ks)) + outer(n, n) * (kn - ks);
        // Moments about the centroid.
        let a0 = self.s0;
        let a1 = self.s1 - x * a0;
        let a2 = self.s2 - outer(self.s1, x) - outer(x, self.s1) + outer(x, x) * a0;
        let cross = |v: Vector| {
            Matrix::from_cols(
                Vector::new(0.0, v.z, -v.y),
                Vector::new(-v.z, 0.0, v.x),
                Vector::new(v.y, -v.x, 0.0),
            )
        };
        let k_tt = c * a0;
        // Σ A [r] C = [a1] C (linear in r).
        let k_rt = cross(a1) * c;
        // Σ A [r] C [r]ᵀ: with [r] = Σ_i r_i E_i, it is Σ_ij (A r_i r_j) E_i C E_jᵀ.
        let e = [cross(Vector::X), cross(Vector::Y), cross(Vector::Z)];
        let mut k_rr = Matrix::ZERO;
        for (i, ei) in e.iter().enumerate() {
            for (j, ej) in e.iter().enumerate() {
                k_rr += (*ei * c * ej.transpose()) * a2.col(j)[i];
            }
        }
        // Scale: translations by D = diag(1/√m), rotations by S P (zero where prescribed);
        // for a free block the products are those of `k/m`, `S k /√m` and `S k S`.
        let t = scaling.translation;
        let p = Matrix::from_diagonal(scaling.free_rotations);
        let (sp, ps) = (scaling.rotation * p, p * scaling.rotation);
        let tt = Matrix::from_cols(
            k_tt.x_axis * (t * t.x),
            k_tt.y_axis * (t * t.y),
            k_tt.z_axis * (t * t.z),
        );
        let rt = sp * k_rt * Matrix::from_diagonal(t);
        let rr = sp * k_rr * ps;
        let mut out = Stiffness6::default();
        for i in 0..3 {
            for j in 0..3 {
                out.0[i][j] = tt.col(j)[i];
                out.0[3 + i][j] = rt.col(j)[i];
                out.0[j][3 + i] = rt.col(j)[i];
                out.0[3 + i][3 + j] = rr.col(j)[i];
            }
        }
        out
    }
}

fn outer(a: Vector, b: Vector) -> crate::math::Matrix {
    crate::math::Matrix::from_cols(a * b.x, a * b.y, a * b.z)
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::math::Rotation;

    /// The moments from the anchor plane's are those of the cells summed one by one in the
    /// world, to round-off: random cells on randomly turned planes, about the plane's origin.
    #[test]
    fn plane_moments_are_the_cells_moments() {
        let mut next = crate::math::test_uniform(0x51_7cc1_b727_220a_u64);
        for _ in 0..200 {
            let turn = Rotation::from_scaled_axis(Vector::new(next() - 0.5, next() - 0.5, next() - 0.5) * 6.0);
            let (u, v) = (turn * Vector::X, turn * Vector::Y);
            let mut plane = [0.0; 6];
            let mut cells = AreaMoments::default();
            for _ in 0..1 + (next() * 40.0) as usize {
                let (x, y, a) = (next() * 0.4 - 0.1, next() * 0.2 - 0.05, next() * 1e-3);
                for (m, add) in plane.iter_mut().zip([a, a * x, a * y, a * x * x, a * x * y, a * y * y]) {
                    *m += add;
                }
                cells.add(u * x + v * y, a);
            }
            let from_plane = AreaMoments::of_plane(plane, u, v);
            let close = |p: Real, q: Real, scale: Real| (p - q).abs() <= 1e-13 * scale;
            assert!(close(from_plane.s0, cells.s0, cells.s0));
            let scale1 = cells.s0 * 0.4;
            for k in 0..3 {
                assert!(
                    close(from_plane.s1[k], cells.s1[k], scale1),
                    "{:?} vs {:?}",
                    from_plane.s1,
                    cells.s1
                );
                for l in 0..3 {
                    let (p, q) = (from_plane.s2.col(l)[k], cells.s2.col(l)[k]);
                    assert!(close(p, q, cells.s0 * 0.16), "{p} vs {q}");
                }
            }
        }
    }

    /// The moment-based assembly equals the sum of rank-one spring terms.
    #[test]
    fn area_moments_assemble_the_spring_stiffness() {
        let n = Vector::new(0.3, -0.2, 0.9).normalize();
        let (kn, ks) = (4e9, 1.6e9);
        let rot = Rotation::from_scaled_axis(Vector::new(0.2, -0.4, 0.7));
        let (inv_sqrt_m, inv_sqrt_i) = (1.0 / 3.0, Vector::new(2.0, 3.0, 5.0));
        let x = Vector::new(0.1, 0.5, -0.2);
        let pts = [
            (Vector::new(0.3, 0.1, 0.4), 0.01),
            (Vector::new(-0.2, 0.3, 0.1), 0.02),
            (Vector::new(0.05, -0.3, 0.2), 0.005),
        ];
        let mut m = AreaMoments::default();
        let mut direct = Stiffness6::default();
        let (t1, t2) = crate::math::plane_basis(n);
        let s = crate::math::Matrix::from_quat(rot)
            * crate::math::Matrix::from_diagonal(inv_sqrt_i)
            * crate::math::Matrix::from_quat(rot).transpose();
        for (p, a) in pts {
            m.add(p, a);
            for (d, k) in [(n, kn), (t1, ks), (t2, ks)] {
                let t = d * inv_sqrt_m;
                let w = s * (p - x).cross(d);
                direct.add_spring(&[t.x, t.y, t.z, w.x, w.y, w.z], k * a);
            }
        }
        let scaling = Normalisation {
            translation: Vector::splat(inv_sqrt_m),
            rotation: s,
            free_rotations: Vector::ONE,
        };
        let assembled = m.stiffness(x, n, kn, ks, &scaling);
        for i in 0..6 {
            for j in 0..6 {
                let (u, v) = (assembled.0[i][j], direct.0[i][j]);
                assert!(
                    (u - v).abs() <= 1e-9 * direct.0[i][i].abs().max(1.0),
                    "({i},{j}): {u} vs {v}"
                );
            }
        }
        assert!((assembled.max_eigenvalue() - direct.max_eigenvalue()).abs() < 1e-6 * direct.max_eigenvalue());
    }

    /// A prescribed degree of freedom does not vibrate. A cube on a fixed base (the base adds
    /// no coupling) is bounded with its rotations prescribed by its translations alone, exactly
    /// `kn·A/m`; with them free, by its rocking too (`kn·I_A/I` about an edge of the face is
    /// above `kn·A/m` for a cube), and with one of them prescribed, in between.
    #[test]
    fn prescribed_degrees_of_freedom_do_not_bound_the_step() {
        use crate::block::{Dof, Fixity, RigidBlock};
        use crate::law::JointStiffness;
        let (kn, ks) = (1e9, 0.4e9);
        let base = RigidBlock::cuboid(
            "base",
            Vector::new(-1.0, -1.0, -0.1),
            Vector::new(1.0, 1.0, 0.0),
            2500.0,
        )
        .expect("base")
        .with_fixity(Fixity::FIXED);
        let cube =
            RigidBlock::cuboid("cube", Vector::new(-0.1, -0.1, 0.0), Vector::new(0.1, 0.1, 0.2), 2500.0).expect("cube");
        let mass = cube.mass_properties().mass;
        let mut moments = AreaMoments::default();
        for i in 0..3 {
            for j in 0..3 {
                let p = Vector::new(-0.1 + 0.1 * i as Real, -0.1 + 0.1 * j as Real, 0.0);
                moments.add(p, 0.04 / 9.0);
            }
        }
        let contact = ContactStiffness {
            a: 0,
            b: 1,
            normal: Vector::Z,
            stiffness: JointStiffness { normal: kn, shear: ks },
            origin: Vector::ZERO,
            moments,
        };
        let bound = |rotation: [Dof; 3]| {
            let fixity = Fixity {
                rotation,
                ..Fixity::FREE
            };
            let blocks = [base.clone(), cube.clone().with_fixity(fixity)];
            let k_max = kn + 2.0 * ks;
            let with = [(contact, contact_eigenvalues(&blocks, &contact))];
            assert_eq!(block_bound(&blocks, 0, with.into_iter(), k_max).omega_squared, 0.0);
            block_bound(&blocks, 1, with.into_iter(), k_max).omega_squared
        };
        let translations_only = bound([Dof::Fixed; 3]);
        let expected = kn * 0.04 / mass;
        assert!(
            (translations_only - expected).abs() < 1e-9 * expected,
            "{translations_only} vs kn·A/m = {expected}"
        );
        let one_free = bound([Dof::Fixed, Dof::Free, Dof::Fixed]);
        let all_free = bound([Dof::Free; 3]);
        assert!(
            translations_only < one_free && one_free <= all_free * (1.0 + 1e-12),
            "{translations_only} < {one_free} <= {all_free}"
        );
    }
}
