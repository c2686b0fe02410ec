//! Post-processing of a model's state: joint states and collapse mechanisms.

mod mechanism;

pub use mechanism::{classify_joints, Hinge, HingeSide, JointRef, JointState, Mechanism, MechanismCriteria};
