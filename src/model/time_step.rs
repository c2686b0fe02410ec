//! The model's time step: the contacts' stiffness handed to the integrator's stability limit
//! ([`crate::integrate::Integrator::critical_step`]), then the step the parameters ask for.

use super::pipeline::Pipeline;
use super::ModelState;
use crate::error::{Error, Result};
use crate::integrate::{AreaMoments, ContactStiffness, TimeStep};
use crate::law::ConstitutiveLaw;
use crate::math::{Real, Vector};

impl<L: ConstitutiveLaw> ModelState<L> {
    /// Re-evaluates the critical step from the current contacts and each block's potential
    /// contact on its largest face, then sets `dt`.
    pub(super) fn refresh_time_step(&mut self, pipeline: &mut Pipeline<L::State>) -> Result<()> {
        if self.blocks.is_empty() {
            return Ok(());
        }
        let laws = self.laws.laws();
        let mut contacts = Vec::with_capacity(self.pairs.len());
        for (p, reference) in self.pairs.iter().zip(self.references.iter_mut()) {
            let subs = &self.subs[p.range()];
            reference.bound_area = reference.area;
            // Area moments of the sub-contact points about the first one (for digits).
            let (sa, sb) = (&self.blocks[p.a as usize].state, &self.blocks[p.b as usize].state);
            let frame = p.frame(reference, &sa.pose, &sb.pose, self.params.mode);
            let origin = subs
                .first()
                .map_or(Vector::ZERO, |s| frame.transform_point(p.anchor(s)));
            let mut moments = AreaMoments::default();
            for s in subs {
                moments.add(frame.transform_point(p.anchor(s)) - origin, s.area);
            }
            contacts.push(ContactStiffness {
                a: p.a as usize,
                b: p.b as usize,
                normal: p.normal,
                stiffness: laws[p.law as usize].stiffness(),
                origin,
                moments,
            });
        }
        let k_max = laws
            .iter()
            .map(|l| {
                let k = l.stiffness();
                k.normal + 2.0 * k.shear
            })
            .fold(0.0, Real::max);
        crate::integrate::block_bounds(&self.blocks, &contacts, k_max, &mut pipeline.bounds);
        self.critical = self.integrator.critical_step(&pipeline.bounds);
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
