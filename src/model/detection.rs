//! Contact re-detection with history transfer, the block → contact index, and the time step.

use super::Model;
use crate::block::{Block, BlockId};
use crate::constitutive::{ConstitutiveLaw, JointForce, JointStatus};
use crate::contact::{ContactPair, DisplacementMode, SubContact};
use crate::error::{Error, Result};
use crate::geometry::{detect, BlockGeometry, BroadPhase, NarrowPhaseScratch, SubcontactSeed};
use crate::integrate::{critical_time_step, StiffnessBound, TimeStep};
use crate::math::{Real, Vector};

/// Buffers reused from one detection to the next.
#[derive(Debug, Clone)]
pub(crate) struct DetectionScratch<S> {
    pub force_full_detection: bool,
    broad: BroadPhase,
    narrow: NarrowPhaseScratch,
    candidates: Vec<(u32, u32)>,
    seeds: Vec<SubcontactSeed>,
    moved: Vec<bool>,
    pairs: Vec<ContactPair>,
    subs: Vec<SubContact<S>>,
    sub_pair: Vec<u32>,
}

impl<S> Default for DetectionScratch<S> {
    fn default() -> Self {
        Self {
            force_full_detection: true,
            broad: BroadPhase::default(),
            narrow: NarrowPhaseScratch::default(),
            candidates: Vec::new(),
            seeds: Vec::new(),
            moved: Vec::new(),
            pairs: Vec::new(),
            subs: Vec::new(),
            sub_pair: Vec::new(),
        }
    }
}

impl<L: ConstitutiveLaw> Model<L> {
    /// Largest motion of a material point of any block since its last detection, compared
    /// with the trigger distance.
    pub(super) fn needs_detection(&self) -> bool {
        if self.scratch.force_full_detection {
            return true;
        }
        let trigger = self.params.contact.redetect_fraction * self.params.contact.tolerance;
        self.blocks
            .iter()
            .zip(&self.ref_poses)
            .any(|(b, r)| movement(b, r) > trigger)
    }

    /// Re-detects contacts: pairs where a block moved beyond the trigger get a fresh narrow phase
    /// with sub-contact history carried over by key; other pairs are kept as they are.
    pub(super) fn detect(&mut self) -> Result<()> {
        let params = self.params.contact;
        let full = self.scratch.force_full_detection || self.params.mode == DisplacementMode::Small;
        let trigger = params.redetect_fraction * params.tolerance;
        let sc = &mut self.scratch;
        sc.moved.clear();
        sc.moved.extend(
            self.blocks
                .iter()
                .zip(&self.ref_poses)
                .map(|(b, r)| full || movement(b, r) > trigger),
        );
        sc.broad.pairs(
            self.blocks.iter().map(|b| (b.shape(), &b.state.pose)),
            params.tolerance,
            &mut sc.candidates,
        );
        sc.pairs.clear();
        sc.subs.clear();
        sc.sub_pair.clear();
        for &(i, j) in &sc.candidates {
            let old = self.pairs.binary_search_by_key(&(i, j), |p| (p.a, p.b)).ok();
            let (bi, bj) = (&self.blocks[i as usize], &self.blocks[j as usize]);
            if bi.fixity().is_fixed() && bj.fixity().is_fixed() {
                continue;
            }
            if !sc.moved[i as usize] && !sc.moved[j as usize] {
                if let Some(k) = old {
                    let p = &self.pairs[k];
                    let mut kept = p.clone();
                    kept.first = sc.subs.len() as u32;
                    sc.subs.extend_from_slice(&self.subs[p.range()]);
                    sc.sub_pair
                        .extend(std::iter::repeat_n(sc.pairs.len() as u32, p.count as usize));
                    sc.pairs.push(kept);
                }
                continue;
            }
            sc.seeds.clear();
            let found = detect(
                BlockGeometry {
                    shape: bi.shape(),
                    pose: &bi.state.pose,
                },
                BlockGeometry {
                    shape: bj.shape(),
                    pose: &bj.state.pose,
                },
                &params,
                &mut sc.narrow,
                &mut sc.seeds,
            );
            let Some(dc) = found else { continue };
            if sc.seeds.is_empty() {
                continue;
            }
            let law = self
                .joints
                .index_of(bi.material(), bj.material())
                .ok_or(Error::MissingJointLaw {
                    a: bi.material(),
                    b: bj.material(),
                    block_a: BlockId(i),
                    block_b: BlockId(j),
                })?;
            let host = if dc.host_is_a { bi } else { bj };
            let old_subs = old.map(|k| {
                let p = &self.pairs[k];
                (p.kind == dc.kind && p.host_is_a == dc.host_is_a).then(|| &self.subs[p.range()])
            });
            let old_subs = old_subs.flatten().unwrap_or(&[]);
            let pair_index = sc.pairs.len() as u32;
            let first = sc.subs.len() as u32;
            for seed in &sc.seeds {
                let point = host.state.pose.transform_point(seed.anchor);
                let mut sub = SubContact {
                    key: seed.key,
                    anchor: seed.anchor,
                    area: seed.area,
                    gap: seed.gap,
                    force: JointForce::default(),
                    status: JointStatus::Open,
                    slip: 0.0,
                    state: L::State::default(),
                    point,
                    spring: Vector::ZERO,
                    total: Vector::ZERO,
                    work: 0.0,
                    dashpot_work: 0.0,
                    elastic: 0.0,
                };
                if let Ok(k) = old_subs.binary_search_by_key(&seed.key, |s| s.key) {
                    let o = &old_subs[k];
                    sub.force = o.force;
                    sub.status = o.status;
                    sub.slip = o.slip;
                    sub.state = o.state.clone();
                    sub.spring = o.spring;
                    sub.total = o.total;
                    sub.elastic = o.elastic;
                }
                sc.subs.push(sub);
                sc.sub_pair.push(pair_index);
            }
            sc.pairs.push(ContactPair {
                a: i,
                b: j,
                kind: dc.kind,
                host_is_a: dc.host_is_a,
                law,
                first,
                count: sc.seeds.len() as u32,
                normal: dc.normal,
                host_normal: dc.normal,
                other_normal: -dc.normal,
                other_offset: 0.0,
                ref_a: bi.state.pose.translation,
                ref_b: bj.state.pose.translation,
                force: Vector::ZERO,
                moment_a: Vector::ZERO,
                moment_b: Vector::ZERO,
                normal_force: 0.0,
                work: 0.0,
                dashpot_work: 0.0,
                elastic: 0.0,
            });
        }
        std::mem::swap(&mut self.pairs, &mut sc.pairs);
        std::mem::swap(&mut self.subs, &mut sc.subs);
        std::mem::swap(&mut self.sub_pair, &mut sc.sub_pair);
        for (i, moved) in sc.moved.iter().enumerate() {
            if *moved {
                self.ref_poses[i] = self.blocks[i].state.pose;
            }
        }
        sc.force_full_detection = false;
        self.detections += 1;
        self.rebuild_block_index();
        self.refresh_time_step()
    }

    pub(super) fn rebuild_block_index(&mut self) {
        let n = self.blocks.len();
        self.block_offsets.clear();
        self.block_offsets.resize(n + 1, 0);
        for p in &self.pairs {
            self.block_offsets[p.a as usize + 1] += 1;
            self.block_offsets[p.b as usize + 1] += 1;
        }
        for i in 0..n {
            self.block_offsets[i + 1] += self.block_offsets[i];
        }
        self.block_contacts.clear();
        self.block_contacts.resize(self.block_offsets[n] as usize, 0);
        let mut fill: Vec<u32> = self.block_offsets[..n].to_vec();
        for (c, p) in self.pairs.iter().enumerate() {
            for k in [p.a as usize, p.b as usize] {
                self.block_contacts[fill[k] as usize] = c as u32;
                fill[k] += 1;
            }
        }
    }

    /// Recomputes the per-block stiffness bounds without touching `dt` (after a restart).
    pub(super) fn refresh_bounds_only(&mut self) {
        let dt = self.dt;
        let critical = self.critical;
        let _ = self.refresh_time_step();
        self.dt = dt;
        self.critical = critical;
    }

    /// Re-evaluates the critical step from the current contacts and each block's potential
    /// contact on its largest face, then sets `dt`.
    pub(super) fn refresh_time_step(&mut self) -> Result<()> {
        if self.blocks.is_empty() {
            return Ok(());
        }
        let k_max = self
            .joints
            .laws()
            .iter()
            .map(|l| {
                let k = l.stiffness();
                k.normal + 2.0 * k.shear
            })
            .fold(0.0, Real::max);
        // Compliance of each block at its farthest vertex (0 for blocks that cannot move).
        let compliance: Vec<Real> = self
            .blocks
            .iter()
            .map(|b| {
                if all_constrained(b) {
                    0.0
                } else {
                    let mp = b.mass_properties();
                    let i_min = mp.principal_inertia.min_element();
                    1.0 / mp.mass + b.shape().radius().powi(2) / i_min
                }
            })
            .collect();
        for (i, b) in self.blocks.iter().enumerate() {
            let face = b.shape().faces().iter().map(|f| f.area).fold(0.0, Real::max);
            self.bounds[i] = StiffnessBound {
                omega_squared: 2.0 * k_max * face * compliance[i],
            };
        }
        let mut from_contacts = vec![0.0; self.blocks.len()];
        for p in &self.pairs {
            let k = self.joints.laws()[p.law as usize].stiffness();
            let k = k.normal + 2.0 * k.shear;
            let area: Real = self.subs[p.range()].iter().map(|s| s.area).sum();
            let term = k * area * (compliance[p.a as usize] + compliance[p.b as usize]);
            from_contacts[p.a as usize] += term;
            from_contacts[p.b as usize] += term;
        }
        for (i, b) in self.blocks.iter().enumerate() {
            if all_constrained(b) {
                self.bounds[i].omega_squared = 0.0;
            } else {
                self.bounds[i].omega_squared = self.bounds[i].omega_squared.max(from_contacts[i]);
            }
        }
        let b_damp = self.integrator.damping().stiffness_coefficient();
        self.critical = critical_time_step(&self.bounds, b_damp);
        let Some(crit) = self.critical else {
            // No stiffness anywhere: free flight; keep a previous step or a small default.
            if self.dt == 0.0 {
                self.dt = match self.params.time_step {
                    TimeStep::Fixed(dt) => dt,
                    TimeStep::Auto { .. } => 1e-4,
                };
            }
            return Ok(());
        };
        self.dt = match self.params.time_step {
            TimeStep::Auto { safety } => safety * crit.dt,
            TimeStep::Fixed(dt) => {
                if dt > crit.dt {
                    return Err(Error::TimeStepTooLarge {
                        dt,
                        limit: crit.dt,
                        block: crit.block,
                    });
                }
                dt
            }
        };
        Ok(())
    }
}

fn all_constrained(b: &crate::block::RigidBlock) -> bool {
    let f = b.fixity();
    f.translation
        .iter()
        .chain(&f.rotation)
        .all(|d| d.prescribed().is_some())
}

/// Largest displacement of a point of the block since pose `r`: translation plus radius × angle.
fn movement(b: &crate::block::RigidBlock, r: &crate::math::Pose) -> Real {
    let s = &b.state.pose;
    let dq = s.rotation * r.rotation.inverse();
    let angle = 2.0 * dq.xyz().length().atan2(dq.w.abs());
    (s.translation - r.translation).length() + b.shape().radius() * angle
}
