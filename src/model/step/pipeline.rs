//! The step's pipeline: what each step computes afresh from the model's state, and the buffers
//! it reuses so that a step does not allocate. Nothing here is state: a checkpoint does not
//! store it, and a restored model rebuilds it.

use super::contact_pass::PairSums;
use crate::block::{BlockMotion, Wrench};
use crate::integrate::StiffnessBound;
use crate::math::Real;
use crate::model::{BlockSums, Timings};

/// Scratch of the step's stages. `D` is the detection's scratch
/// (`detection::DetectionScratch`), a parameter so that the pipeline, which the detection stage
/// takes, does not depend on that stage (`crate::model::Pipeline` names the model's pipeline).
#[derive(Debug, Clone)]
pub(in crate::model) struct PipelineOf<D> {
    /// Block → contact index (CSR with `block_offsets`): `2 × contact + side`, side 1 when the
    /// block is the contact's `b`. Rebuilt at detection and on checkpoint load.
    pub block_contacts: Vec<u32>,
    pub block_offsets: Vec<u32>,
    /// Each block's total force and moment in the step (gathered by the block pass).
    pub forces: Vec<Wrench>,
    /// Per-chunk sums of the contact pass and of the block pass.
    pub pair_sums: Vec<PairSums>,
    pub block_sums: Vec<BlockSums>,
    /// The blocks' motions at the start of the step, as the contact pass reads them (see
    /// `prepare_blocks`).
    pub motions: Vec<BlockMotion>,
    /// The blocks' squared frequency bounds of the last step evaluation (critical step and
    /// impact probe).
    pub bounds: Vec<StiffnessBound>,
    /// The blocks whose bounds a partial re-evaluation takes, and their new bounds.
    pub refresh_blocks: Vec<u32>,
    pub refresh_bounds: Vec<StiffnessBound>,
    /// Detection's buffers, and what the block pass prepared for the next step.
    pub detection: D,
    /// The largest speed of a point of a block at the end of the last step
    /// ([`super::block_pass::speed_bound`], m/s), for the next step's length; `None` after a setter
    /// touched a block or a load: the next step takes it in a pass of its own.
    pub max_speed: Option<Real>,
    /// Wall-clock time per stage.
    pub timings: Timings,
    /// Asked at a long step's sequential points whether to stop ([`crate::Model::set_interrupt_check`]).
    pub interrupt: Option<crate::model::InterruptCheck>,
    /// When a step last asked [`Self::interrupt`] before it began (`None`: never).
    pub interrupt_asked: Option<std::time::Instant>,
}

/// How often a run of short steps asks the interrupt check, at most: a step asks it before it
/// begins when this much wall-clock time has passed since the last ask (an ask costs a front
/// end's signal check; a clock reading costs tens of nanoseconds).
pub const INTERRUPT_INTERVAL: std::time::Duration = std::time::Duration::from_millis(20);

impl<D> PipelineOf<D> {
    /// Whether the interrupt check, asked now if [`INTERRUPT_INTERVAL`] has passed since it was
    /// last asked before a step, says to stop.
    pub fn interrupt_due(&mut self) -> bool {
        let Some(check) = &self.interrupt else {
            return false;
        };
        let now = std::time::Instant::now();
        if self
            .interrupt_asked
            .is_some_and(|t| now.duration_since(t) < INTERRUPT_INTERVAL)
        {
            return false;
        }
        self.interrupt_asked = Some(now);
        check.stop()
    }
}

impl<D: Default> Default for PipelineOf<D> {
    fn default() -> Self {
        Self {
            block_contacts: Vec::new(),
            block_offsets: vec![0],
            forces: Vec::new(),
            pair_sums: Vec::new(),
            block_sums: Vec::new(),
            motions: Vec::new(),
            bounds: Vec::new(),
            refresh_blocks: Vec::new(),
            refresh_bounds: Vec::new(),
            detection: D::default(),
            max_speed: None,
            timings: Timings::default(),
            interrupt: None,
            interrupt_asked: None,
        }
    }
}
