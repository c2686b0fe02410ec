//! Reading a model: blocks, laws, contacts (as views), counters, the step, energies, reactions
//! and contact wrenches, timings and damping. None of these changes the model's state.

use rayon::prelude::*;

use super::{block_pass, Energies, Model, ModelParameters, Timings};
use crate::block::{Block, BlockId, RigidBlock, Wrench};
use crate::contact::{ContactView, DisplacementMode, SmallReference};
use crate::error::{Error, Result};
use crate::integrate::{CriticalStep, Damping};
use crate::law::{ConstitutiveLaw, LawTable};
use crate::math::Real;

impl<L: ConstitutiveLaw> Model<L> {
    /// The global parameters.
    pub fn parameters(&self) -> &ModelParameters {
        &self.state.params
    }

    /// A block by id.
    ///
    /// # Errors
    /// [`Error::UnknownBlock`].
    pub fn block(&self, id: BlockId) -> Result<&RigidBlock> {
        self.state.blocks.get(id.index()).ok_or(Error::UnknownBlock {
            id,
            count: self.state.blocks.len(),
        })
    }

    /// All blocks, indexed by [`BlockId::index`].
    pub fn blocks(&self) -> &[RigidBlock] {
        &self.state.blocks
    }

    /// The joint laws.
    pub fn law_table(&self) -> &LawTable<L> {
        &self.state.laws
    }

    /// The current contacts, each with its sub-contacts.
    pub fn contacts(&self) -> impl ExactSizeIterator<Item = ContactView<'_, L::State>> + '_ {
        (0..self.state.contacts.pairs.len()).map(move |k| self.view(k))
    }

    /// The contact between two blocks, if any.
    pub fn contact_between(&self, a: BlockId, b: BlockId) -> Option<ContactView<'_, L::State>> {
        let key = (a.0.min(b.0), a.0.max(b.0));
        self.state
            .contacts
            .pairs
            .binary_search_by_key(&key, |p| (p.a, p.b))
            .ok()
            .map(|k| self.view(k))
    }

    /// The **contact polygon** of `contact` (world, m): for a face–face joint, the part of the
    /// other face within the contact tolerance of the host face's plane, projected on it and
    /// clipped by the host face (the area its sub-contacts can carry; `docs/theory.md` §2.2);
    /// for a node contact (vertex, edge, tilted faces), the 2-D hull of its sub-contacts in the
    /// plane normal to the contact normal — a polygon, a segment or a point. Corners in order
    /// around the polygon. The limit analysis takes its joints from these polygons.
    ///
    /// ```
    /// use voussoir::prelude::*;
    ///
    /// let mut model: Model = Model::new(ModelParameters::default())?;
    /// model.set_joint_law(MaterialId(0), MaterialId(0), CoulombSlip::dry(1e9, 4e8, 30.0)?)?;
    /// let base = Vector::new(-1.0, -1.0, -0.2);
    /// model.add_block(RigidBlock::cuboid("base", base, Vector::new(1.0, 1.0, 0.0), 2500.0)?.with_fixity(Fixity::FIXED))?;
    /// model.add_block(RigidBlock::cuboid("block", Vector::ZERO, Vector::new(0.4, 0.3, 0.2), 2500.0)?)?;
    /// model.step()?;
    /// let contact = model.contacts().next().unwrap();
    /// let polygon = model.contact_polygon(&contact);
    /// assert_eq!(polygon.len(), 4); // the block's 0.4 × 0.3 m face
    /// # Ok::<(), voussoir::Error>(())
    /// ```
    pub fn contact_polygon(&self, contact: &ContactView<'_, L::State>) -> Vec<crate::math::Vector> {
        let (a, b) = contact.blocks();
        let (ba, bb) = (&self.state.blocks[a.index()], &self.state.blocks[b.index()]);
        let points: Vec<crate::math::Vector> = contact.points().collect();
        crate::geometry::contact_polygon(
            crate::geometry::BlockGeometry {
                shape: ba.shape(),
                pose: &ba.state().pose,
            },
            crate::geometry::BlockGeometry {
                shape: bb.shape(),
                pose: &bb.state().pose,
            },
            contact.kind(),
            contact.host_is_a(),
            contact.normal(),
            &points,
            self.state.params.contact.tolerance,
        )
    }

    pub(super) fn view(&self, k: usize) -> ContactView<'_, L::State> {
        let p = &self.state.contacts.pairs[k];
        let (sa, sb) = (
            &self.state.blocks[p.a as usize].state,
            &self.state.blocks[p.b as usize].state,
        );
        let nodes = matches!(p.kind, crate::geometry::ContactKind::Nodes).then(|| crate::contact::NodeGeometry {
            states: [sa, sb],
            rotations: [
                crate::math::Matrix::from_quat(sa.pose.rotation),
                crate::math::Matrix::from_quat(sb.pose.rotation),
            ],
            shapes: [
                self.state.blocks[p.a as usize].shape(),
                self.state.blocks[p.b as usize].shape(),
            ],
        });
        let law = &self.state.laws.laws()[p.law as usize];
        let exact = matches!(p.kind, crate::geometry::ContactKind::FaceFace { .. })
            && self.state.params.mode == DisplacementMode::Large
            && law.elastic_regime().is_some_and(|r| r.normal_stiffness > 0.0);
        let cells = exact.then(|| crate::contact::CellGeometry {
            law: law as &dyn crate::contact::TensionFree<L::State>,
            coefficients: crate::contact::face_gap_coefficients(p, &sa.pose, &sb.pose),
        });
        ContactView::new(
            p,
            &self.state.contacts.subs[p.range()],
            (
                &self.state.contacts.references[k],
                if self.state.contacts.dashpots_kept {
                    &self.state.contacts.sub_dashpots[p.range()]
                } else {
                    &[]
                },
            ),
            p.frame(
                SmallReference::of(&self.state.contacts.small_refs, k, self.state.params.mode),
                &sa.pose,
                &sb.pose,
            ),
            self.state.contacts.wrenches[k],
            (nodes, cells),
        )
    }

    /// How many joints are stepped as a whole after the last step: face-face joints closed all
    /// over whose sub-contacts all stick, open all over with their sub-contacts unloaded, or
    /// open in part (a hinge) with the sub-contacts closed over their cells sticking, which are
    /// stepped as a whole with its open ones at one end, and the others one by one ([`Model::set_joint_stepping`],
    /// `docs/theory.md` §3.1).
    pub fn whole_joint_count(&self) -> usize {
        self.state.contacts.pairs.iter().filter(|p| p.joint.active).count()
    }

    /// Total number of sub-contacts.
    pub fn subcontact_count(&self) -> usize {
        self.state.contacts.pairs.iter().map(|p| p.count as usize).sum()
    }

    /// How closed, sticking joints are stepped ([`Model::set_joint_stepping`]).
    pub fn joint_stepping(&self) -> super::JointStepping {
        self.state.joint_stepping
    }

    /// Steps taken.
    pub fn step_count(&self) -> u64 {
        self.state.clock.step
    }

    /// Simulated time (s).
    pub fn time(&self) -> Real {
        self.state.clock.time
    }

    /// The time step in use (s); zero before the first step.
    pub fn dt(&self) -> Real {
        self.state.clock.dt
    }

    /// The duration of the last step (s): [`dt`](Self::dt), or shorter while the step was refined
    /// around an impact (see [`ModelParameters::impact_step`]); `dt` before the first step.
    pub fn last_step(&self) -> Real {
        if self.state.clock.drift > 0.0 {
            self.state.clock.drift
        } else {
            self.state.clock.dt
        }
    }

    /// The critical time step and the block that limits it (after the first step).
    pub fn critical_step(&self) -> Option<CriticalStep> {
        self.state.clock.critical
    }

    /// Energies since the start.
    ///
    /// The elastic energy stored in the joints is not needed to step, so it is summed over the
    /// sub-contacts here, when asked for: a call costs about one pass over the sub-contacts.
    pub fn energies(&self) -> Energies {
        let mut e = self.state.energy;
        e.elastic = self.elastic_energy();
        e
    }

    /// Elastic energy in the joint springs (J): per contact in sub-contact order, contacts in
    /// fixed chunks, chunks in order, so the sum does not depend on the thread count.
    pub(super) fn elastic_energy(&self) -> Real {
        let laws = self.state.laws.laws();
        let chunk_sums: Vec<Real> = self
            .state
            .contacts
            .pairs
            .par_chunks(1024)
            .map(|chunk| {
                chunk
                    .iter()
                    .map(|p| {
                        let law = &laws[p.law as usize];
                        self.state.contacts.subs[p.range()]
                            .iter()
                            .enumerate()
                            .map(|(i, s)| law.elastic_energy(s.area, &p.joint.live(i, s).0, &s.state))
                            .sum::<Real>()
                            + p.spread_energy
                    })
                    .sum::<Real>()
            })
            .collect();
        chunk_sums.iter().sum()
    }

    /// The accumulated energy terms without the elastic and friction terms (which
    /// [`Model::energies`] fills in).
    pub(crate) fn energy_accumulators(&self) -> &Energies {
        &self.state.energy
    }

    /// Number of contact detections run so far.
    pub fn detection_count(&self) -> u64 {
        self.state.found.detections
    }

    /// Number of block pairs the narrow phase tested since the model was built or restored: at
    /// a detection, only the pairs with a block that moved beyond the re-detection trigger whose
    /// relative pose changed beyond it since their last test (`docs/theory.md` §2.3). A
    /// statistic, like [`Model::timings`]; a checkpoint does not store it.
    pub fn pair_tests(&self) -> u64 {
        self.pipeline.detection.tests
    }

    /// Unbalanced-force ratio of the last step: the largest out-of-balance force on a free block
    /// divided by the mean contact force (infinite before the first step or without contacts).
    pub fn unbalanced_force_ratio(&self) -> Real {
        self.state.unbalanced_ratio
    }

    /// Force and moment the supports or prescribed velocities applied to a block in the last step.
    ///
    /// # Errors
    /// [`Error::UnknownBlock`].
    pub fn reaction(&self, id: BlockId) -> Result<Wrench> {
        self.block(id)?;
        Ok(self.state.records[id.index()].reaction)
    }

    /// Total contact force and moment (about its centroid) on a block in the last step.
    ///
    /// # Errors
    /// [`Error::UnknownBlock`].
    pub fn contact_wrench(&self, id: BlockId) -> Result<Wrench> {
        self.block(id)?;
        Ok(self.contact_wrench_of(id.index()))
    }

    pub(super) fn contact_wrench_of(&self, i: usize) -> Wrench {
        // Before the first detection (no step yet, or a block added since), the block has no
        // contacts the model knows of.
        let offsets = &self.pipeline.block_offsets;
        let (Some(&start), Some(&end)) = (offsets.get(i), offsets.get(i + 1)) else {
            return Wrench::default();
        };
        let entries = &self.pipeline.block_contacts[start as usize..end as usize];
        block_pass::add_contact_wrenches(Wrench::default(), entries, &self.state.contacts.wrenches)
    }

    /// Time spent per stage (wall clock).
    pub fn timings(&self) -> &Timings {
        &self.pipeline.timings
    }

    /// Restarts the stage timers.
    pub fn reset_timings(&mut self) {
        self.pipeline.timings = Timings::default();
    }

    /// The integrator's damping model.
    pub fn damping(&self) -> Damping {
        self.state.integrator.damping()
    }
}
