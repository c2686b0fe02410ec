//! Convex polyhedra in their principal frame, with exact mass properties.

use super::inertia::{symmetric_eigen, volume_moments};
use super::narrow_phase::nodes::FaceGrid;
use parry3d_f64::shape::ConvexPolyhedron;
use parry3d_f64::transformation::try_convex_hull;
#[cfg(feature = "serde")]
use serde::{Deserialize, Serialize};

use crate::error::{Error, Result};
use crate::math::{is_finite_vector, Pose, Real, Vector};

/// One planar face of a [`Polyhedron`], in the body frame.
#[derive(Debug, Clone, Copy, PartialEq)]
#[cfg_attr(feature = "serde", derive(Serialize, Deserialize))]
pub struct Face {
    /// Outward unit normal (Newell's method over the whole vertex loop).
    pub normal: Vector,
    /// Plane offset: `normal · x = offset` on the face.
    pub offset: Real,
    /// Face area (m²).
    pub area: Real,
    first: u32,
    len: u32,
}

/// Mass properties of a block: mass and principal moments about the centroid.
#[derive(Debug, Clone, Copy, PartialEq)]
#[cfg_attr(feature = "serde", derive(Serialize, Deserialize))]
pub struct MassProperties {
    /// Mass (kg).
    pub mass: Real,
    /// Volume (m³).
    pub volume: Real,
    /// Principal moments of inertia about the centroid (kg·m²), along the body axes.
    pub principal_inertia: Vector,
}

/// A rigid convex polyhedron stored in its principal frame: the origin is the centroid and the
/// axes are the principal axes of inertia, so the inertia tensor is diagonal.
///
/// Build one with [`Polyhedron::from_hull`] or [`Polyhedron::from_faces`]; both return the pose
/// that places the body frame in the world.
#[derive(Debug, Clone)]
#[cfg_attr(feature = "serde", derive(Serialize, Deserialize))]
pub struct Polyhedron {
    vertices: Vec<Vector>,
    faces: Vec<Face>,
    face_vertices: Vec<u32>,
    /// Unique edges as vertex index pairs.
    edges: Vec<[u32; 2]>,
    /// One edge (its index in `edges`, the first in order) per direction of the edges: the
    /// separating-axis test needs one axis per pair of directions, not per pair of edges (a
    /// cuboid's 12 edges have 3). Derived from the vertices and edges.
    #[cfg_attr(feature = "serde", serde(skip))]
    edge_directions: Vec<u32>,
    /// Each face's node grid frame (node contacts, `narrow_phase/nodes.rs`). Derived from the
    /// vertices and faces.
    #[cfg_attr(feature = "serde", serde(skip))]
    face_grids: Vec<FaceGrid>,
    /// Largest distance from the centroid to a vertex (m).
    radius: Real,
    volume: Real,
    /// Inertia about the centroid per unit density (m⁵), principal axes.
    unit_inertia: Vector,
    #[cfg_attr(feature = "serde", serde(skip, default = "empty_parry"))]
    parry: Option<ConvexPolyhedron>,
}

#[cfg(feature = "serde")]
fn empty_parry() -> Option<ConvexPolyhedron> {
    None
}

/// The most vertices a block's convex hull may have. Contact detection (the separating-axis test
/// in [`crate::geometry::detect`]) costs about `D_a·D_b·(V_a + V_b)` for two blocks with `V`
/// vertices and `D` edge directions (`D ≤ E ≈ 3V` edges; a cuboid has 3, a generic hull `E`):
/// measured, the first step of two touching 256-vertex blocks takes
/// 0.24 s, of two 1,000-vertex blocks 12.9 s, and of a 20,000-vertex block on a box 10.4 s.
/// Larger shapes are refused with [`Error::TooManyVertices`]; masonry units need far fewer (a
/// 128-sided column drum has 256).
pub const MAX_HULL_VERTICES: usize = 256;

/// A block shape placed in the world: the body-frame polyhedron and its pose.
#[derive(Debug, Clone)]
pub struct PlacedPolyhedron {
    /// The shape in its principal frame.
    pub shape: Polyhedron,
    /// Pose of the principal frame in the world (translation = centroid).
    pub pose: Pose,
}

impl Polyhedron {
    /// Builds the convex hull of `points` (world coordinates). Interior points are ignored.
    ///
    /// `name` is used in error messages only.
    ///
    /// # Errors
    /// [`Error::NonFinite`] for NaN or infinite coordinates, [`Error::DegenerateGeometry`] for fewer
    /// than four points or a flat or collinear set, [`Error::NonPositiveVolume`] for a volume not above
    /// `1e-12` of the bounding box volume (the product of the extents), [`Error::TooManyVertices`]
    /// for a hull with more than [`MAX_HULL_VERTICES`] vertices (interior points given do not
    /// count).
    ///
    /// # Example
    /// ```
    /// use voussoir::geometry::Polyhedron;
    /// use voussoir::math::Vector;
    /// let corners: Vec<Vector> = (0..8)
    ///     .map(|i| Vector::new((i & 1) as f64 * 2.0, (i >> 1 & 1) as f64, (i >> 2) as f64 * 0.5))
    ///     .collect();
    /// let placed = Polyhedron::from_hull("brick", &corners)?;
    /// assert!((placed.shape.volume() - 1.0).abs() < 1e-12);
    /// assert_eq!(placed.shape.faces().len(), 6);
    /// assert!((placed.pose.translation - Vector::new(1.0, 0.5, 0.25)).length() < 1e-12);
    /// # Ok::<(), voussoir::Error>(())
    /// ```
    pub fn from_hull(name: &str, points: &[Vector]) -> Result<PlacedPolyhedron> {
        check_points(name, points)?;
        // parry's hull loses the thin direction of slender boxes (a 100 m × 0.3 m × 0.05 m slab
        // came out flat). An axis scaling is affine, so it maps the hull onto the hull: compute it
        // in coordinates scaled to the unit box, then scale back.
        let (mut lo, mut hi) = (Vector::splat(Real::INFINITY), Vector::splat(Real::NEG_INFINITY));
        for p in points {
            lo = lo.min(*p);
            hi = hi.max(*p);
        }
        let extent = hi - lo;
        if extent.min_element() <= 1e-12 * extent.max_element() {
            return Err(Error::DegenerateGeometry {
                block: name.to_owned(),
                reason: "the vertices are flat (no extent in some direction)".into(),
            });
        }
        let centre = 0.5 * (lo + hi);
        let unit: Vec<Vector> = points.iter().map(|p| (*p - centre) / extent).collect();
        let (verts, tris) = try_convex_hull(&unit).map_err(|e| Error::DegenerateGeometry {
            block: name.to_owned(),
            reason: format!("convex hull failed: {e:?}"),
        })?;
        let verts = verts.into_iter().map(|v| v * extent + centre).collect();
        Self::from_triangles(name, verts, &tris)
    }

    /// Builds a polyhedron from vertices and explicit faces (vertex index loops, counter-clockwise
    /// seen from outside). The faces are checked for planarity and the solid for convexity.
    ///
    /// # Errors
    /// As [`Polyhedron::from_hull`], plus [`Error::NonConvex`] when a face is not planar, a vertex
    /// lies outside a face plane or a face index is out of range.
    pub fn from_faces(name: &str, points: &[Vector], faces: &[Vec<usize>]) -> Result<PlacedPolyhedron> {
        check_points(name, points)?;
        // Before the convexity check, which costs faces × vertices.
        if points.len() > MAX_HULL_VERTICES {
            return Err(Error::TooManyVertices {
                block: name.to_owned(),
                vertices: points.len(),
                limit: MAX_HULL_VERTICES,
            });
        }
        if faces.len() < 4 {
            return Err(Error::DegenerateGeometry {
                block: name.to_owned(),
                reason: format!("{} faces given, a solid needs at least 4", faces.len()),
            });
        }
        let scale = bbox_diagonal(points);
        let tol = 1e-9 * scale;
        let mut tris = Vec::new();
        for (fi, face) in faces.iter().enumerate() {
            if face.len() < 3 {
                return Err(Error::DegenerateGeometry {
                    block: name.to_owned(),
                    reason: format!("face {fi} has {} vertices", face.len()),
                });
            }
            if let Some(&bad) = face.iter().find(|&&v| v >= points.len()) {
                return Err(Error::NonConvex {
                    block: name.to_owned(),
                    reason: format!(
                        "face {fi} refers to vertex {bad}, but there are {} vertices",
                        points.len()
                    ),
                });
            }
            let loop_pts: Vec<Vector> = face.iter().map(|&i| points[i]).collect();
            let normal = newell_normal(&loop_pts);
            let len = normal.length();
            if len < 1e-14 * scale * scale {
                return Err(Error::DegenerateGeometry {
                    block: name.to_owned(),
                    reason: format!("face {fi} has zero area"),
                });
            }
            let n = normal / len;
            let offset = n.dot(loop_pts[0]);
            for (k, p) in loop_pts.iter().enumerate() {
                if (n.dot(*p) - offset).abs() > tol {
                    return Err(Error::NonConvex {
                        block: name.to_owned(),
                        reason: format!("face {fi} is not planar at its vertex {}", face[k]),
                    });
                }
            }
            for (vi, p) in points.iter().enumerate() {
                if n.dot(*p) - offset > tol {
                    return Err(Error::NonConvex {
                        block: name.to_owned(),
                        reason: format!("vertex {vi} lies outside face {fi} (or the face is inward-facing)"),
                    });
                }
            }
            for k in 1..face.len() - 1 {
                tris.push([face[0] as u32, face[k] as u32, face[k + 1] as u32]);
            }
        }
        Self::from_triangles(name, points.to_vec(), &tris)
    }

    fn from_triangles(name: &str, verts: Vec<Vector>, tris: &[[u32; 3]]) -> Result<PlacedPolyhedron> {
        if verts.len() > MAX_HULL_VERTICES {
            return Err(Error::TooManyVertices {
                block: name.to_owned(),
                vertices: verts.len(),
                limit: MAX_HULL_VERTICES,
            });
        }
        let extent = bbox_extent(&verts);
        if extent.min_element() <= 1e-12 * extent.max_element() {
            return Err(Error::DegenerateGeometry {
                block: name.to_owned(),
                reason: "the vertices are flat (no extent in some direction)".into(),
            });
        }
        let world = ConvexPolyhedron::from_convex_mesh(verts, tris).ok_or_else(|| Error::DegenerateGeometry {
            block: name.to_owned(),
            reason: "the faces do not form a closed convex manifold".into(),
        })?;
        // Our own moments and eigen solver, not parry's (`inertia.rs` says why); the moments are
        // taken about the vertices' mean and then the centroid, so that they keep their digits
        // far from the origin.
        let moments = volume_moments(world.points(), tris);
        let volume = moments.volume;
        // Each term of the divergence sum is a triple product of one x, one y and one z
        // coordinate relative to the reference point, so its round-off is of the order of
        // ε·(extent.x·extent.y·extent.z) whatever the orientation: compare the volume with the
        // bounding box's, not with the cube of the diagonal, which refused long slender blocks
        // (a 600 km × 1 m × 0.23 m slab of 137,870 m³).
        let bounding_box = extent.x * extent.y * extent.z;
        if volume.is_nan() || volume <= 1e-12 * bounding_box {
            return Err(Error::NonPositiveVolume {
                block: name.to_owned(),
                volume,
                bounding_box,
            });
        }
        let (unit_inertia, frame) = symmetric_eigen(moments.inertia);
        let com = moments.centroid;
        let inv = frame.inverse();
        let body: Vec<Vector> = world.points().iter().map(|p| inv * (*p - com)).collect();
        let pose = Pose::from_parts(com, frame);
        let shape = Self::from_body_mesh(name, body, tris, volume, unit_inertia)?;
        Ok(PlacedPolyhedron { shape, pose })
    }

    fn from_body_mesh(
        name: &str,
        body: Vec<Vector>,
        tris: &[[u32; 3]],
        volume: Real,
        unit_inertia: Vector,
    ) -> Result<Self> {
        let parry = ConvexPolyhedron::from_convex_mesh(body, tris).ok_or_else(|| Error::DegenerateGeometry {
            block: name.to_owned(),
            reason: "the faces do not form a closed convex manifold".into(),
        })?;
        let vertices = parry.points().to_vec();
        let mut faces = Vec::with_capacity(parry.faces().len());
        let mut face_vertices = Vec::new();
        for f in parry.faces() {
            let i1 = f.first_vertex_or_edge as usize;
            let i2 = i1 + f.num_vertices_or_edges as usize;
            let ids = &parry.vertices_adj_to_face()[i1..i2];
            let loop_pts: Vec<Vector> = ids.iter().map(|&v| vertices[v as usize]).collect();
            let nw = newell_normal(&loop_pts);
            let area = 0.5 * nw.length();
            let normal = nw.normalize();
            let offset = loop_pts.iter().map(|p| normal.dot(*p)).sum::<Real>() / loop_pts.len() as Real;
            faces.push(Face {
                normal,
                offset,
                area,
                first: face_vertices.len() as u32,
                len: ids.len() as u32,
            });
            face_vertices.extend_from_slice(ids);
        }
        let radius = vertices.iter().map(|v| v.length()).fold(0.0, Real::max);
        let mut edges: Vec<[u32; 2]> = Vec::new();
        for f in &faces {
            let ids = &face_vertices[f.first as usize..(f.first + f.len) as usize];
            for k in 0..ids.len() {
                let (i, j) = (ids[k], ids[(k + 1) % ids.len()]);
                edges.push([i.min(j), i.max(j)]);
            }
        }
        edges.sort_unstable();
        edges.dedup();
        let edge_directions = distinct_directions(&vertices, &edges);
        let mut shape = Self {
            vertices,
            faces,
            face_vertices,
            edges,
            edge_directions,
            face_grids: Vec::new(),
            radius,
            volume,
            unit_inertia,
            parry: Some(parry),
        };
        shape.face_grids = (0..shape.faces.len()).map(|f| FaceGrid::compute(&shape, f)).collect();
        Ok(shape)
    }

    /// Rebuilds parry's shape after deserialisation and checks the stored topology.
    #[cfg(feature = "serde")]
    pub(crate) fn restore(&mut self) -> Result<()> {
        let bad = |reason: &str| Error::DegenerateGeometry {
            block: "(restored)".into(),
            reason: reason.into(),
        };
        let n = self.vertices.len() as u32;
        if self.faces.len() < 4 || self.face_vertices.iter().any(|&v| v >= n) {
            return Err(bad("stored faces refer to missing vertices"));
        }
        let mut tris = Vec::new();
        for f in &self.faces {
            let end = f.first as usize + f.len as usize;
            if f.len < 3 || end > self.face_vertices.len() {
                return Err(bad("stored face loop out of range"));
            }
            let ids = &self.face_vertices[f.first as usize..end];
            for k in 1..ids.len() - 1 {
                tris.push([ids[0], ids[k], ids[k + 1]]);
            }
        }
        if self.edges.iter().any(|e| e[0] >= n || e[1] >= n) {
            return Err(bad("stored edges refer to missing vertices"));
        }
        self.edge_directions = distinct_directions(&self.vertices, &self.edges);
        self.face_grids = (0..self.faces.len()).map(|f| FaceGrid::compute(self, f)).collect();
        self.parry = Some(
            ConvexPolyhedron::from_convex_mesh(self.vertices.clone(), &tris)
                .ok_or_else(|| bad("stored faces do not form a convex manifold"))?,
        );
        Ok(())
    }

    /// Checks the stored derived data against the vertices and face loops (after
    /// [`Polyhedron::restore`]): each face's plane and area, the edges and the radius as
    /// construction computes them from the vertices (the same code, so bit for bit); every
    /// vertex on or inside every face plane (convexity); and the volume, centroid (the origin)
    /// and inertia per unit density (diagonal, along the body axes) as the geometry gives them,
    /// to round-off (construction computes them in world coordinates, before the move to the
    /// principal frame). The error names the field and gives both values.
    #[cfg(feature = "serde")]
    pub(crate) fn check_derived(&self) -> std::result::Result<(), (String, String)> {
        let differs = |field: String, stored: &dyn std::fmt::Debug, computed: &dyn std::fmt::Debug| {
            Err((
                field,
                format!("is {stored:?} in the file, its vertices give {computed:?}"),
            ))
        };
        if self.vertices.len() > MAX_HULL_VERTICES {
            return Err((
                "shape.vertices".into(),
                format!(
                    "has {} vertices, more than the {MAX_HULL_VERTICES} a block may have",
                    self.vertices.len()
                ),
            ));
        }
        let mut edges: Vec<[u32; 2]> = Vec::new();
        for (i, f) in self.faces.iter().enumerate() {
            let ids = self.face_loop(i);
            let loop_pts: Vec<Vector> = ids.iter().map(|&v| self.vertices[v as usize]).collect();
            let nw = newell_normal(&loop_pts);
            let (area, normal) = (0.5 * nw.length(), nw.normalize());
            let offset = loop_pts.iter().map(|p| normal.dot(*p)).sum::<Real>() / loop_pts.len() as Real;
            if normal.to_array().map(Real::to_bits) != f.normal.to_array().map(Real::to_bits) {
                return differs(format!("shape.faces[{i}].normal"), &f.normal, &normal);
            }
            if offset.to_bits() != f.offset.to_bits() {
                return differs(format!("shape.faces[{i}].offset"), &f.offset, &offset);
            }
            if area.to_bits() != f.area.to_bits() {
                return differs(format!("shape.faces[{i}].area"), &f.area, &area);
            }
            for k in 0..ids.len() {
                let (a, b) = (ids[k], ids[(k + 1) % ids.len()]);
                edges.push([a.min(b), a.max(b)]);
            }
        }
        edges.sort_unstable();
        edges.dedup();
        if edges != self.edges {
            return Err(("shape.edges".into(), "are not those of the face loops".into()));
        }
        let radius = self.vertices.iter().map(|v| v.length()).fold(0.0, Real::max);
        if radius.to_bits() != self.radius.to_bits() {
            return differs("shape.radius".into(), &self.radius, &radius);
        }
        let tol = 1e-9 * bbox_diagonal(&self.vertices);
        for (i, f) in self.faces.iter().enumerate() {
            if let Some(v) = self.vertices.iter().position(|p| f.normal.dot(*p) - f.offset > tol) {
                return Err((
                    format!("shape.vertices[{v}]"),
                    format!("lies outside face {i}: the shape is not convex"),
                ));
            }
        }
        let mut tris: Vec<[u32; 3]> = Vec::new();
        for i in 0..self.faces.len() {
            let ids = self.face_loop(i);
            tris.extend((1..ids.len() - 1).map(|k| [ids[0], ids[k], ids[k + 1]]));
        }
        let moments = volume_moments(&self.vertices, &tris);
        let volume = moments.volume;
        if !(volume > 0.0 && (volume - self.volume).abs() <= 1e-9 * volume) {
            return differs("shape.volume".into(), &self.volume, &volume);
        }
        if moments.centroid.length() > 1e-9 * radius {
            return Err((
                "shape.vertices".into(),
                format!(
                    "have their centroid at {:?}, not at the origin of the body frame",
                    moments.centroid
                ),
            ));
        }
        let inertia = moments.inertia;
        let scale = self.unit_inertia.abs().max_element();
        for i in 0..3 {
            for j in 0..3 {
                let stored = if i == j { self.unit_inertia[i] } else { 0.0 };
                let computed = inertia.col(j)[i];
                if !((computed - stored).abs() <= 1e-6 * scale && scale > 0.0) {
                    return Err((
                        "shape.unit_inertia".into(),
                        format!(
                            "is {:?} in the file (body axes principal), its vertices give the tensor {:?}",
                            self.unit_inertia,
                            inertia.to_cols_array_2d()
                        ),
                    ));
                }
            }
        }
        Ok(())
    }

    /// Whether `other` is this shape bit for bit: the same vertices (as bits: `-0.0` is not
    /// `0.0`), faces and edges. Derived data follow from these.
    #[cfg(feature = "serde")]
    pub(crate) fn same_as(&self, other: &Self) -> bool {
        let bits = |v: &Vector| v.to_array().map(Real::to_bits);
        self.vertices.len() == other.vertices.len()
            && self
                .vertices
                .iter()
                .zip(&other.vertices)
                .all(|(a, b)| bits(a) == bits(b))
            && self.faces == other.faces
            && self.face_vertices == other.face_vertices
            && self.edges == other.edges
    }

    /// A hash of the vertices' bits (for [`Polyhedron::same_as`] lookups).
    #[cfg(feature = "serde")]
    pub(crate) fn vertex_hash(&self) -> u64 {
        let mut h: u64 = 0xcbf2_9ce4_8422_2325;
        for v in &self.vertices {
            for x in v.to_array() {
                h = (h ^ x.to_bits()).wrapping_mul(0x0100_0000_01b3);
            }
        }
        h
    }

    /// Vertices in the body frame (m).
    pub fn vertices(&self) -> &[Vector] {
        &self.vertices
    }

    /// Faces in the body frame.
    pub fn faces(&self) -> &[Face] {
        &self.faces
    }

    /// Vertex indices of face `face`, counter-clockwise seen from outside.
    pub fn face_loop(&self, face: usize) -> &[u32] {
        let f = &self.faces[face];
        &self.face_vertices[f.first as usize..(f.first + f.len) as usize]
    }

    /// The node grid frame of face `face` (node contacts).
    #[inline]
    pub(crate) fn face_grid(&self, face: usize) -> &FaceGrid {
        &self.face_grids[face]
    }

    /// Unique edges as pairs of vertex indices.
    pub fn edges(&self) -> &[[u32; 2]] {
        &self.edges
    }

    /// One edge per direction of the edges (parallel edges, either way round, share one): the
    /// first of [`Polyhedron::edges`] along each direction, in that order.
    pub fn edges_by_direction(&self) -> impl Iterator<Item = [u32; 2]> + '_ {
        self.edge_directions.iter().map(|&e| self.edges[e as usize])
    }

    /// Volume (m³).
    pub fn volume(&self) -> Real {
        self.volume
    }

    /// Largest distance from the centroid to a vertex (m).
    pub fn radius(&self) -> Real {
        self.radius
    }

    /// Mass properties for a uniform `density` (kg/m³).
    pub fn mass_properties(&self, density: Real) -> MassProperties {
        MassProperties {
            mass: density * self.volume,
            volume: self.volume,
            principal_inertia: self.unit_inertia * density,
        }
    }

    /// parry's view of the shape, for GJK/EPA and AABBs.
    pub(crate) fn parry(&self) -> &ConvexPolyhedron {
        self.parry.as_ref().expect("polyhedron restored after deserialisation")
    }

    /// The face whose outward normal is most aligned with `dir` (body frame).
    pub fn most_aligned_face(&self, dir: Vector) -> usize {
        let mut best = 0;
        let mut best_dot = Real::NEG_INFINITY;
        for (i, f) in self.faces.iter().enumerate() {
            let d = f.normal.dot(dir);
            if d > best_dot {
                best_dot = d;
                best = i;
            }
        }
        best
    }
}

fn check_points(name: &str, points: &[Vector]) -> Result<()> {
    if let Some(i) = points.iter().position(|p| !is_finite_vector(*p)) {
        return Err(Error::NonFinite {
            what: format!("vertex {i} of block {name:?}"),
        });
    }
    if points.len() < 4 {
        return Err(Error::DegenerateGeometry {
            block: name.to_owned(),
            reason: format!("{} vertices given, a solid needs at least 4", points.len()),
        });
    }
    Ok(())
}

fn bbox_extent(points: &[Vector]) -> Vector {
    let (mut lo, mut hi) = (Vector::splat(Real::INFINITY), Vector::splat(Real::NEG_INFINITY));
    for p in points {
        lo = lo.min(*p);
        hi = hi.max(*p);
    }
    hi - lo
}

fn bbox_diagonal(points: &[Vector]) -> Real {
    bbox_extent(points).length().max(Real::MIN_POSITIVE)
}

/// Newell's normal of a polygon loop: twice the vector area (not normalised).
pub(crate) fn newell_normal(pts: &[Vector]) -> Vector {
    let mut n = Vector::ZERO;
    for i in 0..pts.len() {
        let (a, b) = (pts[i], pts[(i + 1) % pts.len()]);
        n += a.cross(b);
    }
    n
}

/// The first edge of `edges` along each direction (by index, in order): edges whose directions
/// are parallel within the separating-axis test's own threshold (`|u × v| ≤ 10⁻⁹ |u| |v|`) share
/// one. Quadratic in the edges, once per shape.
fn distinct_directions(vertices: &[Vector], edges: &[[u32; 2]]) -> Vec<u32> {
    let direction = |e: &[u32; 2]| vertices[e[1] as usize] - vertices[e[0] as usize];
    let mut kept: Vec<u32> = Vec::new();
    for (k, e) in edges.iter().enumerate() {
        let d = direction(e);
        let parallel = kept.iter().any(|&j| {
            let u = direction(&edges[j as usize]);
            u.cross(d).length() <= 1e-9 * u.length() * d.length()
        });
        if !parallel {
            kept.push(k as u32);
        }
    }
    kept
}

#[cfg(test)]
mod tests {
    use super::*;

    fn brick(a: Real, b: Real, c: Real, origin: Vector) -> Vec<Vector> {
        (0..8)
            .map(|i| {
                origin
                    + Vector::new(
                        (i & 1) as Real * a,
                        ((i >> 1) & 1) as Real * b,
                        ((i >> 2) & 1) as Real * c,
                    )
            })
            .collect()
    }

    #[test]
    fn brick_mass_properties_match_closed_form() {
        let (a, b, c) = (0.2, 0.1, 0.05);
        let p = Polyhedron::from_hull("b", &brick(a, b, c, Vector::new(1000.0, -3.0, 7.0))).unwrap();
        let mp = p.shape.mass_properties(2500.0);
        let m = 2500.0 * a * b * c;
        assert!((mp.mass - m).abs() < 1e-12 * m);
        let mut expect = [
            m * (b * b + c * c) / 12.0,
            m * (a * a + c * c) / 12.0,
            m * (a * a + b * b) / 12.0,
        ];
        let mut got = mp.principal_inertia.to_array();
        expect.sort_by(Real::total_cmp);
        got.sort_by(Real::total_cmp);
        for k in 0..3 {
            assert!((expect[k] - got[k]).abs() < 1e-9 * expect[k], "{expect:?} {got:?}");
        }
        let c0 = Vector::new(1000.0 + a / 2.0, -3.0 + b / 2.0, 7.0 + c / 2.0);
        assert!((p.pose.translation - c0).length() < 1e-12);
        let total_area: Real = p.shape.faces().iter().map(|f| f.area).sum();
        assert!((total_area - 2.0 * (a * b + b * c + a * c)).abs() < 1e-12);
    }

    /// parry's hull alone flattens this slab (volume 0); the scaled hull must not.
    #[test]
    fn slender_slab_keeps_its_volume() {
        let corners: Vec<Vector> = (0..8)
            .map(|i| {
                Vector::new(
                    if i & 1 == 0 { -0.1 } else { 100.0 },
                    if i & 2 == 0 { -0.1 } else { 0.2 },
                    if i & 4 == 0 { -0.05 } else { 0.0 },
                )
            })
            .collect();
        let p = Polyhedron::from_hull("slab", &corners).unwrap();
        let v = 100.1 * 0.3 * 0.05;
        assert!((p.shape.volume() - v).abs() < 1e-12 * v, "{}", p.shape.volume());
        assert_eq!(p.shape.faces().len(), 6);
    }

    #[test]
    fn explicit_faces_agree_with_hull_and_reject_bad_input() {
        let pts = vec![Vector::ZERO, Vector::X, Vector::Y, Vector::Z];
        let faces = vec![vec![0, 2, 1], vec![0, 1, 3], vec![1, 2, 3], vec![2, 0, 3]];
        let p = Polyhedron::from_faces("tet", &pts, &faces).unwrap();
        assert!((p.shape.volume() - 1.0 / 6.0).abs() < 1e-14);
        assert!((p.pose.translation - Vector::splat(0.25)).length() < 1e-14);
        let inward: Vec<Vec<usize>> = faces.iter().map(|f| f.iter().rev().copied().collect()).collect();
        assert!(matches!(
            Polyhedron::from_faces("tet", &pts, &inward),
            Err(Error::NonConvex { .. })
        ));
        let flat = vec![Vector::ZERO, Vector::X, Vector::Y, Vector::new(1.0, 1.0, 0.0)];
        assert!(matches!(
            Polyhedron::from_hull("flat", &flat),
            Err(Error::DegenerateGeometry { .. } | Error::NonPositiveVolume { .. })
        ));
        let nan = vec![Vector::ZERO, Vector::X, Vector::Y, Vector::new(Real::NAN, 0.0, 1.0)];
        assert!(matches!(
            Polyhedron::from_hull("nan", &nan),
            Err(Error::NonFinite { .. })
        ));
        let bad_index = vec![vec![0, 2, 1], vec![0, 1, 3], vec![1, 2, 3], vec![2, 0, 9]];
        assert!(matches!(
            Polyhedron::from_faces("tet", &pts, &bad_index),
            Err(Error::NonConvex { .. })
        ));
    }
}
