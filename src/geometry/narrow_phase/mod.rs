//! Narrow phase: the common plane, the contact polygon and its sub-contacts for one block pair.
//!
//! The common plane comes from a separating-axis test over face normals and edge pairs (exact for
//! convex polyhedra, also for faces that just touch, where GJK/EPA normals are arbitrary); the
//! face-to-face polygon and the sub-contact grid are built here. See `docs/theory.md`, "Contact geometry".

use glam::DVec2;
#[cfg(feature = "serde")]
use serde::{Deserialize, Serialize};

use super::polyhedron::Polyhedron;
use crate::error::{in_range, positive, Result};
use crate::math::{Pose, Real, Vector};

mod face;
mod hull;
pub(crate) mod nodes;
pub(crate) mod strips;

pub(crate) use face::contact_polygon;
use face::*;
pub(crate) use face::{face_frame, PARALLEL_ANGLE};
use hull::hull2d;
use nodes::node_contact;

/// The former name of [`SubContactDensity`] (sub-contact types are spelt `SubContact…`).
///
/// ```
/// #[allow(deprecated)]
/// let d: voussoir::geometry::SubcontactDensity = voussoir::geometry::SubContactDensity::PerEdge(5);
/// # let _ = d;
/// ```
#[deprecated(since = "0.1.0", note = "renamed SubContactDensity")]
pub type SubcontactDensity = SubContactDensity;

/// The former name of [`SubContactSeed`].
#[deprecated(since = "0.1.0", note = "renamed SubContactSeed")]
pub type SubcontactSeed = SubContactSeed;

/// How densely joint faces are covered with sub-contacts.
#[derive(Debug, Clone, Copy, PartialEq)]
#[cfg_attr(feature = "serde", derive(Serialize, Deserialize))]
pub enum SubContactDensity {
    /// `n` sub-contacts along each edge of the host face's bounding rectangle (`n × n` cells);
    /// the reference paper uses 15.
    PerEdge(u16),
    /// Nodes at most this far apart (m); at most [`MAX_SUBCONTACTS_PER_EDGE`] nodes along a
    /// face edge of any block.
    Spacing(Real),
}

impl SubContactDensity {
    /// The grid with its cells halved along each edge: `2n − 1` nodes for `n` (3 for a single
    /// node), at most [`MAX_SUBCONTACTS_PER_EDGE`]; half the spacing.
    ///
    /// ```
    /// use voussoir::geometry::SubContactDensity;
    /// assert_eq!(SubContactDensity::PerEdge(15).refined(), SubContactDensity::PerEdge(29));
    /// assert_eq!(SubContactDensity::Spacing(0.02).refined(), SubContactDensity::Spacing(0.01));
    /// ```
    pub fn refined(&self) -> Self {
        match *self {
            SubContactDensity::PerEdge(n) => SubContactDensity::PerEdge(if n < 2 {
                3
            } else {
                (2 * n - 1).min(MAX_SUBCONTACTS_PER_EDGE)
            }),
            SubContactDensity::Spacing(h) => SubContactDensity::Spacing(0.5 * h),
        }
    }

    /// Runs an analysis at this density and at [`refined`](Self::refined), in parallel, and
    /// returns the quantity each run reports (a collapse load, a displacement): the check that
    /// an answer does not depend on how finely the joints are divided, as
    /// [`crate::loading::Servo::check_convergence`] checks that it does not depend on the
    /// loading rate. Face-face joints integrate their normal springs over their cells
    /// (`docs/theory.md` §2.3): the hinge-governed collapse load of the reference arch (φ 35°)
    /// moves by 0.14 % from 15 to 29 sub-contacts per edge (by 3 % from 15 to 30 with
    /// sub-contacts at points).
    ///
    /// `run` builds and runs the whole analysis with the density it is given.
    ///
    /// # Errors
    /// The first error of either run.
    ///
    /// # Example
    /// ```
    /// use voussoir::geometry::SubContactDensity;
    /// // A stand-in for an analysis whose answer drifts with the cell size.
    /// let load = |d: SubContactDensity| match d {
    ///     SubContactDensity::PerEdge(n) => Ok::<_, voussoir::Error>(1000.0 * (1.0 + 0.1 / n as f64)),
    ///     SubContactDensity::Spacing(_) => unreachable!(),
    /// };
    /// let c = SubContactDensity::PerEdge(15).check_convergence(load)?;
    /// assert!(c.converged(0.005) && !c.converged(0.002));
    /// # Ok::<(), voussoir::Error>(())
    /// ```
    pub fn check_convergence<F>(&self, run: F) -> Result<crate::math::Convergence>
    where
        F: Fn(SubContactDensity) -> Result<Real> + Sync,
    {
        let (value, refined) = rayon::join(|| run(*self), || run(self.refined()));
        Ok(crate::math::Convergence {
            value: value?,
            refined: refined?,
        })
    }
}

/// The most sub-contacts along an edge of a face (`n × n` per face): 1,000, a million per
/// face. A denser grid is refused rather than allocated (the reference paper uses 15).
pub const MAX_SUBCONTACTS_PER_EDGE: u16 = 1000;

/// A loaded joint whose faces turn beyond the face angle tolerance stays a joint up to this
/// angle (rad, 60°) while the larger face covers the smaller one whole: a block rocking or
/// toppling on a larger one, whose loaded edge row or corner node lies in cells that the other
/// face covers (`docs/theory.md` §2.2).
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
    /// How far a loaded face-to-face joint (a grid of sub-contacts on one of the faces, gaps
    /// measured to the other face's plane) may rotate and stay a joint (rad): its faces'
    /// normals opposite within this angle, or up to 60° while the larger face covers the smaller
    /// one whole. Default 15°, so that an opening hinge keeps its sub-contacts and their
    /// history. A new joint forms where the two faces most aligned with the contact normal are
    /// parallel within 1° (and this angle); every other contact — vertices, edges, tilted or
    /// partly overlapping faces — is a node contact ([`ContactKind::Nodes`],
    /// `docs/theory.md` §2.2).
    pub face_angle_tolerance: Real,
    /// Sub-contact density on joint faces. Default `PerEdge(15)` (the paper's value).
    pub density: SubContactDensity,
    /// How a node contact's normal springs act: at each node's point (the default) or
    /// integrated over the surface each node stands for ([`NodeRule`]).
    pub node_rule: NodeRule,
}

/// How the normal spring of a node of a node contact (vertices, edges, tilted or partly
/// overlapping faces; `docs/theory.md` §2.2, "Node contacts") acts.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Default)]
#[cfg_attr(feature = "serde", derive(Serialize, Deserialize))]
#[cfg_attr(feature = "serde", serde(rename_all = "snake_case"))]
pub enum NodeRule {
    /// At the node's point `p`: the energy `½ k_n A min(g(p), 0)²` of its tributary area `A`
    /// at its own gap. Cheap, and exact where the gap is uniform (faces pressed flat), but a
    /// corner or an edge pressed in carries its node's whole area from the first touch, and
    /// a loaded hinge that turns past [`ContactParameters::face_angle_tolerance`] into a node
    /// contact changes its stored energy (`docs/benchmarks/arch-impact.md`, item 6).
    #[default]
    Point,
    /// Integrated over the surface each node stands for: `½ k_n Σ ρ ∫ min(g(x), 0)² dA` over
    /// its pieces of its block's faces, exactly, for laws whose normal spring is linear
    /// ([`crate::law::ElasticRegime`]) and in large-displacement mode (elsewhere the point
    /// rule). A pressed node's shear acts in the plane normal to its load's resultant. The
    /// change of kind of a loaded hinge then keeps its energy; a node step costs several
    /// times the point rule's (`docs/theory.md` §2.2).
    Integrated,
}

impl NodeRule {
    /// Every rule, the default first.
    pub const ALL: [NodeRule; 2] = [NodeRule::Point, NodeRule::Integrated];

    /// The rule's name (in scene files, on command lines and in Python): `point`,
    /// `integrated`.
    pub fn name(self) -> &'static str {
        match self {
            NodeRule::Point => "point",
            NodeRule::Integrated => "integrated",
        }
    }
}

impl std::fmt::Display for NodeRule {
    fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        f.write_str(self.name())
    }
}

impl std::str::FromStr for NodeRule {
    type Err = String;

    /// Parses a rule's [`NodeRule::name`].
    ///
    /// ```
    /// use voussoir::geometry::NodeRule;
    /// assert_eq!("integrated".parse::<NodeRule>(), Ok(NodeRule::Integrated));
    /// assert!("points".parse::<NodeRule>().is_err());
    /// ```
    fn from_str(s: &str) -> std::result::Result<Self, Self::Err> {
        NodeRule::ALL
            .into_iter()
            .find(|r| r.name() == s)
            .ok_or_else(|| format!("node rule {s:?}: expected \"point\" or \"integrated\""))
    }
}

/// The default sub-contacts per face edge ([`ContactParameters::default`]).
pub const DEFAULT_SUBCONTACTS_PER_EDGE: u16 = 15;

impl Default for ContactParameters {
    fn default() -> Self {
        Self {
            tolerance: 1e-3,
            redetect_fraction: 0.25,
            face_angle_tolerance: 15f64.to_radians(),
            density: SubContactDensity::PerEdge(DEFAULT_SUBCONTACTS_PER_EDGE),
            node_rule: NodeRule::Point,
        }
    }
}

impl ContactParameters {
    /// Checks that a [`SubContactDensity::Spacing`] leaves at most
    /// [`MAX_SUBCONTACTS_PER_EDGE`] sub-contacts along the faces of a block of circumradius
    /// `radius` (m), named `block` in the error.
    ///
    /// # Errors
    /// [`crate::Error::InvalidParameter`] naming the block.
    pub fn check_block(&self, radius: Real, block: &str) -> Result<()> {
        if let SubContactDensity::Spacing(h) = self.density {
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
            SubContactDensity::PerEdge(n) => {
                in_range(
                    "contact.density.per_edge",
                    n as Real,
                    1.0,
                    MAX_SUBCONTACTS_PER_EDGE as Real + 1.0,
                    "must lie in 1..=1000 (MAX_SUBCONTACTS_PER_EDGE)",
                )?;
            }
            SubContactDensity::Spacing(h) => {
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
    /// The key of cell `(i, j)` of the grid on the host face of a face-face joint between face
    /// `face_a` of block `a` and face `face_b` of block `b` (whichever is the host): the faces
    /// in the upper 32 bits (each cut to 16), the grid indices (16 bits each, below
    /// `MAX_NODES_PER_EDGE`) in the lower.
    pub(crate) fn cell(face_a: u32, face_b: u32, i: u32, j: u32) -> Self {
        Self(((face_a as u64) << 48) | ((face_b as u64 & 0xffff) << 32) | ((i as u64) << 16) | j as u64)
    }

    /// The grid indices `(i, j)` of a cell's key ([`SubKey::cell`]): with the joint's faces,
    /// which its contact holds, they make the key again.
    pub(crate) fn cell_indices(self) -> [u16; 2] {
        [(self.0 >> 16) as u16, self.0 as u16]
    }

    /// Whether this is the key of a cell of a joint between faces `face_a` and `face_b`
    /// ([`SubKey::cell`]).
    pub(crate) fn is_cell_of(self, face_a: u32, face_b: u32) -> bool {
        let [i, j] = self.cell_indices();
        Self::cell(face_a, face_b, u32::from(i), u32::from(j)) == self
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
    /// Vertex–face, edge–edge, edge–face and partly overlapping faces beyond the face angle
    /// tolerance: fixed material nodes on the vertices and edges of both blocks, each pressed
    /// out of the other block by its depth inside it (see `docs/theory.md` §2.2, "Node
    /// contacts"). A node's key names its block, vertex or edge and place on the edge.
    Nodes,
}

impl ContactKind {
    /// Whether a contact re-detected as `other` is the same joint, whose sub-contacts may carry
    /// their history over by key: the same pair of faces, or a node contact again (its keys
    /// name material nodes of the two blocks).
    pub(crate) fn same_joint(&self, other: &ContactKind) -> bool {
        match (self, other) {
            (ContactKind::FaceFace { .. }, ContactKind::FaceFace { .. }) => self == other,
            (ContactKind::Nodes, ContactKind::Nodes) => true,
            _ => false,
        }
    }
}

/// The contact a pair had before a detection, as [`detect`] takes it.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct PreviousContact {
    /// Its kind.
    pub kind: ContactKind,
    /// Whether its sub-contacts were anchored to block `a`.
    pub host_is_a: bool,
    /// Whether it carried a normal force.
    pub loaded: bool,
    /// Whether, a loaded node contact, it may turn back into a face-face joint when its blocks'
    /// faces have come back parallel: its nodes integrated over the surface they stand for
    /// ([`NodeRule::Integrated`], large-displacement mode, a law with a linear normal spring) and
    /// in the state a new cell starts from, so that the joint's cells store what the nodes
    /// stored (`docs/theory.md` §6). `false` for any other contact.
    pub turns_back: bool,
    /// Whether it is a face-face joint whose sub-contacts carry nothing the step reads: no
    /// force, no dashpot force, each in a fresh cell's state (a joint open all over that never
    /// closed, or only without changing its law's state). Such a joint has no history to keep,
    /// and its host is chosen again as a new joint's would be (its cells' record of
    /// accumulated slip, which the step only adds to, then starts again from zero).
    pub blank: bool,
}

/// A sub-contact as created by detection.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct SubContactSeed {
    /// Identity within the pair.
    pub key: SubKey,
    /// Material point in the host block's body frame (m).
    pub anchor: Vector,
    /// Tributary area (m²).
    pub area: Real,
    /// Normal gap at detection (m, positive = open): the signed distance of the anchor from the
    /// other block's plane.
    pub gap: Real,
    /// Half sizes along the host face's frame of the rectangle a face-face sub-contact's
    /// normal spring is integrated over (m): the cell's second moments of area about the
    /// anchor are `A h_x²/3`, `A h_y²/3` (`docs/theory.md` §2.3). Zero for a node.
    pub half: crate::math::Vector2,
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
/// `face_face`); a loaded contact keeps its kind while it can (see `docs/theory.md` §2.2, "Node
/// contacts").
pub fn detect(
    a: BlockGeometry<'_>,
    b: BlockGeometry<'_>,
    previous: Option<PreviousContact>,
    params: &ContactParameters,
    scratch: &mut NarrowPhaseScratch,
    seeds: &mut Vec<SubContactSeed>,
) -> Option<DetectedContact> {
    let axis = separating_axis(a, b, scratch);
    scratch.separation = axis.separation;
    if axis.separation > params.tolerance {
        return None;
    }
    let n = axis.normal;
    let tolerance = params.face_angle_tolerance.cos();
    let opposite = |fa: usize, fb: usize| {
        let na = a.pose.rotation * a.shape.faces()[fa].normal;
        let nb = b.pose.rotation * b.shape.faces()[fb].normal;
        -na.dot(nb)
    };
    // A loaded contact keeps its kind while it can: a face-face joint while its two faces stay
    // opposite within the tolerance, or within `COVERED_FACE_ANGLE` while the larger face covers
    // the smaller one whole (a block rocking on a larger one: the loaded edge row or corner node
    // sits in cells the other face covers), a node contact always but for integrated nodes whose
    // faces have come back parallel (below). Point nodes and cells store different energies for
    // the same overlap, and a change under load would make or destroy the difference.
    if let Some(p) = previous.filter(|p| p.loaded) {
        let start = seeds.len();
        let kept = match p.kind {
            ContactKind::FaceFace { face_a, face_b } => {
                let cos = opposite(face_a as usize, face_b as usize);
                (cos >= tolerance || cos >= COVERED_FACE_ANGLE.cos())
                    .then(|| {
                        face_face(
                            a,
                            face_a as usize,
                            b,
                            face_b as usize,
                            if cos < tolerance { 1.0 } else { 0.0 },
                            Some(p.host_is_a),
                            params,
                            scratch,
                            seeds,
                        )
                    })
                    .flatten()
            }
            // Integrated nodes store what a joint's cells store for the same overlap, so a node
            // contact whose faces have come back parallel turns back into a joint (its forces
            // handed to the cells, `model/step/detection/staging.rs`); point nodes do not.
            ContactKind::Nodes if p.turns_back => closing_joint(a, b, n, axis.separation, params, scratch, seeds)
                .or_else(|| node_contact(a, b, n, params, seeds)),
            ContactKind::Nodes => node_contact(a, b, n, params, seeds),
        };
        // A kept face-face joint must still be the contact: its faces the most aligned and no
        // part of either block outside them in the other (a stone toppling onto its next face).
        let blind = match p.kind {
            ContactKind::FaceFace { face_a, face_b } if kept.is_some() => {
                let (fa, fb) = (face_a as usize, face_b as usize);
                next_face_takes_over(a, fa, b, fb, tolerance)
                    || !sees_the_overlap(&seeds[start..], axis.separation, a.shape.radius() + b.shape.radius())
                    || vertex_outside_joint_inside(a, fa, &scratch.world_a, b)
                    || vertex_outside_joint_inside(b, fb, &scratch.world_b, a)
            }
            _ => false,
        };
        if kept.is_some() && !blind {
            return kept;
        }
        seeds.truncate(start);
    }
    // A new joint needs its faces parallel, within `PARALLEL_ANGLE` and the tolerance. Tilted
    // faces meet along an edge or at a corner, which nodes carry whole: the grid of one face
    // against the plane of the other misses the other face's edge digging into it where they
    // overlap in part, and the grids of the different faces around a corner store different
    // energies for the same overlap (a corner landing changed its energy by 5 % of m g h when
    // the most aligned face changed under load).
    let fa = a.shape.most_aligned_face(a.pose.rotation.inverse() * n);
    let fb = b.shape.most_aligned_face(b.pose.rotation.inverse() * -n);
    let cos = opposite(fa, fb);
    // A joint kept between the same faces keeps its host, so that its sub-contacts keep their
    // keys and history; a blank one has none to keep, and is hosted as a new joint would be.
    let kept_host = match previous {
        Some(PreviousContact {
            kind: ContactKind::FaceFace { face_a, face_b },
            host_is_a,
            blank: false,
            ..
        }) if face_a as usize == fa && face_b as usize == fb => Some(host_is_a),
        _ => None,
    };
    if cos >= tolerance && cos >= PARALLEL_ANGLE.cos() && !near_coplanar_neighbour(a, fa, b, fb, params, scratch, seeds)
    {
        let start = seeds.len();
        if let Some(found) = face_face(a, fa, b, fb, 0.0, kept_host, params, scratch, seeds) {
            return Some(found);
        }
        seeds.truncate(start);
    }
    node_contact(a, b, n, params, seeds)
}

/// The joint a loaded node contact turns back into when the blocks' most aligned faces have come
/// back parallel (within [`PARALLEL_ANGLE`] and the face angle tolerance, as a new joint needs)
/// and the joint they make is the whole contact (the checks a kept joint passes in [`detect`]):
/// a voussoir joint that opened past [`PARALLEL_ANGLE`] unloaded, became a node contact and closed
/// again. `None` (and no seeds pushed) otherwise.
fn closing_joint(
    a: BlockGeometry<'_>,
    b: BlockGeometry<'_>,
    n: Vector,
    separation: Real,
    params: &ContactParameters,
    scratch: &mut NarrowPhaseScratch,
    seeds: &mut Vec<SubContactSeed>,
) -> Option<DetectedContact> {
    let fa = a.shape.most_aligned_face(a.pose.rotation.inverse() * n);
    let fb = b.shape.most_aligned_face(b.pose.rotation.inverse() * -n);
    let na = a.pose.rotation * a.shape.faces()[fa].normal;
    let nb = b.pose.rotation * b.shape.faces()[fb].normal;
    let (cos, tolerance) = (-na.dot(nb), params.face_angle_tolerance.cos());
    if cos < tolerance || cos < PARALLEL_ANGLE.cos() || near_coplanar_neighbour(a, fa, b, fb, params, scratch, seeds) {
        return None;
    }
    let start = seeds.len();
    let found = face_face(a, fa, b, fb, 0.0, None, params, scratch, seeds);
    let whole = found.is_some()
        && !next_face_takes_over(a, fa, b, fb, tolerance)
        && sees_the_overlap(&seeds[start..], separation, a.shape.radius() + b.shape.radius())
        && !vertex_outside_joint_inside(a, fa, &scratch.world_a, b)
        && !vertex_outside_joint_inside(b, fb, &scratch.world_b, a);
    if !whole {
        seeds.truncate(start);
        return None;
    }
    found
}

/// Whether a kept joint's sub-contacts see the blocks' overlap: the overlap along the separating
/// axis (`-separation`, the least penetration, a lower bound on how deep any point of one block
/// is in the other) may exceed the deepest sub-contact's only by the distance from a cell's
/// anchor to its corner (the polygon's deepest corner lies in some cell). More means a part of
/// a block outside the joint's faces has gone into the other: an irregular stone toppling on a
/// slab (kept up to `COVERED_FACE_ANGLE`) whose next face, at a shallow angle to the first,
/// comes down; its corner went 4.6 cm into the slab while the joint on the first face carried
/// its weight with 0.05 mm overlaps (a sharp-block drop). Node contacts see every vertex and
/// edge and are not asked.
fn sees_the_overlap(seeds: &[SubContactSeed], separation: Real, size: Real) -> bool {
    if separation >= 0.0 {
        return true;
    }
    let deepest = seeds.iter().map(|s| s.gap).fold(Real::INFINITY, Real::min);
    let corner = seeds.iter().map(|s| s.half.length()).fold(0.0, Real::max);
    // Round-off of the two depths, each a difference of coordinates of the blocks' size.
    let round_off = 1e-12 * size;
    -separation <= (-deepest).max(0.0) + corner + round_off
}

/// Whether another face of either block has turned nearer the joint's opposite face than the
/// joint's own, and to within the face angle tolerance of it (`tolerance`: its cosine). A block
/// rocking or toppling about an edge of its joint face turns its next face towards the other
/// block; for an irregular stone whose next face meets the joint face at a shallow angle, that
/// face lies nearly flat on the other block after a few degrees, overlapping it over its whole
/// width while the joint measures gaps over the first face only. The contact is then found
/// afresh. A cuboid's next face is 90° away: still beyond the tolerance when it becomes the more
/// aligned (at 45°), so a rocking cuboid keeps its joint as before.
fn next_face_takes_over(a: BlockGeometry<'_>, fa: usize, b: BlockGeometry<'_>, fb: usize, tolerance: Real) -> bool {
    let na = a.pose.rotation * a.shape.faces()[fa].normal;
    let nb = b.pose.rotation * b.shape.faces()[fb].normal;
    let turned = |x: BlockGeometry<'_>, fx: usize, other: Vector| {
        let g = x.shape.most_aligned_face(x.pose.rotation.inverse() * -other);
        g != fx && -(x.pose.rotation * x.shape.faces()[g].normal).dot(other) >= tolerance
    };
    turned(b, fb, na) || turned(a, fa, nb)
}

/// Whether a vertex of `a` that is not on the joint's face `fa` lies inside `b` (`world_a`: the
/// vertices of `a` in the world, as the separating-axis test left them): a kept face-face joint
/// measures gaps over its two faces only, so such a vertex goes into `b` without a force. An
/// irregular stone toppling on a slab about an edge of its joint face brings its next face down
/// at a shallow angle; the joint must turn into nodes when that face's far corner touches, not
/// once it is deep (`sees_the_overlap` catches that only a cell's size deep, and the node
/// contact then found it 7 mm in and threw the stone up with 15 `m g h`).
/// A vertex exactly on a face of `b` (within round-off of the blocks' size) is not inside.
fn vertex_outside_joint_inside(a: BlockGeometry<'_>, fa: usize, world_a: &[Vector], b: BlockGeometry<'_>) -> bool {
    let joint = a.shape.face_loop(fa);
    let round_off = 1e-12 * (a.shape.radius() + b.shape.radius());
    world_a.iter().enumerate().any(|(i, p)| {
        if joint.contains(&(i as u32)) {
            return false;
        }
        let local = b.pose.inverse_transform_point(*p);
        b.shape
            .faces()
            .iter()
            .all(|f| f.normal.dot(local) - f.offset < -round_off)
    })
}

/// Faces of one block whose outward normals lie within this angle (rad, 10°) of each other are
/// near-coplanar neighbours for [`near_coplanar_neighbour`].
const NEIGHBOUR_ANGLE: Real = 0.174_532_925_199_432_95;

/// Whether face `fa` of `a` (or `fb` of `b`) also meets, within the tolerance and with an
/// overlap, another face of the other block nearly coplanar with `fb` (or `fa`): a flat face
/// across the shallow ridge of an irregular stone. A joint holds one pair of faces, and its
/// grid measures gaps to one plane: the other face's part would be pressed into without a
/// force, its overlap appearing whole, with its energy, when a later detection took that face
/// (2.5 % of `m g h` in one of the sharp-block drops). Nodes carry such a contact; the faces of
/// masonry units (cuboids, voussoirs) meet at far larger angles and never take this path.
fn near_coplanar_neighbour(
    a: BlockGeometry<'_>,
    fa: usize,
    b: BlockGeometry<'_>,
    fb: usize,
    params: &ContactParameters,
    scratch: &mut NarrowPhaseScratch,
    seeds: &mut Vec<SubContactSeed>,
) -> bool {
    fn neighbours(shape: &Polyhedron, f: usize) -> impl Iterator<Item = usize> + '_ {
        let n = shape.faces()[f].normal;
        (0..shape.faces().len()).filter(move |&g| g != f && shape.faces()[g].normal.dot(n) >= NEIGHBOUR_ANGLE.cos())
    }
    let start = seeds.len();
    let mut meets = |fa: usize, fb: usize| {
        let host_is_a = a.shape.faces()[fa].area <= b.shape.faces()[fb].area;
        let found = face_face_hosted(a, fa, b, fb, host_is_a, false, 0.0, params, scratch, seeds);
        seeds.truncate(start);
        matches!(found, Hosted::Contact(_))
    };
    neighbours(b.shape, fb).any(|g| meets(fa, g)) || neighbours(a.shape, fa).any(|g| meets(g, fb))
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
    // One axis per pair of edge directions: parallel edges give the same axis.
    for ea in a.shape.edges_by_direction() {
        let da = wa[ea[1] as usize] - wa[ea[0] as usize];
        for eb in b.shape.edges_by_direction() {
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

/// Characteristic sub-contact spacing for a pair (m), used for node contacts.
pub(crate) fn spacing(a: &Polyhedron, b: &Polyhedron, density: SubContactDensity) -> Real {
    match density {
        SubContactDensity::Spacing(h) => h,
        SubContactDensity::PerEdge(n) => a.volume().cbrt().min(b.volume().cbrt()) / n as Real,
    }
}
