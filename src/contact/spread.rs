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

/// A cell the line `g = 0` crosses: the rectangle clipped to its closed part, integrated by
/// triangles (the edge-midpoint rule, exact for the quadratic integrands).
#[cold]
#[inline(never)]
fn straddling(gap: Real, slope: Vector2, half: Vector2, area: Real) -> CellResponse {
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

#[cfg(test)]
mod tests {
    use super::*;

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
