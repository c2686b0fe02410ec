//! Post-processing of a model's state: joint states and collapse mechanisms, and (feature
//! `limit`) the limit analysis of the blocks as they stand.

#[cfg(feature = "limit")]
#[cfg_attr(docsrs, doc(cfg(feature = "limit")))]
pub mod limit;
mod mechanism;

pub use mechanism::{classify_joints, Hinge, HingeSide, JointRef, JointState, Mechanism, MechanismCriteria};
