//! Broad phase: candidate block pairs from parry's bounding-volume hierarchy (rebuilt at every
//! call, or kept and updated incrementally), and a uniform cell grid kept for comparison
//! (`docs/performance.md`).

use parry3d_f64::bounding_volume::{Aabb, BoundingVolume};
use parry3d_f64::partitioning::{Bvh, BvhBuildStrategy, BvhLeafUpdateStatus, BvhWorkspace};
use parry3d_f64::shape::Shape;

use super::polyhedron::Polyhedron;
use crate::math::{Pose, Real};

/// Fat leaves of the incremental BVH: the box of [`BroadPhase::pairs`] enlarged by this many
/// `margin`s more. A leaf is re-inserted only once its box leaves its fat box.
const FAT_FACTOR: Real = 1.0;

/// Below this many re-inserted leaves per `REFIT_PARTIAL_RATIO` leaves, the incremental BVH is
/// refitted along the changed leaves' paths only (`Bvh::refit_partial`, O(changed · height));
/// above it, in one O(n) pass (`Bvh::refit`).
const REFIT_PARTIAL_RATIO: usize = 32;

/// The incremental tree is rebuilt once its leaves have been re-inserted this many times the
/// number of leaves since it was built: re-insertion never rebalances it, and blocks that travel
/// far (a collapse) would otherwise leave a tree that is exact but slow to traverse.
const REBUILD_AFTER_REINSERTIONS: usize = 4;

/// Reusable broad-phase state.
#[derive(Default)]
pub struct BroadPhase {
    aabbs: Vec<Aabb>,
    workspace: BvhWorkspace,
    incremental: Option<Incremental>,
}

/// State kept between calls of [`BroadPhase::pairs_incremental`].
struct Incremental {
    /// `margin` the tree was built for; another margin rebuilds it.
    margin: Real,
    /// Leaves re-inserted since the tree was built.
    reinserted: usize,
    /// Leaves are the boxes of [`BroadPhase::pairs`] enlarged by `FAT_FACTOR * margin`.
    bvh: Bvh,
    /// Copy of the leaves, by block: checking them in order is much cheaper than asking the tree
    /// (one scattered lookup per leaf). Same values as the tree's, bit for bit.
    fat_leaves: Vec<Aabb>,
    /// Every pair `(i, j)`, `i < j`, whose fat leaves overlap, sorted. A superset of the result.
    fat_pairs: Vec<(u32, u32)>,
    /// Leaves whose change flag the last refit set (cleared by the next refit).
    flagged: Vec<u32>,
    /// Leaves re-inserted during the current call.
    updated: Vec<u32>,
    /// `updated` as a mask.
    is_updated: Vec<bool>,
    /// Pairs reported by the changed-only traversal.
    new_pairs: Vec<(u32, u32)>,
    /// Merge buffer for `fat_pairs`.
    merged: Vec<(u32, u32)>,
}

impl std::fmt::Debug for BroadPhase {
    fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        f.debug_struct("BroadPhase")
            .field("leaves", &self.aabbs.len())
            .field(
                "incremental_fat_pairs",
                &self.incremental.as_ref().map(|inc| inc.fat_pairs.len()),
            )
            .finish()
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

    /// Same pairs as [`BroadPhase::pairs`], from a BVH kept between calls.
    ///
    /// The leaves are "fat": the box of [`BroadPhase::pairs`] enlarged by `margin` more. A block
    /// whose box is still inside its fat leaf leaves the tree alone; the others are updated in
    /// place, the tree is refitted, and a traversal restricted to the updated leaves finds their
    /// pairs of overlapping fat leaves. Pairs between two untouched leaves are kept from the
    /// previous call, since their fat leaves have not changed. The kept set of fat-overlapping
    /// pairs is then filtered with the exact test of [`BroadPhase::pairs`], so the result is the
    /// same, sorted, whatever moved.
    ///
    /// The boxes of all the blocks are recomputed at every call, as in [`BroadPhase::pairs`]; the
    /// work on the tree and on the pairs is then proportional to the re-inserted leaves, plus one
    /// pass over the kept pairs.
    ///
    /// The first call, a change of `margin` or of the number of shapes builds the tree afresh;
    /// a `margin` that is not positive falls back on [`BroadPhase::pairs`]. The tree is never
    /// re-balanced: fine for blocks that move little, not for blocks that travel far.
    ///
    /// Returns how many leaves were (re)inserted (all of them on a fresh build).
    pub fn pairs_incremental<'a>(
        &mut self,
        shapes: impl Iterator<Item = (&'a Polyhedron, &'a Pose)>,
        margin: Real,
        out: &mut Vec<(u32, u32)>,
    ) -> usize {
        self.collect_aabbs(shapes, margin);
        let boxes = std::mem::take(&mut self.aabbs);
        let reinserted = self.pairs_of_boxes(&boxes, margin, out);
        self.aabbs = boxes;
        reinserted
    }

    /// All pairs `(i, j)`, `i < j`, of overlapping `boxes`, sorted, from the BVH of
    /// [`BroadPhase::pairs_incremental`] (leaves: the boxes loosened by `margin`), for a caller
    /// that keeps the blocks' boxes itself and updates only those of the blocks that moved.
    ///
    /// Returns how many leaves were (re)inserted (all of them on a fresh build).
    pub fn pairs_of_boxes(&mut self, boxes: &[Aabb], margin: Real, out: &mut Vec<(u32, u32)>) -> usize {
        self.pairs_of_boxes_where(boxes, None, margin, out)
    }

    /// The pairs of [`BroadPhase::pairs_of_boxes`] with at least one block `i` for which
    /// `moved[i]`, given that the boxes of the other blocks have not changed since the last
    /// call (on the same tree): only the moved blocks' leaves are looked at, and the kept pairs
    /// are filtered by the flags before their boxes are compared. The first call (or a change of
    /// `margin` or of the number of boxes) builds the tree from every box.
    ///
    /// ```
    /// use parry3d_f64::bounding_volume::Aabb;
    /// use voussoir::geometry::BroadPhase;
    /// use voussoir::math::Vector;
    ///
    /// let cube = |x: f64| Aabb::new(Vector::new(x, 0.0, 0.0), Vector::new(x + 1.0, 1.0, 1.0));
    /// let mut boxes = vec![cube(0.0), cube(1.0), cube(2.0), cube(5.0)];
    /// let mut bp = BroadPhase::default();
    /// let mut pairs = Vec::new();
    /// bp.pairs_of_boxes(&boxes, 1e-3, &mut pairs);
    /// assert_eq!(pairs, [(0, 1), (1, 2)]);
    /// // Block 3 moves next to block 2: only its pairs are asked for.
    /// boxes[3] = cube(3.0);
    /// bp.pairs_of_moved_boxes(&boxes, &[false, false, false, true], 1e-3, &mut pairs);
    /// assert_eq!(pairs, [(2, 3)]);
    /// ```
    ///
    /// # Panics
    /// If `moved` is shorter than `boxes`.
    pub fn pairs_of_moved_boxes(
        &mut self,
        boxes: &[Aabb],
        moved: &[bool],
        margin: Real,
        out: &mut Vec<(u32, u32)>,
    ) -> usize {
        assert!(moved.len() >= boxes.len(), "a flag per box");
        self.pairs_of_boxes_where(boxes, Some(moved), margin, out)
    }

    fn pairs_of_boxes_where(
        &mut self,
        boxes: &[Aabb],
        moved: Option<&[bool]>,
        margin: Real,
        out: &mut Vec<(u32, u32)>,
    ) -> usize {
        let n = boxes.len();
        let touches = |i: u32, j: u32| moved.is_none_or(|m| m[i as usize] || m[j as usize]);
        if n < 2 || margin <= 0.0 {
            self.incremental = None;
            self.aabbs.clear();
            self.aabbs.extend_from_slice(boxes);
            self.bvh_pairs(out);
            out.retain(|&(i, j)| touches(i, j));
            return n;
        }
        let fat = FAT_FACTOR * margin;
        let ws = &mut self.workspace;
        let reinserted = match &mut self.incremental {
            Some(inc)
                if inc.margin == margin
                    && inc.bvh.leaf_count() as usize == n
                    && inc.reinserted <= REBUILD_AFTER_REINSERTIONS * n =>
            {
                let count = inc.update(boxes, moved, fat, ws);
                inc.reinserted += count;
                count
            }
            _ => {
                self.incremental = Some(Incremental::build(boxes, margin, fat, ws));
                n
            }
        };
        let inc = self.incremental.as_ref().expect("just set");
        out.clear();
        out.extend(
            inc.fat_pairs
                .iter()
                .filter(|&&(i, j)| touches(i, j) && boxes[i as usize].intersects(&boxes[j as usize])),
        );
        reinserted
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

impl Incremental {
    /// A fresh tree of fat leaves, with no change flag set, and its overlapping pairs.
    fn build(aabbs: &[Aabb], margin: Real, fat: Real, ws: &mut BvhWorkspace) -> Self {
        let fat_leaves: Vec<Aabb> = aabbs.iter().map(|a| a.loosened(fat)).collect();
        let mut bvh = Bvh::from_leaves(BvhBuildStrategy::Binned, &fat_leaves);
        // `from_leaves` flags every leaf as changed (or pending, for two leaves): clear them.
        bvh.refit(ws);
        bvh.refit(ws);
        let mut fat_pairs = Vec::with_capacity(4 * aabbs.len());
        bvh.traverse_bvtt_single_tree::<false>(ws, &mut |i, j| fat_pairs.push((i.min(j), i.max(j))));
        fat_pairs.sort_unstable();
        fat_pairs.dedup();
        Self {
            margin,
            reinserted: 0,
            bvh,
            fat_leaves,
            fat_pairs,
            flagged: Vec::new(),
            updated: Vec::new(),
            is_updated: vec![false; aabbs.len()],
            new_pairs: Vec::new(),
            merged: Vec::new(),
        }
    }

    /// Re-inserts the leaves whose box left its fat leaf, refits, and brings `fat_pairs` up to
    /// date: pairs of two untouched leaves are kept, pairs with an updated leaf come from the
    /// changed-only traversal. Returns how many leaves were re-inserted.
    ///
    /// Only the leaves flagged in `moved` (when given) are looked at: the others' boxes have not
    /// changed.
    fn update(&mut self, aabbs: &[Aabb], moved: Option<&[bool]>, fat: Real, ws: &mut BvhWorkspace) -> usize {
        self.updated.clear();
        for (i, (a, leaf)) in aabbs.iter().zip(&mut self.fat_leaves).enumerate() {
            if moved.is_some_and(|m| !m[i]) || leaf.contains(a) {
                continue;
            }
            // The tight box goes in: parry stores it enlarged by `fat`, as `loosened` does.
            if self.bvh.update_partially_if_present(*a, i as u32, fat) == Some(BvhLeafUpdateStatus::UpdatedInPlace) {
                *leaf = a.loosened(fat);
                self.updated.push(i as u32);
            }
        }
        if self.updated.is_empty() {
            // Nothing to traverse. The flags of the last refit stay set until the next one.
            return 0;
        }
        if (self.flagged.len() + self.updated.len()) * REFIT_PARTIAL_RATIO < aabbs.len() {
            self.bvh.refit_partial(&self.flagged, &self.updated);
        } else {
            // Clears every flag not pending, so the previously flagged leaves as well.
            self.bvh.refit(ws);
        }
        std::mem::swap(&mut self.flagged, &mut self.updated);

        self.new_pairs.clear();
        let new_pairs = &mut self.new_pairs;
        self.bvh
            .traverse_bvtt_single_tree::<true>(ws, &mut |i, j| new_pairs.push((i.min(j), i.max(j))));
        new_pairs.sort_unstable();
        new_pairs.dedup();

        for &i in &self.flagged {
            self.is_updated[i as usize] = true;
        }
        let is_updated = &self.is_updated;
        let kept = self
            .fat_pairs
            .iter()
            .copied()
            .filter(|&(i, j)| !is_updated[i as usize] && !is_updated[j as usize]);
        merge_sorted(kept, new_pairs, &mut self.merged);
        for &i in &self.flagged {
            self.is_updated[i as usize] = false;
        }
        std::mem::swap(&mut self.fat_pairs, &mut self.merged);
        self.flagged.len()
    }
}

/// Merges the sorted `a` and the sorted, deduplicated `b` (disjoint from `a`) into `out`.
fn merge_sorted(a: impl Iterator<Item = (u32, u32)>, b: &[(u32, u32)], out: &mut Vec<(u32, u32)>) {
    out.clear();
    let mut b = b.iter().copied().peekable();
    for x in a {
        while let Some(y) = b.next_if(|&y| y < x) {
            out.push(y);
        }
        out.push(x);
    }
    out.extend(b);
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

    /// The incremental BVH gives exactly the pairs of a rebuild, round after round, while blocks
    /// move within their fat leaves, out of them, and away from or into their neighbours.
    #[test]
    fn incremental_matches_rebuild() {
        use crate::math::{Rotation, Vector};

        let blocks = running_bond_wall(&WallSpec {
            bricks_per_course: 20,
            courses: 10,
            ..WallSpec::default()
        })
        .unwrap();
        let shapes: Vec<&Polyhedron> = blocks.iter().map(|b| b.shape()).collect();
        let mut poses: Vec<Pose> = blocks.iter().map(|b| b.state().pose).collect();
        let n = poses.len();

        // Deterministic pseudo-random numbers in [-1, 1).
        let mut uniform = crate::math::test_uniform(0x9e37_79b9_7f4a_7c15_u64);
        let mut rand = move || 2.0 * uniform() - 1.0;

        let (mut rebuild, mut incremental) = (BroadPhase::default(), BroadPhase::default());
        let (mut expected, mut got) = (Vec::new(), Vec::new());
        let mut initial = Vec::new();
        let (mut changed_rounds, mut partial_rounds) = (0, 0);
        for round in 0..40 {
            let margin = if round < 30 { 1e-3 } else { 2e-3 };
            let step = match round % 5 {
                // Every block a little, within its fat leaf or just out of it.
                0 => Some(0.3 * margin),
                1 => Some(1.2 * margin),
                // Nothing moves.
                2 => None,
                // A few blocks far: away from or into their neighbours.
                _ => Some(20.0 * margin),
            };
            let mut moved = 0;
            if let Some(step) = step {
                for (k, p) in poses.iter_mut().enumerate() {
                    if step > 10.0 * margin && (rand() > -0.96 || k == 0) {
                        continue;
                    }
                    moved += 1;
                    p.translation += step * Vector::new(rand(), rand(), rand());
                    if round % 3 == 0 {
                        let tilt = Rotation::from_scaled_axis(0.02 * step * Vector::new(rand(), rand(), rand()));
                        p.rotation = (tilt * p.rotation).normalize();
                    }
                }
            }
            let flagged = incremental.incremental.as_ref().map_or(0, |inc| inc.flagged.len());
            let pairs = || shapes.iter().copied().zip(poses.iter());
            rebuild.pairs(pairs(), margin, &mut expected);
            let reinserted = incremental.pairs_incremental(pairs(), margin, &mut got);
            assert_eq!(got, expected, "round {round}");
            let inc = incremental.incremental.as_ref().unwrap();
            for (i, leaf) in inc.fat_leaves.iter().enumerate() {
                let node = inc.bvh.leaf_node(i as u32).unwrap();
                assert_eq!((node.mins(), node.maxs()), (leaf.mins, leaf.maxs));
            }
            assert!(got.windows(2).all(|w| w[0] < w[1]) && got.iter().all(|&(i, j)| i < j));
            match round {
                0 | 30 => assert_eq!(reinserted, n, "fresh build at round {round}"),
                _ if step.is_none() => assert_eq!(reinserted, 0),
                _ => {
                    assert!(reinserted <= moved);
                    if reinserted > 0 && (flagged + reinserted) * REFIT_PARTIAL_RATIO < n {
                        partial_rounds += 1;
                    }
                }
            }
            if round == 0 {
                assert!(expected.len() > 400);
                initial.clone_from(&expected);
            } else if expected != initial {
                changed_rounds += 1;
            }
        }
        assert!(
            changed_rounds > 20,
            "the pair set changed in {changed_rounds} rounds only"
        );
        assert!(partial_rounds > 3, "partial refit used in {partial_rounds} rounds only");
    }
}
