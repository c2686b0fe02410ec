//! A joint closed everywhere (a joint at rest), four cells at a time: each cell's force is the
//! elastic regime's step at its anchor gap ([`ElasticRegime::step`]), computed lane-wise.
//!
//! Two builds of the same operations: [`closed_groups_portable`], on arrays of four, and
//! `closed_groups_avx2`, on AVX registers, whose lanes do the same IEEE operations in the same
//! order (no fused multiply-add), so that both give the bits of the one-at-a-time way
//! (`elastic.rs`) for every cell, and the same sums as each other. The forces enter the
//! contact's sums per lane (the lanes added in order at the end, [`LaneSums::total`]); the
//! energy the slides dissipated is added in cell order.
//!
//! The sub-contacts are stored one after the other (an array of structures), so the AVX build
//! gathers a field of four cells from four places; what it saves is the arithmetic, the tests
//! and the sums, done once for four cells.

use super::lanes::{face_gap, increment, Kinematics, LaneSums, F4, LANES};
use super::SubContact;
use crate::law::{ElasticRegime, JointForce, JointStatus};
use crate::math::{Real, Vector2};

/// How a contact's all-closed cells are computed: with AVX (the processor has it, and the
/// contact pass runs its AVX2 build) or on arrays.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub(crate) enum LaneBuild {
    Portable,
    #[cfg_attr(not(target_arch = "x86_64"), allow(dead_code))]
    Avx2,
}

/// What the cells of a joint closed everywhere share: the elastic regime of its law, its
/// kinematics, its gap coefficients (`face_gap`) and its law's virgin state.
#[derive(Clone, Copy)]
pub(crate) struct ClosedJoint<'a, S> {
    pub regime: &'a ElasticRegime,
    pub kinematics: &'a Kinematics,
    pub gap: (Real, Real, Real),
    pub virgin: &'a S,
}

/// The cells' groups of four, in order, while every cell of a group is `virgin` and in the
/// regime (in compression; within the strength, or sliding in a regime that slides): each such
/// group's cells get the regime's step (forces, gap, status, slip) and their forces enter
/// `sums`. Returns how many groups were done; the group that stopped it is left untouched.
#[inline(always)]
pub(crate) fn closed_groups<S: PartialEq>(
    build: LaneBuild,
    groups: &mut [[SubContact<S>; LANES]],
    joint: &ClosedJoint<'_, S>,
    sums: &mut LaneSums,
    dissipated: &mut Real,
) -> usize {
    #[cfg(target_arch = "x86_64")]
    if build == LaneBuild::Avx2 {
        // SAFETY: `Avx2` is chosen only by the contact pass's AVX2 build, which runs where the
        // processor has AVX2 (`dispatch::has_avx2`).
        return unsafe { avx2::closed_groups_avx2(groups, joint, sums, dissipated) };
    }
    let _ = build;
    closed_groups_portable(groups, joint, sums, dissipated)
}

/// [`closed_groups`] on arrays of four.
#[inline(always)]
fn closed_groups_portable<S: PartialEq>(
    groups: &mut [[SubContact<S>; LANES]],
    joint: &ClosedJoint<'_, S>,
    sums: &mut LaneSums,
    dissipated: &mut Real,
) -> usize {
    for (done, group) in groups.iter_mut().enumerate() {
        if !closed_group(group, joint, sums, dissipated) {
            return done;
        }
    }
    groups.len()
}

/// One group of [`closed_groups_portable`]; `false` (nothing written) when a cell does not fit.
#[inline(always)]
fn closed_group<S: PartialEq>(
    group: &mut [SubContact<S>; LANES],
    joint: &ClosedJoint<'_, S>,
    sums: &mut LaneSums,
    dissipated: &mut Real,
) -> bool {
    let (regime, k, g) = (joint.regime, joint.kinematics, joint.gap);
    if group.iter().any(|s| s.state != *joint.virgin) {
        return false;
    }
    let x = F4::from_fn(|l| group[l].plane.x);
    let y = F4::from_fn(|l| group[l].plane.y);
    let area = F4::from_fn(|l| group[l].area);
    let [_, du_1, du_2] = increment(k, x, y);
    let gap = face_gap(g, x, y);
    // As `ElasticRegime::step`: `(−k_n g) A`, `F_s − Δu_s (k_s A)`, `c A + F_n tan φ`.
    let normal = F4::splat(-regime.normal_stiffness) * gap * area;
    let ks_area = F4::splat(regime.shear_stiffness) * area;
    let before = [
        F4::from_fn(|l| group[l].force.shear.x),
        F4::from_fn(|l| group[l].force.shear.y),
    ];
    let trial = [before[0] - du_1 * ks_area, before[1] - du_2 * ks_area];
    let limit = F4::splat(regime.cohesion) * area + normal * F4::splat(regime.tan_friction);
    let trial_squared = trial[0] * trial[0] + trial[1] * trial[1];
    // No compression (or NaN) in a lane: the law decides.
    if !normal.0.iter().all(|&n| n > 0.0) {
        return false;
    }
    let sliding: [bool; LANES] =
        std::array::from_fn(|l| limit.0[l] < 0.0 || trial_squared.0[l] > limit.0[l] * limit.0[l]);
    let mut shear = trial;
    if sliding.contains(&true) {
        if !regime.slides {
            return false;
        }
        // The trial shear scaled back onto the strength where it slides.
        let scale = F4::from_fn(|l| {
            let trial = trial_squared.0[l].sqrt();
            if trial > 0.0 {
                limit.0[l].max(0.0) / trial
            } else {
                0.0
            }
        });
        for (s, t) in shear.iter_mut().zip(trial) {
            *s = F4::from_fn(|l| if sliding[l] { t.0[l] * scale.0[l] } else { t.0[l] });
        }
        // As `slide_dissipation` (elastic.rs): the shear spring's work less its energy change.
        let work = F4::splat(-0.5) * ((before[0] + shear[0]) * du_1 + (before[1] + shear[1]) * du_2);
        let change = (shear[0] * shear[0] + shear[1] * shear[1]) - (before[0] * before[0] + before[1] * before[1]);
        let slip = du_1 * du_1 + du_2 * du_2;
        for (l, sub) in group.iter_mut().enumerate() {
            if sliding[l] {
                *dissipated += if ks_area.0[l] > 0.0 {
                    work.0[l] - 0.5 * change.0[l] / ks_area.0[l]
                } else {
                    work.0[l]
                };
                sub.slip += slip.0[l].sqrt();
            }
        }
    }
    for (l, sub) in group.iter_mut().enumerate() {
        sub.force = JointForce {
            normal: normal.0[l],
            shear: Vector2::new(shear[0].0[l], shear[1].0[l]),
        };
        sub.gap = gap.0[l];
        sub.status = if sliding[l] {
            JointStatus::Sliding
        } else {
            JointStatus::Elastic
        };
    }
    sums.add([normal, shear[0], shear[1]], x, y);
    true
}

#[cfg(target_arch = "x86_64")]
mod avx2 {
    use std::arch::x86_64::*;

    use super::super::lanes::{LaneSums, F4, LANES};
    use super::super::SubContact;
    use super::ClosedJoint;
    use crate::law::JointStatus;
    use crate::math::{Real, Vector2};

    /// Four `(x, y)` pairs (one per cell) as the vectors of the four `x` and the four `y`.
    #[inline(always)]
    unsafe fn gather_pairs(p: [&Vector2; LANES]) -> (__m256d, __m256d) {
        let load = |v: &Vector2| _mm_loadu_pd(std::ptr::from_ref(v).cast::<Real>());
        let even = _mm256_insertf128_pd(_mm256_castpd128_pd256(load(p[0])), load(p[2]), 1);
        let odd = _mm256_insertf128_pd(_mm256_castpd128_pd256(load(p[1])), load(p[3]), 1);
        (_mm256_unpacklo_pd(even, odd), _mm256_unpackhi_pd(even, odd))
    }

    /// The four lanes of `v`, in order.
    #[inline(always)]
    unsafe fn lanes(v: __m256d) -> [Real; LANES] {
        let mut out = [0.0; LANES];
        _mm256_storeu_pd(out.as_mut_ptr(), v);
        out
    }

    #[inline(always)]
    unsafe fn load(v: &F4) -> __m256d {
        _mm256_loadu_pd(v.0.as_ptr())
    }

    #[inline(always)]
    unsafe fn store(v: __m256d, to: &mut F4) {
        _mm256_storeu_pd(to.0.as_mut_ptr(), v);
    }

    /// [`super::closed_groups`] on AVX registers: per lane, the operations of the portable
    /// build in its order.
    ///
    /// # Safety
    /// The processor must support AVX2.
    #[target_feature(enable = "avx2")]
    pub(super) unsafe fn closed_groups_avx2<S: PartialEq>(
        groups: &mut [[SubContact<S>; LANES]],
        joint: &ClosedJoint<'_, S>,
        sums: &mut LaneSums,
        dissipated: &mut Real,
    ) -> usize {
        let (regime, k, g, virgin) = (joint.regime, joint.kinematics, joint.gap, joint.virgin);
        let splat = |v: Real| _mm256_set1_pd(v);
        let (o1, px1, py1) = (splat(k.at_origin.y), splat(k.per_x.y), splat(k.per_y.y));
        let (o2, px2, py2) = (splat(k.at_origin.z), splat(k.per_x.z), splat(k.per_y.z));
        let (g0, gx, gy) = (splat(g.0), splat(g.1), splat(g.2));
        let (minus_kn, ks) = (splat(-regime.normal_stiffness), splat(regime.shear_stiffness));
        let (cohesion, tan_friction) = (splat(regime.cohesion), splat(regime.tan_friction));
        let (zero, minus_half, half) = (_mm256_setzero_pd(), splat(-0.5), splat(0.5));
        let (mut force, mut per_x, mut per_y) = (
            sums.force.each_ref().map(|v| load(v)),
            sums.per_x.each_ref().map(|v| load(v)),
            sums.per_y.each_ref().map(|v| load(v)),
        );
        let mut done = 0;
        for group in groups.iter_mut() {
            if group.iter().any(|s| s.state != *virgin) {
                break;
            }
            let (x, y) = gather_pairs([&group[0].plane, &group[1].plane, &group[2].plane, &group[3].plane]);
            let (bx, by) = gather_pairs([
                &group[0].force.shear,
                &group[1].force.shear,
                &group[2].force.shear,
                &group[3].force.shear,
            ]);
            let area = _mm256_set_pd(group[3].area, group[2].area, group[1].area, group[0].area);
            // `increment`: (o + p_x x) + p_y y; `face_gap`: (g_o − g_x x) − g_y y.
            let du_1 = _mm256_add_pd(_mm256_add_pd(o1, _mm256_mul_pd(px1, x)), _mm256_mul_pd(py1, y));
            let du_2 = _mm256_add_pd(_mm256_add_pd(o2, _mm256_mul_pd(px2, x)), _mm256_mul_pd(py2, y));
            let gap = _mm256_sub_pd(_mm256_sub_pd(g0, _mm256_mul_pd(gx, x)), _mm256_mul_pd(gy, y));
            let normal = _mm256_mul_pd(_mm256_mul_pd(minus_kn, gap), area);
            let ks_area = _mm256_mul_pd(ks, area);
            let tx = _mm256_sub_pd(bx, _mm256_mul_pd(du_1, ks_area));
            let ty = _mm256_sub_pd(by, _mm256_mul_pd(du_2, ks_area));
            let limit = _mm256_add_pd(_mm256_mul_pd(cohesion, area), _mm256_mul_pd(normal, tan_friction));
            let trial_squared = _mm256_add_pd(_mm256_mul_pd(tx, tx), _mm256_mul_pd(ty, ty));
            // No compression (or NaN) in a lane: the law decides.
            if _mm256_movemask_pd(_mm256_cmp_pd::<_CMP_GT_OQ>(normal, zero)) != 0b1111 {
                break;
            }
            let sliding = _mm256_or_pd(
                _mm256_cmp_pd::<_CMP_LT_OQ>(limit, zero),
                _mm256_cmp_pd::<_CMP_GT_OQ>(trial_squared, _mm256_mul_pd(limit, limit)),
            );
            let slides = _mm256_movemask_pd(sliding);
            let (mut sx, mut sy) = (tx, ty);
            if slides != 0 {
                if !regime.slides {
                    break;
                }
                let trial = _mm256_sqrt_pd(trial_squared);
                // `limit.max(0.0)`: the limit is not NaN here (the normal force is positive).
                let scale = _mm256_and_pd(
                    _mm256_div_pd(_mm256_max_pd(limit, zero), trial),
                    _mm256_cmp_pd::<_CMP_GT_OQ>(trial, zero),
                );
                sx = _mm256_blendv_pd(tx, _mm256_mul_pd(tx, scale), sliding);
                sy = _mm256_blendv_pd(ty, _mm256_mul_pd(ty, scale), sliding);
                let work = _mm256_mul_pd(
                    minus_half,
                    _mm256_add_pd(
                        _mm256_mul_pd(_mm256_add_pd(bx, sx), du_1),
                        _mm256_mul_pd(_mm256_add_pd(by, sy), du_2),
                    ),
                );
                let change = _mm256_sub_pd(
                    _mm256_add_pd(_mm256_mul_pd(sx, sx), _mm256_mul_pd(sy, sy)),
                    _mm256_add_pd(_mm256_mul_pd(bx, bx), _mm256_mul_pd(by, by)),
                );
                let lost = _mm256_blendv_pd(
                    work,
                    _mm256_sub_pd(work, _mm256_div_pd(_mm256_mul_pd(half, change), ks_area)),
                    _mm256_cmp_pd::<_CMP_GT_OQ>(ks_area, zero),
                );
                let slip = _mm256_sqrt_pd(_mm256_add_pd(_mm256_mul_pd(du_1, du_1), _mm256_mul_pd(du_2, du_2)));
                let (lost, slip) = (lanes(lost), lanes(slip));
                for (l, sub) in group.iter_mut().enumerate() {
                    if slides & (1 << l) != 0 {
                        *dissipated += lost[l];
                        sub.slip += slip[l];
                    }
                }
            }
            let (normal_l, gap_l) = (lanes(normal), lanes(gap));
            // `(sx, sy)` of each cell, as stored.
            let (even, odd) = (_mm256_unpacklo_pd(sx, sy), _mm256_unpackhi_pd(sx, sy));
            let shear = [
                _mm256_castpd256_pd128(even),
                _mm256_castpd256_pd128(odd),
                _mm256_extractf128_pd::<1>(even),
                _mm256_extractf128_pd::<1>(odd),
            ];
            for (l, sub) in group.iter_mut().enumerate() {
                sub.force.normal = normal_l[l];
                _mm_storeu_pd(std::ptr::from_mut(&mut sub.force.shear).cast::<Real>(), shear[l]);
                sub.gap = gap_l[l];
                sub.status = if slides & (1 << l) != 0 {
                    JointStatus::Sliding
                } else {
                    JointStatus::Elastic
                };
            }
            // `LaneSums::add`.
            for (kk, f) in [normal, sx, sy].into_iter().enumerate() {
                force[kk] = _mm256_add_pd(force[kk], f);
                per_x[kk] = _mm256_add_pd(per_x[kk], _mm256_mul_pd(f, x));
                per_y[kk] = _mm256_add_pd(per_y[kk], _mm256_mul_pd(f, y));
            }
            done += 1;
        }
        for kk in 0..3 {
            store(force[kk], &mut sums.force[kk]);
            store(per_x[kk], &mut sums.per_x[kk]);
            store(per_y[kk], &mut sums.per_y[kk]);
        }
        done
    }
}
