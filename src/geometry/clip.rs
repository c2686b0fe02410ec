//! Planar convex-polygon kernels in 2-D: half-plane clipping (Sutherland–Hodgman), area, centroid.

use glam::DVec2;

use crate::math::Real;

/// Clips the convex polygon `poly` by the half-plane `{p : (p - origin) · outward <= 0}` into `out`.
pub fn clip_halfplane(poly: &[DVec2], origin: DVec2, outward: DVec2, out: &mut Vec<DVec2>) {
    clip_by(poly, out, |p| (p - origin).dot(outward));
}

/// Sutherland–Hodgman on one half-plane: keeps the part of the convex polygon `poly` where
/// `distance(p) <= 0`, into `out`, starting at `poly[0]`. Each vertex's distance is taken once
/// (it is both the start of one edge and the end of the previous).
#[inline(always)]
fn clip_by(poly: &[DVec2], out: &mut Vec<DVec2>, distance: impl Fn(DVec2) -> Real) {
    out.clear();
    let Some(&first) = poly.first() else {
        return;
    };
    let d_first = distance(first);
    let (mut a, mut da) = (first, d_first);
    for i in 1..=poly.len() {
        let (b, db) = match poly.get(i) {
            Some(&b) => (b, distance(b)),
            None => (first, d_first),
        };
        if da <= 0.0 {
            out.push(a);
        }
        if (da < 0.0 && db > 0.0) || (da > 0.0 && db < 0.0) {
            let t = da / (da - db);
            out.push(a + (b - a) * t);
        }
        (a, da) = (b, db);
    }
}

/// Intersection of the convex polygon `subject` with the convex, counter-clockwise polygon `clip`.
/// `scratch` is reused to avoid allocation; the result is left in `subject`.
pub fn clip_convex(subject: &mut Vec<DVec2>, clip: &[DVec2], scratch: &mut Vec<DVec2>) {
    let n = clip.len();
    for i in 0..n {
        if subject.is_empty() {
            return;
        }
        let a = clip[i];
        let b = clip[(i + 1) % n];
        let edge = b - a;
        let outward = DVec2::new(edge.y, -edge.x);
        clip_halfplane(subject, a, outward, scratch);
        std::mem::swap(subject, scratch);
    }
}

/// Clips `subject` to the axis-aligned rectangle `[lo, hi]`.
///
/// The four half-planes in the order and with the distances of [`clip_halfplane`] with the
/// outward normals `−x`, `−y`, `+x`, `+y`: `(p − o)·(−1, 0)` is `−(p.x − o.x)` exactly (a zero
/// may change its sign, which neither test nor cut sees), so the result is the same to the bit.
pub fn clip_rect(subject: &mut Vec<DVec2>, lo: DVec2, hi: DVec2, scratch: &mut Vec<DVec2>) {
    for side in 0..4 {
        if subject.is_empty() {
            return;
        }
        match side {
            0 => clip_by(subject, scratch, |p| -(p.x - lo.x)),
            1 => clip_by(subject, scratch, |p| -(p.y - lo.y)),
            2 => clip_by(subject, scratch, |p| p.x - hi.x),
            _ => clip_by(subject, scratch, |p| p.y - hi.y),
        }
        std::mem::swap(subject, scratch);
    }
}

/// Signed area (positive for counter-clockwise) and centroid of a simple polygon.
pub fn area_centroid(poly: &[DVec2]) -> (Real, DVec2) {
    let n = poly.len();
    if n < 3 {
        return (0.0, poly.first().copied().unwrap_or(DVec2::ZERO));
    }
    // Shift to the first vertex to keep digits.
    let o = poly[0];
    let mut a2 = 0.0;
    let mut c = DVec2::ZERO;
    for i in 1..n - 1 {
        let p = poly[i] - o;
        let q = poly[i + 1] - o;
        let cr = p.perp_dot(q);
        a2 += cr;
        c += (p + q) * cr;
    }
    if a2.abs() < Real::MIN_POSITIVE {
        return (0.0, o);
    }
    (0.5 * a2, o + c / (3.0 * a2))
}

/// Second moments of area of a convex polygon about `about`, `(∫ (x − aₓ)² dA, ∫ (y − a_y)² dA)`
/// (counter-clockwise: positive).
pub fn second_moments(poly: &[DVec2], about: DVec2) -> (Real, Real) {
    let n = poly.len();
    if n < 3 {
        return (0.0, 0.0);
    }
    let o = poly[0] - about;
    let (mut jx, mut jy) = (0.0, 0.0);
    for i in 1..n - 1 {
        let (p, q) = (poly[i] - about, poly[i + 1] - about);
        let twice_area = (p - o).perp_dot(q - o);
        jx += twice_area * (o.x * o.x + p.x * p.x + q.x * q.x + o.x * p.x + p.x * q.x + q.x * o.x);
        jy += twice_area * (o.y * o.y + p.y * p.y + q.y * q.y + o.y * p.y + p.y * q.y + q.y * o.y);
    }
    (jx / 12.0, jy / 12.0)
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn second_moments_of_a_rectangle_and_a_triangle() {
        let rect = [
            DVec2::new(1.0, 2.0),
            DVec2::new(3.0, 2.0),
            DVec2::new(3.0, 3.0),
            DVec2::new(1.0, 3.0),
        ];
        let (jx, jy) = second_moments(&rect, DVec2::new(2.0, 2.5));
        // b h³/12 about the centroid: 1·2³/12 and 2·1³/12.
        assert!((jx - 8.0 / 12.0).abs() < 1e-14 && (jy - 2.0 / 12.0).abs() < 1e-14);
        // A right triangle with legs 3 (x) and 2 (y) about its centroid: b h³/36 each way.
        let tri = [DVec2::new(0.0, 0.0), DVec2::new(3.0, 0.0), DVec2::new(0.0, 2.0)];
        let (jx, jy) = second_moments(&tri, DVec2::new(1.0, 2.0 / 3.0));
        assert!((jx - 2.0 * 27.0 / 36.0).abs() < 1e-13 && (jy - 3.0 * 8.0 / 36.0).abs() < 1e-13);
    }

    #[test]
    fn coincident_squares_give_the_square() {
        let sq = vec![
            DVec2::new(0.0, 0.0),
            DVec2::new(1.0, 0.0),
            DVec2::new(1.0, 1.0),
            DVec2::new(0.0, 1.0),
        ];
        let mut s = sq.clone();
        let mut scratch = Vec::new();
        clip_convex(&mut s, &sq, &mut scratch);
        let (a, c) = area_centroid(&s);
        assert!((a - 1.0).abs() < 1e-15);
        assert!((c - DVec2::splat(0.5)).length() < 1e-15);
    }

    #[test]
    fn rotated_square_overlap_is_an_octagon() {
        let sq: Vec<DVec2> = (0..4)
            .map(|k| DVec2::from_angle(std::f64::consts::FRAC_PI_2 * k as f64).rotate(DVec2::new(1.0, 1.0)))
            .collect();
        let rot: Vec<DVec2> = sq
            .iter()
            .map(|p| DVec2::from_angle(std::f64::consts::FRAC_PI_4).rotate(*p))
            .collect();
        let mut s = rot.clone();
        let mut scratch = Vec::new();
        clip_convex(&mut s, &sq, &mut scratch);
        let (a, _) = area_centroid(&s);
        // Regular octagon with inradius 1: area 8 tan(pi/8).
        assert!((a - 8.0 * (std::f64::consts::PI / 8.0).tan()).abs() < 1e-12);
        let mut r = sq.clone();
        clip_rect(&mut r, DVec2::new(0.0, 0.0), DVec2::new(2.0, 0.5), &mut scratch);
        assert!((area_centroid(&r).0 - 0.5).abs() < 1e-15);
    }

    /// `clip_rect` is the four general half-planes to the bit: random convex polygons (a
    /// rotated, scaled square and regular polygons) against rectangles that cut them, hold
    /// them, miss them, or share an edge or a vertex with them.
    #[test]
    fn clip_rect_matches_the_general_half_planes_to_the_bit() {
        let mut next = crate::math::test_uniform(0x9e37_79b9_7f4a_7c15_u64);
        let (mut scratch, mut general) = (Vec::new(), Vec::new());
        for case in 0..2000 {
            let sides = 3 + case % 6;
            let (cx, cy, r, turn) = (next() - 0.5, next() - 0.5, 0.1 + next(), next() * 6.3);
            let poly: Vec<DVec2> = (0..sides)
                .map(|k| {
                    let t = turn + std::f64::consts::TAU * k as f64 / sides as f64;
                    DVec2::new(cx + r * t.cos(), cy + r * t.sin())
                })
                .collect();
            // Rectangles from a grid (shared vertices and edges with each other) or random.
            let (lo, hi) = if case % 3 == 0 {
                let (i, j) = ((next() * 8.0).floor(), (next() * 8.0).floor());
                let lo = DVec2::new(-1.0 + 0.25 * i, -1.0 + 0.25 * j);
                (lo, lo + DVec2::splat(0.25))
            } else {
                let lo = DVec2::new(next() * 2.0 - 1.0, next() * 2.0 - 1.0);
                (lo, lo + DVec2::new(next(), next()))
            };
            let mut fast = poly.clone();
            clip_rect(&mut fast, lo, hi, &mut scratch);
            general.clear();
            general.extend_from_slice(&poly);
            for (origin, outward) in [
                (lo, DVec2::new(-1.0, 0.0)),
                (lo, DVec2::new(0.0, -1.0)),
                (hi, DVec2::new(1.0, 0.0)),
                (hi, DVec2::new(0.0, 1.0)),
            ] {
                if general.is_empty() {
                    break;
                }
                let mut out = Vec::new();
                clip_halfplane(&general, origin, outward, &mut out);
                general = out;
            }
            let bits = |v: &[DVec2]| v.iter().map(|p| (p.x.to_bits(), p.y.to_bits())).collect::<Vec<_>>();
            let (f, g) = (bits(&fast), bits(&general));
            // Equal, but for the sign of a zero.
            let zero = |x: u64| if f64::from_bits(x) == 0.0 { 0 } else { x };
            let norm = |v: Vec<(u64, u64)>| v.into_iter().map(|(x, y)| (zero(x), zero(y))).collect::<Vec<_>>();
            assert_eq!(norm(f), norm(g), "case {case}");
        }
    }
}
