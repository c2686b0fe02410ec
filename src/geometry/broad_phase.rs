//! Broad phase: candidate block pairs from parry's bounding-volume hierarchy.

use parry3d_f64::bounding_volume::{Aabb, BoundingVolume};
use parry3d_f64::partitioning::{Bvh, BvhBuildStrategy, BvhWorkspace};
use parry3d_f64::shape::Shape;

use super::polyhedron::Polyhedron;
use crate::math::{Pose, Real};

/// Reusable broad-phase state.
#[derive(Default)]
pub struct BroadPhase {
    aabbs: Vec<Aabb>,
    workspace: BvhWorkspace,
}

impl std::fmt::Debug for BroadPhase {
    fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        f.debug_struct("BroadPhase").field("leaves", &self.aabbs.len()).finish()
    }
}

impl Clone for BroadPhase {
    fn clone(&self) -> Self {
        Self::default()
    }
}

impl BroadPhase {
    /// All pairs `(i, j)`, `i < j`, whose bounding boxes enlarged by `margin` overlap, sorted.
    pub fn pairs<'a>(
        &mut self,
        shapes: impl Iterator<Item = (&'a Polyhedron, &'a Pose)>,
        margin: Real,
        out: &mut Vec<(u32, u32)>,
    ) {
        self.aabbs.clear();
        self.aabbs
            .extend(shapes.map(|(s, p)| s.parry().compute_aabb(p).loosened(0.5 * margin)));
        out.clear();
        if self.aabbs.len() < 2 {
            return;
        }
        let bvh = Bvh::from_leaves(BvhBuildStrategy::Binned, &self.aabbs);
        bvh.traverse_bvtt_single_tree::<false>(&mut self.workspace, &mut |i, j| out.push((i.min(j), i.max(j))));
        out.sort_unstable();
        out.dedup();
    }
}
