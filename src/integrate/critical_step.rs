//! Critical time step of central difference for a block system on contact springs.

#[cfg(feature = "serde")]
use serde::{Deserialize, Serialize};

use crate::block::BlockId;
use crate::math::Real;

/// How the model chooses its time step.
#[derive(Debug, Clone, Copy, PartialEq)]
#[cfg_attr(feature = "serde", derive(Serialize, Deserialize))]
#[cfg_attr(feature = "serde", serde(deny_unknown_fields))]
pub enum TimeStep {
    /// `safety × critical step`, re-evaluated whenever contacts are re-detected.
    Auto {
        /// Fraction of the critical step, in `(0, 1]`. Default 0.5: the bound is exact for a
        /// block against a fixed support, and close to it central difference is stable but
        /// distorts the bouncing of contacts that open and close (a sliding block on an
        /// undamped incline errs by 24 % at 0.9, by < 0.01 % at 0.7 and 0.5).
        safety: Real,
    },
    /// A fixed step (s); an error if it exceeds the critical step.
    Fixed(Real),
}

/// The default safety factor of [`TimeStep::Auto`] ([`TimeStep::default`]).
pub const DEFAULT_SAFETY: Real = 0.5;

impl Default for TimeStep {
    fn default() -> Self {
        TimeStep::Auto { safety: DEFAULT_SAFETY }
    }
}

/// Upper bound of a block's squared natural frequency (rad²/s²), assembled from its contacts.
///
/// For a spring of stiffness `k` at lever arm `r` from the centroid, the compliance of a rigid
/// block in any direction is at most `c = 1/m + |r|²/I_min`. Summing `k·(c_self + c_other)` over
/// all springs acting on a block bounds the largest eigenvalue of `M⁻¹K` (a trace / Gershgorin
/// bound), so the estimate is safe with several contacts. Fixed or driven blocks have `c = 0`.
#[derive(Debug, Clone, Copy, PartialEq, Default)]
pub struct StiffnessBound {
    /// Sum of `k·(c_self + c_other)` (1/s²).
    pub omega_squared: Real,
}

/// The critical step and the block that sets it.
#[derive(Debug, Clone, Copy, PartialEq)]
#[cfg_attr(feature = "serde", derive(Serialize, Deserialize))]
pub struct CriticalStep {
    /// Critical time step with the damping correction (s).
    pub dt: Real,
    /// Highest natural frequency bound (rad/s).
    pub omega_max: Real,
    /// The block with the highest frequency.
    pub block: BlockId,
}

/// `Δt_crit = (2/ω_max)·(√(1+ξ²) − ξ)` with `ξ = b·ω_max/2` for stiffness-proportional damping
/// coefficient `b` (s). Returns `None` when no block has any stiffness.
///
/// ```
/// use voussoir::integrate::{critical_time_step, StiffnessBound};
/// let bounds = [StiffnessBound { omega_squared: 1e6 }, StiffnessBound { omega_squared: 4e6 }];
/// let c = critical_time_step(&bounds, 0.0).unwrap();
/// assert_eq!(c.block.0, 1);
/// assert!((c.dt - 1e-3).abs() < 1e-15); // 2 / 2000 rad/s
/// ```
pub fn critical_time_step(bounds: &[StiffnessBound], stiffness_damping: Real) -> Option<CriticalStep> {
    let (index, w2) = bounds
        .iter()
        .enumerate()
        .map(|(i, b)| (i, b.omega_squared))
        .fold((0, 0.0), |acc, x| if x.1 > acc.1 { x } else { acc });
    if w2 <= 0.0 {
        return None;
    }
    let w = w2.sqrt();
    let xi = 0.5 * stiffness_damping * w;
    Some(CriticalStep {
        dt: 2.0 / w * ((1.0 + xi * xi).sqrt() - xi),
        omega_max: w,
        block: BlockId(index as u32),
    })
}

/// A symmetric 6×6 matrix: the mass-normalised stiffness `M^{-1/2} K M^{-1/2}` of one block
/// (three translations, three rotations), assembled from rank-one spring terms.
#[derive(Debug, Clone, Copy, PartialEq, Default)]
pub struct Stiffness6(pub [[Real; 6]; 6]);

impl Stiffness6 {
    /// Adds `k · j jᵀ`.
    #[inline]
    pub fn add_spring(&mut self, j: &[Real; 6], k: Real) {
        for (r, row) in self.0.iter_mut().enumerate() {
            let kj = k * j[r];
            for (c, v) in row.iter_mut().enumerate() {
                *v += kj * j[c];
            }
        }
    }

    /// Adds another matrix.
    pub fn add(&mut self, other: &Stiffness6) {
        for r in 0..6 {
            for c in 0..6 {
                self.0[r][c] += other.0[r][c];
            }
        }
    }

    /// An upper bound of the largest eigenvalue, tight to about 1e-6: a few cyclic Jacobi
    /// rotations (a similarity transform, so the eigenvalues are unchanged) followed by the
    /// Gershgorin bound of the nearly diagonal result.
    ///
    /// ```
    /// use voussoir::integrate::Stiffness6;
    /// let mut k = Stiffness6::default();
    /// k.add_spring(&[1.0, 1.0, 0.0, 0.0, 0.0, 0.0], 2.0); // eigenvalue 2·|j|² = 4
    /// k.add_spring(&[0.0, 0.0, 0.0, 1.0, 0.0, 0.0], 3.0);
    /// let l = k.max_eigenvalue();
    /// assert!(l > 4.0 * (1.0 - 1e-12) && l < 4.0 * (1.0 + 1e-6));
    /// ```
    pub fn max_eigenvalue(&self) -> Real {
        Self::max_eigenvalues([self])[0]
    }

    /// [`Stiffness6::max_eigenvalue`] of `N` matrices at once, each to the same bits as alone:
    /// the same rotations in the same order on each, interleaved, so that the processor
    /// overlaps the divisions and square roots of one matrix's rotation with the other's (each
    /// rotation waits on the last; the critical step of a large model takes two per contact).
    pub(crate) fn max_eigenvalues<const N: usize>(matrices: [&Stiffness6; N]) -> [Real; N] {
        let mut a = matrices.map(|m| m.0);
        let gershgorin = |a: &[[Real; 6]; 6]| {
            (0..6)
                .map(|r| a[r][r] + (0..6).filter(|&c| c != r).map(|c| a[r][c].abs()).sum::<Real>())
                .fold(Real::NEG_INFINITY, Real::max)
        };
        let scale = a.map(|a| (0..6).map(|r| a[r][r].abs()).fold(0.0, Real::max));
        let mut active = [true; N];
        for _sweep in 0..8 {
            for k in 0..N {
                if active[k] {
                    let off: Real = (0..6)
                        .map(|r| (0..6).filter(|&c| c != r).map(|c| a[k][r][c].abs()).sum::<Real>())
                        .fold(0.0, Real::max);
                    // A NaN keeps rotating, as it did alone (`scale` is never NaN: `max`
                    // passes over NaNs).
                    active[k] = off > 1e-7 * scale[k] || off.is_nan();
                }
            }
            if !active.contains(&true) {
                break;
            }
            for p in 0..6 {
                for q in p + 1..6 {
                    // Each matrix's rotation first (their divisions and roots independent),
                    // then each applied.
                    let mut rotations = [None; N];
                    for ((a, on), rotation) in a.iter().zip(active).zip(&mut rotations) {
                        if !on || a[p][q].abs() <= 1e-300 {
                            continue;
                        }
                        let theta = (a[q][q] - a[p][p]) / (2.0 * a[p][q]);
                        let t = if theta == 0.0 {
                            1.0
                        } else {
                            theta.signum() / (theta.abs() + (theta * theta + 1.0).sqrt())
                        };
                        let c = 1.0 / (t * t + 1.0).sqrt();
                        *rotation = Some((c, t * c));
                    }
                    for (a, rotation) in a.iter_mut().zip(rotations) {
                        let Some((c, s)) = rotation else { continue };
                        for row in a.iter_mut() {
                            let (akp, akq) = (row[p], row[q]);
                            row[p] = c * akp - s * akq;
                            row[q] = s * akp + c * akq;
                        }
                        let (rp, rq) = (a[p], a[q]);
                        for k in 0..6 {
                            a[p][k] = c * rp[k] - s * rq[k];
                            a[q][k] = s * rp[k] + c * rq[k];
                        }
                    }
                }
            }
        }
        a.map(|a| gershgorin(&a))
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    /// The one-matrix Jacobi of earlier versions, kept as the reference of the interleaved one.
    fn reference(m: &Stiffness6) -> Real {
        let mut a = m.0;
        let gershgorin = |a: &[[Real; 6]; 6]| {
            (0..6)
                .map(|r| a[r][r] + (0..6).filter(|&c| c != r).map(|c| a[r][c].abs()).sum::<Real>())
                .fold(Real::NEG_INFINITY, Real::max)
        };
        let scale: Real = (0..6).map(|r| a[r][r].abs()).fold(0.0, Real::max);
        for _sweep in 0..8 {
            let off: Real = (0..6)
                .map(|r| (0..6).filter(|&c| c != r).map(|c| a[r][c].abs()).sum::<Real>())
                .fold(0.0, Real::max);
            if off <= 1e-7 * scale {
                break;
            }
            for p in 0..6 {
                for q in p + 1..6 {
                    if a[p][q].abs() <= 1e-300 {
                        continue;
                    }
                    let theta = (a[q][q] - a[p][p]) / (2.0 * a[p][q]);
                    let t = if theta == 0.0 {
                        1.0
                    } else {
                        theta.signum() / (theta.abs() + (theta * theta + 1.0).sqrt())
                    };
                    let c = 1.0 / (t * t + 1.0).sqrt();
                    let s = t * c;
                    for row in a.iter_mut() {
                        let (akp, akq) = (row[p], row[q]);
                        row[p] = c * akp - s * akq;
                        row[q] = s * akp + c * akq;
                    }
                    let (rp, rq) = (a[p], a[q]);
                    for k in 0..6 {
                        a[p][k] = c * rp[k] - s * rq[k];
                        a[q][k] = s * rp[k] + c * rq[k];
                    }
                }
            }
        }
        gershgorin(&a)
    }

    /// Several matrices at once give each the bits it gets alone, and alone the bits of the
    /// earlier one-matrix code: random mass-normalised stiffnesses of a few springs (rank one to
    /// full, scales from 1e-3 to 1e12), a zero matrix, a diagonal one and one with a NaN.
    #[test]
    fn interleaved_jacobi_is_the_single_one_to_the_bit() {
        let mut next = crate::math::test_uniform(0x2545_f491_4f6c_dd1d_u64);
        let mut matrices = vec![Stiffness6::default()];
        let mut diagonal = Stiffness6::default();
        for i in 0..6 {
            diagonal.0[i][i] = 1.0 + i as f64;
        }
        matrices.push(diagonal);
        for case in 0..400 {
            let mut m = Stiffness6::default();
            let scale = 10f64.powf(-3.0 + 15.0 * next());
            for _ in 0..1 + case % 8 {
                let j: [f64; 6] = std::array::from_fn(|_| next() - 0.5);
                m.add_spring(&j, scale * next());
            }
            matrices.push(m);
        }
        let mut nan = matrices[5];
        nan.0[2][3] = f64::NAN;
        matrices.push(nan);
        let bits = |x: f64| if x.is_nan() { u64::MAX } else { x.to_bits() };
        for pair in matrices.windows(2) {
            let [x, y] = Stiffness6::max_eigenvalues([&pair[0], &pair[1]]);
            let (rx, ry) = (reference(&pair[0]), reference(&pair[1]));
            assert_eq!((bits(x), bits(y)), (bits(rx), bits(ry)));
            assert_eq!(bits(pair[0].max_eigenvalue()), bits(rx));
        }
    }
}
