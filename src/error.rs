//! Typed errors: every bad input names what is wrong, where, and the offending value.

use crate::ids::{BlockId, MaterialId};
use crate::math::Real;

/// Result type of fallible voussoir operations.
pub type Result<T, E = Error> = std::result::Result<T, E>;

/// Everything that can go wrong in voussoir.
///
/// Input errors name the parameter, block or material concerned and the value that was rejected;
/// run-time errors name the step and the block.
#[derive(Debug, Clone, PartialEq, thiserror::Error)]
#[non_exhaustive]
pub enum Error {
    /// A scalar parameter is out of its admissible range.
    #[error("invalid parameter `{name}` = {value}: {expected}")]
    InvalidParameter {
        /// Parameter name, e.g. `"normal_stiffness"`.
        name: String,
        /// The rejected value.
        value: Real,
        /// What was expected, e.g. `"must be positive and finite"`.
        expected: &'static str,
    },
    /// An input vector or point holds a NaN or an infinite component.
    #[error("non-finite input in {what}")]
    NonFinite {
        /// Which input, e.g. `"vertex 3 of block \"voussoir 5\""`.
        what: String,
    },
    /// A vertex set cannot make a solid (too few points, coplanar, collinear, duplicated).
    #[error("block {block:?}: degenerate geometry: {reason}")]
    DegenerateGeometry {
        /// Name of the block being built.
        block: String,
        /// What is wrong.
        reason: String,
    },
    /// Explicit faces do not describe a convex polyhedron.
    #[error("block {block:?}: not convex: {reason}")]
    NonConvex {
        /// Name of the block being built.
        block: String,
        /// Which face or vertex violates convexity.
        reason: String,
    },
    /// A block's volume is zero, negative (for example inward-facing faces) or negligible: at
    /// most `1e-12` of the volume of its axis-aligned bounding box, the scale of the round-off
    /// in the volume. The threshold is relative, so a large block is never refused for its size.
    #[error(
        "block {block:?}: volume {volume} m^3 is not above 1e-12 of its bounding box's volume \
         {bounding_box} m^3 (the round-off scale): the vertices are flat or nearly so"
    )]
    NonPositiveVolume {
        /// Name of the block being built.
        block: String,
        /// The computed volume.
        volume: Real,
        /// Volume of the block's axis-aligned bounding box (product of its extents, m³).
        bounding_box: Real,
    },
    /// A name that cannot be used where it was given, e.g. a series name that is not a
    /// portable file name.
    #[error("invalid {what} {name:?}: {reason}")]
    InvalidName {
        /// What the name is for, e.g. `"series name"`.
        what: &'static str,
        /// The rejected name.
        name: String,
        /// Why it is rejected, e.g. `"contains the path separator '/'"`.
        reason: String,
    },
    /// A block shape with more vertices than [`crate::geometry::MAX_HULL_VERTICES`]: contact
    /// detection between two blocks costs about the product of their edge counts times their
    /// vertex counts, so a step with such a block would take seconds.
    #[error(
        "block {block:?}: {vertices} vertices on its convex hull, more than the limit {limit}: \
         contact detection would take seconds per step; simplify the shape"
    )]
    TooManyVertices {
        /// Name of the block being built.
        block: String,
        /// Number of vertices of its convex hull (or of its explicit faces).
        vertices: usize,
        /// The limit, [`crate::geometry::MAX_HULL_VERTICES`].
        limit: usize,
    },
    /// A block id that the model does not hold.
    #[error("block {id} does not exist (the model has {count} blocks)")]
    UnknownBlock {
        /// The id that was asked for.
        id: BlockId,
        /// Number of blocks in the model.
        count: usize,
    },
    /// Two blocks touch but no joint law was given for their pair of materials.
    #[error("no joint law for materials {a} and {b} (blocks {block_a} and {block_b} touch)")]
    MissingJointLaw {
        /// First material.
        a: MaterialId,
        /// Second material.
        b: MaterialId,
        /// A block of material `a`.
        block_a: BlockId,
        /// A block of material `b`.
        block_b: BlockId,
    },
    /// A user-given time step above the stability limit of central difference.
    #[error("time step {dt} s exceeds the stable limit {limit} s set by block {block}")]
    TimeStepTooLarge {
        /// The requested step.
        dt: Real,
        /// The critical step (with the damping correction).
        limit: Real,
        /// The block with the highest frequency.
        block: BlockId,
    },
    /// The run produced a non-finite or runaway state.
    #[error("run diverged at step {step} (t = {time} s) in block {block}: {reason}")]
    Diverged {
        /// Step number at which the problem was found.
        step: u64,
        /// Simulated time at that step.
        time: Real,
        /// The offending block.
        block: BlockId,
        /// What was found, e.g. `"velocity is NaN"`.
        reason: String,
    },
    /// Reading or writing a file failed.
    #[error("{path}: {message}")]
    Io {
        /// The file or folder.
        path: String,
        /// What went wrong.
        message: String,
    },
    /// A checkpoint or scene file is truncated, corrupt or inconsistent.
    #[error("bad checkpoint or scene at `{path}`: {message}")]
    Checkpoint {
        /// Where in the document (for example `blocks[3].density`).
        path: String,
        /// What is wrong.
        message: String,
    },
    /// A checkpoint's checksum does not match its content: the file was corrupted (a disk or
    /// transfer error) or edited by hand. A checkpoint edited on purpose can be resealed with
    /// [`crate::model::reseal_checkpoint`].
    #[error(
        "checkpoint corrupted or edited: its checksum is {stored} but its content gives {computed} \
         (reseal a checkpoint edited on purpose with voussoir::model::reseal_checkpoint)"
    )]
    CheckpointChecksum {
        /// The checksum stored in the file.
        stored: String,
        /// The checksum of the content as read.
        computed: String,
    },
    /// A checkpoint written by a model of one joint law type, loaded as a model of another.
    #[error("checkpoint written for law type {written}, loading it as law type {loading}")]
    CheckpointLawType {
        /// The law type the file was written for (its serde name, e.g. `CoulombSlip`).
        written: String,
        /// The law type it is being loaded as.
        loading: String,
    },
    /// A checkpointed contact whose law index is not the one the law table gives its pair of
    /// blocks (their interface's own law, else their materials').
    #[error(
        "checkpoint contact {contact} between blocks {a} and {b} uses law {law}, but their interface \
         and materials ({material_a}, {material_b}) map to {expected}"
    )]
    CheckpointContactLaw {
        /// Index of the contact in the file (`contacts[contact]`).
        contact: usize,
        /// First block of the contact.
        a: BlockId,
        /// Second block of the contact.
        b: BlockId,
        /// Material of block `a`.
        material_a: MaterialId,
        /// Material of block `b`.
        material_b: MaterialId,
        /// The law index stored in the file.
        law: u32,
        /// The law index the law table gives the pair (`"no law"` when it has none).
        expected: String,
    },
    /// A checkpointed block whose stored derived data (mass properties, face planes, angular
    /// momentum) disagrees with what its geometry, density and velocities give.
    #[error("checkpoint block {block} ({name:?}): {field} {message}")]
    CheckpointBlock {
        /// The block.
        block: BlockId,
        /// Its name.
        name: String,
        /// The field concerned, e.g. `"mass"` or `"shape.faces[2].normal"`.
        field: String,
        /// What is wrong, with the stored and the expected value.
        message: String,
    },
    /// A monitor history whose columns do not fit together (read from a file, e.g. with a
    /// checkpoint).
    #[error("inconsistent history: {what}")]
    InconsistentHistory {
        /// What does not fit, e.g. `"column 1 (\"top x\") has 29 samples, steps has 30"`.
        what: String,
    },
    /// Two blocks overlap at the start of a run by more than the contact tolerance.
    #[error(
        "blocks {a} and {b} overlap by {depth:.3e} m at the start, more than the contact tolerance {tolerance} m: \
         move them apart"
    )]
    InitialOverlap {
        /// First block.
        a: BlockId,
        /// Second block.
        b: BlockId,
        /// Depth of the overlap (m).
        depth: Real,
        /// The contact tolerance (m).
        tolerance: Real,
    },
    /// A block added to a model that has already stepped overlaps one of its blocks by more than
    /// the contact tolerance (the same layout before the first step is [`Error::InitialOverlap`]).
    #[error(
        "block {block:?} added after the first step overlaps block {other} by {depth:.3e} m, more than the \
         contact tolerance {tolerance} m: move it clear"
    )]
    AddedBlockOverlap {
        /// The name of the block being added (it has no id: it was not added).
        block: String,
        /// The block it overlaps.
        other: BlockId,
        /// Depth of the overlap (m).
        depth: Real,
        /// The contact tolerance (m).
        tolerance: Real,
    },
    /// A block's translation driven by a base motion was to be set free: the motion would put
    /// it back at the next step, and a model saved in between would not load.
    #[error(
        "block {block}: its translation along {axis} is driven by a base motion ({motion}) and cannot \
         be set free while the motion applies: remove the motion first (set_base_motion(block, None))"
    )]
    DrivenAxisFreed {
        /// The block.
        block: BlockId,
        /// The world axis, `"x"`, `"y"` or `"z"`.
        axis: &'static str,
        /// The motion, e.g. `"Acceleration on x, y, started at t = 0 s"`.
        motion: String,
    },
    /// A step moved a block further than the contact tolerance allows: contacts could be
    /// missed (a block passing through another). The step is too long for the block's speed:
    /// lower the speed or the fixed time step, or raise the contact tolerance.
    #[error(
        "step {step} (t = {time} s, dt = {dt} s) moved block {block} by {distance:.4e} m, more than \
         the contact tolerance {tolerance} m allows in one step: contacts could be missed \
         (a speed of {speed:.4e} m/s needs dt <= {max_dt:.4e} s)"
    )]
    StepTooLong {
        /// The step that moved the block.
        step: u64,
        /// Time at the start of the step.
        time: Real,
        /// The step's length (s).
        dt: Real,
        /// The block.
        block: BlockId,
        /// How far a point of the block moved in the step (m): translation plus rotation times
        /// the block's radius.
        distance: Real,
        /// The contact tolerance (m).
        tolerance: Real,
        /// The block's speed in the step (`distance / dt`, m/s).
        speed: Real,
        /// The longest step at that speed that stays within the tolerance (s).
        max_dt: Real,
    },
    /// A size beyond what voussoir builds or reads (blocks of a generator, facets of a friction
    /// pyramid, bytes of a file): refused before allocating, instead of the process aborting
    /// when memory runs out. (Python: `MemoryError`.)
    #[error("{what}: {requested} is more than the limit {limit}")]
    TooLarge {
        /// What was asked for, e.g. `"wall.courses × (wall.bricks_per_course + 1) blocks"`.
        what: String,
        /// The size asked for.
        requested: u128,
        /// The largest size accepted.
        limit: u64,
    },
    /// A model with no blocks was asked to step (time could not advance: a run would never end).
    #[error("the model has no blocks: add one before stepping")]
    EmptyModel,
    /// Two blocks overlap by more than half the smaller one's size (its radius): the joint
    /// springs cannot carry what presses them together, and the blocks are passing through each
    /// other. Found at a contact detection, which then stops the step: the model is as before
    /// it.
    #[error(
        "step {step}: blocks {a} and {b} overlap by {depth:.4} m, more than half the smaller \
         block's size ({limit:.4} m): the joints cannot carry what presses them together (stiffer \
         joints, or a lighter load)"
    )]
    Overlap {
        /// The step at whose detection the overlap was found.
        step: u64,
        /// The two blocks.
        a: BlockId,
        /// The two blocks.
        b: BlockId,
        /// Their overlap (m): the depth along the axis of least penetration.
        depth: Real,
        /// Half the smaller block's radius (m).
        limit: Real,
    },
    /// The interrupt check ([`crate::Model::set_interrupt_check`]) asked a step to stop (before
    /// the step began, or during its contact detection). The step did not happen: the model is
    /// as before it (after an interrupted detection, its next step detects every contact afresh).
    #[error("step {step} interrupted; the model is as before the step")]
    Interrupted {
        /// The step that was interrupted (the model's step count).
        step: u64,
    },
    /// An operation this model cannot do as set up, e.g. checkpointing a custom integrator.
    #[error("unsupported: {what}")]
    Unsupported {
        /// What was asked and why it cannot be done.
        what: String,
    },
    /// A run reached its step budget before its stopping condition. An infinite unbalanced-force
    /// ratio says that no contact carries a force (nothing supports the blocks, or they have
    /// not touched yet): the message says so.
    #[error("{what} not reached after {steps} steps (last value {last}){}", not_converged_hint(.last))]
    NotConverged {
        /// What was being waited for.
        what: &'static str,
        /// Number of steps taken.
        steps: u64,
        /// The last value of the monitored quantity.
        last: Real,
    },
    /// Limit analysis of a live load: no set of admissible contact forces carries the dead
    /// loads (gravity and the blocks' constant loads), with or without the live load: the
    /// structure cannot carry its own weight. (The dead-load question alone,
    /// `LimitProblem::dead_load`, answers that without an error; Python raises
    /// `voussoir.LimitInfeasibleError`.)
    #[error("limit analysis: the structure cannot carry its own weight: {reason}")]
    LimitInfeasible {
        /// What was found, e.g. the negative multiplier it would need.
        reason: String,
    },
    /// Limit analysis: the load multiplier has no upper bound, e.g. the live load acts only on
    /// supports' constrained degrees of freedom or is carried straight into them. (Python:
    /// `voussoir.LimitUnboundedError`.)
    #[error("limit analysis: the load multiplier is unbounded: {reason}")]
    LimitUnbounded {
        /// The live loads concerned.
        reason: String,
    },
    /// Limit analysis: the conic solver (Clarabel) stopped without a solution or a certificate.
    /// (Python: `voussoir.LimitSolverError`.)
    #[error("limit analysis: the conic solver stopped with status {status} after {iterations} iterations")]
    LimitSolver {
        /// Clarabel's status, e.g. `MaxIterations` or `NumericalError`.
        status: String,
        /// Interior-point iterations taken.
        iterations: u32,
    },
}

/// Checks that `value` is finite and strictly positive; the error names the parameter. For
/// validating the parameters of laws, generators and scenarios written outside the crate.
///
/// ```
/// use voussoir::error::positive;
/// assert_eq!(positive("density", 2500.0), Ok(2500.0));
/// assert!(positive("density", -1.0).unwrap_err().to_string().contains("density"));
/// ```
///
/// # Errors
/// [`Error::InvalidParameter`] naming `name`.
pub fn positive(name: &str, value: Real) -> Result<Real> {
    if value.is_finite() && value > 0.0 {
        Ok(value)
    } else {
        Err(Error::InvalidParameter {
            name: name.to_owned(),
            value,
            expected: "must be positive and finite",
        })
    }
}

/// Checks that `value` is finite and not negative; the error names the parameter.
///
/// # Errors
/// [`Error::InvalidParameter`] naming `name`.
pub fn non_negative(name: &str, value: Real) -> Result<Real> {
    if value.is_finite() && value >= 0.0 {
        Ok(value)
    } else {
        Err(Error::InvalidParameter {
            name: name.to_owned(),
            value,
            expected: "must be finite and not negative",
        })
    }
}

/// Checks that `value` lies in `[lo, hi)`; the error names the parameter and says `expected`.
///
/// # Errors
/// [`Error::InvalidParameter`] naming `name`.
pub fn in_range(name: &str, value: Real, lo: Real, hi: Real, expected: &'static str) -> Result<Real> {
    if value.is_finite() && value >= lo && value < hi {
        Ok(value)
    } else {
        Err(Error::InvalidParameter {
            name: name.to_owned(),
            value,
            expected,
        })
    }
}

/// [`Error::Io`] naming the file.
pub(crate) fn io_error(path: &std::path::Path, e: &std::io::Error) -> Error {
    Error::Io {
        path: path.display().to_string(),
        message: e.to_string(),
    }
}

/// What an infinite last value of [`Error::NotConverged`] means.
fn not_converged_hint(last: &Real) -> &'static str {
    if last.is_infinite() {
        ": no contact carries a force, so nothing holds the blocks up; a model settles on a fixed \
         block or a block with a prescribed motion under it"
    } else {
        ""
    }
}
