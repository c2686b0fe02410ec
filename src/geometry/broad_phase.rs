//! Broad phase: candidate block pairs from parry's bounding-volume hierarchy, and a uniform cell
//! grid kept for comparison (`docs/performance.md`).

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
        self.collect_aabbs(shapes, margin);
        self.bvh_pairs(out);
    }

    /// Same pairs as [`BroadPhase::pairs`], from a uniform cell grid (cell side = the largest box
    /// extent, so each box touches at most 8 cells). Kept to compare with the BVH.
    pub fn pairs_grid<'a>(
        &mut self,
        shapes: impl Iterator<Item = (&'a Polyhedron, &'a Pose)>,
        margin: Real,
        out: &mut Vec<(u32, u32)>,
    ) {
        self.collect_aabbs(shapes, margin);
        out.clear();
        if self.aabbs.len() < 2 {
            return;
        }
        let side = self
            .aabbs
            .iter()
            .map(|a| (a.maxs - a.mins).max_element())
            .fold(0.0, Real::max)
            .max(Real::MIN_POSITIVE);
        let cell = |x: Real| (x / side).floor() as i64;
        let mut entries: Vec<([i64; 3], u32)> = Vec::with_capacity(8 * self.aabbs.len());
        for (i, a) in self.aabbs.iter().enumerate() {
            for cx in cell(a.mins.x)..=cell(a.maxs.x) {
                for cy in cell(a.mins.y)..=cell(a.maxs.y) {
                    for cz in cell(a.mins.z)..=cell(a.maxs.z) {
                        entries.push(([cx, cy, cz], i as u32));
                    }
                }
            }
        }
        entries.sort_unstable();
        for run in entries.chunk_by(|x, y| x.0 == y.0) {
            for (k, &(_, i)) in run.iter().enumerate() {
                for &(_, j) in &run[k + 1..] {
                    if self.aabbs[i as usize].intersects(&self.aabbs[j as usize]) {
                        out.push((i.min(j), i.max(j)));
                    }
                }
            }
        }
        out.sort_unstable();
        out.dedup();
    }

    fn collect_aabbs<'a>(&mut self, shapes: impl Iterator<Item = (&'a Polyhedron, &'a Pose)>, margin: Real) {
        self.aabbs.clear();
        self.aabbs
            .extend(shapes.map(|(s, p)| s.parry().compute_aabb(p).loosened(0.5 * margin)));
    }

    fn bvh_pairs(&mut self, out: &mut Vec<(u32, u32)>) {
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

#[cfg(test)]
mod tests {
    use super::*;
    use crate::block::Block;
    use crate::build::{running_bond_wall, WallSpec};

    /// The grid and the BVH find the same candidate pairs.
    #[test]
    fn grid_and_bvh_agree() {
        let blocks = running_bond_wall(&WallSpec {
            bricks_per_course: 20,
            courses: 10,
            ..WallSpec::default()
        })
        .unwrap();
        let mut bp = BroadPhase::default();
        let (mut a, mut b) = (Vec::new(), Vec::new());
        bp.pairs(blocks.iter().map(|b| (b.shape(), &b.state().pose)), 1e-3, &mut a);
        bp.pairs_grid(blocks.iter().map(|b| (b.shape(), &b.state().pose)), 1e-3, &mut b);
        assert!(a.len() > 400);
        assert_eq!(a, b);
    }
}
