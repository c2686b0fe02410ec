//! Shapes and contact geometry, with no dynamics: convex polyhedra and their mass properties,
//! the broad phase, the common plane, the contact polygon and its sub-contacts.

mod broad_phase;
pub mod clip;
mod inertia;
mod narrow_phase;
mod polyhedron;

pub use broad_phase::BroadPhase;
pub(crate) use narrow_phase::contact_polygon;
pub(crate) use narrow_phase::nodes::{deepest_two, NodeId};
pub(crate) use narrow_phase::spacing;
pub(crate) use narrow_phase::strips::{NodeStrips, Strip, StripLoad};
pub use narrow_phase::{
    detect, BlockGeometry, ContactKind, ContactParameters, DetectedContact, NarrowPhaseScratch, NodeRule,
    PreviousContact, SubContactDensity, SubContactSeed, SubKey, DEFAULT_SUBCONTACTS_PER_EDGE, MAX_SUBCONTACTS_PER_EDGE,
};
pub(crate) use narrow_phase::{face_frame, PARALLEL_ANGLE};
#[allow(deprecated)]
pub use narrow_phase::{SubcontactDensity, SubcontactSeed};
pub use polyhedron::{Face, MassProperties, PlacedPolyhedron, Polyhedron, MAX_HULL_VERTICES};
