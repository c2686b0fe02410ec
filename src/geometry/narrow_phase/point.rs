//! Point contacts (edge–face, edge–edge, vertex–face): the features nearest the common plane,
//! their intersection in it, and the sub-contacts along it.

use glam::DVec2;

use super::super::clip::clip_convex;
use super::*;
use crate::math::{plane_basis, Real, Vector};

/// Edge–face, edge–edge and vertex–face contacts beyond the face angle tolerance: points on the
/// intersection of the two support features, anchored to the block whose feature has the lower
/// dimension (the host), with gaps to the other block's supporting plane normal to `n`.
pub(super) fn point_contact(
    a: BlockGeometry<'_>,
    b: BlockGeometry<'_>,
    n: Vector,
    dist: Real,
    params: &ContactParameters,
    seeds: &mut Vec<SubcontactSeed>,
) -> Option<DetectedContact> {
    // Vertices within the tolerance of the other block's surface, not of this block's deepest
    // vertex: under penetration (`dist < 0`) the whole penetrating feature is in contact.
    let band = params.tolerance + (-dist).max(0.0);
    let support = |g: BlockGeometry<'_>, dir: Vector| -> Vec<Vector> {
        let world: Vec<Vector> = g.shape.vertices().iter().map(|v| g.pose.transform_point(*v)).collect();
        let top = world.iter().map(|p| dir.dot(*p)).fold(Real::NEG_INFINITY, Real::max);
        world.into_iter().filter(|p| dir.dot(*p) >= top - band).collect()
    };
    let sa = support(a, n);
    let sb = support(b, -n);
    let (e1, e2) = plane_basis(n);
    let to2d = |p: Vector| DVec2::new(e1.dot(p), e2.dot(p));
    let fa = Feature::new(&sa, to2d);
    let fb = Feature::new(&sb, to2d);
    let h = spacing(a.shape, b.shape, params.density);

    // Points of the intersection of the two projected features.
    let (p0, p1) = match (&fa.shape, &fb.shape) {
        (FeatureShape::Point(p), _) => (*p, *p),
        (_, FeatureShape::Point(p)) => (*p, *p),
        (FeatureShape::Polygon(poly), FeatureShape::Segment(s, t))
        | (FeatureShape::Segment(s, t), FeatureShape::Polygon(poly)) => clip_segment(*s, *t, poly)?,
        (FeatureShape::Segment(s0, s1), FeatureShape::Segment(t0, t1)) => segment_segment(*s0, *s1, *t0, *t1),
        (FeatureShape::Polygon(pa), FeatureShape::Polygon(pb)) => {
            // Two faces within the band but not aligned within the angle tolerance: the longest
            // chord of their overlap carries the contact.
            let mut sub = pb.clone();
            let mut tmp = Vec::new();
            clip_convex(&mut sub, pa, &mut tmp);
            if sub.is_empty() {
                return None;
            }
            farthest_pair(&sub)
        }
    };
    // The host carries the points; the other block's supporting plane normal to `n` (its face
    // when its feature is a face) measures their gaps, fixed in that block.
    let host_is_a = fa.dim <= fb.dim;
    let (host, host_feature, other, other_feature, towards_host) = if host_is_a {
        (a, &fa, b, &fb, -n)
    } else {
        (b, &fb, a, &fa, n)
    };
    let (plane_normal, plane_offset) = if other_feature.dim == 2 {
        // The other block's face: its own normal, not the separating axis (which an edge-edge
        // axis may have tilted).
        let f = &other.shape.faces()[other
            .shape
            .most_aligned_face(other.pose.rotation.inverse() * towards_host)];
        (f.normal, f.offset)
    } else {
        let m = other.pose.rotation.inverse() * towards_host;
        let offset = other
            .shape
            .vertices()
            .iter()
            .map(|v| m.dot(*v))
            .fold(Real::NEG_INFINITY, Real::max);
        (m, offset)
    };
    let outward = other.pose.rotation * plane_normal;
    let world_offset = plane_offset + outward.dot(other.pose.translation);
    let length = (p1 - p0).length();
    let count = ((length / h).ceil() as u32).max(1);
    let seg_area = if length > 1e-12 {
        length / count as Real * h
    } else {
        h * h
    };
    let inv = host.pose.inverse();
    for k in 0..count {
        let q = p0 + (p1 - p0) * ((k as Real + 0.5) / count as Real);
        let height = host_feature.height(q, n);
        if !height.is_finite() {
            continue;
        }
        let on_host = e1 * q.x + e2 * q.y + n * height;
        seeds.push(SubcontactSeed {
            key: SubKey::point(fa.dim * 4 + fb.dim, k),
            anchor: inv.transform_point(on_host),
            area: seg_area,
            gap: outward.dot(on_host) - world_offset,
        });
    }
    Some(DetectedContact {
        kind: ContactKind::Point {
            plane_normal,
            plane_offset,
        },
        host_is_a,
        normal: if host_is_a { -outward } else { outward },
    })
}

pub(super) enum FeatureShape {
    Point(DVec2),
    Segment(DVec2, DVec2),
    Polygon(Vec<DVec2>),
}

/// A support feature (vertex, edge or face) projected on the common plane.
pub(super) struct Feature {
    shape: FeatureShape,
    /// Points in 3-D, for heights along the normal.
    pts3: Vec<Vector>,
    dim: u32,
}

impl Feature {
    fn new(pts: &[Vector], to2d: impl Fn(Vector) -> DVec2) -> Self {
        let p2: Vec<DVec2> = pts.iter().map(|p| to2d(*p)).collect();
        let hull = hull2d(&p2);
        let (shape, dim) = match hull.len() {
            1 => (FeatureShape::Point(hull[0]), 0),
            2 => (FeatureShape::Segment(hull[0], hull[1]), 1),
            _ => (FeatureShape::Polygon(hull), 2),
        };
        Self {
            shape,
            pts3: pts.to_vec(),
            dim,
        }
    }

    /// Height along `n` of the feature above the plane point `q` (interpolated).
    fn height(&self, q: DVec2, n: Vector) -> Real {
        let (e1, e2) = plane_basis(n);
        let heights: Vec<(DVec2, Real)> = self
            .pts3
            .iter()
            .map(|p| (DVec2::new(e1.dot(*p), e2.dot(*p)), n.dot(*p)))
            .collect();
        match &self.shape {
            FeatureShape::Point(_) => heights.iter().map(|h| h.1).sum::<Real>() / heights.len() as Real,
            FeatureShape::Segment(s, t) => {
                let d = *t - *s;
                let tt = if d.length_squared() > 0.0 {
                    ((q - *s).dot(d) / d.length_squared()).clamp(0.0, 1.0)
                } else {
                    0.0
                };
                let hs = nearest_height(&heights, *s);
                let ht = nearest_height(&heights, *t);
                hs + (ht - hs) * tt
            }
            FeatureShape::Polygon(_) => {
                // Least-squares plane h = c0 + c1 x + c2 y through the feature points.
                let m = heights.len() as Real;
                let cx = heights.iter().map(|h| h.0).sum::<DVec2>() / m;
                let ch = heights.iter().map(|h| h.1).sum::<Real>() / m;
                let (mut sxx, mut sxy, mut syy, mut sxh, mut syh) = (0.0, 0.0, 0.0, 0.0, 0.0);
                for (p, hh) in &heights {
                    let d = *p - cx;
                    sxx += d.x * d.x;
                    sxy += d.x * d.y;
                    syy += d.y * d.y;
                    sxh += d.x * (hh - ch);
                    syh += d.y * (hh - ch);
                }
                let det = sxx * syy - sxy * sxy;
                if det.abs() < 1e-30 {
                    return ch;
                }
                let gx = (sxh * syy - syh * sxy) / det;
                let gy = (syh * sxx - sxh * sxy) / det;
                ch + gx * (q.x - cx.x) + gy * (q.y - cx.y)
            }
        }
    }
}

pub(super) fn nearest_height(heights: &[(DVec2, Real)], p: DVec2) -> Real {
    heights
        .iter()
        .min_by(|a, b| (a.0 - p).length_squared().total_cmp(&(b.0 - p).length_squared()))
        .map(|h| h.1)
        .unwrap_or(0.0)
}

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

pub(super) fn clip_segment(s: DVec2, t: DVec2, poly: &[DVec2]) -> Option<(DVec2, DVec2)> {
    let (mut t0, mut t1) = (0.0, 1.0);
    let d = t - s;
    for i in 0..poly.len() {
        let a = poly[i];
        let e = poly[(i + 1) % poly.len()] - a;
        let outward = DVec2::new(e.y, -e.x);
        let num = (s - a).dot(outward);
        let den = d.dot(outward);
        if den.abs() < 1e-300 {
            if num > 0.0 {
                return nearest_on_polygon(s, t, poly);
            }
        } else {
            let r = -num / den;
            if den > 0.0 {
                t1 = Real::min(t1, r);
            } else {
                t0 = Real::max(t0, r);
            }
        }
    }
    if t0 > t1 {
        return nearest_on_polygon(s, t, poly);
    }
    Some((s + d * t0, s + d * t1))
}

/// When a segment misses the polygon in projection (touching within the tolerance band only),
/// the contact point is the segment point nearest to the polygon's centroid.
pub(super) fn nearest_on_polygon(s: DVec2, t: DVec2, poly: &[DVec2]) -> Option<(DVec2, DVec2)> {
    let c = poly.iter().copied().sum::<DVec2>() / poly.len() as Real;
    let d = t - s;
    let tt = if d.length_squared() > 0.0 {
        ((c - s).dot(d) / d.length_squared()).clamp(0.0, 1.0)
    } else {
        0.0
    };
    let p = s + d * tt;
    Some((p, p))
}

pub(super) fn segment_segment(s0: DVec2, s1: DVec2, t0: DVec2, t1: DVec2) -> (DVec2, DVec2) {
    let d = s1 - s0;
    let e = t1 - t0;
    let cr = d.perp_dot(e);
    if cr.abs() <= 0.02 * d.length() * e.length() {
        // Parallel within about 1°: overlap of the two intervals along d.
        let dir = d.normalize_or_zero();
        let (a0, a1): (Real, Real) = (0.0, d.length());
        let (b0, b1) = {
            let x = (t0 - s0).dot(dir);
            let y = (t1 - s0).dot(dir);
            (x.min(y), x.max(y))
        };
        let lo = a0.max(b0);
        let hi = a1.min(b1);
        if lo <= hi {
            return (s0 + dir * lo, s0 + dir * hi);
        }
        let m = s0 + dir * (0.5 * (lo + hi));
        return (m, m);
    }
    let r = (t0 - s0).perp_dot(e) / cr;
    let p = s0 + d * r.clamp(0.0, 1.0);
    (p, p)
}

pub(super) fn farthest_pair(poly: &[DVec2]) -> (DVec2, DVec2) {
    let mut best = (0.0, poly[0], poly[0]);
    for i in 0..poly.len() {
        for j in i + 1..poly.len() {
            let l = (poly[i] - poly[j]).length_squared();
            if l > best.0 {
                best = (l, poly[i], poly[j]);
            }
        }
    }
    (best.1, best.2)
}
