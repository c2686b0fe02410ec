//! Mechanism classifier: from the sub-contact states of a set of joints, name the hinges (and on
//! which edge they turn) and the sliding joints.
//!
//! A joint is described by its two blocks and its two edge points, called *intrados* and
//! *extrados* after the arch case (for a wall: the two faces). For each joint:
//!
//! * the **open fraction** is the share of its area whose sub-contacts carry no compression;
//! * the **compression centre** is the force-weighted centroid of the compressed sub-contacts,
//!   located along the joint by `s ∈ [0, 1]` from the intrados (0) to the extrados (1);
//! * it is a **hinge** when the open fraction is at least [`MechanismCriteria::open_fraction`]
//!   and the compression centre lies within [`MechanismCriteria::edge_band`] of an edge; the hinge
//!   turns about that edge;
//! * it is **sliding** when the area-weighted mean accumulated slip of its sub-contacts exceeds
//!   [`MechanismCriteria::slip`].

#[cfg(feature = "serde")]
use serde::{Deserialize, Serialize};

use crate::block::{Block, BlockId, RigidBlock};
use crate::contact::Contact;
use crate::law::ConstitutiveLaw;
use crate::math::{Real, Vector};
use crate::model::Model;

/// A joint to classify.
#[derive(Debug, Clone, Copy, PartialEq)]
#[cfg_attr(feature = "serde", derive(Serialize, Deserialize))]
pub struct JointRef {
    /// A label (for an arch: the joint number).
    pub index: usize,
    /// The two blocks.
    pub blocks: (BlockId, BlockId),
    /// Intrados edge point (m, world, at the reference pose).
    pub intrados: Vector,
    /// Extrados edge point (m).
    pub extrados: Vector,
}

/// Thresholds of the classifier, with documented defaults.
#[derive(Debug, Clone, Copy, PartialEq)]
#[cfg_attr(feature = "serde", derive(Serialize, Deserialize))]
pub struct MechanismCriteria {
    /// Minimum open fraction of a hinge. Default 0.5.
    pub open_fraction: Real,
    /// The compression centre must lie within this fraction of the joint depth from an edge.
    /// Default 0.25.
    pub edge_band: Real,
    /// Mean accumulated slip (m) above which a joint is sliding. Default 0.5 mm.
    pub slip: Real,
}

impl Default for MechanismCriteria {
    fn default() -> Self {
        Self {
            open_fraction: 0.5,
            edge_band: 0.25,
            slip: 5e-4,
        }
    }
}

/// Which edge a hinge turns about.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
#[cfg_attr(feature = "serde", derive(Serialize, Deserialize))]
#[cfg_attr(feature = "serde", serde(rename_all = "lowercase"))]
pub enum HingeSide {
    /// The intrados edge (the joint opens at the extrados).
    Intrados,
    /// The extrados edge (the joint opens at the intrados).
    Extrados,
}

/// A hinge at a joint.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
#[cfg_attr(feature = "serde", derive(Serialize, Deserialize))]
pub struct Hinge {
    /// Joint label.
    pub joint: usize,
    /// Edge it turns about.
    pub side: HingeSide,
}

/// Measured state of one joint.
#[derive(Debug, Clone, Copy, PartialEq)]
#[cfg_attr(feature = "serde", derive(Serialize, Deserialize))]
pub struct JointState {
    /// Joint label.
    pub joint: usize,
    /// Area share without compression (1 when the blocks are not in contact).
    pub open_fraction: Real,
    /// Position of the compression centre from the intrados (0) to the extrados (1); NaN when
    /// nothing is compressed.
    pub compression_position: Real,
    /// Area-weighted mean accumulated slip (m).
    pub slip: Real,
    /// Total normal force (N).
    pub normal_force: Real,
    /// Hinge, if any.
    pub hinge: Option<HingeSide>,
    /// Whether the joint is sliding.
    pub sliding: bool,
}

/// Hinges and sliding joints.
#[derive(Debug, Clone, Default, PartialEq, Eq)]
#[cfg_attr(feature = "serde", derive(Serialize, Deserialize))]
pub struct Mechanism {
    /// Hinges, in joint order.
    pub hinges: Vec<Hinge>,
    /// Labels of the sliding joints.
    pub sliding_joints: Vec<usize>,
}

impl Mechanism {
    /// A short description such as `"hinges 2e 5i 9i 13e; sliding 4"` (`i` intrados, `e` extrados).
    pub fn describe(&self) -> String {
        let h: Vec<String> = self
            .hinges
            .iter()
            .map(|h| format!("{}{}", h.joint, if h.side == HingeSide::Intrados { "i" } else { "e" }))
            .collect();
        let s: Vec<String> = self.sliding_joints.iter().map(|j| j.to_string()).collect();
        let mut out = if h.is_empty() {
            "no hinges".to_owned()
        } else {
            format!("hinges {}", h.join(" "))
        };
        if !s.is_empty() {
            out.push_str(&format!("; sliding {}", s.join(" ")));
        }
        out
    }
}

/// Measures and classifies the given joints.
pub fn classify_joints<L: ConstitutiveLaw>(
    model: &Model<L>,
    joints: &[JointRef],
    criteria: &MechanismCriteria,
) -> (Vec<JointState>, Mechanism) {
    let mut states = Vec::with_capacity(joints.len());
    let mut mechanism = Mechanism::default();
    for j in joints {
        let contact = model.contact_between(j.blocks.0, j.blocks.1);
        let state = joint_state(contact.as_ref(), &model.blocks()[j.blocks.0.index()], j, criteria);
        if let Some(side) = state.hinge {
            mechanism.hinges.push(Hinge { joint: j.index, side });
        }
        if state.sliding {
            mechanism.sliding_joints.push(j.index);
        }
        states.push(state);
    }
    (states, mechanism)
}

/// Measures one joint, read through the law-free [`Contact`] interface (`None`: no contact),
/// with the edge points carried by `block`, the joint's first block.
fn joint_state(contact: Option<&impl Contact>, block: &RigidBlock, j: &JointRef, c: &MechanismCriteria) -> JointState {
    let Some(contact) = contact else {
        return JointState {
            joint: j.index,
            open_fraction: 1.0,
            compression_position: Real::NAN,
            slip: 0.0,
            normal_force: 0.0,
            hinge: None,
            sliding: false,
        };
    };
    // Edge points move with the first block.
    let current = |p: Vector| block.world_point(block.initial_pose().inverse_transform_point(p));
    let (i, e) = (current(j.intrados), current(j.extrados));
    let depth = e - i;
    let (mut area, mut open, mut force, mut moment, mut slip) = (0.0, 0.0, 0.0, Vector::ZERO, 0.0);
    for s in (0..contact.subcontact_count()).map(|k| contact.subcontact(k)) {
        area += s.area;
        slip += s.slip * s.area;
        if s.normal_force > 0.0 {
            force += s.normal_force;
            moment += s.normal_force_point * s.normal_force;
        } else {
            open += s.area;
        }
    }
    let open_fraction = if area > 0.0 { open / area } else { 1.0 };
    let position = if force > 0.0 {
        (moment / force - i).dot(depth) / depth.length_squared()
    } else {
        Real::NAN
    };
    let hinge = if open_fraction >= c.open_fraction {
        if position <= c.edge_band {
            Some(HingeSide::Intrados)
        } else if position >= 1.0 - c.edge_band {
            Some(HingeSide::Extrados)
        } else {
            None
        }
    } else {
        None
    };
    let slip = if area > 0.0 { slip / area } else { 0.0 };
    JointState {
        joint: j.index,
        open_fraction,
        compression_position: position,
        slip,
        normal_force: force,
        hinge,
        sliding: slip > c.slip,
    }
}
