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

use super::*;
use crate::math::Real;

/// Bits of a node key: side (1), first vertex (15), second vertex (16), node along the edge (16),
/// segments of the edge (16).
const SIDE_BIT: u64 = 1 << 63;

/// The largest vertex index a node can name (the key gives it 15 bits).
pub(crate) const MAX_NODE_VERTEX: u32 = 0x7fff;

/// A node of a node contact: on block `b` (`on_b`) or `a`, point `k` of `n` along the edge from
/// vertex `v0` to `v1` (a vertex: `v0 == v1`, `k = 0`, `n = 1`).
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub(crate) struct NodeId {
    pub on_b: bool,
    pub v0: u32,
    pub v1: u32,
    pub k: u32,
    pub n: u32,
}

impl NodeId {
    /// Its sub-contact key (node keys sort by side, then vertex, edge and position).
    pub(crate) fn key(&self) -> SubKey {
        SubKey(
            if self.on_b { SIDE_BIT } else { 0 }
                | ((self.v0 as u64 & 0x7fff) << 48)
                | ((self.v1 as u64 & 0xffff) << 32)
                | ((self.k as u64 & 0xffff) << 16)
                | (self.n as u64 & 0xffff),
        )
    }

    /// The node a key names.
    pub(crate) fn from_key(key: SubKey) -> Self {
        let k = key.0;
        Self {
            on_b: k & SIDE_BIT != 0,
            v0: ((k >> 48) & 0x7fff) as u32,
            v1: ((k >> 32) & 0xffff) as u32,
            k: ((k >> 16) & 0xffff) as u32,
            n: (k & 0xffff) as u32,
        }
    }

    /// Whether the node exists on `shape` (its vertices in range, `k < n`).
    pub(crate) fn fits(&self, shape: &Polyhedron) -> bool {
        let count = shape.vertices().len() as u32;
        self.v0 < count && self.v1 < count && self.n >= 1 && self.k < self.n
    }

    /// The node in its block's body frame (m).
    #[inline]
    pub(crate) fn point(&self, shape: &Polyhedron) -> Vector {
        let v = shape.vertices();
        let p0 = v[self.v0 as usize];
        if self.k == 0 {
            return p0;
        }
        p0 + (v[self.v1 as usize] - p0) * (self.k as Real / self.n as Real)
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
fn segments(length: Real, h: Real) -> u32 {
    ((length / h).ceil() as u32).clamp(1, MAX_NODES_PER_EDGE)
}

/// The tributary area of a node (m²): its share of the faces around it, each face's area shared
/// among the nodes of its boundary by the length of boundary each stands for (half the segments
/// on either side), so that the nodes of a block carry its whole surface once, whatever the
/// spacing `h`. A vertex of a cube of side `L` carries `3 L²/(4 n)`, `n` the segments per edge;
/// a node inside an edge twice that.
pub(crate) fn node_area(shape: &Polyhedron, id: &NodeId, h: Real) -> Real {
    let v = shape.vertices();
    let mut area = 0.0;
    for (f, face) in shape.faces().iter().enumerate() {
        let ring = shape.face_loop(f);
        let m = ring.len();
        let perimeter: Real = (0..m)
            .map(|i| (v[ring[(i + 1) % m] as usize] - v[ring[i] as usize]).length())
            .sum();
        if perimeter <= 0.0 {
            continue;
        }
        for i in 0..m {
            let (p, q) = (ring[i], ring[(i + 1) % m]);
            let length = (v[q as usize] - v[p as usize]).length();
            let segment = length / segments(length, h) as Real;
            let share = if id.v0 == id.v1 {
                // A vertex stands for half the segment next to it on each of its edges.
                if p == id.v0 || q == id.v0 {
                    0.5 * segment
                } else {
                    0.0
                }
            } else if (p.min(q), p.max(q)) == (id.v0, id.v1) {
                segment
            } else {
                0.0
            };
            area += face.area * share / perimeter;
        }
    }
    area
}

/// The nodes of `host` (on block `b` when `on_b`) whose gap to `other` is below `tolerance`,
/// as seeds (anchor in the host's body frame), in key order.
fn push_nodes(
    host: BlockGeometry<'_>,
    other: BlockGeometry<'_>,
    on_b: bool,
    h: Real,
    tolerance: Real,
    seeds: &mut Vec<SubcontactSeed>,
) {
    let to_other = other.pose.inverse() * *host.pose;
    // Nodes farther than this from the other block's centroid cannot be within the tolerance.
    let reach = other.shape.radius() + tolerance;
    let vertices = host.shape.vertices();
    let try_node = |id: NodeId, seeds: &mut Vec<SubcontactSeed>| {
        let anchor = id.point(host.shape);
        let q = to_other.transform_point(anchor);
        if q.length() > reach {
            return;
        }
        let (_, gap) = deepest_face(other.shape, q);
        if gap < tolerance {
            seeds.push(SubcontactSeed {
                key: id.key(),
                anchor,
                area: node_area(host.shape, &id, h),
                gap,
            });
        }
    };
    let start = seeds.len();
    for v in 0..(vertices.len() as u32).min(MAX_NODE_VERTEX + 1) {
        try_node(
            NodeId {
                on_b,
                v0: v,
                v1: v,
                k: 0,
                n: 1,
            },
            seeds,
        );
    }
    for &[i, j] in host.shape.edges() {
        let (v0, v1) = (i.min(j), i.max(j));
        if v1 > MAX_NODE_VERTEX {
            continue;
        }
        let (p0, p1) = (vertices[v0 as usize], vertices[v1 as usize]);
        // The edge in the other block's frame, against its bounding sphere.
        let (q0, q1) = (to_other.transform_point(p0), to_other.transform_point(p1));
        let d = q1 - q0;
        let t = if d.length_squared() > 0.0 {
            (-q0.dot(d) / d.length_squared()).clamp(0.0, 1.0)
        } else {
            0.0
        };
        if (q0 + d * t).length() > reach {
            continue;
        }
        let n = segments((p1 - p0).length(), h);
        for k in 1..n {
            try_node(NodeId { on_b, v0, v1, k, n }, seeds);
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
    seeds: &mut Vec<SubcontactSeed>,
) -> Option<DetectedContact> {
    let h = spacing(a.shape, b.shape, params.density);
    let start = seeds.len();
    push_nodes(a, b, false, h, params.tolerance, seeds);
    push_nodes(b, a, true, h, params.tolerance, seeds);
    (seeds.len() > start).then_some(DetectedContact {
        kind: ContactKind::Nodes,
        host_is_a: true,
        normal: n,
    })
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::geometry::Polyhedron;

    fn cube(s: Real) -> Polyhedron {
        Polyhedron::from_hull(
            "cube",
            &[
                Vector::new(-s, -s, -s),
                Vector::new(s, -s, -s),
                Vector::new(-s, s, -s),
                Vector::new(s, s, -s),
                Vector::new(-s, -s, s),
                Vector::new(s, -s, s),
                Vector::new(-s, s, s),
                Vector::new(s, s, s),
            ],
        )
        .expect("cube")
        .shape
    }

    /// Keys name their nodes back, and sort by side first.
    #[test]
    fn node_keys_round_trip() {
        for id in [
            NodeId {
                on_b: false,
                v0: 3,
                v1: 3,
                k: 0,
                n: 1,
            },
            NodeId {
                on_b: true,
                v0: 0x7fff,
                v1: 0xffff,
                k: 12,
                n: 0xffff,
            },
        ] {
            assert_eq!(NodeId::from_key(id.key()), id);
        }
        let a = NodeId {
            on_b: false,
            v0: 0x7fff,
            v1: 0xffff,
            k: 1,
            n: 2,
        };
        let b = NodeId {
            on_b: true,
            v0: 0,
            v1: 0,
            k: 0,
            n: 1,
        };
        assert!(a.key() < b.key());
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
}

#[cfg(test)]
mod area_tests {
    use super::*;

    /// The nodes of a block carry its whole surface, whatever the spacing.
    #[test]
    fn node_areas_add_up_to_the_surface() {
        let shape = Polyhedron::from_hull(
            "wedge",
            &[
                Vector::new(-0.1, -0.1, -0.1),
                Vector::new(0.1, -0.1, -0.1),
                Vector::new(0.0, -0.1, 0.1),
                Vector::new(-0.1, 0.1, -0.1),
                Vector::new(0.1, 0.1, -0.1),
                Vector::new(0.0, 0.1, 0.1),
            ],
        )
        .expect("wedge")
        .shape;
        let surface: Real = shape.faces().iter().map(|f| f.area).sum();
        for h in [0.3, 0.05, 0.013] {
            let mut total = 0.0;
            for v in 0..shape.vertices().len() as u32 {
                total += node_area(
                    &shape,
                    &NodeId {
                        on_b: false,
                        v0: v,
                        v1: v,
                        k: 0,
                        n: 1,
                    },
                    h,
                );
            }
            for &[i, j] in shape.edges() {
                let (v0, v1) = (i.min(j), i.max(j));
                let n = segments(
                    (shape.vertices()[v1 as usize] - shape.vertices()[v0 as usize]).length(),
                    h,
                );
                for k in 1..n {
                    total += node_area(
                        &shape,
                        &NodeId {
                            on_b: false,
                            v0,
                            v1,
                            k,
                            n,
                        },
                        h,
                    );
                }
            }
            assert!(
                (total - surface).abs() < 1e-12 * surface,
                "h {h}: {total} against {surface}"
            );
        }
    }
}
