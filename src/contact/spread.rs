//! The elastic normal response of a face-face cell integrated exactly over the cell, for joints
//! that carry no tension: what makes a joint's hinge independent of its sub-contact density
//! (`docs/theory.md` §2.3, "Exact integration over the cells").
//!
//! A cell is the part of the contact polygon around one sub-contact. Between detections it is
//! a fixed region of the host face, and the gap over it is affine in the plane coordinates,
//! `g(r) = ḡ + s·r` (`ḡ` at the anchor, the cell's centroid; `s` the gap's slope on the plane,
//! the same for every cell of the contact). A no-tension spring of stiffness `k_n` per unit area
//! stores `½ k_n ∫ min(g, 0)² dA` over the cell: a function of the two blocks' poses whatever
//! the cell's size, whose gradient is the normal force `k_n ∫ max(−g, 0) dA` acting at the
//! centre of its distribution. A point rule (the force `k_n A max(−ḡ, 0)` at the anchor)
//! differs from it by an amount that depends on the cell size wherever a joint is not uniformly
//! closed — above all at a hinge, where the compressed zone is narrower than a cell.
//!
//! The cell is represented by the rectangle aligned with the plane axes, centred on its
//! centroid, whose half sizes `(h_x, h_y)` give the cell's second moments of area
//! (`J_xx = A h_x²/3`, `J_yy = A h_y²/3`), weighted by `A / (4 h_x h_y)` so that it has the
//! cell's area: the same region for the rectangular cells of rectangular faces, the same
//! area, centroid and principal moments otherwise. The integrals over it are exact.

use super::moments::ForceMoments;
use super::SubContact;
use crate::law::ConstitutiveLaw;
use crate::math::{Real, Vector2};

/// A cell's elastic normal response for the gap `ḡ` at its anchor and the slope `s`.
#[derive(Debug, Clone, Copy, PartialEq)]
pub(crate) struct CellResponse {
    /// The gap the law is given: `−(1/A) ∫ max(−g, 0) dA` while any of the cell is closed (so
    /// that the law's `F_n = −k_n A g` is the integral), the smallest gap over the cell while it
    /// is all open (its distance from closing).
    pub law_gap: Real,
    /// Where the normal force acts, from the anchor (plane coordinates, m): the centre of
    /// `max(−g, 0)` over the cell; zero while the cell is open.
    pub offset: Vector2,
    /// `½ (∫ g² − (∫ g)²/A)` over the closed part (m⁴): the elastic energy per unit `k_n` the
    /// spread of the gap over the cell stores beyond the law's `F_n²/(2 k_n A)`.
    pub excess_energy: Real,
}

impl CellResponse {
    /// A point rule: the gap at the anchor, the force there.
    #[inline(always)]
    pub(crate) fn at_anchor(gap: Real) -> Self {
        Self {
            law_gap: gap,
            offset: Vector2::ZERO,
            excess_energy: 0.0,
        }
    }
}

/// The response of a cell of area `area` and half sizes `half` (see the module) under the gap
/// `gap` at its anchor and the slope `slope`.
#[inline(always)]
pub(crate) fn cell_response(gap: Real, slope: Vector2, half: Vector2, area: Real) -> CellResponse {
    // The gap's range over the rectangle: ḡ ± (|s_x| h_x + |s_y| h_y).
    let spread = slope.x.abs() * half.x + slope.y.abs() * half.y;
    if gap >= spread {
        return CellResponse::at_anchor(gap - spread);
    }
    if gap <= -spread {
        // All closed: ∫ −g = −A ḡ, ∫ r (−g) = −(J_xx s_x, J_yy s_y), ∫ g² = A ḡ² + J_xx s_x² + J_yy s_y².
        let jx = area * half.x * half.x / 3.0;
        let jy = area * half.y * half.y / 3.0;
        let offset = if gap < 0.0 {
            Vector2::new(jx * slope.x, jy * slope.y) / (area * gap)
        } else {
            Vector2::ZERO
        };
        return CellResponse {
            law_gap: gap,
            offset,
            excess_energy: 0.5 * (jx * slope.x * slope.x + jy * slope.y * slope.y),
        };
    }
    straddling(gap, slope, half, area)
}

/// A cell the line `g = 0` crosses, integrated in closed form (`docs/theory.md` §3).
///
/// In the unit square `u = x/h_x`, `v = y/h_y` the gap is `ḡ + p u + q v` with `p = s_x h_x`,
/// `q = s_y h_y`; reflections make `p ≥ q ≥ 0` (they are undone on the first moments). For a
/// given `v` the closed part of the row `u ∈ [−1, 1]` is `u < −c/p`, `c = ḡ + q v`: the whole row
/// while `L = (p − c)/p ≥ 2` (region A), the first `L` of it while `0 < L < 2` (region B),
/// nothing after (region C). `L = λ − κ v` with `λ = 1 − ḡ/p`, `κ = q/p ∈ [0, 1]` is linear in
/// `v`, so the rows' integrals are polynomials in `v` on each region, integrated about the
/// region's midpoint (every term positive or a centroid: no cancellation however thin the
/// closed corner). Per row, `∫ max(−g, 0) du`, `∫ u max(−g, 0) du`, `∫ min(g, 0)² du` are
/// `−2c`, `−2p/3`, `2c² + 2p²/3` in A and `p L²/2`, `p (L³/6 − L²/2)`, `p² L³/3` in B.
#[cold]
#[inline(never)]
fn straddling(gap: Real, slope: Vector2, half: Vector2, area: Real) -> CellResponse {
    let (px, py) = (slope.x * half.x, slope.y * half.y);
    let swap = py.abs() > px.abs();
    let (p, q) = if swap {
        (py.abs(), px.abs())
    } else {
        (px.abs(), py.abs())
    };
    // Nothing closed (or a degenerate rectangle, or NaN): no force.
    let usable = p > 0.0 && half.x > 0.0 && half.y > 0.0;
    if !usable {
        return CellResponse::at_anchor(0.0);
    }
    let inverse_p = 1.0 / p;
    let (lambda, kappa) = (1.0 - gap * inverse_p, q * inverse_p);
    // Region A is v ≤ v_a (L ≥ 2: q v ≤ −p − ḡ), region C is v ≥ v_c (L ≤ 0: q v ≥ p − ḡ),
    // within [−1, 1].
    let (v_a, v_c) = if q > 0.0 {
        let inverse_q = 1.0 / q;
        (
            ((-p - gap) * inverse_q).clamp(-1.0, 1.0),
            ((p - gap) * inverse_q).clamp(-1.0, 1.0),
        )
    } else if lambda >= 2.0 {
        (1.0, 1.0)
    } else if lambda <= 0.0 {
        (-1.0, -1.0)
    } else {
        (-1.0, 1.0)
    };
    // Integrals over the unit square: ∫ max(−g, 0), ∫ u max(−g, 0), ∫ v max(−g, 0), ∫ min(g, 0)².
    let (mut i0, mut iu, mut iv, mut i2) = (0.0, 0.0, 0.0, 0.0);
    let t = v_a + 1.0;
    if t > 0.0 {
        let vm = 0.5 * (v_a - 1.0);
        let cm = gap + q * vm;
        let t3 = t * t * t / 12.0;
        i0 -= 2.0 * t * cm;
        iu -= 2.0 * p * t / 3.0;
        iv -= 2.0 * (t * vm * cm + q * t3);
        i2 += 2.0 * (t * cm * cm + q * q * t3) + 2.0 * p * p * t / 3.0;
    }
    let t = v_c - v_a;
    if t > 0.0 {
        let vm = 0.5 * (v_a + v_c);
        let lm = lambda - kappa * vm;
        let kt2 = kappa * kappa * t * t;
        // ∫ L², ∫ L³, ∫ v L² over the region.
        let j2 = t * (lm * lm + kt2 / 12.0);
        let j3 = t * lm * (lm * lm + kt2 / 4.0);
        let jv2 = vm * j2 - lm * kappa * t * t * t / 6.0;
        i0 += 0.5 * p * j2;
        iu += p * (j3 / 6.0 - 0.5 * j2);
        iv += 0.5 * p * jv2;
        i2 += p * p * j3 / 3.0;
    }
    // Back to the cell: reflections and the swap undone, the rectangle's scale and weight.
    let (mut mx, mut my) = if swap { (iv, iu) } else { (iu, iv) };
    if px < 0.0 {
        mx = -mx;
    }
    if py < 0.0 {
        my = -my;
    }
    // Over the cell, `∫ = (A/4) ∫∫ du dv`.
    if i0.partial_cmp(&0.0) != Some(std::cmp::Ordering::Greater) {
        return CellResponse::at_anchor(0.0);
    }
    let offset = Vector2::new(mx * half.x, my * half.y) * (1.0 / i0);
    CellResponse {
        law_gap: -0.25 * i0,
        offset: offset.clamp(-half, half),
        excess_energy: (0.125 * area * (i2 - 0.25 * i0 * i0)).max(0.0),
    }
}

/// How a face-face contact integrates its cells' normal springs (`contact/spread.rs`): exactly
/// over each cell where the law's normal spring is linear ([`ConstitutiveLaw::elastic_regime`])
/// and carries no tension in the cell's state ([`ConstitutiveLaw::stays_open`] at the smallest
/// opening), with the gap geometric (large displacements); at the anchor otherwise.
#[derive(Debug, Clone, Copy)]
pub(crate) struct ExactCells {
    /// `k_n` (Pa/m).
    pub(super) normal_stiffness: Real,
    /// The gap's slope on the anchor plane, `∂g/∂x`, `∂g/∂y`.
    pub(super) slope: Vector2,
    /// Whether a virgin sub-contact carries no tension.
    pub(super) virgin_without_tension: bool,
}

impl ExactCells {
    /// For a contact whose face gap has the coefficients `face` (`None`: not geometric).
    #[inline(always)]
    pub(crate) fn of<L: ConstitutiveLaw>(law: &L, face: Option<(Real, Real, Real)>) -> Option<Self> {
        let (_, gx, gy) = face?;
        let regime = law.elastic_regime()?;
        (regime.normal_stiffness > 0.0).then(|| Self {
            normal_stiffness: regime.normal_stiffness,
            slope: Vector2::new(-gx, -gy),
            virgin_without_tension: tension_free(law, &L::State::default()),
        })
    }
}

/// Whether a sub-contact in `state` carries no tension: the law keeps it open at the smallest
/// opening ([`ConstitutiveLaw::stays_open`]); its cell's normal spring is then integrated
/// exactly ([`ExactCells`]).
#[inline]
pub(crate) fn tension_free<L: ConstitutiveLaw>(law: &L, state: &L::State) -> bool {
    law.stays_open(1.0, Real::MIN_POSITIVE, state)
}

/// [`ExactCells`] of a contact, or none.
pub(crate) trait CellRule {
    /// The response of `sub`'s cell to the gap `anchor_gap` at its anchor.
    fn cell<L: ConstitutiveLaw>(&self, law: &L, sub: &SubContact<L::State>, anchor_gap: Real) -> CellResponse;
    /// Adds `sub`'s spring forces to `sums` (joint axes), its normal force where `cell` puts
    /// it, and the cell's spread energy to `spread_energy`.
    fn add<S>(&self, sums: &mut ForceMoments, spread_energy: &mut Real, sub: &SubContact<S>, cell: &CellResponse);
}

impl CellRule for Option<ExactCells> {
    #[inline(always)]
    fn cell<L: ConstitutiveLaw>(&self, law: &L, sub: &SubContact<L::State>, anchor_gap: Real) -> CellResponse {
        match self {
            Some(e)
                if if sub.state == L::State::default() {
                    e.virgin_without_tension
                } else {
                    tension_free(law, &sub.state)
                } =>
            {
                cell_response(anchor_gap, e.slope, sub.half(), sub.area)
            }
            _ => CellResponse::at_anchor(anchor_gap),
        }
    }

    #[inline(always)]
    fn add<S>(&self, sums: &mut ForceMoments, spread_energy: &mut Real, sub: &SubContact<S>, cell: &CellResponse) {
        sums.add_joint(&sub.force, sub.plane);
        if let Some(e) = self {
            let normal = sub.force.normal;
            if normal > 0.0 {
                sums.per_x.x += normal * cell.offset.x;
                sums.per_y.x += normal * cell.offset.y;
                *spread_energy += e.normal_stiffness * cell.excess_energy;
            }
        }
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    /// The former integration, kept as a reference: the rectangle clipped to its closed part,
    /// integrated by triangles (the edge-midpoint rule, exact for the quadratic integrands).
    fn straddling_by_triangles(gap: Real, slope: Vector2, half: Vector2, area: Real) -> CellResponse {
        let g = |r: Vector2| gap + slope.dot(r);
        let corners = [
            Vector2::new(-half.x, -half.y),
            Vector2::new(half.x, -half.y),
            Vector2::new(half.x, half.y),
            Vector2::new(-half.x, half.y),
        ];
        let mut closed = [Vector2::ZERO; 6];
        let mut n = 0;
        for k in 0..4 {
            let (a, b) = (corners[k], corners[(k + 1) % 4]);
            let (ga, gb) = (g(a), g(b));
            if ga <= 0.0 {
                closed[n] = a;
                n += 1;
            }
            if (ga <= 0.0) != (gb <= 0.0) {
                closed[n] = a + (b - a) * (ga / (ga - gb));
                n += 1;
            }
        }
        let (mut i0, mut i1, mut i2) = (0.0, Vector2::ZERO, 0.0);
        for k in 1..n.saturating_sub(1) {
            let (a, b, c) = (closed[0], closed[k], closed[k + 1]);
            let third_area = (b - a).perp_dot(c - a) / 6.0;
            for m in [0.5 * (a + b), 0.5 * (b + c), 0.5 * (c + a)] {
                let gm = g(m);
                i0 -= third_area * gm;
                i1 -= m * (third_area * gm);
                i2 += third_area * gm * gm;
            }
        }
        let weight = area / (4.0 * half.x * half.y);
        let (i0, i1, i2) = (i0 * weight, i1 * weight, i2 * weight);
        // Nothing closed (or a degenerate rectangle: NaN): no force.
        if i0.partial_cmp(&0.0) != Some(std::cmp::Ordering::Greater) {
            return CellResponse::at_anchor(0.0);
        }
        CellResponse {
            law_gap: -i0 / area,
            offset: i1 / i0,
            excess_energy: (0.5 * (i2 - i0 * i0 / area)).max(0.0),
        }
    }

    /// `∫ max(−g, 0)`, `∫ r max(−g, 0)`, `∫ min(g, 0)²` over the rectangle by a fine midpoint
    /// grid.
    fn brute(gap: Real, slope: Vector2, half: Vector2, area: Real) -> (Real, Vector2, Real) {
        let n = 800;
        let weight = area / (4.0 * half.x * half.y);
        let d = Vector2::new(2.0 * half.x / n as Real, 2.0 * half.y / n as Real);
        let (mut i0, mut i1, mut i2) = (0.0, Vector2::ZERO, 0.0);
        for i in 0..n {
            for j in 0..n {
                let r = Vector2::new(-half.x + (i as Real + 0.5) * d.x, -half.y + (j as Real + 0.5) * d.y);
                let p = (-(gap + slope.dot(r))).max(0.0) * d.x * d.y * weight;
                i0 += p;
                i1 += r * p;
                i2 += p * p / (d.x * d.y * weight);
            }
        }
        (i0, i1, i2)
    }

    #[test]
    fn the_integrals_match_a_fine_quadrature_in_every_regime() {
        let half = Vector2::new(0.03, 0.01);
        let area = 0.7 * 4.0 * half.x * half.y;
        let slope = Vector2::new(2e-3, -1.5e-3);
        for gap in [-1e-4, -6e-5, -3e-5, -1e-5, 0.0, 1e-5, 3e-5, 6e-5, 1e-4] {
            let c = cell_response(gap, slope, half, area);
            let (i0, i1, i2) = brute(gap, slope, half, area);
            let force = -c.law_gap.min(0.0) * area;
            let scale = 1e-4 * area;
            assert!((force - i0).abs() <= 1e-4 * scale, "gap {gap}: {force} vs {i0}");
            if i0 > 0.0 {
                let moment = c.offset * force;
                assert!(
                    (moment - i1).length() <= 1e-4 * scale * half.x,
                    "gap {gap}: {moment} vs {i1}"
                );
                let energy = 0.5 * force * force / area + c.excess_energy;
                assert!(
                    (energy - 0.5 * i2).abs() <= 1e-4 * scale * 1e-4,
                    "gap {gap}: {energy} vs {}",
                    0.5 * i2
                );
            } else {
                assert!(c.law_gap >= 0.0 && c.excess_energy == 0.0);
            }
        }
    }

    /// The closed form agrees with the clipped rectangle integrated by triangles, over slopes
    /// of both signs and either axis dominant, one component zero, and gaps from a sliver of a
    /// closed corner to a sliver of an open one.
    #[test]
    fn the_closed_form_matches_the_clipped_rectangle() {
        let half = Vector2::new(0.03, 0.012);
        let area = 0.9 * 4.0 * half.x * half.y;
        for slope in [
            Vector2::new(2e-3, -1.5e-3),
            Vector2::new(-2e-4, 3e-3),
            Vector2::new(-1e-3, -1e-3),
            Vector2::new(1e-3, 0.0),
            Vector2::new(0.0, -2e-3),
            Vector2::new(3e-3, 1e-9),
        ] {
            let spread = slope.x.abs() * half.x + slope.y.abs() * half.y;
            for f in [
                -0.999999, -0.99, -0.7, -0.3, -1e-3, 0.0, 0.2, 0.5, 0.9, 0.9999, 0.999999,
            ] {
                let gap = f * spread;
                let (a, b) = (
                    straddling(gap, slope, half, area),
                    straddling_by_triangles(gap, slope, half, area),
                );
                let (fa, fb) = (-a.law_gap * area, -b.law_gap * area);
                // Relative to the force of the cell fully compressed by the spread.
                let scale = spread * area;
                let e = ((fa - fb).abs() / scale)
                    .max((a.offset * fa - b.offset * fb).length() / (scale * half.x))
                    .max((a.excess_energy - b.excess_energy).abs() / (scale * spread));
                assert!(fa > 0.0 && e < 1e-12, "slope {slope}, gap {gap}: {a:?} vs {b:?}");
                // The force acts within the cell.
                assert!(a.offset.abs().cmple(half).all());
            }
        }
    }

    /// Four quarter cells give what the whole cell gives, whatever the gap: the response does
    /// not depend on how finely a joint is divided.
    #[test]
    fn quartered_cells_add_up_to_the_whole() {
        let half = Vector2::new(0.02, 0.05);
        let area = 4.0 * half.x * half.y;
        let slope = Vector2::new(-4e-3, 1e-3);
        for gap in [-2e-4, -1e-4, -5e-5, -1e-5, 2e-5, 5e-5, 1.4e-4] {
            let whole = cell_response(gap, slope, half, area);
            let (mut force, mut moment, mut energy) = (0.0, Vector2::ZERO, 0.0);
            for (sx, sy) in [(-1.0, -1.0), (1.0, -1.0), (1.0, 1.0), (-1.0, 1.0)] {
                let centre = Vector2::new(sx * half.x / 2.0, sy * half.y / 2.0);
                let q = cell_response(gap + slope.dot(centre), slope, half / 2.0, area / 4.0);
                let f = -q.law_gap.min(0.0) * area / 4.0;
                force += f;
                moment += (centre + q.offset) * f;
                energy += 0.5 * f * f / (area / 4.0) + q.excess_energy;
            }
            let f = -whole.law_gap.min(0.0) * area;
            assert!((force - f).abs() <= 1e-12 * area * 2e-4, "gap {gap}");
            assert!((moment - whole.offset * f).length() <= 1e-12 * area * 2e-4, "gap {gap}");
            let e = 0.5 * f * f / area + whole.excess_energy;
            assert!((energy - e).abs() <= 1e-12 * area * 4e-8, "gap {gap}: {energy} vs {e}");
        }
    }

    /// The response is continuous where a cell starts and stops straddling the line `g = 0`.
    #[test]
    fn continuous_where_the_regime_changes() {
        let half = Vector2::new(0.03, 0.02);
        let area = 4.0 * half.x * half.y;
        let slope = Vector2::new(1e-3, 2e-3);
        let spread = slope.x * half.x + slope.y * half.y;
        for edge in [-spread, spread] {
            let below = cell_response(edge * (1.0 + 1e-9) - 1e-15, slope, half, area);
            let above = cell_response(edge * (1.0 - 1e-9) + 1e-15, slope, half, area);
            assert!((below.law_gap - above.law_gap).abs() < 1e-12, "{below:?} {above:?}");
            assert!((below.excess_energy - above.excess_energy).abs() < 1e-14);
        }
    }
}
