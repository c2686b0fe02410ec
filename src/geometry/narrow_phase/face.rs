//! Face–face contacts: the contact polygon of two faces and its sub-contact grid on the host face.

use glam::DVec2;

use super::super::clip::{area_centroid, clip_convex, clip_rect, second_moments};
use super::super::polyhedron::Polyhedron;
use super::*;
use crate::math::plane_basis;
use crate::math::{Real, Vector};

/// Faces whose normals are opposite within this angle (rad, 1°) are parallel: the smaller face
/// hosts the sub-contacts. Beyond it, the face whose edge or corner digs into the other does.
pub(crate) const PARALLEL_ANGLE: Real = 0.017_453_292_519_943_295;

/// A face-face contact between face `fa` of `a` and face `fb` of `b`, only if their overlap covers
/// at least the fraction `cover` of the smaller face (1: whole; 0: any overlap); hosted by
/// `kept_host` when given (the contact existed before).
///
/// The host is the smaller face when the faces are parallel within [`PARALLEL_ANGLE`]. When
/// they are not, the deepest point of the overlap lies on the boundary of the face whose edge or
/// corner digs into the other, and that face hosts the sub-contacts, so that the loaded ones are
/// its edge row or corner node, whose cells the other face covers: their areas do not change as
/// the edge slides along the face. (Hosted by the other face, the deepest sub-contacts sit in
/// the partly covered cells along the edge, whose areas are refreshed only at re-detections,
/// and each refresh changed their stored energy by `½ k ΔA g²` at the deepest gaps.) Faces
/// parallel within [`PARALLEL_ANGLE`] whose gaps still vary are hosted so too when an edge of
/// the other face is the deepest by more than round-off (see [`face_face_hosted`]); a joint
/// kept without history (`kept_host` `None` for a blank joint, see
/// [`super::PreviousContact::blank`]) is hosted afresh by the same rules.
#[allow(clippy::too_many_arguments)]
pub(super) fn face_face(
    a: BlockGeometry<'_>,
    fa: usize,
    b: BlockGeometry<'_>,
    fb: usize,
    cover: Real,
    kept_host: Option<bool>,
    params: &ContactParameters,
    scratch: &mut NarrowPhaseScratch,
    seeds: &mut Vec<SubContactSeed>,
) -> Option<DetectedContact> {
    let smaller_is_a = a.shape.faces()[fa].area <= b.shape.faces()[fb].area;
    if let Some(host_is_a) = kept_host {
        return match face_face_hosted(a, fa, b, fb, host_is_a, false, cover, params, scratch, seeds) {
            Hosted::Contact(found) => Some(found),
            _ => None,
        };
    }
    let start = seeds.len();
    match face_face_hosted(a, fa, b, fb, smaller_is_a, true, cover, params, scratch, seeds) {
        Hosted::Contact(found) => Some(found),
        Hosted::None => None,
        Hosted::DeepestOnOther => {
            seeds.truncate(start);
            match face_face_hosted(a, fa, b, fb, !smaller_is_a, false, 0.0, params, scratch, seeds) {
                Hosted::Contact(found) => Some(found),
                _ => None,
            }
        }
    }
}

/// What [`face_face_hosted`] found.
pub(super) enum Hosted {
    Contact(DetectedContact),
    /// The faces are not parallel and the overlap's deepest point is not on the host face's
    /// boundary: the other face should host (nothing pushed).
    DeepestOnOther,
    None,
}

#[allow(clippy::too_many_arguments)]
pub(super) fn face_face_hosted(
    a: BlockGeometry<'_>,
    fa: usize,
    b: BlockGeometry<'_>,
    fb: usize,
    host_is_a: bool,
    check_deepest: bool,
    cover: Real,
    params: &ContactParameters,
    scratch: &mut NarrowPhaseScratch,
    seeds: &mut Vec<SubContactSeed>,
) -> Hosted {
    let (host, fh, other, fo) = if host_is_a { (a, fa, b, fb) } else { (b, fb, a, fa) };
    let face = &host.shape.faces()[fh];
    let (origin, u, v) = face_frame(host.shape, fh);
    let to2d = |p: Vector| DVec2::new(u.dot(p - origin), v.dot(p - origin));

    scratch.host.clear();
    scratch.host.extend(
        host.shape
            .face_loop(fh)
            .iter()
            .map(|&i| to2d(host.shape.vertices()[i as usize])),
    );
    // The other face, in the host body frame, projected on the host plane; reversed so that it
    // is counter-clockwise seen from the host's outside.
    let rel = host.pose.inv_mul(other.pose);
    scratch.other.clear();
    scratch.other.extend(
        other
            .shape
            .face_loop(fo)
            .iter()
            .rev()
            .map(|&i| to2d(rel.transform_point(other.shape.vertices()[i as usize]))),
    );
    // Faces more oblique than the largest tolerance are not projected on each other.
    let n_other = rel.rotation * other.shape.faces()[fo].normal;
    if n_other.dot(face.normal) > -MAX_FACE_ANGLE.cos() {
        return Hosted::None;
    }
    clip_convex(&mut scratch.other, &scratch.host, &mut scratch.tmp);
    let (overlap_area, _) = area_centroid(&scratch.other);
    // Covered: the overlap is the smaller face whole (when the host is the larger face, the
    // smaller face's projection on it).
    let other_area = other.shape.faces()[fo].area;
    let smaller_whole = if face.area <= other_area {
        face.area
    } else {
        other_area * n_other.dot(face.normal).abs()
    };
    if overlap_area <= 1e-9 * face.area || (cover > 0.0 && overlap_area < (cover - 1e-9) * smaller_whole) {
        return Hosted::None;
    }
    // Gap at a point of the host face: its signed distance from the other face's plane, along
    // that face's outward normal (the gap the step uses, `docs/theory.md` §3).
    let other_offset = n_other.dot(rel.transform_point(other.shape.vertices()[other.shape.face_loop(fo)[0] as usize]));
    let gap_at = |q: DVec2| {
        let p = origin + u * q.x + v * q.y;
        n_other.dot(p) - other_offset
    };
    let min_gap = scratch.other.iter().map(|&q| gap_at(q)).fold(Real::INFINITY, Real::min);
    if min_gap > params.tolerance {
        return Hosted::None;
    }
    // Whether a point of the host plane lies on the host face's boundary.
    let on_host_boundary = |at: DVec2| {
        let poly = &scratch.host;
        (0..poly.len()).any(|k| {
            let (p, q) = (poly[k], poly[(k + 1) % poly.len()]);
            let e = q - p;
            let t = ((at - p).dot(e) / e.length_squared()).clamp(0.0, 1.0);
            (at - (p + e * t)).length() <= 1e-6 * e.length()
        })
    };
    // The overlap's edges, each with the sum of its end points' gaps (twice its mean gap) and
    // its midpoint (an edge, so that an edge crossing the host face, whose end points lie on
    // the host's boundary, is not taken for the host's).
    let overlap = &scratch.other;
    let edges = (0..overlap.len()).map(|k| {
        let (p, q) = (overlap[k], overlap[(k + 1) % overlap.len()]);
        (gap_at(p) + gap_at(q), 0.5 * (p + q))
    });
    if check_deepest && n_other.dot(face.normal) > -PARALLEL_ANGLE.cos() {
        // Tilted faces: the host is the face that the overlap's deepest edge belongs to.
        let deepest = edges
            .min_by(|(g, _), (h, _)| g.total_cmp(h))
            .map_or(DVec2::ZERO, |(_, mid)| mid);
        if !on_host_boundary(deepest) {
            return Hosted::DeepestOnOther;
        }
    } else if check_deepest {
        // Faces parallel within `PARALLEL_ANGLE` whose gaps still vary over the overlap (the
        // faces turned by a fraction of a degree): when an edge of the other face is deeper
        // than every edge of the host's own boundary by more than round-off, the joint would
        // close along the other face's edge, in cells that edge cuts, whose areas change at
        // each re-detection while it slides — each change making or destroying `½ k ΔA g²`
        // at the deepest gaps. The other face hosts instead, as for tilted faces. Faces that
        // are parallel to round-off keep the smaller face as the host.
        let (mut own, mut other) = (Real::INFINITY, Real::INFINITY);
        for (g, mid) in edges {
            if on_host_boundary(mid) {
                own = own.min(g);
            } else {
                other = other.min(g);
            }
        }
        let (host_lo, host_hi) = bounds(&scratch.host);
        let round_off = 1e-9 * (host_hi - host_lo).length();
        if other < own - round_off {
            return Hosted::DeepestOnOther;
        }
    }

    let (lo, hi) = bounds(&scratch.host);
    let size = hi - lo;
    // Sub-contacts sit at the nodes of an nu × nv grid over the host face's bounding rectangle,
    // the outer nodes on its boundary (trapezoidal rule), so that a joint opening about an edge
    // hinges on that edge. Each node carries the overlap within its tributary cell.
    let (nu, nv) = match params.density {
        SubContactDensity::PerEdge(k) => (k as u32, k as u32),
        SubContactDensity::Spacing(h) => (
            ((size.x / h).ceil() as u32).max(1) + 1,
            ((size.y / h).ceil() as u32).max(1) + 1,
        ),
    };
    // Sub-contact keys hold 16-bit grid indices.
    let (nu, nv) = (nu.min(MAX_NODES_PER_EDGE), nv.min(MAX_NODES_PER_EDGE));
    let spacing = |n: u32, len: Real| if n > 1 { len / (n - 1) as Real } else { len };
    let cell = DVec2::new(spacing(nu, size.x), spacing(nv, size.y));
    let first = lo
        + DVec2::new(
            if nu > 1 { 0.0 } else { 0.5 * size.x },
            if nv > 1 { 0.0 } else { 0.5 * size.y },
        );
    let (olo, ohi) = bounds(&scratch.other);
    let range = |o0: Real, o1: Real, f: Real, c: Real, n: u32| {
        let i0 = ((o0 - f) / c - 0.5).ceil().max(0.0) as u32;
        let i1 = (((o1 - f) / c + 0.5).floor().max(0.0) as u32).min(n - 1);
        (i0.min(n - 1), i1)
    };
    let (i0, i1) = range(olo.x, ohi.x, first.x, cell.x, nu);
    let (j0, j1) = range(olo.y, ohi.y, first.y, cell.y, nv);
    let min_area = 1e-9 * cell.x * cell.y;
    for i in i0..=i1 {
        for j in j0..=j1 {
            let node = first + cell * DVec2::new(i as Real, j as Real);
            let clo = node - 0.5 * cell;
            let chi = node + 0.5 * cell;
            scratch.cell.clear();
            scratch.cell.extend_from_slice(&scratch.other);
            clip_rect(&mut scratch.cell, clo, chi, &mut scratch.tmp);
            let (area, centroid) = area_centroid(&scratch.cell);
            if area > min_area {
                let (fh32, fo32) = (fh as u32, fo as u32);
                let key = if host_is_a {
                    SubKey::cell(fh32, fo32, i, j)
                } else {
                    SubKey::cell(fo32, fh32, i, j)
                };
                // The anchor is the centroid of the cell (the overlap's part of the node's
                // tributary rectangle), and the cell's second moments about it give the half
                // sizes of the rectangle the normal springs are integrated over
                // (`contact/spread.rs`). The cell follows the overlap's edge continuously as it
                // crosses the rectangle; the integration puts the hinge of a joint opening about
                // an edge on that edge at any density.
                let (jx, jy) = second_moments(&scratch.cell, centroid);
                let half = DVec2::new((3.0 * jx / area).max(0.0).sqrt(), (3.0 * jy / area).max(0.0).sqrt());
                let at = centroid;
                seeds.push(SubContactSeed {
                    key,
                    anchor: origin + u * at.x + v * at.y,
                    area,
                    gap: gap_at(at),
                    half,
                });
            }
        }
    }
    // The normal is the other face's: the direction of the gap's gradient, so that the
    // springs' forces derive from their energy (`docs/theory.md` §3).
    let normal = if host_is_a {
        -(b.pose.rotation * b.shape.faces()[fb].normal)
    } else {
        a.pose.rotation * a.shape.faces()[fa].normal
    };
    Hosted::Contact(DetectedContact {
        kind: ContactKind::FaceFace {
            face_a: fa as u32,
            face_b: fb as u32,
        },
        host_is_a,
        normal,
    })
}

/// The corners of a contact's polygon (world, counter-clockwise seen from outside the host):
/// for a face-face contact the part of the other face within `tolerance` of the host face's
/// plane (the whole face when the faces are parallel; a strip along the touching edge when they
/// are at an angle, as for a block balanced on its edge), projected on that plane and clipped by
/// the host face — where the grid cells that carry the sub-contacts can close
/// (`face_face_hosted`); for a
/// node contact, or a face-face polygon that came out degenerate, the 2-D hull of `points`
/// (the sub-contacts) in the plane normal to `normal`: a polygon, a segment or a point.
/// Corners closer than 1e-9 of the polygon's extent are merged, collinear ones dropped.
pub(crate) fn contact_polygon(
    a: BlockGeometry<'_>,
    b: BlockGeometry<'_>,
    kind: ContactKind,
    host_is_a: bool,
    normal: Vector,
    points: &[Vector],
    tolerance: Real,
) -> Vec<Vector> {
    if let ContactKind::FaceFace { face_a, face_b } = kind {
        let (fa, fb) = (face_a as usize, face_b as usize);
        let (host, fh, other, fo) = if host_is_a { (a, fa, b, fb) } else { (b, fb, a, fa) };
        if fh < host.shape.faces().len() && fo < other.shape.faces().len() {
            let (origin, u, v) = face_frame(host.shape, fh);
            let to2d = |p: Vector| DVec2::new(u.dot(p - origin), v.dot(p - origin));
            let host_loop: Vec<DVec2> = host
                .shape
                .face_loop(fh)
                .iter()
                .map(|&i| to2d(host.shape.vertices()[i as usize]))
                .collect();
            let rel = host.pose.inv_mul(other.pose);
            let other_loop: Vec<Vector> = other
                .shape
                .face_loop(fo)
                .iter()
                .rev()
                .map(|&i| rel.transform_point(other.shape.vertices()[i as usize]))
                .collect();
            // The part of the other face within the tolerance of the host face's plane: only
            // there can its sub-contacts close (a tilted face touches along a strip).
            let n = host.shape.faces()[fh].normal;
            let (near, cut) = clip_by_height(&other_loop, |p| n.dot(p - origin), tolerance);
            let mut overlap: Vec<DVec2> = near.into_iter().map(to2d).collect();
            let mut tmp = Vec::new();
            clip_convex(&mut overlap, &host_loop, &mut tmp);
            let corners = hull2d(&overlap);
            if cut && corners.len() < 3 {
                // A strip thinner than round-off, a segment or nothing: what touches.
                return corners
                    .into_iter()
                    .map(|q| host.pose.transform_point(origin + u * q.x + v * q.y))
                    .collect();
            }
            if corners.len() >= 3 {
                return corners
                    .into_iter()
                    .map(|q| host.pose.transform_point(origin + u * q.x + v * q.y))
                    .collect();
            }
        }
    }
    let Some(&o) = points.first() else {
        return Vec::new();
    };
    let (u, v) = plane_basis(normal);
    let flat: Vec<DVec2> = points.iter().map(|&p| DVec2::new(u.dot(p - o), v.dot(p - o))).collect();
    hull2d(&flat).into_iter().map(|q| o + u * q.x + v * q.y).collect()
}

/// The polygon `points` clipped to `height(p) <= limit` (Sutherland–Hodgman on one plane),
/// and whether anything was cut.
fn clip_by_height(points: &[Vector], height: impl Fn(Vector) -> Real, limit: Real) -> (Vec<Vector>, bool) {
    let h: Vec<Real> = points.iter().map(|&p| height(p) - limit).collect();
    if h.iter().all(|&h| h <= 0.0) {
        return (points.to_vec(), false);
    }
    let mut out = Vec::with_capacity(points.len() + 1);
    for k in 0..points.len() {
        let j = (k + 1) % points.len();
        let (p, q, hp, hq) = (points[k], points[j], h[k], h[j]);
        if hp <= 0.0 {
            out.push(p);
        }
        if (hp <= 0.0) != (hq <= 0.0) {
            out.push(p + (q - p) * (hp / (hp - hq)));
        }
    }
    (out, true)
}

/// A material frame on face `f`: origin at its first vertex, `u` along its longest edge.
pub(crate) fn face_frame(shape: &Polyhedron, f: usize) -> (Vector, Vector, Vector) {
    let ids = shape.face_loop(f);
    let vs = shape.vertices();
    let mut best = (0.0, Vector::X);
    for k in 0..ids.len() {
        let e = vs[ids[(k + 1) % ids.len()] as usize] - vs[ids[k] as usize];
        let l = e.length_squared();
        if l > best.0 {
            best = (l, e);
        }
    }
    let n = shape.faces()[f].normal;
    let u = (best.1 - n * n.dot(best.1)).normalize();
    (vs[ids[0] as usize], u, n.cross(u))
}

pub(super) fn bounds(poly: &[DVec2]) -> (DVec2, DVec2) {
    poly.iter().fold(
        (DVec2::splat(Real::INFINITY), DVec2::splat(Real::NEG_INFINITY)),
        |(lo, hi), p| (lo.min(*p), hi.max(*p)),
    )
}
