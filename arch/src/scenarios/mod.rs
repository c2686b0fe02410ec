//! Ready-made reproductions of published tests, shared by the examples and the integration
//! tests: the quasi-static load test and the drop-weight impact tests of the reference arch
//! (Pulatsu, Gonen & Lourenço 2021), and the limit analysis of its static test.

pub mod arch_impact;
pub mod arch_limit;
pub mod arch_static;
pub mod impact_case;
pub mod impact_summary;

use voussoir::build::arch::{Arch, ArchSpec};
use voussoir::contact::DisplacementMode;
use voussoir::error::Result;
use voussoir::geometry::{ContactParameters, NodeRule, SubContactDensity};
use voussoir::integrate::TimeStep;
use voussoir::law::{CoulombSlip, MaterialId};
use voussoir::math::{Real, Vector};
use voussoir::model::{Model, ModelParameters};

/// Material of the stones.
pub const STONE: MaterialId = MaterialId(0);
/// Material of the steel loading parts (plate, seat, impactor).
pub const STEEL: MaterialId = MaterialId(1);
/// Material of the fixed frame that guides the impactor of the impact tests.
pub const FRAME: MaterialId = MaterialId(2);

/// The joint parameters shared by the scenarios.
#[derive(Debug, Clone, Copy)]
pub(crate) struct ArchJoints {
    pub width: Real,
    pub per_edge: u16,
    pub node_rule: NodeRule,
    pub kn: Real,
    pub ks: Real,
    pub friction_deg: Real,
    pub mode: DisplacementMode,
    pub time_step: TimeStep,
}

/// The reference arch in a model with gravity along −y and the dry Coulomb joint between every
/// pair of stone and steel (the paper gives one joint law); blocks in [`Arch::blocks`] order.
pub(crate) fn reference_arch_model(j: ArchJoints) -> Result<(Model, Arch)> {
    let arch = Arch::new(&ArchSpec::reference(j.width))?;
    let params = ModelParameters {
        gravity: Vector::new(0.0, -9.81, 0.0),
        contact: ContactParameters {
            density: SubContactDensity::PerEdge(j.per_edge),
            node_rule: j.node_rule,
            ..ContactParameters::default()
        },
        mode: j.mode,
        time_step: j.time_step,
        ..ModelParameters::default()
    };
    let mut model: Model = Model::new(params)?;
    let law = CoulombSlip::dry(j.kn, j.ks, j.friction_deg)?;
    for (a, b) in [(STONE, STONE), (STONE, STEEL), (STEEL, STEEL)] {
        model.set_joint_law(a, b, law)?;
    }
    for b in &arch.blocks {
        model.add_block(b.clone())?;
    }
    Ok((model, arch))
}

pub(crate) use voussoir::error::{in_range, non_negative, positive};

/// The answer of a run's observer: stop once `done`.
pub(crate) fn stop_when(done: bool) -> std::ops::ControlFlow<()> {
    if done {
        std::ops::ControlFlow::Break(())
    } else {
        std::ops::ControlFlow::Continue(())
    }
}
