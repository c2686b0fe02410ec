//! A checkpoint's tested pairs (the narrow phase's verdicts that detection keeps): read,
//! checked, and their slack re-derived from the blocks' shapes rather than trusted.

use serde::{Deserialize, Serialize};

use crate::block::{Block, RigidBlock};
use crate::error::{Error, Result};
use crate::geometry::{detect, BlockGeometry, ContactParameters, NarrowPhaseScratch};
use crate::math::{Pose, Real};
use crate::model::detection::TestedPair;

/// A pair the narrow phase tested, as checkpoints store it.
#[derive(Serialize, Deserialize)]
#[serde(deny_unknown_fields)]
pub(super) struct TestedEntry {
    pub blocks: (u32, u32),
    /// The pose of the smaller block in the body frame of the other at the test.
    pub relative: Pose,
    /// The separation beyond the tolerance of a pair found apart (m).
    pub slack: Real,
}

/// The tested pairs of a checkpoint of `n` blocks, checked: pairs `a < b < n` in strictly
/// increasing order, finite poses with unit rotations, finite slacks not below zero.
pub(super) fn tested_pairs(entries: &[TestedEntry], n: usize) -> Result<Vec<TestedPair>> {
    let corrupt = |path: &str, message: &str| Error::Checkpoint {
        path: path.into(),
        message: message.into(),
    };
    let mut tested = Vec::with_capacity(entries.len());
    for (k, e) in entries.iter().enumerate() {
        let (a, b) = e.blocks;
        let ordered = tested.last().is_none_or(|t: &TestedPair| (t.a, t.b) < (a, b));
        if !(a < b && (b as usize) < n && ordered) {
            return Err(corrupt(
                &format!("tested[{k}].blocks"),
                "block pairs a < b < block count, in increasing order, expected",
            ));
        }
        if !crate::math::is_unit_pose(&e.relative) {
            return Err(corrupt(
                &format!("tested[{k}].relative"),
                "not a finite pose with a unit rotation",
            ));
        }
        if !(e.slack.is_finite() && e.slack >= 0.0) {
            return Err(corrupt(&format!("tested[{k}].slack"), "a finite length ≥ 0 expected"));
        }
        tested.push(TestedPair {
            a,
            b,
            relative: e.relative,
            slack: e.slack,
        });
    }
    Ok(tested)
}

/// Each pair found apart keeps its verdict while it moves less than its slack: the slack is
/// derived data, re-derived here from the two shapes at the stored relative pose (the narrow
/// phase's separation less the tolerance). A stored slack above the re-derived one (beyond
/// round-off: 1e-9 of the blocks' size and offset, and 1e-6 of the tolerance) is refused: it
/// would let a block pass through another without a test.
pub(super) fn check_slacks(blocks: &[RigidBlock], tested: &[TestedPair], params: &ContactParameters) -> Result<()> {
    let mut scratch = NarrowPhaseScratch::default();
    let mut seeds = Vec::new();
    for (k, t) in tested.iter().enumerate().filter(|(_, t)| t.slack > 0.0) {
        let (a, b) = (&blocks[t.a as usize], &blocks[t.b as usize]);
        // As `detection::relative_pose`: the frame is the larger block (`a` on a tie).
        let (frame, moving) = if b.radius > a.radius { (b, a) } else { (a, b) };
        let identity = Pose::IDENTITY;
        seeds.clear();
        let found = detect(
            BlockGeometry {
                shape: frame.shape(),
                pose: &identity,
            },
            BlockGeometry {
                shape: moving.shape(),
                pose: &t.relative,
            },
            None,
            params,
            &mut scratch,
            &mut seeds,
        );
        let derived = if found.is_some() {
            0.0
        } else {
            (scratch.separation() - params.tolerance).max(0.0)
        };
        let allowance = 1e-9 * (a.radius + b.radius + t.relative.translation.length()) + 1e-6 * params.tolerance;
        if t.slack > derived + allowance {
            return Err(Error::Checkpoint {
                path: format!("tested[{k}].slack"),
                message: format!(
                    "{} m, but blocks {} and {} at the stored relative pose are {derived} m beyond the contact \
                     tolerance (the slack is derived data; a larger one would let the blocks pass through \
                     each other untested)",
                    t.slack, t.a, t.b
                ),
            });
        }
    }
    Ok(())
}
