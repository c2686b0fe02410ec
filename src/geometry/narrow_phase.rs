//! Narrow phase: the common plane, the contact polygon and its sub-contacts for one block pair.
//!
//! The common plane comes from a separating-axis test over face normals and edge pairs (exact for
//! convex polyhedra, also for faces that just touch, where GJK/EPA normals are arbitrary); the
//! face-to-face polygon and the sub-contact grid are built here. See `docs/theory.md`, "Contact geometry".

use glam::DVec2;
#[cfg(feature = "serde")]
use serde::{Deserialize, Serialize};

use super::clip::{area_centroid, clip_convex, clip_rect};
use super::polyhedron::Polyhedron;
use crate::error::{in_range, positive, Result};
use crate::math::{plane_basis, Pose, Real, Vector};

/// How densely joint faces are covered with sub-contacts.
#[derive(Debug, Clone, Copy, PartialEq)]
#[cfg_attr(feature = "serde", derive(Serialize, Deserialize))]
pub enum SubcontactDensity {
    /// `n` sub-contacts along each edge of the host face's bounding rectangle (`n × n` cells);
    /// the reference paper uses 15.
    PerEdge(u16),
    /// Nodes at most this far apart (m); at most [`MAX_SUBCONTACTS_PER_EDGE`] nodes along a
    /// face edge of any block.
    Spacing(Real),
}

/// The most sub-contacts along an edge of a face (`n × n` per face): 1,000, a million per
/// face. A denser grid is refused rather than allocated (the reference paper uses 15).
pub const MAX_SUBCONTACTS_PER_EDGE: u16 = 1000;

/// Two faces further apart than the face angle tolerance but within this angle (rad, 60°) still
/// form a face-face contact when the larger face covers the smaller one whole: an edge or a
/// corner landing on a face is then the edge row or corner node of the grid that carries the
/// face once it lands, instead of a differently discretised point contact (`docs/theory.md`
/// §2.2). Where the faces overlap only in part (edge against edge), a point contact.
const COVERED_FACE_ANGLE: Real = std::f64::consts::FRAC_PI_3;

/// Largest face angle tolerance (rad, 75°): beyond it the projection of one face on the other
/// is too oblique to place sub-contacts.
const MAX_FACE_ANGLE: Real = 5.0 * std::f64::consts::PI / 12.0;

/// Largest number of sub-contact nodes along a face edge (keys hold 16-bit indices).
const MAX_NODES_PER_EDGE: u32 = 65_535;

/// Parameters of contact detection and discretisation.
#[derive(Debug, Clone, Copy, PartialEq)]
#[cfg_attr(feature = "serde", derive(Serialize, Deserialize))]
#[cfg_attr(feature = "serde", serde(default, deny_unknown_fields))]
pub struct ContactParameters {
    /// Blocks closer than this (m) are in contact; contacts whose gap grows beyond it are dropped.
    /// Default `1e-3` m.
    pub tolerance: Real,
    /// The re-detection trigger, as a fraction of `tolerance`: contacts are re-detected once
    /// some block has moved more than this since it last did, and then a pair is tested afresh
    /// only if its two blocks moved relative to each other (a contact: by more than half the
    /// trigger since its test; `docs/theory.md` §2.3). Default `0.25`.
    pub redetect_fraction: Real,
    /// The two faces most aligned with the contact normal form a face-to-face joint (a grid of
    /// sub-contacts on one of the faces, gaps measured to the other face's plane) while their
    /// normals are opposite within this angle (rad). Default 15°, so that an opening hinge keeps
    /// its sub-contacts and their history. Beyond it and up to 60°, they still form a face-face
    /// contact when the larger face covers the smaller one whole (an edge or corner landing on
    /// a face); otherwise the contact is a point contact (`docs/theory.md` §2.2).
    pub face_angle_tolerance: Real,
    /// Sub-contact density on joint faces. Default `PerEdge(15)` (the paper's value).
    pub density: SubcontactDensity,
}

impl Default for ContactParameters {
    fn default() -> Self {
        Self {
            tolerance: 1e-3,
            redetect_fraction: 0.25,
            face_angle_tolerance: 15f64.to_radians(),
            density: SubcontactDensity::PerEdge(15),
        }
    }
}

impl ContactParameters {
    /// Checks that a [`SubcontactDensity::Spacing`] leaves at most
    /// [`MAX_SUBCONTACTS_PER_EDGE`] sub-contacts along the faces of a block of circumradius
    /// `radius` (m), named `block` in the error.
    ///
    /// # Errors
    /// [`crate::Error::InvalidParameter`] naming the block.
    pub fn check_block(&self, radius: Real, block: &str) -> Result<()> {
        if let SubcontactDensity::Spacing(h) = self.density {
            let nodes = (2.0 * radius / h).ceil() + 1.0;
            if nodes.is_nan() || nodes > MAX_SUBCONTACTS_PER_EDGE as Real {
                return Err(crate::Error::InvalidParameter {
                    name: format!(
                        "contact.density.spacing for block {block:?} ({:.3} m across)",
                        2.0 * radius
                    ),
                    value: h,
                    expected: "must leave at most 1000 sub-contacts along a face edge (MAX_SUBCONTACTS_PER_EDGE)",
                });
            }
        }
        Ok(())
    }

    /// Checks every field.
    ///
    /// # Errors
    /// [`crate::Error::InvalidParameter`] naming the bad field.
    pub fn validate(&self) -> Result<()> {
        positive("contact.tolerance", self.tolerance)?;
        in_range(
            "contact.redetect_fraction",
            self.redetect_fraction,
            1e-6,
            1.0 + 1e-12,
            "must lie in (0, 1]",
        )?;
        in_range(
            "contact.face_angle_tolerance",
            self.face_angle_tolerance,
            0.0,
            MAX_FACE_ANGLE,
            "must lie in [0, 5 pi/12) rad (75 degrees)",
        )?;
        match self.density {
            SubcontactDensity::PerEdge(n) => {
                in_range(
                    "contact.density.per_edge",
                    n as Real,
                    1.0,
                    MAX_SUBCONTACTS_PER_EDGE as Real + 1.0,
                    "must lie in 1..=1000 (MAX_SUBCONTACTS_PER_EDGE)",
                )?;
            }
            SubcontactDensity::Spacing(h) => {
                positive("contact.density.spacing", h)?;
            }
        }
        Ok(())
    }
}

/// Stable identity of a sub-contact within its block pair: used to carry history across
/// re-detection.
#[derive(Debug, Clone, Copy, PartialEq, Eq, PartialOrd, Ord, Hash)]
#[cfg_attr(feature = "serde", derive(Serialize, Deserialize))]
pub struct SubKey(pub u64);

impl SubKey {
    fn cell(face_host: u32, face_other: u32, i: u32, j: u32) -> Self {
        Self(((face_host as u64) << 48) | ((face_other as u64 & 0xffff) << 32) | ((i as u64) << 16) | j as u64)
    }
    fn point(feature: u32, i: u32) -> Self {
        Self((0xffffu64 << 48) | ((feature as u64 & 0xffff) << 32) | i as u64)
    }
}

/// The kind of a detected contact.
#[derive(Debug, Clone, Copy, PartialEq)]
#[cfg_attr(feature = "serde", derive(Serialize, Deserialize))]
pub enum ContactKind {
    /// Two nearly parallel faces: a polygon covered with a grid of sub-contacts anchored to the
    /// host face. Faces are indices into each block's [`Polyhedron::faces`].
    FaceFace {
        /// Face of block `a`.
        face_a: u32,
        /// Face of block `b`.
        face_b: u32,
    },
    /// Edge–face, edge–edge or vertex–face beyond the face angle tolerance: sub-contacts on a
    /// segment or at a point, anchored to the host (the block whose feature has the lower
    /// dimension), their gaps measured to a plane fixed in the other block: its face, or for
    /// an edge or vertex the plane through it normal to the contact normal at detection.
    Point {
        /// Outward unit normal of the plane, in the other block's body frame.
        plane_normal: Vector,
        /// Offset of the plane along `plane_normal` (m): the plane is `plane_normal·x = offset`
        /// in the other block's body frame.
        plane_offset: Real,
    },
}

impl ContactKind {
    /// Whether a contact re-detected as `other` is the same joint, whose sub-contacts may carry
    /// their history over by key: the same pair of faces, or a point contact again. A point
    /// contact's plane is set afresh at each detection, so it is not compared; the keys (which
    /// name the features) decide which sub-contacts carry on.
    pub(crate) fn same_joint(&self, other: &ContactKind) -> bool {
        match (self, other) {
            (ContactKind::FaceFace { .. }, ContactKind::FaceFace { .. }) => self == other,
            (ContactKind::Point { .. }, ContactKind::Point { .. }) => true,
            _ => false,
        }
    }
}

/// A sub-contact as created by detection.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct SubcontactSeed {
    /// Identity within the pair.
    pub key: SubKey,
    /// Material point in the host block's body frame (m).
    pub anchor: Vector,
    /// Tributary area (m²).
    pub area: Real,
    /// Normal gap at detection (m, positive = open): the signed distance of the anchor from the
    /// other block's plane.
    pub gap: Real,
}

/// A detected contact between blocks `a` and `b`.
#[derive(Debug, Clone, PartialEq)]
pub struct DetectedContact {
    /// The geometric case.
    pub kind: ContactKind,
    /// `true` if sub-contacts are anchored to block `a`, `false` for block `b`.
    pub host_is_a: bool,
    /// World normal from `a` to `b`: the normal of the other block's plane, oriented from `a`
    /// to `b`.
    pub normal: Vector,
}

/// Scratch buffers reused between detections.
#[derive(Debug, Default, Clone)]
pub struct NarrowPhaseScratch {
    world_a: Vec<Vector>,
    world_b: Vec<Vector>,
    host: Vec<DVec2>,
    other: Vec<DVec2>,
    cell: Vec<DVec2>,
    tmp_cell: Vec<DVec2>,
    tmp: Vec<DVec2>,
    separation: Real,
}

impl NarrowPhaseScratch {
    /// The separation the last [`detect`] call found along its separating axis (m): when
    /// positive, a lower bound on the distance between the two blocks (positive = apart,
    /// negative = overlap depth along that axis).
    pub fn separation(&self) -> Real {
        self.separation
    }
}

/// Everything the narrow phase needs to know about one block.
#[derive(Debug, Clone, Copy)]
pub struct BlockGeometry<'a> {
    /// The shape in its body frame.
    pub shape: &'a Polyhedron,
    /// Its pose.
    pub pose: &'a Pose,
}

/// Detects the contact between `a` and `b`, pushing its sub-contacts into `seeds`.
/// Returns `None` (and pushes nothing) when the gap exceeds the tolerance.
///
/// `previous` is the contact the pair had before, if any: a face-face contact between the same
/// two faces keeps its host, so that its sub-contacts keep their keys and history (the host of
/// a new face-face contact between tilted faces is chosen by where the overlap is deepest, see
/// `face_face`).
pub fn detect(
    a: BlockGeometry<'_>,
    b: BlockGeometry<'_>,
    previous: Option<(ContactKind, bool)>,
    params: &ContactParameters,
    scratch: &mut NarrowPhaseScratch,
    seeds: &mut Vec<SubcontactSeed>,
) -> Option<DetectedContact> {
    let axis = separating_axis(a, b, scratch);
    scratch.separation = axis.separation;
    if axis.separation > params.tolerance {
        return None;
    }
    let n = axis.normal;
    let fa = a.shape.most_aligned_face(a.pose.rotation.inverse() * n);
    let fb = b.shape.most_aligned_face(b.pose.rotation.inverse() * -n);
    let na = a.pose.rotation * a.shape.faces()[fa].normal;
    let nb = b.pose.rotation * b.shape.faces()[fb].normal;
    let cos = -na.dot(nb);
    if cos >= params.face_angle_tolerance.cos() || cos >= COVERED_FACE_ANGLE.cos() {
        let start = seeds.len();
        let require_cover = cos < params.face_angle_tolerance.cos();
        let kept_host = match previous {
            Some((ContactKind::FaceFace { face_a, face_b }, host_is_a))
                if face_a as usize == fa && face_b as usize == fb =>
            {
                Some(host_is_a)
            }
            _ => None,
        };
        if let Some(found) = face_face(a, fa, b, fb, require_cover, kept_host, params, scratch, seeds) {
            return Some(found);
        }
        seeds.truncate(start);
    }
    point_contact(a, b, n, axis.separation, params, seeds)
}

/// The common-plane normal from the separating axis theorem.
#[derive(Debug, Clone, Copy)]
struct Axis {
    /// Unit normal from `a` to `b`.
    normal: Vector,
    /// Signed separation along it (m): positive = gap, negative = overlap depth.
    separation: Real,
}

/// Separating axis test over the face normals of both blocks and the cross products of their
/// edges: the axis of largest separation is the contact normal (the least-penetration axis when
/// they overlap). Exact for convex polyhedra, including faces that touch with zero overlap, where
/// GJK/EPA normals are arbitrary. Face axes win ties against edge axes.
fn separating_axis(a: BlockGeometry<'_>, b: BlockGeometry<'_>, scratch: &mut NarrowPhaseScratch) -> Axis {
    scratch.world_a.clear();
    scratch
        .world_a
        .extend(a.shape.vertices().iter().map(|v| a.pose.transform_point(*v)));
    scratch.world_b.clear();
    scratch
        .world_b
        .extend(b.shape.vertices().iter().map(|v| b.pose.transform_point(*v)));
    let (wa, wb) = (&scratch.world_a, &scratch.world_b);
    let separation = |d: Vector| {
        let max_a = wa.iter().map(|p| d.dot(*p)).fold(Real::NEG_INFINITY, Real::max);
        let min_b = wb.iter().map(|p| d.dot(*p)).fold(Real::INFINITY, Real::min);
        min_b - max_a
    };
    let mut best = Axis {
        normal: Vector::Z,
        separation: Real::NEG_INFINITY,
    };
    for f in a.shape.faces() {
        let d = a.pose.rotation * f.normal;
        let s = separation(d);
        if s > best.separation {
            best = Axis {
                normal: d,
                separation: s,
            };
        }
    }
    for f in b.shape.faces() {
        let d = -(b.pose.rotation * f.normal);
        let s = separation(d);
        if s > best.separation {
            best = Axis {
                normal: d,
                separation: s,
            };
        }
    }
    // Edge–edge axes must beat the face axes clearly, so that touching faces stay face contacts.
    let bias = 1e-9 * (a.shape.radius() + b.shape.radius());
    let centre = b.pose.translation - a.pose.translation;
    for ea in a.shape.edges() {
        let da = wa[ea[1] as usize] - wa[ea[0] as usize];
        for eb in b.shape.edges() {
            let db = wb[eb[1] as usize] - wb[eb[0] as usize];
            let c = da.cross(db);
            let len = c.length();
            if len <= 1e-9 * da.length() * db.length() {
                continue;
            }
            let mut d = c / len;
            if d.dot(centre) < 0.0 {
                d = -d;
            }
            let s = separation(d);
            if s > best.separation + bias {
                best = Axis {
                    normal: d,
                    separation: s,
                };
            }
        }
    }
    best
}

/// Characteristic sub-contact spacing for a pair (m), used for point contacts.
fn spacing(a: &Polyhedron, b: &Polyhedron, density: SubcontactDensity) -> Real {
    match density {
        SubcontactDensity::Spacing(h) => h,
        SubcontactDensity::PerEdge(n) => a.volume().cbrt().min(b.volume().cbrt()) / n as Real,
    }
}

/// Faces whose normals are opposite within this angle (rad, 1°) are parallel: the smaller face
/// hosts the sub-contacts. Beyond it, the face whose edge or corner digs into the other does.
const PARALLEL_ANGLE: Real = 0.017_453_292_519_943_295;

/// A face-face contact between face `fa` of `a` and face `fb` of `b`; with `require_cover`,
/// only if the larger face covers the smaller one whole; hosted by `kept_host` when given (the
/// contact existed before).
///
/// The host is the smaller face when the faces are parallel within [`PARALLEL_ANGLE`]. When
/// they are not, the deepest point of the overlap lies on the boundary of the face whose edge or
/// corner digs into the other, and that face hosts the sub-contacts, so that the loaded ones are
/// its edge row or corner node, whose cells the other face covers: their areas do not change as
/// the edge slides along the face. (Hosted by the other face, the deepest sub-contacts sit in
/// the partly covered cells along the edge, whose areas are refreshed only at re-detections,
/// and each refresh changed their stored energy by `½ k ΔA g²` at the deepest gaps.)
#[allow(clippy::too_many_arguments)]
fn face_face(
    a: BlockGeometry<'_>,
    fa: usize,
    b: BlockGeometry<'_>,
    fb: usize,
    require_cover: bool,
    kept_host: Option<bool>,
    params: &ContactParameters,
    scratch: &mut NarrowPhaseScratch,
    seeds: &mut Vec<SubcontactSeed>,
) -> Option<DetectedContact> {
    let smaller_is_a = a.shape.faces()[fa].area <= b.shape.faces()[fb].area;
    if let Some(host_is_a) = kept_host {
        return match face_face_hosted(a, fa, b, fb, host_is_a, false, require_cover, params, scratch, seeds) {
            Hosted::Contact(found) => Some(found),
            _ => None,
        };
    }
    let start = seeds.len();
    match face_face_hosted(a, fa, b, fb, smaller_is_a, true, require_cover, params, scratch, seeds) {
        Hosted::Contact(found) => Some(found),
        Hosted::None => None,
        Hosted::DeepestOnOther => {
            seeds.truncate(start);
            match face_face_hosted(a, fa, b, fb, !smaller_is_a, false, false, params, scratch, seeds) {
                Hosted::Contact(found) => Some(found),
                _ => None,
            }
        }
    }
}

/// What [`face_face_hosted`] found.
enum Hosted {
    Contact(DetectedContact),
    /// The faces are not parallel and the overlap's deepest point is not on the host face's
    /// boundary: the other face should host (nothing pushed).
    DeepestOnOther,
    None,
}

#[allow(clippy::too_many_arguments)]
fn face_face_hosted(
    a: BlockGeometry<'_>,
    fa: usize,
    b: BlockGeometry<'_>,
    fb: usize,
    host_is_a: bool,
    check_deepest: bool,
    require_cover: bool,
    params: &ContactParameters,
    scratch: &mut NarrowPhaseScratch,
    seeds: &mut Vec<SubcontactSeed>,
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
    if overlap_area <= 1e-9 * face.area || (require_cover && overlap_area < (1.0 - 1e-9) * smaller_whole) {
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
    if check_deepest && n_other.dot(face.normal) > -PARALLEL_ANGLE.cos() {
        // The midpoint of the overlap's deepest edge (an edge, so that an edge crossing the
        // host face, whose end points lie on the host's boundary, is not taken for the host's).
        let overlap = &scratch.other;
        let deepest = (0..overlap.len())
            .map(|k| (overlap[k], overlap[(k + 1) % overlap.len()]))
            .min_by(|(p, q), (r, t)| (gap_at(*p) + gap_at(*q)).total_cmp(&(gap_at(*r) + gap_at(*t))))
            .map_or(DVec2::ZERO, |(p, q)| 0.5 * (p + q));
        let poly = &scratch.host;
        let on_boundary = (0..poly.len()).any(|k| {
            let (p, q) = (poly[k], poly[(k + 1) % poly.len()]);
            let e = q - p;
            let t = ((deepest - p).dot(e) / e.length_squared()).clamp(0.0, 1.0);
            (deepest - (p + e * t)).length() <= 1e-6 * e.length()
        });
        if !on_boundary {
            return Hosted::DeepestOnOther;
        }
    }

    let (lo, hi) = bounds(&scratch.host);
    let size = hi - lo;
    // Sub-contacts sit at the nodes of an nu × nv grid over the host face's bounding rectangle,
    // the outer nodes on its boundary (trapezoidal rule), so that a joint opening about an edge
    // hinges on that edge. Each node carries the overlap within its tributary cell.
    let (nu, nv) = match params.density {
        SubcontactDensity::PerEdge(k) => (k as u32, k as u32),
        SubcontactDensity::Spacing(h) => (
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
                // The node, shifted by how far the overlap's share of the cell has its centroid
                // from the centroid of the cell's part of the host face: the node itself when
                // the overlap covers that part, and a point that follows the overlap's edge
                // continuously as it crosses the cell. (At the node always, a sub-contact at the
                // overlap's edge carried its force up to half a cell outside the overlap; at the
                // centroid of its share once its node was uncovered, as before, it jumped by up
                // to a quarter cell at that moment, and with it its gap and stored energy.)
                let full = cell.x * cell.y;
                let (host_area, host_centroid) = if area >= full * (1.0 - 1e-12) {
                    (full, node)
                } else {
                    scratch.tmp_cell.clear();
                    scratch.tmp_cell.extend_from_slice(&scratch.host);
                    clip_rect(&mut scratch.tmp_cell, clo, chi, &mut scratch.tmp);
                    area_centroid(&scratch.tmp_cell)
                };
                let at = if area >= host_area * (1.0 - 1e-12) || host_area <= 0.0 {
                    if host_area > 0.0 {
                        node
                    } else {
                        centroid
                    }
                } else {
                    node + (centroid - host_centroid)
                };
                seeds.push(SubcontactSeed {
                    key,
                    anchor: origin + u * at.x + v * at.y,
                    area,
                    gap: gap_at(at),
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
/// point contact, or a face-face polygon that came out degenerate, the 2-D hull of `points`
/// (the sub-contacts) in the plane normal to `normal`: a polygon, a segment or a point.
/// Corners closer than 1e-9 of the polygon's extent are merged, collinear ones dropped.
#[cfg(feature = "limit")]
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
#[cfg(feature = "limit")]
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

fn bounds(poly: &[DVec2]) -> (DVec2, DVec2) {
    poly.iter().fold(
        (DVec2::splat(Real::INFINITY), DVec2::splat(Real::NEG_INFINITY)),
        |(lo, hi), p| (lo.min(*p), hi.max(*p)),
    )
}

/// Edge–face, edge–edge and vertex–face contacts beyond the face angle tolerance: points on the
/// intersection of the two support features, anchored to the block whose feature has the lower
/// dimension (the host), with gaps to the other block's supporting plane normal to `n`.
fn point_contact(
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

enum FeatureShape {
    Point(DVec2),
    Segment(DVec2, DVec2),
    Polygon(Vec<DVec2>),
}

/// A support feature (vertex, edge or face) projected on the common plane.
struct Feature {
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

fn nearest_height(heights: &[(DVec2, Real)], p: DVec2) -> Real {
    heights
        .iter()
        .min_by(|a, b| (a.0 - p).length_squared().total_cmp(&(b.0 - p).length_squared()))
        .map(|h| h.1)
        .unwrap_or(0.0)
}

/// 2-D convex hull (monotone chain), counter-clockwise; merges points closer than 1e-9 of the
/// extent. Returns 1 point for a vertex, 2 for a segment.
fn hull2d(pts: &[DVec2]) -> Vec<DVec2> {
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

fn clip_segment(s: DVec2, t: DVec2, poly: &[DVec2]) -> Option<(DVec2, DVec2)> {
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
fn nearest_on_polygon(s: DVec2, t: DVec2, poly: &[DVec2]) -> Option<(DVec2, DVec2)> {
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

fn segment_segment(s0: DVec2, s1: DVec2, t0: DVec2, t1: DVec2) -> (DVec2, DVec2) {
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

fn farthest_pair(poly: &[DVec2]) -> (DVec2, DVec2) {
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
