//! Limit analysis of rigid-block assemblies: the largest multiplier `λ` of a live load that the
//! blocks can carry in equilibrium with no-tension, Coulomb-frictional joints, and the collapse
//! mechanism at it — the answer of RING or LiABlock beside the DEM's (`docs/theory.md` §9).
//!
//! The formulation (Livesley 1978; Gilbert, Casapulla & Ahmed 2006; Portioli et al. 2014): the
//! blocks and face-face contacts of a [`Model`] as it stands (its current poses and contacts);
//! at every corner of every contact polygon a normal force `n ≥ 0` and a shear force `t` with
//! `‖t‖ ≤ μ n + c A/m` (the Coulomb cone, exact, as a second-order cone; `m` corners share the
//! cohesion `c A`); six equilibrium equations per free block (force and moment about its
//! centroid) under the dead loads (gravity × mass at the centroid, and the blocks' constant
//! loads) and `λ` times the live loads; maximise `λ`. The programme is solved by
//! [Clarabel](https://docs.rs/clarabel)'s interior-point method. The duals of the equilibrium
//! equations are the blocks' virtual velocities in the collapse mechanism, which
//! [`LimitResult::classify`] reads as hinges and sliding joints in the terms of
//! [`classify_joints`](super::classify_joints).
//!
//! Without a live load the programme answers the dead-load question alone
//! ([`LimitProblem::dead_load`], or [`LimitProblem::analyse`] with no live load or live loads of
//! zero force): whether the blocks carry their own weight, with the contact forces of an
//! admissible state (e.g. to draw the thrust line) when they do, and the blocks that fall (a
//! mechanism of the dead loads) when they do not ([`DeadLoadResult`]; no multiplier).
//!
//! The flow rule of this (associative) formulation is dilatant: a sliding corner opens at
//! `μ` times its slip rate. The DEM's Coulomb joints slide without dilatancy; by Radenković's
//! theorem the associative limit load bounds the non-associative one from above.
//!
//! ```
//! use voussoir::analysis::limit::{LimitOptions, LimitProblem, LiveLoad};
//! use voussoir::prelude::*;
//!
//! // A 0.2 m × 0.2 m × 0.4 m pier on a fixed base, pushed sideways at the top.
//! let mut model: Model = Model::new(ModelParameters::default())?;
//! model.set_joint_law(MaterialId(0), MaterialId(0), CoulombSlip::dry(1e9, 4e8, 40.0)?)?;
//! model.add_block(
//!     RigidBlock::cuboid("base", Vector::new(-1.0, -1.0, -0.2), Vector::new(1.0, 1.0, 0.0), 2500.0)?
//!         .with_fixity(Fixity::FIXED),
//! )?;
//! let pier = model.add_block(RigidBlock::cuboid("pier", Vector::ZERO, Vector::new(0.2, 0.2, 0.4), 2500.0)?)?;
//! model.step()?; // detects the contact
//! let problem = LimitProblem::from_model(&model)?;
//! let push = LiveLoad { block: pier, point: Vector::new(0.0, 0.1, 0.4), force: Vector::X };
//! let result = problem.solve(&[push], &LimitOptions::default())?;
//! // Overturning about the toe: λ h = W b/2.
//! let weight = 2500.0 * 0.016 * 9.81;
//! assert!((result.multiplier - weight * 0.1 / 0.4).abs() < 1e-4 * weight);
//! // The mechanism: the pier turns about the toe at x = 0.2 (clockwise seen from +y).
//! let (v, w) = result.block_velocity(pier).expect("a block of the model");
//! assert!(v.x > 0.0 && w.y > 0.0);
//! # Ok::<(), voussoir::Error>(())
//! ```

use clarabel::solver::{SolverStatus, SupportedConeT};

mod inputs;
mod programme;
mod result;

use crate::block::{Block, BlockId, Dof, Fixity};
use crate::error::{Error, Result};
use crate::law::ConstitutiveLaw;
use crate::math::{Real, Vector};
use crate::model::Model;
pub use inputs::{FrictionModel, JointStrength, LimitOptions, LimitStrength, LiveLoad};
use programme::{Corner, Programme, Scales, Solution, Triplets};
pub use result::{BlockMotion, DeadLoadResult, JointMotion, LimitAnswer, LimitContact, LimitResult, LimitVertex};

/// What the programme needs of one block.
#[derive(Debug, Clone)]
struct BlockData {
    name: String,
    centroid: Vector,
    /// Free degrees of freedom: translations x, y, z, rotations x, y, z.
    free: [bool; 6],
    /// Dead load: gravity and the block's constant load (force; moment about the centroid).
    dead_force: Vector,
    dead_moment: Vector,
    radius: Real,
    weight: Real,
}

/// What the programme needs of one contact.
#[derive(Debug, Clone)]
struct ContactData {
    a: usize,
    b: usize,
    normal: Vector,
    t1: Vector,
    t2: Vector,
    vertices: Vec<Vector>,
    /// Cohesive force per corner (N): `c A / m`.
    cohesion_share: Real,
    friction: Real,
}

/// The limit-analysis programme of a model's blocks and contacts as they stand.
///
/// Build it from a model whose contacts have been detected (after at least one step, e.g. once
/// it has settled under gravity), then [`solve`](LimitProblem::solve) it for a live load. The
/// contact polygons are the contacts' own: for a face-face contact the overlap of the two faces
/// (`docs/theory.md` §2.2), for a point contact the hull of its sub-contacts (a segment or a
/// point). Contacts whose blocks are both supports are left out.
#[derive(Debug, Clone)]
pub struct LimitProblem {
    blocks: Vec<BlockData>,
    contacts: Vec<ContactData>,
}

impl LimitProblem {
    /// The programme of `model` with each contact's strength from its joint law
    /// ([`LimitStrength`]).
    ///
    /// # Errors
    /// As [`LimitProblem::from_model_with`].
    pub fn from_model<L: ConstitutiveLaw + LimitStrength>(model: &Model<L>) -> Result<Self> {
        Self::from_model_with(model, |law: &L| law.limit_strength())
    }

    /// The programme of `model` with each contact's strength given by `strength` from its
    /// joint law (e.g. a table of your own per pair of materials, or a law of your own).
    ///
    /// # Errors
    /// [`Error::Unsupported`] for a model never stepped (no contact detected yet), or naming
    /// the contact whose law `strength` gives no strength for;
    /// [`Error::InvalidParameter`] for a negative or non-finite strength.
    pub fn from_model_with<L: ConstitutiveLaw>(
        model: &Model<L>,
        strength: impl Fn(&L) -> Option<JointStrength>,
    ) -> Result<Self> {
        let gravity = model.parameters().gravity;
        let blocks: Vec<BlockData> = model
            .blocks()
            .iter()
            .map(|b| {
                let mass = b.mass_properties().mass;
                let load = b.load();
                BlockData {
                    name: b.name().to_owned(),
                    centroid: b.state().pose.translation,
                    free: free_dofs(b.fixity()),
                    dead_force: gravity * mass + load.force,
                    dead_moment: load.moment,
                    radius: b.shape().radius(),
                    weight: (gravity * mass).length(),
                }
            })
            .collect();
        if model.detection_count() == 0 {
            return Err(Error::Unsupported {
                what: "limit analysis of a model whose contacts were never detected (it was never stepped): \
                       step it once (Model::step) so that its contacts are found"
                    .into(),
            });
        }
        let mut contacts = Vec::new();
        for view in model.contacts() {
            let (a, b) = view.blocks();
            let (ia, ib) = (a.index(), b.index());
            if !blocks[ia].free.iter().chain(&blocks[ib].free).any(|&f| f) {
                continue;
            }
            let law = &model.law_table().laws()[view.law_index()];
            let s = strength(law).ok_or_else(|| Error::Unsupported {
                what: format!(
                    "limit analysis of the contact between blocks {a} ({:?}) and {b} ({:?}): its joint law has no \
                     strength limit; give one with LimitProblem::from_model_with",
                    blocks[ia].name, blocks[ib].name
                ),
            })?;
            let s = JointStrength::new(s.friction, s.cohesion)?;
            let vertices = model.contact_polygon(&view);
            if vertices.is_empty() {
                continue;
            }
            // Cohesion acts on the part of the joint that touches: at most the polygon's area
            // (a tilted face touches along a strip).
            let area: Real = view
                .subcontacts()
                .map(|s| s.area())
                .sum::<Real>()
                .min(polygon_area(&vertices));
            let axes = view.axes();
            contacts.push(ContactData {
                a: ia,
                b: ib,
                normal: axes.normal,
                t1: axes.tangent,
                t2: axes.tangent_2(),
                cohesion_share: s.cohesion * area / vertices.len() as Real,
                friction: s.friction,
                vertices,
            });
        }
        Ok(Self { blocks, contacts })
    }

    /// Replaces the fixity of `block` for the analysis: e.g. a loading plate driven in the DEM
    /// (its vertical velocity prescribed) that the limit analysis loads by force instead.
    /// Equilibrium is written for the free degrees of freedom only; a constrained one is a
    /// support that takes any reaction.
    ///
    /// # Errors
    /// [`Error::UnknownBlock`].
    pub fn set_fixity(&mut self, block: BlockId, fixity: Fixity) -> Result<()> {
        let count = self.blocks.len();
        let data = self
            .blocks
            .get_mut(block.index())
            .ok_or(Error::UnknownBlock { id: block, count })?;
        data.free = free_dofs(&fixity);
        Ok(())
    }

    /// Number of contacts in the programme.
    pub fn contact_count(&self) -> usize {
        self.contacts.len()
    }

    /// The contacts' blocks and polygon corners (m, world).
    pub fn polygons(&self) -> impl Iterator<Item = ((BlockId, BlockId), &[Vector])> + '_ {
        self.contacts
            .iter()
            .map(|c| ((BlockId(c.a as u32), BlockId(c.b as u32)), c.vertices.as_slice()))
    }

    /// The largest multiplier `λ` of `live` that the blocks carry, with the forces at collapse
    /// and the mechanism.
    ///
    /// # Errors
    /// [`Error::UnknownBlock`] or [`Error::NonFinite`] for a bad live load,
    /// [`Error::InvalidParameter`] for no live load or a zero one (ask the dead-load question
    /// with [`LimitProblem::dead_load`] or [`LimitProblem::analyse`]) or a pyramid of fewer
    /// than 3 facets;
    /// [`Error::LimitInfeasible`] when the dead loads are not carried (no admissible `λ`, or
    /// only negative ones, or — with [`LimitOptions::check_dead_load`] — only positive ones);
    /// [`Error::LimitUnbounded`] when `λ` has no bound; [`Error::LimitSolver`] when Clarabel
    /// stops without an answer.
    pub fn solve(&self, live: &[LiveLoad], options: &LimitOptions) -> Result<LimitResult> {
        let total = self.check_live(live)?;
        self.check_live_size(live, total)?;
        let scales = self.scales(live);
        let programme = self.assemble(Some(live), options.friction, &scales)?;
        let (solution, status, iterations) = programme.run(options.max_iterations)?;
        match status {
            SolverStatus::Solved | SolverStatus::AlmostSolved => {}
            SolverStatus::PrimalInfeasible | SolverStatus::AlmostPrimalInfeasible => {
                return Err(Error::LimitInfeasible {
                    reason: "no contact forces within the joints' strength carry the dead loads, whatever the live \
                             load"
                        .into(),
                })
            }
            SolverStatus::DualInfeasible | SolverStatus::AlmostDualInfeasible => {
                return Err(Error::LimitUnbounded {
                    reason: format!(
                        "the live load ({}) is carried whatever its size: it acts on constrained degrees of freedom, \
                         goes straight into the supports, or wedges blocks that friction locks",
                        describe_live(live, &self.blocks)
                    ),
                })
            }
            other => {
                return Err(Error::LimitSolver {
                    status: format!("{other:?}"),
                    iterations,
                })
            }
        }
        // A multiplier within round-off below zero is a zero capacity (e.g. a block on a joint
        // without friction, pushed along it): reported as 0.
        let multiplier = solution.x[0].max(0.0) * scales.multiplier;
        if solution.x[0] < -FEASIBILITY_TOLERANCE {
            return Err(Error::LimitInfeasible {
                reason: format!(
                    "the largest admissible multiplier of the live load is {:.6e} < 0: the dead loads are \
                     carried only with a live load against its direction",
                    solution.x[0] * scales.multiplier
                ),
            });
        }
        if options.check_dead_load && !self.carries_dead_load(options)? {
            return Err(Error::LimitInfeasible {
                reason: format!(
                    "the dead loads alone are not carried; the structure stands only with part of the live load \
                     (largest multiplier {multiplier:.6e})"
                ),
            });
        }
        Ok(self.result(&programme, &solution, &scales, multiplier, status, iterations))
    }

    /// The collapse multiplier of `live` ([`LimitProblem::solve`]) or, when there is no live
    /// load (an empty slice, or live loads whose forces are all zero), the dead-load question
    /// alone ([`LimitProblem::dead_load`]): one entry point for a caller whose live load may be
    /// empty. The dead-load answer is an answer, not an error, whether carried or not.
    ///
    /// ```
    /// use voussoir::analysis::limit::{LimitAnswer, LimitOptions, LimitProblem};
    /// use voussoir::prelude::*;
    ///
    /// let mut model: Model = Model::new(ModelParameters::default())?;
    /// model.set_joint_law(MaterialId(0), MaterialId(0), CoulombSlip::dry(1e9, 4e8, 30.0)?)?;
    /// model.add_block(
    ///     RigidBlock::cuboid("base", Vector::new(-1.0, -1.0, -0.2), Vector::new(1.0, 1.0, 0.0), 2500.0)?
    ///         .with_fixity(Fixity::FIXED),
    /// )?;
    /// model.add_block(RigidBlock::cuboid("cube", Vector::ZERO, Vector::splat(0.2), 2500.0)?)?;
    /// model.step()?;
    /// let answer = LimitProblem::from_model(&model)?.analyse(&[], &LimitOptions::default())?;
    /// assert_eq!(answer.multiplier(), None);
    /// let LimitAnswer::DeadLoad(dead) = answer else { unreachable!() };
    /// assert!(dead.carried);
    /// // The base holds the cube up with its weight.
    /// let weight = 2500.0 * 0.008 * 9.81;
    /// assert!((dead.contacts[0].resultant().z - weight).abs() < 1e-6 * weight);
    /// # Ok::<(), voussoir::Error>(())
    /// ```
    ///
    /// # Errors
    /// [`Error::UnknownBlock`] or [`Error::NonFinite`] for a bad live load; otherwise as
    /// [`LimitProblem::solve`] with a live load and [`LimitProblem::dead_load`] without.
    pub fn analyse(&self, live: &[LiveLoad], options: &LimitOptions) -> Result<LimitAnswer> {
        if self.check_live(live)? > 0.0 {
            self.solve(live, options).map(LimitAnswer::Collapse)
        } else {
            self.dead_load(options).map(LimitAnswer::DeadLoad)
        }
    }

    /// Whether the dead loads alone (gravity and the blocks' constant loads) are carried:
    /// whether contact forces within the joints' strength equilibrate every free block (the
    /// structure "can carry its own weight"). When they are, the contact forces of one such
    /// state; when not, the solver's certificate, a mechanism of the dead loads
    /// ([`DeadLoadResult`]). A structure that does not stand is an answer (`carried` false),
    /// not an error.
    ///
    /// # Errors
    /// [`Error::InvalidParameter`] for a pyramid of fewer than 3 facets; [`Error::LimitSolver`]
    /// when Clarabel stops without an answer or a certificate.
    pub fn dead_load(&self, options: &LimitOptions) -> Result<DeadLoadResult> {
        let scales = self.scales(&[]);
        let programme = self.assemble(None, options.friction, &scales)?;
        let (solution, status, iterations) = programme.run(options.max_iterations)?;
        let carried = match status {
            SolverStatus::Solved | SolverStatus::AlmostSolved => true,
            SolverStatus::PrimalInfeasible | SolverStatus::AlmostPrimalInfeasible => false,
            other => {
                return Err(Error::LimitSolver {
                    status: format!("{other:?}"),
                    iterations,
                })
            }
        };
        let status = format!("{status:?}");
        if carried {
            let (contacts, blocks) = self.state(&programme, Some(&solution.x), None, &scales);
            return Ok(DeadLoadResult {
                carried,
                contacts,
                blocks,
                status,
                iterations,
                reason: None,
            });
        }
        // The certificate of infeasibility: velocities on which the dead loads do more work
        // than the joints can dissipate. Scaled so that the dead loads' power is the
        // reference force (the free blocks' weight).
        let power: Real = self
            .blocks
            .iter()
            .enumerate()
            .map(|(k, b)| {
                let dual = |d: usize| programme.row_of[6 * k + d].map_or(0.0, |r| solution.z[r]);
                b.dead_force.dot(Vector::new(dual(0), dual(1), dual(2)))
                    + b.dead_moment.dot(Vector::new(dual(3), dual(4), dual(5))) / scales.length
            })
            .sum();
        let factor = scales.force / power;
        let z: Vec<Real> = if factor.is_finite() && factor > 0.0 {
            solution.z.iter().map(|v| v * factor).collect()
        } else {
            vec![0.0; solution.z.len()]
        };
        let (contacts, blocks) = self.state(&programme, None, Some(&z), &scales);
        let reason = format!(
            "no contact forces within the joints' strength hold every free block in equilibrium under the dead \
             loads (gravity and the blocks' constant loads); in the solver's certificate, a mechanism of them, {}",
            describe_motion(&blocks, &self.blocks)
        );
        Ok(DeadLoadResult {
            carried,
            contacts,
            blocks,
            status,
            iterations,
            reason: Some(reason),
        })
    }

    /// Whether the dead loads alone are carried: [`LimitProblem::dead_load`]'s
    /// [`carried`](DeadLoadResult::carried).
    ///
    /// # Errors
    /// As [`LimitProblem::dead_load`].
    pub fn carries_dead_load(&self, options: &LimitOptions) -> Result<bool> {
        Ok(self.dead_load(options)?.carried)
    }

    /// Checks the live loads' blocks and numbers; returns the sum of their magnitudes (N).
    fn check_live(&self, live: &[LiveLoad]) -> Result<Real> {
        for (k, l) in live.iter().enumerate() {
            if l.block.index() >= self.blocks.len() {
                return Err(Error::UnknownBlock {
                    id: l.block,
                    count: self.blocks.len(),
                });
            }
            if !(l.point.is_finite() && l.force.is_finite()) {
                return Err(Error::NonFinite {
                    what: format!("live load {k} (on block {})", l.block),
                });
            }
        }
        Ok(live.iter().map(|l| norm(l.force)).sum())
    }

    /// Checks that the live loads (of magnitudes summing to `total`) make a multiplier.
    fn check_live_size(&self, live: &[LiveLoad], total: Real) -> Result<()> {
        if live.is_empty() {
            return Err(Error::InvalidParameter {
                name: "live loads (count)".into(),
                value: 0.0,
                expected: "at least one live load (without one, LimitProblem::dead_load or LimitProblem::analyse \
                           answers whether the dead loads are carried)",
            });
        }
        if total <= 0.0 {
            return Err(Error::InvalidParameter {
                name: "live load force".into(),
                value: total,
                expected: "must not be zero (without a live load, LimitProblem::dead_load or \
                           LimitProblem::analyse answers whether the dead loads are carried)",
            });
        }
        // λ is in units of the live load: the reference force over it must be a number.
        let reference = self.scales(&[]).force;
        if !(total.is_finite() && (reference / total).is_finite() && reference / total > 0.0) {
            return Err(Error::InvalidParameter {
                name: "live load force (sum of magnitudes, N)".into(),
                value: total,
                expected: "a size whose ratio to the blocks' weight is a finite, non-zero number \
                           (scale the live load; λ is reported in its units)",
            });
        }
        Ok(())
    }

    /// Reference force, length and multiplier scale of the programme.
    fn scales(&self, live: &[LiveLoad]) -> Scales {
        let free: Vec<&BlockData> = self.blocks.iter().filter(|b| b.free.iter().any(|&f| f)).collect();
        let weight: Real = free.iter().map(|b| b.weight.max(b.dead_force.length())).sum();
        let force = if weight > 0.0 { weight } else { 1.0 };
        let length = if free.is_empty() {
            1.0
        } else {
            free.iter().map(|b| b.radius).sum::<Real>() / free.len() as Real
        };
        let live_total: Real = live.iter().map(|l| norm(l.force)).sum();
        Scales {
            force,
            length,
            live: if live_total > 0.0 { live_total } else { 1.0 },
            multiplier: force / if live_total > 0.0 { live_total } else { 1.0 },
        }
    }

    /// The conic programme in Clarabel's form: minimise `qᵀx` subject to `A x + s = b`,
    /// `s ∈ K`; variables `[λ̂?, per corner: n̂, t̂₁, t̂₂]` in units of the reference force.
    fn assemble(&self, live: Option<&[LiveLoad]>, friction: FrictionModel, sc: &Scales) -> Result<Programme> {
        if let FrictionModel::Pyramid { facets } = friction {
            if facets < 3 {
                return Err(Error::InvalidParameter {
                    name: "limit analysis pyramid facets".into(),
                    value: facets as Real,
                    expected: "at least 3",
                });
            }
            if facets as u64 > MAX_PYRAMID_FACETS {
                return Err(Error::TooLarge {
                    what: "limit analysis pyramid facets".into(),
                    requested: facets as u128,
                    limit: MAX_PYRAMID_FACETS,
                });
            }
        }
        // Equilibrium rows: the free degrees of freedom.
        let mut row_of = vec![None; 6 * self.blocks.len()];
        let mut rows = 0;
        for (k, b) in self.blocks.iter().enumerate() {
            for d in 0..6 {
                if b.free[d] {
                    row_of[6 * k + d] = Some(rows);
                    rows += 1;
                }
            }
        }
        let equilibrium_rows = rows;
        let mut eq = Triplets::default();
        let mut b_eq = vec![0.0; equilibrium_rows];
        for (k, b) in self.blocks.iter().enumerate() {
            for d in 0..3 {
                if let Some(r) = row_of[6 * k + d] {
                    b_eq[r] = -b.dead_force[d] / sc.force;
                }
                if let Some(r) = row_of[6 * k + 3 + d] {
                    b_eq[r] = -b.dead_moment[d] / (sc.force * sc.length);
                }
            }
        }
        // A force `dir` (per unit of the variable) at `p` on block `k`.
        let add_force = |eq: &mut Triplets, k: usize, p: Vector, dir: Vector, col: usize| {
            let m = (p - self.blocks[k].centroid).cross(dir) / sc.length;
            for d in 0..3 {
                if let Some(r) = row_of[6 * k + d] {
                    eq.push(r, col, dir[d]);
                }
                if let Some(r) = row_of[6 * k + 3 + d] {
                    eq.push(r, col, m[d]);
                }
            }
        };
        let mut columns = 0;
        let has_live = live.is_some();
        if let Some(live) = live {
            for l in live {
                add_force(&mut eq, l.block.index(), l.point, l.force / sc.live, 0);
            }
            columns = 1;
        }
        // Corner variables.
        let mut corners = Vec::new();
        for (c, contact) in self.contacts.iter().enumerate() {
            let shear = contact.friction > 0.0 || contact.cohesion_share > 0.0;
            for &p in &contact.vertices {
                let n = columns;
                columns += 1;
                let t = shear.then(|| {
                    columns += 2;
                    (n + 1, n + 2)
                });
                for (dir, col) in std::iter::once((contact.normal, n))
                    .chain(t.into_iter().flat_map(|(t1, t2)| [(contact.t1, t1), (contact.t2, t2)]))
                {
                    add_force(&mut eq, contact.b, p, dir, col);
                    add_force(&mut eq, contact.a, p, -dir, col);
                }
                corners.push(Corner {
                    contact: c,
                    point: p,
                    n,
                    t,
                });
            }
        }
        // Cones: no tension, then friction.
        let mut a = eq;
        let mut b = b_eq;
        let mut cones = vec![SupportedConeT::ZeroConeT(equilibrium_rows)];
        let equations = equilibrium_rows;
        let mut row = equilibrium_rows;
        let mut nonneg = 0;
        for corner in &corners {
            a.push(row, corner.n, -1.0);
            b.push(0.0);
            row += 1;
            nonneg += 1;
        }
        let mut socs = 0;
        match friction {
            FrictionModel::Pyramid { facets } => {
                let inscribed = (std::f64::consts::PI / facets as Real).cos();
                for corner in &corners {
                    let Some((t1, t2)) = corner.t else { continue };
                    let contact = &self.contacts[corner.contact];
                    for k in 0..facets {
                        let angle = 2.0 * std::f64::consts::PI * k as Real / facets as Real;
                        a.push(row, corner.n, -inscribed * contact.friction);
                        a.push(row, t1, angle.cos());
                        a.push(row, t2, angle.sin());
                        b.push(inscribed * contact.cohesion_share / sc.force);
                        row += 1;
                        nonneg += 1;
                    }
                }
                cones.push(SupportedConeT::NonnegativeConeT(nonneg));
            }
            FrictionModel::Cone => {
                cones.push(SupportedConeT::NonnegativeConeT(nonneg));
                for corner in &corners {
                    let Some((t1, t2)) = corner.t else { continue };
                    let contact = &self.contacts[corner.contact];
                    a.push(row, corner.n, -contact.friction);
                    b.push(contact.cohesion_share / sc.force);
                    a.push(row + 1, t1, -1.0);
                    b.push(0.0);
                    a.push(row + 2, t2, -1.0);
                    b.push(0.0);
                    row += 3;
                    socs += 1;
                }
                cones.extend(std::iter::repeat_n(SupportedConeT::SecondOrderConeT(3), socs));
            }
        }
        let mut q = vec![0.0; columns];
        if has_live {
            q[0] = -1.0;
        }
        cones.retain(|c| !matches!(c, SupportedConeT::ZeroConeT(0) | SupportedConeT::NonnegativeConeT(0)));
        Ok(Programme {
            equations,
            a: a.into_csc(row, columns),
            b,
            q,
            cones,
            row_of,
            corners,
        })
    }

    fn result(
        &self,
        programme: &Programme,
        solution: &Solution,
        sc: &Scales,
        multiplier: Real,
        status: SolverStatus,
        iterations: u32,
    ) -> LimitResult {
        let (contacts, blocks) = self.state(programme, Some(&solution.x), Some(&solution.z), sc);
        LimitResult {
            multiplier,
            contacts,
            blocks,
            status: format!("{status:?}"),
            iterations,
        }
    }

    /// The contacts' corner forces from the primal variables `x` (zero without) and the
    /// blocks' motion from the equilibrium rows' duals `z` (zero without), with each corner's
    /// relative motion.
    fn state(
        &self,
        programme: &Programme,
        x: Option<&[Real]>,
        z: Option<&[Real]>,
        sc: &Scales,
    ) -> (Vec<LimitContact>, Vec<BlockMotion>) {
        let blocks: Vec<BlockMotion> = self
            .blocks
            .iter()
            .enumerate()
            .map(|(k, b)| {
                let dual = |d: usize| match (programme.row_of[6 * k + d], z) {
                    (Some(r), Some(z)) => z[r],
                    _ => 0.0,
                };
                BlockMotion {
                    centroid: b.centroid,
                    velocity: Vector::new(dual(0), dual(1), dual(2)),
                    angular_velocity: Vector::new(dual(3), dual(4), dual(5)) / sc.length,
                }
            })
            .collect();
        let velocity_at = |k: usize, p: Vector| {
            let m = &blocks[k];
            m.velocity + m.angular_velocity.cross(p - m.centroid)
        };
        let mut contacts: Vec<LimitContact> = self
            .contacts
            .iter()
            .map(|c| LimitContact {
                blocks: (BlockId(c.a as u32), BlockId(c.b as u32)),
                normal: c.normal,
                vertices: Vec::with_capacity(c.vertices.len()),
            })
            .collect();
        let value = |i: usize| x.map_or(0.0, |x| x[i]);
        for corner in &programme.corners {
            let c = &self.contacts[corner.contact];
            let (t1, t2) = corner.t.map_or((0.0, 0.0), |(i, j)| (value(i), value(j)));
            let rel = velocity_at(c.b, corner.point) - velocity_at(c.a, corner.point);
            let opening = c.normal.dot(rel);
            contacts[corner.contact].vertices.push(LimitVertex {
                point: corner.point,
                normal_force: value(corner.n) * sc.force,
                shear_force: (c.t1 * t1 + c.t2 * t2) * sc.force,
                opening,
                sliding: (rel - c.normal * opening).length(),
            });
        }
        (contacts, blocks)
    }
}

/// The most facets of a friction pyramid ([`FrictionModel::Pyramid`]): each adds a row per
/// contact corner; 4096 facets approximate the cone to 3e-7 of its friction, and ten million
/// used to abort the process when memory ran out.
pub const MAX_PYRAMID_FACETS: u64 = 4096;

/// Below this (in units of the reference force) a negative multiplier is round-off.
const FEASIBILITY_TOLERANCE: Real = 1e-7;

/// `|v|` without overflow or underflow of the squares (a force of 1e-300 N or 1e300 N).
fn norm(v: Vector) -> Real {
    let m = v.abs().max_element();
    if m > 0.0 && m.is_finite() {
        m * (v / m).length()
    } else {
        m
    }
}

/// The area of a planar polygon (m²; 0 for a segment or a point).
fn polygon_area(vertices: &[Vector]) -> Real {
    let Some(&o) = vertices.first() else { return 0.0 };
    let mut twice = Vector::ZERO;
    for k in 1..vertices.len().saturating_sub(1) {
        twice += (vertices[k] - o).cross(vertices[k + 1] - o);
    }
    0.5 * twice.length()
}

fn free_dofs(f: &Fixity) -> [bool; 6] {
    let free = |d: &Dof| matches!(d, Dof::Free);
    [
        free(&f.translation[0]),
        free(&f.translation[1]),
        free(&f.translation[2]),
        free(&f.rotation[0]),
        free(&f.rotation[1]),
        free(&f.rotation[2]),
    ]
}

fn describe_live(live: &[LiveLoad], blocks: &[BlockData]) -> String {
    live.iter()
        .map(|l| {
            format!(
                "{} N on block {} ({:?})",
                l.force.length(),
                l.block,
                blocks.get(l.block.index()).map_or("?", |b| b.name.as_str())
            )
        })
        .collect::<Vec<_>>()
        .join(", ")
}

/// The blocks that move most in a mechanism (speed of the centroid plus the angular speed
/// times the block's radius, beyond 1e-3 of the fastest), fastest first, at most eight.
fn describe_motion(motion: &[BlockMotion], blocks: &[BlockData]) -> String {
    let mut speeds: Vec<(usize, Real)> = motion
        .iter()
        .zip(blocks)
        .enumerate()
        .map(|(k, (m, b))| (k, m.velocity.length() + m.angular_velocity.length() * b.radius))
        .collect();
    let fastest = speeds.iter().map(|s| s.1).fold(0.0, Real::max);
    if !(fastest > 0.0 && fastest.is_finite()) {
        return "no block moves (the solver's certificate is empty)".into();
    }
    speeds.retain(|s| s.1 > 1e-3 * fastest);
    speeds.sort_by(|a, b| b.1.total_cmp(&a.1).then(a.0.cmp(&b.0)));
    let count = speeds.len();
    let mut text = speeds
        .iter()
        .take(8)
        .map(|&(k, _)| format!("{} ({:?})", BlockId(k as u32), blocks[k].name))
        .collect::<Vec<_>>()
        .join(", ");
    if count > 8 {
        text.push_str(&format!(" and {} more", count - 8));
    }
    format!(
        "block{} {text} move{}",
        if count == 1 { "" } else { "s" },
        if count == 1 { "s" } else { "" }
    )
}
