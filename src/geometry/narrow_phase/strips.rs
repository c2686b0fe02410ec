//! Nodes integrated over the surface they stand for (`docs/theory.md` §2.2, "Node contacts").
//!
//! A node of a node contact stands for part of its block's surface: a strip half a grid cell
//! wide along each face beside an edge or a vertex, a grid cell of a face's inside
//! ([`NodeAreas`], at half weight: both blocks' nodes are listed). Pressed at its point, a node
//! stores `½ k_n A g²` for its whole share `A`; a face-face joint's cells integrate
//! `½ k_n ∫ min(g, 0)² dA` over the surface itself. The two agree where the gap is uniform
//! (faces pressed flat), not at an edge: a hinge 1.85 mm deep at its edge, opened by 15°, stored
//! 1.15 J in its 225 cells and 6.78 J in the 48 point nodes that replaced them
//! (`docs/benchmarks/arch-impact.md`, item 6). Here a node's share is integrated as the cells
//! integrate theirs: each strip is a rectangle of its face (body frame of the node's block),
//! and
//!
//! ```text
//! E = ½ k_n ρ ∫ min(g(x), 0)² dA,   g(x) = max_f (m_f·q(x) − d_f)
//! ```
//!
//! over the rectangle, with `ρ = A / (4 h_u h_v)` its weight and `g` the signed distance of the
//! rectangle's point `x` from the other (convex) block `Y` (`q` in `Y`'s body frame, `m_f` and
//! `d_f` its faces' outward normals and offsets): exact inside `Y`, positive outside. `E` is a
//! function of the two poses alone, continuous everywhere (also where the face `Y`'s surface
//! is nearest to changes), and its gradient is the pressure `k_n ρ (−g)` along `m_f` over the
//! part of the rectangle under face `f`: the force this module integrates. On each face's part
//! `g` is linear, so the integrals are those of a linear function over a convex polygon (the
//! rectangle clipped by `g_f ≤ 0` and by `g_f ≥ g_h` for every other face `h` that can be
//! deepest there), exact by triangles.

use super::nodes::{FaceGrid, NodeAreas, NodeId, NodePlace};
use crate::geometry::Polyhedron;
use crate::math::{Real, Vector};

/// One piece of the surface a node stands for, in its block's body frame: a rectangle of its
/// face (centre, unit axes in the face's plane, half sizes) cut to the face where it sticks out
/// (at an acute corner), whose springs have the stiffness `k_n ρ` per unit area, `ρ` the area
/// the rectangle stands for over its own area (one half, as the shares are made).
#[derive(Debug, Clone, Copy, PartialEq)]
pub(crate) struct Strip {
    pub centre: Vector,
    pub u: Vector,
    pub v: Vector,
    /// The piece in the coordinates `(s, t)` along `u`, `v` from the centre.
    pub polygon: Polygon,
    /// The piece's area moments `(∫1, ∫s, ∫t, ∫s², ∫st, ∫t²)`: a piece under one face all
    /// over integrates from them.
    moments: [Real; 6],
    pub density: Real,
}

impl Strip {
    /// The rectangle of half sizes `half` about `centre` along `u`, `v`, standing for `area`,
    /// cut to face `face` of `shape`.
    fn new(
        shape: &Polyhedron,
        face: usize,
        (centre, u, v): (Vector, Vector, Vector),
        half: (Real, Real),
        area: Real,
    ) -> Self {
        let mut polygon = Polygon::rectangle(half.0, half.1);
        let n = shape.faces()[face].normal;
        let ring = shape.face_loop(face);
        let vertices = shape.vertices();
        for i in 0..ring.len() {
            let (p, q) = (
                vertices[ring[i] as usize],
                vertices[ring[(i + 1) % ring.len()] as usize],
            );
            // Inside the face (counter-clockwise seen from outside): n·((q − p) × (x − p)) ≥ 0.
            let e = q - p;
            let (c, a, b) = (n.dot(e.cross(centre - p)), n.dot(e.cross(u)), n.dot(e.cross(v)));
            // (Less a hair of round-off: the rectangle's own edges lie on the face's.)
            let slack = 1e-12 * e.length() * (half.0 + half.1);
            // Most rectangles lie inside their face: clipped only where a corner sticks out.
            if c + slack - a.abs() * half.0 - b.abs() * half.1 < 0.0 {
                polygon.clip(|s, t| c + a * s + b * t + slack);
            }
        }
        let density = if half.0 > 0.0 && half.1 > 0.0 {
            area / (4.0 * half.0 * half.1)
        } else {
            0.0
        };
        Self::of((centre, u, v), polygon, density)
    }

    /// The piece `polygon` in the plane through `centre` along `u`, `v`, of weight `density`.
    fn of((centre, u, v): (Vector, Vector, Vector), polygon: Polygon, density: Real) -> Self {
        let (area, s, t, _) = polygon.integrals(|_, _| 1.0);
        let (_, ss, st, _) = polygon.integrals(|s, _| s);
        let (_, _, tt, _) = polygon.integrals(|_, t| t);
        Self {
            centre,
            u,
            v,
            polygon,
            moments: [area, s, t, ss, st, tt],
            density,
        }
    }

    /// The area it stands for (m²): `ρ` times its piece's area.
    #[cfg(test)]
    pub(crate) fn area(&self) -> Real {
        self.density * self.polygon.integrals(|_, _| 1.0).0
    }

    /// The largest distance from `point` to the strip (m): a node's strips lie within this of
    /// it.
    #[cfg(test)]
    fn reach(&self, point: Vector) -> Real {
        self.polygon.points[..self.polygon.len]
            .iter()
            .map(|&(s, t)| (self.centre + self.u * s + self.v * t - point).length())
            .fold(0.0, Real::max)
    }
}

/// The share of a face's area its nodes stand for: per unit length of its boundary (m) and
/// per inner node (m²), as [`NodeAreas`] gives them.
pub(crate) trait FaceShares {
    /// The boundary share of face `face` (m).
    fn boundary_share(&self, face: usize) -> Real;
    /// The inner nodes' share of face `face` (m²).
    fn inner_share(&self, face: usize) -> Real;
}

impl FaceShares for NodeAreas {
    #[inline]
    fn boundary_share(&self, face: usize) -> Real {
        self.boundary(face)
    }
    #[inline]
    fn inner_share(&self, face: usize) -> Real {
        self.inner(face)
    }
}

/// A block's face shares ([`NodeAreas`]) with one node's own area for its face's inner share:
/// the area its sub-contact holds (the same, as detection gives it).
pub(crate) struct SharesOf<'a> {
    pub areas: &'a NodeAreas,
    pub inner: Real,
}

impl FaceShares for SharesOf<'_> {
    #[inline]
    fn boundary_share(&self, face: usize) -> Real {
        self.areas.boundary(face)
    }
    #[inline]
    fn inner_share(&self, _: usize) -> Real {
        self.inner
    }
}

/// The strips of every node of a node contact, in the order of its sub-contacts, in the body
/// frame of each node's block. They depend on the blocks' shapes and the node spacing alone, so
/// a contact builds them at its first integrated step after its detection
/// ([`crate::contact::ContactReference::node_keys_and_strips`]) and steps with them until the next.
#[derive(Debug, Clone, PartialEq, Default)]
pub(crate) struct NodeStrips {
    /// Node `k`'s strips are `strips[starts[k]..starts[k + 1]]`; empty until built.
    starts: Vec<u32>,
    strips: Vec<Strip>,
}

impl NodeStrips {
    /// The strips of `nodes` (each node's id and area) of a contact between blocks of shapes
    /// `a` and `b`, for node spacing `h`.
    pub(crate) fn build(
        nodes: impl ExactSizeIterator<Item = (NodeId, Real)>,
        (a, b): (&Polyhedron, &Polyhedron),
        h: Real,
    ) -> Self {
        let mut starts = Vec::with_capacity(nodes.len() + 1);
        let mut strips = Vec::new();
        let mut areas: [Option<NodeAreas>; 2] = [None, None];
        starts.push(0);
        for (id, area) in nodes {
            let shape = if id.on_b { b } else { a };
            let areas = areas[usize::from(id.on_b)].get_or_insert_with(|| NodeAreas::of(shape, h));
            let shares = SharesOf { areas, inner: area };
            for_each_strip(shape, &shares, id.place, h, |s| strips.push(s));
            starts.push(strips.len() as u32);
        }
        Self { starts, strips }
    }

    /// Whether it holds the strips of `nodes` nodes.
    #[inline]
    pub(crate) fn holds(&self, nodes: usize) -> bool {
        self.starts.len() == nodes + 1
    }

    /// Node `k`'s strips.
    #[inline]
    pub(crate) fn of(&self, k: usize) -> &[Strip] {
        match (self.starts.get(k), self.starts.get(k + 1)) {
            (Some(&from), Some(&to)) => &self.strips[from as usize..to as usize],
            _ => &[],
        }
    }
}

/// The strips of a node (at most two per face around a vertex): `f` is called with each.
pub(crate) fn for_each_strip(
    shape: &Polyhedron,
    areas: &impl FaceShares,
    place: NodePlace,
    h: Real,
    mut f: impl FnMut(Strip),
) {
    let v = shape.vertices();
    match place {
        NodePlace::Face { face, i, j, nu, nv } => {
            let grid = FaceGrid::of(shape, face as usize);
            let (du, dv) = grid.cell(nu, nv);
            f(Strip::new(
                shape,
                face as usize,
                (grid.point_at(i, j, nu, nv), grid.axes().0, grid.axes().1),
                (0.5 * du, 0.5 * dv),
                areas.inner_share(face as usize),
            ));
        }
        NodePlace::Edge { v0, v1, k, n } => {
            let (p0, p1) = (v[v0 as usize], v[v1 as usize]);
            let length = (p1 - p0).length();
            if length <= 0.0 {
                return;
            }
            let t = (p1 - p0) / length;
            let point = p0 + (p1 - p0) * (k as Real / n as Real);
            let segment = length / n as Real;
            for face in faces_with_edge(shape, v0, v1) {
                let boundary = areas.boundary_share(face);
                let width = 2.0 * boundary;
                let inward = inward(shape, face, t, p0);
                f(Strip::new(
                    shape,
                    face,
                    (point + inward * (0.5 * width), t, inward),
                    (0.5 * segment, 0.5 * width),
                    boundary * segment,
                ));
            }
        }
        NodePlace::Vertex(vertex) => {
            let point = v[vertex as usize];
            for face in 0..shape.faces().len() {
                let ring = shape.face_loop(face);
                let m = ring.len();
                let Some(i) = ring.iter().position(|&r| r == vertex) else {
                    continue;
                };
                let boundary = areas.boundary_share(face);
                let width = 2.0 * boundary;
                for other in [ring[(i + m - 1) % m], ring[(i + 1) % m]] {
                    let edge = v[other as usize] - point;
                    let length = edge.length();
                    if length <= 0.0 {
                        continue;
                    }
                    let t = edge / length;
                    // Half of the segment next to the vertex.
                    let along = 0.5 * length / super::nodes::segments(length, h) as Real;
                    let inward = inward(shape, face, t, point);
                    f(Strip::new(
                        shape,
                        face,
                        (point + t * (0.5 * along) + inward * (0.5 * width), t, inward),
                        (0.5 * along, 0.5 * width),
                        boundary * along,
                    ));
                }
            }
        }
    }
}

/// The faces of `shape` whose loop holds the edge `v0`–`v1`.
fn faces_with_edge(shape: &Polyhedron, v0: u32, v1: u32) -> impl Iterator<Item = usize> + '_ {
    (0..shape.faces().len()).filter(move |&f| {
        let ring = shape.face_loop(f);
        let m = ring.len();
        (0..m).any(|i| {
            let (p, q) = (ring[i], ring[(i + 1) % m]);
            (p.min(q), p.max(q)) == (v0.min(v1), v0.max(v1))
        })
    })
}

/// The unit vector in face `face`'s plane normal to the direction `t` of its edge through
/// `on_edge`, pointing into the face (towards its vertices' average, inside the convex face).
fn inward(shape: &Polyhedron, face: usize, t: Vector, on_edge: Vector) -> Vector {
    let w = shape.faces()[face].normal.cross(t).normalize_or_zero();
    let ring = shape.face_loop(face);
    let v = shape.vertices();
    let centroid = ring.iter().map(|&r| v[r as usize]).sum::<Vector>() / ring.len() as Real;
    if w.dot(centroid - on_edge) >= 0.0 {
        w
    } else {
        -w
    }
}

/// What the other block does to a node's strips, per unit `k_n` (in the other block's body
/// frame).
#[derive(Debug, Clone, Copy, Default, PartialEq)]
pub(crate) struct StripLoad {
    /// `Σ ρ ∫ max(−g, 0) dA` (m³): the normal force over `k_n`.
    pub load: Real,
    /// `Σ ρ ∫ max(−g, 0) m_f dA` (m³): the force on the node's block over `k_n`, along the
    /// other block's outward normals.
    pub force: Vector,
    /// Its moment about the point given to [`StripLoad::add`] (m⁴).
    pub moment: Vector,
    /// `½ Σ ρ ∫ min(g, 0)² dA` (m⁴): the stored energy over `k_n`.
    pub energy: Real,
    /// The load under each face of the other block so far (face, load), the first
    /// [`TRACKED_FACES`] faces met ([`StripLoad::loaded_faces`]).
    parts: [(u32, Real); TRACKED_FACES],
}

/// The most faces of the other block a node's load is told apart by ([`StripLoad::loaded_faces`]).
const TRACKED_FACES: usize = 6;

impl StripLoad {
    /// The faces of the other block that carry a part of the load (among the first
    /// [`TRACKED_FACES`] met): the candidates for the plane a pressed node's stored shear is
    /// kept in (`contact/node_step.rs`).
    pub(crate) fn loaded_faces(&self) -> impl Iterator<Item = usize> + '_ {
        self.parts.iter().filter(|p| p.1 > 0.0).map(|p| p.0 as usize)
    }
}

/// The most vertices a clipped rectangle keeps here: four, one more per clip that cuts it.
const MAX_VERTICES: usize = 16;

/// The most faces of the other block a piece is integrated under.
const MAX_CANDIDATES: usize = 32;

impl StripLoad {
    /// Adds the load of `strip`, whose centre and axes in the body frame of the other block
    /// `other` are `centre`, `u`, `v`, with moments about `about` (same frame). `near` is the
    /// face of `other` the piece is likeliest to be out of (the one its node lies deepest
    /// under): it is tried first.
    pub(crate) fn add(
        &mut self,
        other: &Polyhedron,
        (centre, u, v): (Vector, Vector, Vector),
        strip: &Strip,
        about: Vector,
        near: usize,
    ) {
        let piece = &strip.polygon;
        if piece.len < 3 || strip.density.is_nan() || strip.density <= 0.0 {
            return;
        }
        let corners = &piece.points[..piece.len];
        let faces = other.faces();
        // Each face's signed distance over the piece, `c + a s + b t`; its least value is at a
        // corner of the (convex) piece.
        let linear = |f: usize| {
            let m = faces[f].normal;
            (m.dot(centre) - faces[f].offset, m.dot(u), m.dot(v))
        };
        // Its least and largest value over the piece: at corners of the (convex) piece.
        let extremes = |(c, a, b): (Real, Real, Real)| {
            corners
                .iter()
                .fold((Real::INFINITY, Real::NEG_INFINITY), |(lo, hi), &(s, t)| {
                    let g = c + a * s + b * t;
                    (lo.min(g), hi.max(g))
                })
        };
        // Outside a face's plane all over: outside the block.
        let floor = least_gap(other, (centre, u, v), strip, near, 0.0);
        if floor > 0.0 {
            return;
        }
        // The faces that can be deepest somewhere on the piece and are below zero somewhere. A
        // face whose largest value over the piece is below `floor` is never deepest there;
        // among the others, one that another lies above all over is not either (no face
        // left out by the first test lies above a face kept by it).
        let mut candidates = [(0usize, (0.0, 0.0, 0.0)); MAX_CANDIDATES];
        let mut count = 0;
        let mut below = false;
        for f in 0..faces.len() {
            let lf = linear(f);
            let (lo, hi) = extremes(lf);
            if lo > 0.0 || hi < floor {
                continue;
            }
            if count == candidates.len() {
                // Beyond any shape a step meets (that many faces deepest in pieces of one
                // strip): the faces found so far bound the rest.
                break;
            }
            candidates[count] = (f, lf);
            count += 1;
            below = hi <= 0.0;
        }
        // One face deepest all over, the piece below its plane all over: `g` is that face's
        // linear function on the whole piece, and its integrals follow from the piece's area
        // moments (the usual case, a node pressed flat).
        if count == 1 && below {
            let (f, (c, a, b)) = candidates[0];
            let [area, s, t, ss, st, tt] = strip.moments;
            let rho = strip.density;
            let load = -(c * area + a * s + b * t) * rho;
            let first_s = -(c * s + a * ss + b * st) * rho;
            let first_t = -(c * t + a * st + b * tt) * rho;
            let square = (c * c * area + 2.0 * c * (a * s + b * t) + a * a * ss + 2.0 * a * b * st + b * b * tt) * rho;
            self.accumulate(
                (f, faces[f].normal),
                (centre, u, v),
                about,
                (load, first_s, first_t, square),
            );
            return;
        }
        let kept = &mut [true; MAX_CANDIDATES][..count];
        if count > 1 {
            for k in 0..count {
                let lf = candidates[k].1;
                kept[k] = !(0..count).any(|j| {
                    let lg = candidates[j].1;
                    // `l_g − l_f` positive all over.
                    j != k && extremes((lg.0 - lf.0, lg.1 - lf.1, lg.2 - lf.2)).0 > 0.0
                });
            }
        }
        let mut live = 0;
        for k in 0..count {
            if kept[k] {
                candidates[live] = candidates[k];
                live += 1;
            }
        }
        let candidates = &candidates[..live];
        for (k, &(f, lf)) in candidates.iter().enumerate() {
            let mut polygon = *piece;
            // Below the face's plane…
            polygon.clip(|s, t| -(lf.0 + lf.1 * s + lf.2 * t));
            // …and above every other candidate's.
            for (j, &(_, lg)) in candidates.iter().enumerate() {
                if j == k || polygon.len == 0 {
                    continue;
                }
                // Ties go to the first of the two faces (`deepest_face`'s rule).
                polygon.clip(|s, t| {
                    let d = (lf.0 - lg.0) + (lf.1 - lg.1) * s + (lf.2 - lg.2) * t;
                    if d == 0.0 && j < k {
                        -Real::MIN_POSITIVE
                    } else {
                        d
                    }
                });
            }
            let i = polygon.integrals(|s, t| -(lf.0 + lf.1 * s + lf.2 * t));
            if i.0 <= 0.0 {
                continue;
            }
            let rho = strip.density;
            self.accumulate(
                (f, faces[f].normal),
                (centre, u, v),
                about,
                (i.0 * rho, i.1 * rho, i.2 * rho, i.3 * rho),
            );
        }
    }
}

impl StripLoad {
    /// Adds the part of a piece under a face of outward normal `m`: its load, first moments
    /// along `u` and `v` about `centre`, and `∫ g²` (each times `ρ`), with moments about
    /// `about`.
    #[inline]
    fn accumulate(
        &mut self,
        (face, m): (usize, Vector),
        (centre, u, v): (Vector, Vector, Vector),
        about: Vector,
        (load, first_s, first_t, square): (Real, Real, Real, Real),
    ) {
        let face = face as u32;
        if let Some(part) = self.parts.iter_mut().find(|p| p.0 == face || p.1 == 0.0) {
            *part = (face, part.1 + load);
        }
        self.load += load;
        self.force += m * load;
        self.moment += ((centre - about) * load + u * first_s + v * first_t).cross(m);
        self.energy += 0.5 * square;
    }
}

/// A lower bound of the signed distance from `other` over the piece of `strip` placed at
/// `centre`, `u`, `v` (body frame of `other`): the largest of its faces' least values over the
/// piece (`g ≥ g_f` everywhere for every face `f`), exact where one face is deepest all over.
/// Face `near` is tried first, and the search stops once the bound exceeds `stop`.
pub(crate) fn least_gap(
    other: &Polyhedron,
    (centre, u, v): (Vector, Vector, Vector),
    strip: &Strip,
    near: usize,
    stop: Real,
) -> Real {
    let faces = other.faces();
    let corners = &strip.polygon.points[..strip.polygon.len];
    let mut floor = Real::NEG_INFINITY;
    for f in std::iter::once(near).chain(0..faces.len()).filter(|&f| f < faces.len()) {
        let m = faces[f].normal;
        let (c, a, b) = (m.dot(centre) - faces[f].offset, m.dot(u), m.dot(v));
        let least = corners
            .iter()
            .map(|&(s, t)| c + a * s + b * t)
            .fold(Real::INFINITY, Real::min);
        floor = floor.max(least);
        if floor > stop {
            break;
        }
    }
    floor
}

/// A convex polygon in a strip's coordinates `(s, t)`.
#[derive(Debug, Clone, Copy, PartialEq)]
pub(crate) struct Polygon {
    points: [(Real, Real); MAX_VERTICES],
    len: usize,
}

impl Polygon {
    fn rectangle(hu: Real, hv: Real) -> Self {
        let mut points = [(0.0, 0.0); MAX_VERTICES];
        points[..4].copy_from_slice(&[(-hu, -hv), (hu, -hv), (hu, hv), (-hu, hv)]);
        Self { points, len: 4 }
    }

    /// Keeps the part where `keep(s, t) ≥ 0` (Sutherland–Hodgman; `keep` linear).
    fn clip(&mut self, keep: impl Fn(Real, Real) -> Real) {
        let n = self.len;
        if n == 0 {
            return;
        }
        let mut out = [(0.0, 0.0); MAX_VERTICES];
        let mut m = 0;
        for i in 0..n {
            let (p, q) = (self.points[i], self.points[(i + 1) % n]);
            let (kp, kq) = (keep(p.0, p.1), keep(q.0, q.1));
            if kp >= 0.0 && m < MAX_VERTICES {
                out[m] = p;
                m += 1;
            }
            if (kp >= 0.0) != (kq >= 0.0) && m < MAX_VERTICES {
                let w = kp / (kp - kq);
                out[m] = (p.0 + (q.0 - p.0) * w, p.1 + (q.1 - p.1) * w);
                m += 1;
            }
        }
        self.points = out;
        self.len = if m >= 3 { m } else { 0 };
    }

    /// `(∫ φ, ∫ s φ, ∫ t φ, ∫ φ²)` over the polygon for the linear `φ`, by a fan of triangles
    /// (exact: `∫ φ ψ = A/12 (Σ φᵢψᵢ + Σ φᵢ Σ ψᵢ)` over a triangle for linear `φ`, `ψ`).
    fn integrals(&self, phi: impl Fn(Real, Real) -> Real) -> (Real, Real, Real, Real) {
        let mut sums = (0.0, 0.0, 0.0, 0.0);
        if self.len < 3 {
            return sums;
        }
        let p0 = self.points[0];
        let f0 = phi(p0.0, p0.1);
        for i in 1..self.len - 1 {
            let (p1, p2) = (self.points[i], self.points[i + 1]);
            let area = 0.5 * ((p1.0 - p0.0) * (p2.1 - p0.1) - (p2.0 - p0.0) * (p1.1 - p0.1));
            let (f1, f2) = (phi(p1.0, p1.1), phi(p2.0, p2.1));
            let sf = f0 + f1 + f2;
            let product = |a: (Real, Real, Real), b: (Real, Real, Real)| {
                area / 12.0 * (a.0 * b.0 + a.1 * b.1 + a.2 * b.2 + (a.0 + a.1 + a.2) * (b.0 + b.1 + b.2))
            };
            let f = (f0, f1, f2);
            sums.0 += area * sf / 3.0;
            sums.1 += product((p0.0, p1.0, p2.0), f);
            sums.2 += product((p0.1, p1.1, p2.1), f);
            sums.3 += product(f, f);
        }
        sums
    }
}

#[cfg(test)]
mod tests {
    use super::super::nodes::tests::{all_nodes, cube, shape, wedge};
    use super::super::nodes::{deepest_face, NodeId};
    use super::*;
    use crate::math::Rotation;

    /// A node's strips stand for its area, to round-off, on every node of a cube, a wedge and a
    /// random stone at three spacings; each lies in its face, inside the face's plane.
    #[test]
    fn strips_stand_for_the_node_areas() {
        let stone = shape(&[
            Vector::new(0.11, -0.03, 0.02),
            Vector::new(-0.09, 0.05, -0.04),
            Vector::new(0.02, 0.12, 0.07),
            Vector::new(-0.04, -0.1, 0.09),
            Vector::new(0.05, 0.02, -0.11),
            Vector::new(-0.07, -0.06, -0.05),
            Vector::new(0.08, 0.09, -0.02),
            Vector::new(-0.02, 0.01, 0.13),
        ]);
        for (s, cut) in [(cube(0.1), false), (wedge(0.1), true), (stone, true)] {
            for h in [0.3, 0.05, 0.013] {
                let areas = NodeAreas::of(&s, h);
                for (place, area) in all_nodes(&s, h) {
                    let mut total = 0.0;
                    let p = NodeId { on_b: false, place }.point(&s);
                    for_each_strip(&s, &areas, place, h, |strip| {
                        total += strip.area();
                        // Every corner of its piece lies on one face, inside it.
                        let corners = &strip.polygon.points[..strip.polygon.len];
                        assert!(corners.len() >= 3, "{place:?}");
                        let on_face = (0..s.faces().len()).any(|f| {
                            let face = &s.faces()[f];
                            let ring = s.face_loop(f);
                            corners.iter().all(|&(a, b)| {
                                let x = strip.centre + strip.u * a + strip.v * b;
                                (face.normal.dot(x) - face.offset).abs() < 1e-12
                                    && (0..ring.len()).all(|i| {
                                        let (p, q) = (
                                            s.vertices()[ring[i] as usize],
                                            s.vertices()[ring[(i + 1) % ring.len()] as usize],
                                        );
                                        face.normal.dot((q - p).cross(x - p)) > -1e-9
                                    })
                            })
                        });
                        assert!(on_face, "{place:?}: {strip:?}");
                        assert!(strip.reach(p) <= h / Real::sqrt(2.0) * (1.0 + 1e-12) + 1e-12);
                    });
                    // Cut only where a rectangle sticks out of its face, at an acute corner.
                    if cut {
                        assert!(total <= area * (1.0 + 1e-12), "{place:?}: {total} against {area}");
                    } else {
                        assert!(
                            (total - area).abs() <= 1e-12 * area,
                            "{place:?}: {total} against {area}"
                        );
                    }
                }
            }
        }
    }

    /// Strips (centre, axes, half sizes) of the tests against the cube of half-size 0.1: across
    /// the top face's edge, tilted; over a corner, three faces deepest in parts.
    fn edge_and_corner() -> [(Vector, Vector, Vector, (Real, Real)); 2] {
        [
            (
                Vector::new(0.09, 0.02, 0.095),
                Vector::new(1.0, 0.0, 0.1),
                Vector::new(0.0, 1.0, 0.0),
                (0.03, 0.01),
            ),
            (
                Vector::new(0.085, 0.085, 0.09),
                Vector::new(1.0, 1.0, 0.3),
                Vector::new(-1.0, 1.0, 0.0),
                (0.025, 0.02),
            ),
        ]
    }

    /// The load of a strip equals a fine sampling of the pressure under the block's surface,
    /// where the strip crosses an edge and a corner of a turned cube (three faces deepest in
    /// parts of it), to the sampling's error.
    #[test]
    fn a_strip_is_integrated_exactly() {
        let y = cube(0.1);
        let turn = Rotation::from_scaled_axis(Vector::new(0.2, -0.35, 0.15));
        // Deep inside, one face.
        let inside = (
            Vector::new(0.0, 0.0, 0.08),
            Vector::new(1.0, 0.0, 0.0),
            Vector::new(0.0, 1.0, 0.0),
            (0.02, 0.02),
        );
        for (centre, u, v, half) in edge_and_corner().into_iter().chain([inside]) {
            // The strip's axes turned off the cube's.
            let u = (turn * u.normalize()).normalize();
            let v = turn * v;
            let v = (v - u * u.dot(v)).normalize();
            let about = centre + Vector::new(0.01, -0.02, 0.005);
            let area = 0.5 * 4.0 * half.0 * half.1;
            let y_turned = &y;
            let mut exact = StripLoad::default();
            let strip = Strip::of(
                (centre, u, v),
                Polygon::rectangle(half.0, half.1),
                area / (4.0 * half.0 * half.1),
            );
            exact.add(y_turned, (centre, u, v), &strip, about, 0);
            let n = 500;
            let mut sampled = StripLoad::default();
            let cell = 4.0 * half.0 * half.1 / (n * n) as Real;
            for i in 0..n {
                for j in 0..n {
                    let s = -half.0 + (i as Real + 0.5) * 2.0 * half.0 / n as Real;
                    let t = -half.1 + (j as Real + 0.5) * 2.0 * half.1 / n as Real;
                    let x = centre + u * s + v * t;
                    let (f, g) = deepest_face(y_turned, x);
                    if g < 0.0 {
                        let w = 0.5 * cell;
                        let m = y_turned.faces()[f].normal;
                        sampled.load += -g * w;
                        sampled.force += m * (-g * w);
                        sampled.moment += (x - about).cross(m * (-g * w));
                        sampled.energy += 0.5 * g * g * w;
                    }
                }
            }
            let scale = sampled.load.max(1e-30);
            assert!(exact.load > 0.0);
            assert!(
                (exact.load - sampled.load).abs() < 2e-3 * scale,
                "{exact:?} {sampled:?}"
            );
            assert!(
                (exact.force - sampled.force).length() < 2e-3 * scale,
                "{exact:?} {sampled:?}"
            );
            assert!(
                (exact.moment - sampled.moment).length() < 2e-3 * scale * 0.05,
                "{exact:?} {sampled:?}"
            );
            assert!(
                (exact.energy - sampled.energy).abs() < 3e-3 * sampled.energy,
                "{exact:?} {sampled:?}"
            );
        }
    }

    /// The force and moment are the gradient of the energy: moving the strip by a small
    /// translation or rotation changes the energy by minus their work, to the difference's
    /// round-off, over an edge and a corner of the cube.
    #[test]
    fn the_load_is_the_gradient_of_the_energy() {
        let y = cube(0.1);
        for (centre, u, v, half) in edge_and_corner() {
            let u = u.normalize();
            let v = (v - u * u.dot(v)).normalize();
            let area = 2.0 * half.0 * half.1;
            let about = centre;
            let load = |shift: Vector, turn: Rotation| {
                let mut l = StripLoad::default();
                let c = about + turn * (centre - about) + shift;
                let strip = Strip::of(
                    (c, turn * u, turn * v),
                    Polygon::rectangle(half.0, half.1),
                    area / (4.0 * half.0 * half.1),
                );
                l.add(&y, (c, turn * u, turn * v), &strip, about + shift, 0);
                l
            };
            let at = load(Vector::ZERO, Rotation::IDENTITY);
            let e = 1e-7;
            for axis in [Vector::X, Vector::Y, Vector::Z] {
                let de = load(axis * e, Rotation::IDENTITY).energy - load(-axis * e, Rotation::IDENTITY).energy;
                assert!(
                    (de / (2.0 * e) + at.force.dot(axis)).abs() < 1e-5 * at.load,
                    "{axis}: {de} {at:?}"
                );
                let turn = |a: Real| Rotation::from_scaled_axis(axis * a);
                let de = load(Vector::ZERO, turn(e)).energy - load(Vector::ZERO, turn(-e)).energy;
                assert!(
                    (de / (2.0 * e) + at.moment.dot(axis)).abs() < 1e-5 * at.load * 0.1,
                    "{axis}: {de} {at:?}"
                );
            }
        }
    }
}
