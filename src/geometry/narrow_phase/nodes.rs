//! Node contacts (vertex–face, edge–edge, edge–face, partial faces): fixed material nodes on the
//! vertices and edges of both blocks, each pressed out of the other block by its depth inside it
//! (`docs/theory.md` §2.2, "Node contacts").
//!
//! A node is a material point of one block: a vertex, or one of the points that split an edge
//! into segments no longer than the pair's spacing `h`. Its gap is its signed distance from the
//! other (convex) block, `g = max_f (m_f·q − d_f)` over that block's faces (`q` the node in that
//! block's body frame): exact inside, a lower bound of the distance outside. A node's spring
//! energy `½ k_n A min(g, 0)²` is therefore a function of the two poses alone, continuous
//! wherever the node is (also where the deepest face changes), and zero where the node is out:
//! which nodes a detection lists changes nothing as long as it lists every node that can reach
//! the other block before the next detection (those with `g` below the tolerance).

use super::strips::{for_each_strip, least_gap};
use super::*;
use crate::math::Real;

/// The side bit of a node key (set: a node of block `b`), and the two bits of its place.
const SIDE_BIT: u64 = 1 << 63;
const PLACE_SHIFT: u32 = 61;

/// The largest vertex or face index a node can name (the key gives it 16 bits).
pub(crate) const MAX_NODE_INDEX: u32 = 0xffff;

/// The most nodes along an edge, and grid lines across a face, a key can name (12 and 10 bits).
const MAX_EDGE_SEGMENTS: u32 = 0xfff;
const MAX_FACE_LINES: u32 = 0x3ff;

/// Where on its block a node is.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub(crate) enum NodePlace {
    /// A vertex.
    Vertex(u32),
    /// Point `k` of `n` along the edge from vertex `v0` to `v1` (`v0 < v1`, `0 < k < n`).
    Edge { v0: u32, v1: u32, k: u32, n: u32 },
    /// The crossing of grid lines `i` of `nu` and `j` of `nv` of face `face`'s grid
    /// ([`FaceGrid`]), strictly inside the face.
    Face {
        face: u32,
        i: u32,
        j: u32,
        nu: u32,
        nv: u32,
    },
}

/// A node of a node contact: a material point of block `b` (`on_b`) or `a`.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub(crate) struct NodeId {
    pub on_b: bool,
    pub place: NodePlace,
}

impl NodeId {
    /// Its sub-contact key (node keys sort by side, then by place).
    pub(crate) fn key(&self) -> SubKey {
        let side = if self.on_b { SIDE_BIT } else { 0 };
        SubKey(
            side | match self.place {
                NodePlace::Vertex(v) => (v as u64 & 0xffff) << 40,
                NodePlace::Edge { v0, v1, k, n } => {
                    (1 << PLACE_SHIFT)
                        | ((v0 as u64 & 0xffff) << 40)
                        | ((v1 as u64 & 0xffff) << 24)
                        | ((k as u64 & 0xfff) << 12)
                        | (n as u64 & 0xfff)
                }
                NodePlace::Face { face, i, j, nu, nv } => {
                    (2 << PLACE_SHIFT)
                        | ((face as u64 & 0xffff) << 40)
                        | ((i as u64 & 0x3ff) << 30)
                        | ((j as u64 & 0x3ff) << 20)
                        | ((nu as u64 & 0x3ff) << 10)
                        | (nv as u64 & 0x3ff)
                }
            },
        )
    }

    /// The node a key names.
    pub(crate) fn from_key(key: SubKey) -> Self {
        let k = key.0;
        let field = |shift: u32, bits: u32| ((k >> shift) & ((1 << bits) - 1)) as u32;
        let place = match (k >> PLACE_SHIFT) & 3 {
            0 => NodePlace::Vertex(field(40, 16)),
            1 => NodePlace::Edge {
                v0: field(40, 16),
                v1: field(24, 16),
                k: field(12, 12),
                n: field(0, 12),
            },
            _ => NodePlace::Face {
                face: field(40, 16),
                i: field(30, 10),
                j: field(20, 10),
                nu: field(10, 10),
                nv: field(0, 10),
            },
        };
        Self {
            on_b: k & SIDE_BIT != 0,
            place,
        }
    }

    /// Whether the node exists on `shape` (its vertices or face in range, its grid place on the
    /// grid).
    #[cfg(any(feature = "serde", test))]
    pub(crate) fn fits(&self, shape: &Polyhedron) -> bool {
        let vertices = shape.vertices().len() as u32;
        match self.place {
            NodePlace::Vertex(v) => v < vertices,
            NodePlace::Edge { v0, v1, k, n } => v0 < vertices && v1 < vertices && 0 < k && k < n,
            NodePlace::Face { face, i, j, nu, nv } => {
                (face as usize) < shape.faces().len() && 0 < i && i < nu && 0 < j && j < nv
            }
        }
    }

    /// The node in its block's body frame (m).
    #[inline]
    pub(crate) fn point(&self, shape: &Polyhedron) -> Vector {
        let v = shape.vertices();
        match self.place {
            NodePlace::Vertex(i) => v[i as usize],
            NodePlace::Edge { v0, v1, k, n } => {
                let p0 = v[v0 as usize];
                p0 + (v[v1 as usize] - p0) * (k as Real / n as Real)
            }
            NodePlace::Face { face, i, j, nu, nv } => FaceGrid::of(shape, face as usize).point(i, j, nu, nv),
        }
    }
}

/// The frame of a face's node grid: origin at its first vertex, `u` along its longest edge (the
/// first of the longest), `v = n × u`, and the bounding rectangle of the face in those axes,
/// split into `nu × nv` cells no wider than the spacing; the nodes are the crossings of the
/// inner grid lines that lie inside the face. Computed once per face with the shape
/// ([`Polyhedron::face_grid`]).
#[derive(Debug, Clone, Copy, PartialEq)]
pub(crate) struct FaceGrid {
    origin: Vector,
    u: Vector,
    v: Vector,
    lo: (Real, Real),
    size: (Real, Real),
}

impl FaceGrid {
    /// The grid frame of face `face` of `shape` (stored with the shape).
    #[inline]
    pub(crate) fn of(shape: &Polyhedron, face: usize) -> Self {
        *shape.face_grid(face)
    }

    /// Computes the grid frame of face `face` of `shape` from its vertices.
    pub(crate) fn compute(shape: &Polyhedron, face: usize) -> Self {
        let ring = shape.face_loop(face);
        let vertex = |i: usize| shape.vertices()[ring[i % ring.len()] as usize];
        let origin = vertex(0);
        let mut longest = (Real::NEG_INFINITY, Vector::X);
        for i in 0..ring.len() {
            let e = vertex(i + 1) - vertex(i);
            if e.length() > longest.0 {
                longest = (e.length(), e);
            }
        }
        let u = longest.1.normalize();
        let v = shape.faces()[face].normal.cross(u);
        let (mut lo, mut hi) = (
            (Real::INFINITY, Real::INFINITY),
            (Real::NEG_INFINITY, Real::NEG_INFINITY),
        );
        for i in 0..ring.len() {
            let d = vertex(i) - origin;
            let (x, y) = (u.dot(d), v.dot(d));
            lo = (lo.0.min(x), lo.1.min(y));
            hi = (hi.0.max(x), hi.1.max(y));
        }
        Self {
            origin,
            u,
            v,
            lo,
            size: (hi.0 - lo.0, hi.1 - lo.1),
        }
    }

    /// Grid lines across the face for spacing `h`: `(nu, nv)`.
    fn lines(&self, h: Real) -> (u32, u32) {
        // (Less a hair, so that a width of exactly `k h` makes `k` cells despite round-off.)
        let n = |w: Real| ((w / h - 1e-9).ceil() as u32).clamp(1, MAX_FACE_LINES);
        (n(self.size.0), n(self.size.1))
    }

    /// The unit axes `(u, v)` of the grid (body frame).
    #[inline]
    pub(crate) fn axes(&self) -> (Vector, Vector) {
        (self.u, self.v)
    }

    /// The size of a cell of the grid of `nu × nv` cells (m).
    #[inline]
    pub(crate) fn cell(&self, nu: u32, nv: u32) -> (Real, Real) {
        (self.size.0 / nu as Real, self.size.1 / nv as Real)
    }

    /// Crossing `(i, j)` of the grid of `nu × nv` cells (body frame).
    #[inline]
    pub(crate) fn point_at(&self, i: u32, j: u32, nu: u32, nv: u32) -> Vector {
        self.point(i, j, nu, nv)
    }

    /// Plane coordinates of crossing `(i, j)`.
    fn coordinates(&self, i: u32, j: u32, nu: u32, nv: u32) -> (Real, Real) {
        (
            self.lo.0 + self.size.0 * (i as Real / nu as Real),
            self.lo.1 + self.size.1 * (j as Real / nv as Real),
        )
    }

    #[inline]
    fn point(&self, i: u32, j: u32, nu: u32, nv: u32) -> Vector {
        let (x, y) = self.coordinates(i, j, nu, nv);
        self.origin + self.u * x + self.v * y
    }

    /// The grid lines `i` (of `nu`) whose crossing with line `j` (of `nv`) lies inside the face
    /// by at least `margin` from every edge: a range, the face being convex.
    fn row(&self, shape: &Polyhedron, face: usize, (j, nu, nv): (u32, u32, u32), margin: Real) -> std::ops::Range<u32> {
        let ring = shape.face_loop(face);
        let to2d = |i: usize| {
            let d = shape.vertices()[ring[i % ring.len()] as usize] - self.origin;
            (self.u.dot(d), self.v.dot(d))
        };
        let y = self.coordinates(0, j, nu, nv).1;
        let (mut left, mut right) = (Real::NEG_INFINITY, Real::INFINITY);
        for i in 0..ring.len() {
            let (p, q) = (to2d(i), to2d(i + 1));
            let (ex, ey) = (q.0 - p.0, q.1 - p.1);
            let length = (ex * ex + ey * ey).sqrt();
            if length == 0.0 {
                continue;
            }
            // Counter-clockwise seen from outside, the inside is on the left of each edge:
            // ex (y − p_y) − ey (x − p_x) ≥ margin · length.
            let c = margin * length - ex * (y - p.1);
            if ey < 0.0 {
                left = left.max(p.0 + c / -ey);
            } else if ey > 0.0 {
                right = right.min(p.0 - c / ey);
            } else if c > 0.0 {
                return 0..0;
            }
        }
        let cell = self.size.0 / nu as Real;
        if left > right || left.is_nan() || right.is_nan() || cell <= 0.0 {
            return 0..0;
        }
        let first = (((left - self.lo.0) / cell).ceil().max(1.0)) as u32;
        let last = (((right - self.lo.0) / cell).floor().min((nu - 1) as Real)).max(0.0) as u32;
        first..(last + 1).max(first)
    }

    /// The inner crossings of the grid for spacing `h` inside face `face` (at least a quarter
    /// cell from its edges, which carry their own nodes), as `(i, j, nu, nv)`, in the window
    /// `window` of plane coordinates (`None`: all).
    fn nodes<'s>(
        &'s self,
        shape: &'s Polyhedron,
        face: usize,
        h: Real,
        window: Option<((Real, Real), (Real, Real))>,
    ) -> impl Iterator<Item = (u32, u32, u32, u32)> + 's {
        let (nu, nv) = self.lines(h);
        let (du, dv) = (self.size.0 / nu as Real, self.size.1 / nv as Real);
        let margin = 0.25 * du.min(dv);
        let (i_window, j_window) = match window {
            Some((lo, hi)) if du > 0.0 && dv > 0.0 => (
                (
                    ((lo.0 - self.lo.0) / du).ceil().max(0.0) as u32,
                    ((hi.0 - self.lo.0) / du).floor().max(-1.0),
                ),
                (
                    ((lo.1 - self.lo.1) / dv).ceil().max(1.0) as u32,
                    ((hi.1 - self.lo.1) / dv).floor().min((nv - 1) as Real),
                ),
            ),
            _ => ((0, Real::INFINITY), (1, (nv - 1) as Real)),
        };
        let j_last = if j_window.1 < 0.0 { 0 } else { j_window.1 as u32 + 1 };
        (j_window.0..j_last).flat_map(move |j| {
            let row = self.row(shape, face, (j, nu, nv), margin);
            let start = row.start.max(i_window.0);
            let end = if i_window.1 < 0.0 {
                start
            } else {
                row.end.min((i_window.1.min(u32::MAX as Real) as u32).saturating_add(1))
            };
            (start..end.max(start)).map(move |i| (i, j, nu, nv))
        })
    }

    /// The plane coordinates of a body-frame point.
    fn plane(&self, p: Vector) -> (Real, Real) {
        let d = p - self.origin;
        (self.u.dot(d), self.v.dot(d))
    }
}

/// The face of `shape` that `q` (body frame) lies deepest under, and its signed distance from
/// that face's plane (m, positive = outside): `max_f (m_f·q − d_f)`, the first face on a tie.
#[inline]
pub(crate) fn deepest_face(shape: &Polyhedron, q: Vector) -> (usize, Real) {
    let (face, gap, _) = deepest_two(shape, q);
    (face, gap)
}

/// [`deepest_face`] and the largest signed distance from another face's plane (m): where the
/// two are equal, the node's normal turns from one face to the other.
#[inline]
pub(crate) fn deepest_two(shape: &Polyhedron, q: Vector) -> (usize, Real, Real) {
    let (mut face, mut best, mut second) = (0, Real::NEG_INFINITY, Real::NEG_INFINITY);
    for (i, f) in shape.faces().iter().enumerate() {
        let g = f.normal.dot(q) - f.offset;
        if g > best {
            (face, best, second) = (i, g, best);
        } else if g > second {
            second = g;
        }
    }
    (face, best, second)
}

/// Segments of an edge of length `length` between nodes at most `h` apart.
pub(super) fn segments(length: Real, h: Real) -> u32 {
    ((length / h - 1e-9).ceil() as u32).clamp(1, MAX_EDGE_SEGMENTS)
}

/// The nodes of a block for spacing `h` and the area each stands for.
///
/// Half of every face's area is shared among its nodes, as the cells of a face–face joint's grid
/// share it: the strip along its boundary, half a grid cell wide, among its vertices and edge
/// nodes by the length of boundary each stands for (half the segments on either side), the rest
/// equally among its inner grid nodes ([`FaceGrid`]; the whole face among the boundary nodes
/// when it has none). A vertex or edge node adds up its shares of the faces around it, and the
/// nodes of a block carry half its surface, whatever `h`. Half, because a contact lists the
/// nodes of both blocks: two faces pressed flat on each other both press their nodes into the
/// other, and together make the stiffness `k_n A` of a joint of their overlap `A`.
pub(crate) struct NodeAreas {
    /// Per face: the boundary nodes' area per unit length of boundary (m), and each inner
    /// node's area (m²).
    boundary: Vec<Real>,
    inner: Vec<Real>,
}

impl NodeAreas {
    pub(crate) fn of(shape: &Polyhedron, h: Real) -> Self {
        let (boundary, inner) = (0..shape.faces().len()).map(|f| Self::face_shares(shape, f, h)).unzip();
        Self { boundary, inner }
    }

    /// Face `f`'s boundary nodes' area per unit length of boundary (m) and each inner node's
    /// area (m²), for spacing `h` (see the type).
    fn face_shares(shape: &Polyhedron, f: usize, h: Real) -> (Real, Real) {
        let v = shape.vertices();
        let ring = shape.face_loop(f);
        let m = ring.len();
        let perimeter: Real = (0..m)
            .map(|i| (v[ring[(i + 1) % m] as usize] - v[ring[i] as usize]).length())
            .sum();
        let grid = FaceGrid::of(shape, f);
        let (nu, nv) = grid.lines(h);
        let (du, dv) = (grid.size.0 / nu as Real, grid.size.1 / nv as Real);
        let inner_nodes: u32 = (1..nv)
            .map(|j| grid.row(shape, f, (j, nu, nv), 0.25 * du.min(dv)).len() as u32)
            .sum();
        let area = shape.faces()[f].area;
        let strip = if inner_nodes == 0 {
            area
        } else {
            (0.5 * du.min(dv) * perimeter).min(area)
        };
        (
            if perimeter > 0.0 { 0.5 * strip / perimeter } else { 0.0 },
            if inner_nodes > 0 {
                0.5 * (area - strip) / inner_nodes as Real
            } else {
                0.0
            },
        )
    }

    /// The area of each inner grid node of face `face` (m²).
    #[inline]
    pub(crate) fn inner(&self, face: usize) -> Real {
        self.inner[face]
    }

    /// The area the boundary nodes of face `face` stand for per unit length of its boundary
    /// (m): a strip along the boundary twice as wide (half a grid cell, or the face's area over
    /// its perimeter when it has no inner node), at half weight.
    #[inline]
    pub(crate) fn boundary(&self, face: usize) -> Real {
        self.boundary[face]
    }

    /// The area of node `place` of `shape` for spacing `h` (m²).
    pub(crate) fn area(&self, shape: &Polyhedron, place: NodePlace, h: Real) -> Real {
        let v = shape.vertices();
        let segment = |p: u32, q: u32| {
            let length = (v[q as usize] - v[p as usize]).length();
            length / segments(length, h) as Real
        };
        match place {
            NodePlace::Face { face, .. } => self.inner[face as usize],
            NodePlace::Vertex(vertex) => (0..shape.faces().len())
                .map(|f| {
                    let ring = shape.face_loop(f);
                    let m = ring.len();
                    match ring.iter().position(|&r| r == vertex) {
                        Some(i) => {
                            let (before, after) = (ring[(i + m - 1) % m], ring[(i + 1) % m]);
                            self.boundary[f] * 0.5 * (segment(before, vertex) + segment(vertex, after))
                        }
                        None => 0.0,
                    }
                })
                .sum(),
            NodePlace::Edge { v0, v1, .. } => (0..shape.faces().len())
                .filter(|&f| {
                    let ring = shape.face_loop(f);
                    let m = ring.len();
                    (0..m).any(|i| {
                        let (p, q) = (ring[i], ring[(i + 1) % m]);
                        (p.min(q), p.max(q)) == (v0, v1)
                    })
                })
                .map(|f| self.boundary[f] * segment(v0, v1))
                .sum(),
        }
    }
}

/// The nodes of `host` (on block `b` when `on_b`) whose strips come within `tolerance` of `other`,
/// as seeds (anchor in the host's body frame), in key order.
fn push_nodes(
    host: BlockGeometry<'_>,
    other: BlockGeometry<'_>,
    on_b: bool,
    h: Real,
    (tolerance, rule): (Real, NodeRule),
    seeds: &mut Vec<SubContactSeed>,
) {
    let to_other = other.pose.inverse() * *host.pose;
    // Integrated, a node stands for the strips of surface around it (`strips.rs`) and is
    // listed when they come within the tolerance of the other block; at its point, when it
    // does. Nodes farther than this from the other block's centroid cannot.
    let strips = match rule {
        NodeRule::Point => 0.0,
        NodeRule::Integrated => h,
    };
    let reach = other.shape.radius() + tolerance + strips;
    let centre = to_other.inverse().transform_point(Vector::ZERO);
    let vertices = host.shape.vertices();
    let start = seeds.len();
    let mut areas = None;
    let mut try_node = |place: NodePlace, seeds: &mut Vec<SubContactSeed>| {
        let id = NodeId { on_b, place };
        let anchor = id.point(host.shape);
        let q = to_other.transform_point(anchor);
        if q.length() > reach {
            return;
        }
        let (face, gap) = deepest_face(other.shape, q);
        // Its strips lie within `h` of it (`strips.rs`), and the gap is 1-Lipschitz.
        if gap < tolerance + strips {
            let areas = areas.get_or_insert_with(|| NodeAreas::of(host.shape, h));
            // Its strips, at least as far out as their faces' least values over them. The
            // node lies on its strips: within the tolerance itself, it is listed without them.
            if gap >= tolerance {
                let mut least = Real::INFINITY;
                for_each_strip(host.shape, &*areas, place, h, |s| {
                    if least < tolerance {
                        return;
                    }
                    let placed = (
                        to_other.transform_point(s.centre),
                        to_other.rotation * s.u,
                        to_other.rotation * s.v,
                    );
                    least = least.min(least_gap(other.shape, placed, &s, face, tolerance));
                });
                if least >= tolerance {
                    return;
                }
            }
            seeds.push(SubContactSeed {
                key: id.key(),
                anchor,
                area: areas.area(host.shape, place, h),
                gap,
                half: crate::math::Vector2::ZERO,
            });
        }
    };
    for v in 0..(vertices.len() as u32).min(MAX_NODE_INDEX + 1) {
        try_node(NodePlace::Vertex(v), seeds);
    }
    for &[i, j] in host.shape.edges() {
        let (v0, v1) = (i.min(j), i.max(j));
        if v1 > MAX_NODE_INDEX {
            continue;
        }
        let (p0, p1) = (vertices[v0 as usize], vertices[v1 as usize]);
        // The edge against the other block's bounding sphere.
        let d = p1 - p0;
        let t = if d.length_squared() > 0.0 {
            ((centre - p0).dot(d) / d.length_squared()).clamp(0.0, 1.0)
        } else {
            0.0
        };
        if (p0 + d * t - centre).length() > reach {
            continue;
        }
        let n = segments(d.length(), h);
        for k in 1..n {
            try_node(NodePlace::Edge { v0, v1, k, n }, seeds);
        }
    }
    for (f, face) in host.shape.faces().iter().enumerate().take(MAX_NODE_INDEX as usize + 1) {
        // The face's plane against the other block's bounding sphere.
        if (face.normal.dot(centre) - face.offset).abs() > reach {
            continue;
        }
        let grid = FaceGrid::of(host.shape, f);
        let (cx, cy) = grid.plane(centre);
        let window = ((cx - reach, cy - reach), (cx + reach, cy + reach));
        for (i, j, nu, nv) in grid.nodes(host.shape, f, h, Some(window)) {
            if (grid.point(i, j, nu, nv) - centre).length() <= reach {
                try_node(
                    NodePlace::Face {
                        face: f as u32,
                        i,
                        j,
                        nu,
                        nv,
                    },
                    seeds,
                );
            }
        }
    }
    seeds[start..].sort_unstable_by_key(|s| s.key);
}

/// A node contact between `a` and `b` (`n` the common-plane normal from `a` to `b`): the nodes of
/// both blocks within the tolerance of the other, `None` when there are none.
pub(super) fn node_contact(
    a: BlockGeometry<'_>,
    b: BlockGeometry<'_>,
    n: Vector,
    params: &ContactParameters,
    seeds: &mut Vec<SubContactSeed>,
) -> Option<DetectedContact> {
    let h = spacing(a.shape, b.shape, params.density);
    let start = seeds.len();
    let listing = (params.tolerance, params.node_rule);
    push_nodes(a, b, false, h, listing, seeds);
    push_nodes(b, a, true, h, listing, seeds);
    (seeds.len() > start).then_some(DetectedContact {
        kind: ContactKind::Nodes,
        host_is_a: true,
        normal: n,
    })
}

#[cfg(test)]
pub(super) mod tests {
    use super::*;
    use crate::geometry::Polyhedron;

    pub(in super::super) fn shape(points: &[Vector]) -> Polyhedron {
        Polyhedron::from_hull("test", points).expect("hull").shape
    }

    pub(in super::super) fn cube(s: Real) -> Polyhedron {
        let v = |x, y, z| Vector::new(x, y, z);
        shape(&[
            v(-s, -s, -s),
            v(s, -s, -s),
            v(-s, s, -s),
            v(s, s, -s),
            v(-s, -s, s),
            v(s, -s, s),
            v(-s, s, s),
            v(s, s, s),
        ])
    }

    pub(in super::super) fn wedge(s: Real) -> Polyhedron {
        let v = |x, y, z| Vector::new(x, y, z);
        shape(&[
            v(-s, -s, -s),
            v(s, -s, -s),
            v(0.0, -s, s),
            v(-s, s, -s),
            v(s, s, -s),
            v(0.0, s, s),
        ])
    }

    /// Every node of a block for spacing `h`, with its area.
    pub(in super::super) fn all_nodes(shape: &Polyhedron, h: Real) -> Vec<(NodePlace, Real)> {
        let areas = NodeAreas::of(shape, h);
        let mut places: Vec<NodePlace> = (0..shape.vertices().len() as u32).map(NodePlace::Vertex).collect();
        for &[i, j] in shape.edges() {
            let (v0, v1) = (i.min(j), i.max(j));
            let n = segments(
                (shape.vertices()[v1 as usize] - shape.vertices()[v0 as usize]).length(),
                h,
            );
            places.extend((1..n).map(|k| NodePlace::Edge { v0, v1, k, n }));
        }
        for f in 0..shape.faces().len() {
            let grid = FaceGrid::of(shape, f);
            places.extend(grid.nodes(shape, f, h, None).map(|(i, j, nu, nv)| NodePlace::Face {
                face: f as u32,
                i,
                j,
                nu,
                nv,
            }));
        }
        places.into_iter().map(|p| (p, areas.area(shape, p, h))).collect()
    }

    /// Keys name their nodes back, sort by side first, and are distinct.
    #[test]
    fn node_keys_round_trip() {
        let s = wedge(0.1);
        let nodes = all_nodes(&s, 0.013);
        let mut keys = Vec::new();
        for on_b in [false, true] {
            for (place, _) in &nodes {
                let id = NodeId { on_b, place: *place };
                assert!(id.fits(&s));
                assert_eq!(NodeId::from_key(id.key()), id);
                keys.push(id.key());
            }
        }
        let sorted = keys.windows(2).filter(|w| w[0] > w[1]).count();
        keys.sort();
        keys.dedup();
        assert_eq!(keys.len(), 2 * nodes.len(), "distinct keys");
        // Side first: every node of a sorts before every node of b.
        let last_a = NodeId {
            on_b: false,
            place: NodePlace::Face {
                face: 0xffff,
                i: 0x3ff,
                j: 0x3ff,
                nu: 0x3ff,
                nv: 0x3ff,
            },
        };
        let first_b = NodeId {
            on_b: true,
            place: NodePlace::Vertex(0),
        };
        assert!(last_a.key() < first_b.key());
        let _ = sorted;
    }

    /// The depth of a point inside a cube is its distance to the nearest face; outside, the
    /// distance to the plane it is farthest beyond.
    #[test]
    fn deepest_face_is_the_distance_inside_a_convex_block() {
        let c = cube(0.5);
        let (_, g) = deepest_face(&c, Vector::new(0.1, 0.2, 0.45));
        assert!((g + 0.05).abs() < 1e-12, "{g}");
        let (f, g) = deepest_face(&c, Vector::new(0.0, 0.0, 0.7));
        assert!((g - 0.2).abs() < 1e-12 && c.faces()[f].normal.z > 0.99, "{g}");
    }

    /// The nodes of a block carry half its surface, whatever the spacing; face nodes lie inside
    /// their face, about `h` apart.
    #[test]
    fn node_areas_add_up_to_the_surface() {
        for s in [cube(0.1), wedge(0.1)] {
            let surface: Real = s.faces().iter().map(|f| f.area).sum();
            for h in [0.3, 0.05, 0.013] {
                let nodes = all_nodes(&s, h);
                let total: Real = nodes.iter().map(|(_, a)| a).sum();
                assert!(
                    (2.0 * total - surface).abs() < 1e-12 * surface,
                    "h {h}: {total} against half of {surface}"
                );
                for (place, _) in &nodes {
                    if let NodePlace::Face { face, .. } = place {
                        let p = NodeId {
                            on_b: false,
                            place: *place,
                        }
                        .point(&s);
                        let f = &s.faces()[*face as usize];
                        assert!((f.normal.dot(p) - f.offset).abs() < 1e-12);
                        assert!(deepest_face(&s, p).1 < 1e-12);
                    }
                }
            }
            // A cube face at h = 0.05 (0.2 m): 4 × 4 cells, 3 × 3 inner nodes.
        }
        let c = cube(0.1);
        let inner = FaceGrid::of(&c, 0).nodes(&c, 0, 0.05, None).count();
        assert_eq!(inner, 9);
    }
}
