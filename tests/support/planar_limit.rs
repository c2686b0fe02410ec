//! A planar rigid-block limit analysis of a model as it stands, written for the tests of
//! issue 43 (`tests/collapse.rs`, `arch/tests/collapse.rs`): the programme of
//! `voussoir::analysis::limit` (Livesley's; `docs/theory.md` §9) restricted to the x–y plane, on
//! the model's own contacts — their normals, and their polygons reduced to the segment they make
//! in the plane — so that a joint's segment can be **shrunk** at one end: the hinge of a
//! no-tension Winkler joint turns about its compression resultant, `c/3` inside the edge, not
//! about the edge, and a limit analysis with the segment shrunk by that offset is the rigid
//! analysis of the soft joint's lever arms (`docs/benchmarks/collapse.md`).
//!
//! Unknowns: at the two ends of every contact segment a normal force `n ≥ 0` and a shear force
//! `t` with `|t| ≤ μ n` (the planar Coulomb cone, two linear inequalities, exact); three
//! equilibrium equations (x, y and the moment about z at the centroid) per free block; maximise
//! the multiplier of the live load. A linear programme, solved by Clarabel as the library's.
//! Without shrinking, its answer is the library's for a planar model (the tests check it).

use clarabel::algebra::CscMatrix;
use clarabel::solver::{DefaultSettings, DefaultSolver, IPSolver, SolverStatus, SupportedConeT};
use voussoir::block::{Block, BlockId, Dof};
use voussoir::law::CoulombSlip;
use voussoir::math::Vector;
use voussoir::model::Model;

/// One contact of the planar programme: the segment its polygon makes in the x–y plane.
#[derive(Debug, Clone)]
pub struct Segment {
    /// The blocks, `a` < `b`.
    pub blocks: (BlockId, BlockId),
    /// Unit normal from `a` to `b` (x, y).
    pub normal: Vector,
    /// The segment's two ends (z = 0).
    pub ends: [Vector; 2],
    /// Friction coefficient.
    pub friction: f64,
}

impl Segment {
    /// Moves the end nearest to `edge` towards the other end by `offset` (m).
    pub fn shrink_at(&mut self, edge: Vector, offset: f64) {
        let flat = |v: Vector| Vector::new(v.x, v.y, 0.0);
        let (k, o) = if (self.ends[0] - flat(edge)).length() <= (self.ends[1] - flat(edge)).length() {
            (0, 1)
        } else {
            (1, 0)
        };
        let along = (self.ends[o] - self.ends[k]).normalize();
        self.ends[k] += along * offset;
    }
}

/// A planar programme: blocks and segments of a model as it stands.
#[derive(Debug, Clone)]
pub struct PlanarLimit {
    /// Per block: centroid, free (x, y, rotation about z), dead force and moment about z.
    blocks: Vec<(Vector, [bool; 3], Vector, f64)>,
    /// The contacts.
    pub segments: Vec<Segment>,
}

/// The answer: the multiplier, and the blocks' velocities in the mechanism (vx, vy, ωz).
#[derive(Debug, Clone)]
pub struct PlanarAnswer {
    pub multiplier: f64,
    pub velocities: Vec<[f64; 3]>,
}

impl PlanarLimit {
    /// The programme of `model` (Coulomb joints; friction from each contact's law), with the
    /// blocks' fixities, except those in `free_instead` (block, free x / y / rotation about z).
    pub fn from_model(model: &Model<CoulombSlip>, free_instead: &[(BlockId, [bool; 3])]) -> Self {
        let g = model.parameters().gravity;
        let blocks = model
            .blocks()
            .iter()
            .enumerate()
            .map(|(k, b)| {
                let f = b.fixity();
                let mut free = [
                    f.translation[0] == Dof::Free,
                    f.translation[1] == Dof::Free,
                    f.rotation[2] == Dof::Free,
                ];
                if let Some((_, instead)) = free_instead.iter().find(|(id, _)| id.index() == k) {
                    free = *instead;
                }
                let load = b.load();
                (
                    b.state().pose.translation,
                    free,
                    g * b.mass_properties().mass + load.force,
                    load.moment.z,
                )
            })
            .collect::<Vec<_>>();
        let mut segments = Vec::new();
        for c in model.contacts() {
            let (a, b) = c.blocks();
            if !blocks[a.index()].1.iter().chain(&blocks[b.index()].1).any(|&f| f) {
                continue;
            }
            let n = c.axes().normal;
            let normal = Vector::new(n.x, n.y, 0.0).normalize();
            let along = Vector::new(-normal.y, normal.x, 0.0);
            let polygon = model.contact_polygon(&c);
            let flat = |v: &Vector| Vector::new(v.x, v.y, 0.0);
            let lo = polygon
                .iter()
                .map(flat)
                .min_by(|p, q| p.dot(along).total_cmp(&q.dot(along)));
            let hi = polygon
                .iter()
                .map(flat)
                .max_by(|p, q| p.dot(along).total_cmp(&q.dot(along)));
            let (Some(lo), Some(hi)) = (lo, hi) else { continue };
            let law = &model.law_table().laws()[c.law_index()];
            segments.push(Segment {
                blocks: (a, b),
                normal,
                ends: [lo, hi],
                friction: law.friction_angle().tan(),
            });
        }
        Self { blocks, segments }
    }

    /// The contact between `a` and `b`, if any.
    pub fn segment_mut(&mut self, a: BlockId, b: BlockId) -> Option<&mut Segment> {
        self.segments
            .iter_mut()
            .find(|s| s.blocks == (a, b) || s.blocks == (b, a))
    }

    /// The largest multiplier of the live loads `(block, point, force)`, with the mechanism.
    ///
    /// # Panics
    /// When Clarabel does not solve the programme.
    pub fn solve(&self, live: &[(BlockId, Vector, Vector)]) -> PlanarAnswer {
        // Rows: 3 per block (only the free ones are written).
        let mut row_of = vec![None; 3 * self.blocks.len()];
        let mut rows = 0;
        for (k, b) in self.blocks.iter().enumerate() {
            for d in 0..3 {
                if b.1[d] {
                    row_of[3 * k + d] = Some(rows);
                    rows += 1;
                }
            }
        }
        let scale: f64 = self
            .blocks
            .iter()
            .filter(|b| b.1.iter().any(|&f| f))
            .map(|b| b.2.length())
            .sum();
        let (mut r, mut c, mut v) = (Vec::new(), Vec::new(), Vec::new());
        let mut push = |row: usize, col: usize, val: f64| {
            if val != 0.0 {
                r.push(row);
                c.push(col);
                v.push(val);
            }
        };
        let mut b_eq = vec![0.0; rows];
        for (k, b) in self.blocks.iter().enumerate() {
            for (d, dead) in [b.2.x, b.2.y, b.3].into_iter().enumerate() {
                if let Some(row) = row_of[3 * k + d] {
                    b_eq[row] = -dead / scale;
                }
            }
        }
        let force_at = |k: usize, p: Vector, f: Vector| -> [(usize, f64); 3] {
            let arm = p - self.blocks[k].0;
            [(0, f.x), (1, f.y), (2, arm.x * f.y - arm.y * f.x)]
        };
        for &(block, point, force) in live {
            for (d, val) in force_at(block.index(), point, force) {
                if let Some(row) = row_of[3 * block.index() + d] {
                    push(row, 0, val);
                }
            }
        }
        let mut col = 1;
        let mut corners = Vec::new();
        for s in &self.segments {
            let tangent = Vector::new(-s.normal.y, s.normal.x, 0.0);
            for &p in &s.ends {
                for (j, dir) in [s.normal, tangent].into_iter().enumerate() {
                    for (block, sign) in [(s.blocks.1, 1.0), (s.blocks.0, -1.0)] {
                        for (d, val) in force_at(block.index(), p, dir * sign) {
                            if let Some(row) = row_of[3 * block.index() + d] {
                                push(row, col + j, val);
                            }
                        }
                    }
                }
                corners.push((col, s.friction));
                col += 2;
            }
        }
        // Cones: n ≥ 0, μ n − t ≥ 0, μ n + t ≥ 0.
        let mut b = b_eq;
        let mut row = rows;
        for &(n, mu) in &corners {
            push(row, n, -1.0);
            push(row + 1, n, -mu);
            push(row + 1, n + 1, 1.0);
            push(row + 2, n, -mu);
            push(row + 2, n + 1, -1.0);
            b.extend([0.0; 3]);
            row += 3;
        }
        let a = CscMatrix::new_from_triplets(row, col, r, c, v);
        let p = CscMatrix::zeros((col, col));
        let mut q = vec![0.0; col];
        q[0] = -1.0;
        let cones = [
            SupportedConeT::ZeroConeT(rows),
            SupportedConeT::NonnegativeConeT(row - rows),
        ];
        let settings = DefaultSettings {
            verbose: false,
            ..DefaultSettings::default()
        };
        let mut solver = DefaultSolver::new(&p, &q, &a, &b, &cones, settings).expect("a programme");
        solver.solve();
        let sol = &solver.solution;
        assert!(
            matches!(sol.status, SolverStatus::Solved),
            "planar limit analysis: {:?}",
            sol.status
        );
        let velocities = (0..self.blocks.len())
            .map(|k| {
                let dual = |d: usize| row_of[3 * k + d].map_or(0.0, |r| sol.z[r]);
                [dual(0), dual(1), dual(2)]
            })
            .collect();
        PlanarAnswer {
            multiplier: sol.x[0] * scale,
            velocities,
        }
    }
}

/// The rotation of `block` about z since it was built (rad).
pub fn turn(m: &voussoir::model::Model, block: BlockId) -> f64 {
    let b = m.block(block).unwrap();
    (b.state().pose.rotation * b.initial_pose().rotation.inverse())
        .to_scaled_axis()
        .z
}
