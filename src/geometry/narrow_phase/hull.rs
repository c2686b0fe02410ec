//! The 2-D convex hull of points in a plane (face–face overlaps and their strips).

use glam::DVec2;

use super::*;

/// 2-D convex hull (monotone chain), counter-clockwise; merges points closer than 1e-9 of the
/// extent. Returns 1 point for a vertex, 2 for a segment.
pub(super) fn hull2d(pts: &[DVec2]) -> Vec<DVec2> {
    let mut p: Vec<DVec2> = pts.to_vec();
    p.sort_by(|a, b| a.x.total_cmp(&b.x).then(a.y.total_cmp(&b.y)));
    let (lo, hi) = bounds(&p);
    let eps = 1e-9 * (hi - lo).length().max(1e-12);
    p.dedup_by(|a, b| (*a - *b).length() <= eps);
    if p.len() <= 2 {
        if p.len() == 2 && (p[0] - p[1]).length() <= eps {
            p.pop();
        }
        return p;
    }
    let cross = |o: DVec2, a: DVec2, b: DVec2| (a - o).perp_dot(b - o);
    let tol = eps * (hi - lo).length();
    let mut h: Vec<DVec2> = Vec::with_capacity(2 * p.len());
    // Lower hull, then upper hull; the upper pass must never pop points of the lower hull.
    for &q in &p {
        while h.len() >= 2 && cross(h[h.len() - 2], h[h.len() - 1], q) <= tol {
            h.pop();
        }
        h.push(q);
    }
    let lower = h.len() + 1;
    for &q in p.iter().rev().skip(1) {
        while h.len() >= lower && cross(h[h.len() - 2], h[h.len() - 1], q) <= tol {
            h.pop();
        }
        h.push(q);
    }
    h.pop();
    if h.len() < 3 {
        // Collinear: the two extreme points.
        return vec![p[0], p[p.len() - 1]];
    }
    h
}
