//! Irregular-stone (rubble) walls: convex stones from a Voronoi partition of the wall's volume.
//!
//! The seeds lie on a grid of about one stone per `stone_size` along the length and the height
//! and `leaves` stones across the thickness, each jittered by a seeded random number generator.
//! Each stone is the cell of its seed within the wall's box, computed in grid units (where the
//! grid is cubic, then scaled back): the box cut by the bisecting plane of every nearby seed, a
//! convex polyhedron. Neighbouring stones share their faces exactly (the same plane from both
//! sides), so the wall is dry-stacked with no gap and no overlap: every joint is a face–face
//! contact from the first step, and as the wall moves the stones meet on their edges and
//! corners. A through-stone replaces the seeds across the thickness at its place by one seed in
//! the middle plane with a power weight (a Laguerre cell: still convex, still an exact
//! partition) large enough for its cell to reach both faces of the wall, where that leaves each
//! neighbour its own cell.

#[cfg(feature = "serde")]
use serde::{Deserialize, Serialize};

use crate::block::{Fixity, RigidBlock};
use crate::error::{in_range, positive, Error, Result};
use crate::law::MaterialId;
use crate::math::{Real, Vector};

/// A rubble wall: stones of about `stone_size` filling the box `[0, length] × [0, thickness] ×
/// [0, height]`, on a fixed base slab under `z = 0`.
#[derive(Debug, Clone, Copy, PartialEq)]
#[cfg_attr(feature = "serde", derive(Serialize, Deserialize))]
#[cfg_attr(feature = "serde", serde(default, deny_unknown_fields))]
pub struct RubbleWallSpec {
    /// Length along `x` (m).
    pub length: Real,
    /// Thickness along `y` (m).
    pub thickness: Real,
    /// Height along `z` (m).
    pub height: Real,
    /// Typical stone size (m): the grid spacing of the seeds along the length and the height.
    pub stone_size: Real,
    /// Stones across the thickness (leaves), at least 1.
    pub leaves: usize,
    /// Random displacement of each seed from its grid point, as a fraction of the spacing along
    /// each axis, in `[0, 0.45]`: 0 gives boxes, larger values more irregular stones.
    pub jitter: Real,
    /// Share of the grid places along the wall face, in `[0, 1]`, where one through-stone spans
    /// the thickness instead of `leaves` stones (with `leaves ≥ 2`).
    pub through_stones: Real,
    /// Seed of the random number generator: the same spec gives the same wall.
    pub seed: u64,
    /// Density (kg/m³).
    pub density: Real,
    /// Material of the stones.
    pub material: MaterialId,
    /// Material of the base.
    pub base_material: MaterialId,
}

impl Default for RubbleWallSpec {
    /// A two-leaf wall 2 m long, 0.5 m thick and 1.2 m high of 0.2 m stones, a tenth of them
    /// through-stones.
    fn default() -> Self {
        Self {
            length: 2.0,
            thickness: 0.5,
            height: 1.2,
            stone_size: 0.2,
            leaves: 2,
            jitter: 0.3,
            through_stones: 0.1,
            seed: 1,
            density: 2200.0,
            material: MaterialId(0),
            base_material: MaterialId(0),
        }
    }
}

/// The most stones a rubble wall may have: the cells are computed by plane intersections, about
/// a millisecond per stone.
pub const MAX_RUBBLE_STONES: usize = 100_000;

/// Builds the blocks of a rubble wall; the first block is the fixed base (the wall's footprint
/// and `stone_size` more on each side, `stone_size` deep). Stones are named `stone i j k` by
/// their grid place (along, across, up); through-stones `through i k`.
///
/// ```
/// use voussoir::build::{rubble_wall, RubbleWallSpec};
/// use voussoir::Block;
/// let spec = RubbleWallSpec::default();
/// let blocks = rubble_wall(&spec)?;
/// let volume: f64 = blocks[1..].iter().map(|b| b.shape().volume()).sum();
/// let expected = spec.length * spec.thickness * spec.height;
/// assert!((volume - expected).abs() < 1e-9 * expected);
/// # Ok::<(), voussoir::Error>(())
/// ```
///
/// # Errors
/// [`Error::InvalidParameter`] for sizes, density or `leaves` that are not positive, `jitter` or
/// `through_stones` out of range; [`Error::TooLarge`] for more than [`MAX_RUBBLE_STONES`]
/// stones; a degenerate cell as [`RigidBlock::from_vertices`] reports it.
pub fn rubble_wall(spec: &RubbleWallSpec) -> Result<Vec<RigidBlock>> {
    positive("rubble.length", spec.length)?;
    positive("rubble.thickness", spec.thickness)?;
    positive("rubble.height", spec.height)?;
    positive("rubble.stone_size", spec.stone_size)?;
    positive("rubble.leaves", spec.leaves as Real)?;
    positive("rubble.density", spec.density)?;
    in_range("rubble.jitter", spec.jitter, 0.0, 0.45 + 1e-12, "must lie in [0, 0.45]")?;
    in_range(
        "rubble.through_stones",
        spec.through_stones,
        0.0,
        1.0 + 1e-12,
        "must lie in [0, 1]",
    )?;
    let along = (spec.length / spec.stone_size).round().max(1.0);
    let up = (spec.height / spec.stone_size).round().max(1.0);
    let stones = along * up * spec.leaves as Real;
    if stones > MAX_RUBBLE_STONES as Real {
        return Err(Error::TooLarge {
            what: "rubble wall stones (length / stone_size × height / stone_size × leaves)".into(),
            requested: if stones < u128::MAX as Real {
                stones as u128
            } else {
                u128::MAX
            },
            limit: MAX_RUBBLE_STONES as u64,
        });
    }
    let (nx, nz, ny) = (along as usize, up as usize, spec.leaves);
    let spacing = Vector::new(
        spec.length / nx as Real,
        spec.thickness / ny as Real,
        spec.height / nz as Real,
    );
    // The cells are computed in grid units (one spacing per unit along each axis), where the
    // grid is cubic; scaling back keeps them convex and the partition exact.
    let grid_size = Vector::new(nx as Real, ny as Real, nz as Real);
    let mut random = SplitMix(spec.seed);
    let mut seeds: Vec<Seed> = Vec::with_capacity(nx * ny * nz);
    let mut through_places = Vec::new();
    for k in 0..nz {
        for i in 0..nx {
            if ny >= 2 && random.unit() < spec.through_stones {
                through_places.push((i, k));
            }
            for j in 0..ny {
                let grid = Vector::new(i as Real + 0.5, j as Real + 0.5, k as Real + 0.5);
                let offset = Vector::new(random.signed(), random.signed(), random.signed()) * spec.jitter;
                seeds.push(Seed {
                    at: grid + offset,
                    weight: 0.0,
                    name: format!("stone {i} {j} {k}"),
                });
            }
        }
    }
    let place = |i: usize, k: usize| (k * nx + i) * ny;
    // A through-stone replaces the column of seeds at its place by one seed in the middle plane
    // whose power weight lets its cell reach both faces of the wall, where that weight leaves
    // every neighbouring seed its own cell (else the place keeps its column).
    let mut through = vec![false; seeds.len()];
    let grid_index = SeedGrid::new(&seeds, 3.0);
    for &(i, k) in &through_places {
        let centre = Vector::new(i as Real + 0.5, 0.5 * ny as Real, k as Real + 0.5);
        let faces = [
            Vector::new(centre.x, 0.0, centre.z),
            Vector::new(centre.x, ny as Real, centre.z),
        ];
        let column = place(i, k)..place(i, k) + ny;
        let others = grid_index
            .near(centre)
            .into_iter()
            .filter(|t| !column.contains(t) && !through[*t]);
        let (mut need, mut allowed): (Real, Real) = (0.0, Real::INFINITY);
        for t in others {
            let other = seeds[t].at;
            if (other - centre).abs().max_element() > 2.5 {
                continue;
            }
            for f in faces {
                // Power at the face point: |f − c|² − w below every neighbour's |f − s|².
                need = need.max((f - centre).length_squared() - (f - other).length_squared());
            }
            // The neighbour's seed keeps a smaller power to itself (zero) than to the stone.
            allowed = allowed.min((other - centre).length_squared());
        }
        let weight = need + 0.01;
        if weight < 0.9 * allowed {
            through[column.start] = true;
            seeds[column.start] = Seed {
                at: centre,
                weight,
                name: format!("through {i} {k}"),
            };
            for t in column.start + 1..column.end {
                through[t] = true;
                seeds[t].weight = Real::NAN; // removed below
            }
        }
    }
    seeds.retain(|s| !s.weight.is_nan());
    let margin = spec.stone_size;
    let mut blocks = Vec::with_capacity(seeds.len() + 1);
    blocks.push(
        RigidBlock::cuboid(
            "base",
            Vector::new(-margin, -margin, -margin),
            Vector::new(spec.length + margin, spec.thickness + margin, 0.0),
            spec.density,
        )?
        .with_fixity(Fixity::FIXED)
        .with_material(spec.base_material),
    );
    // The seeds that can bound a cell lie within a few units of its own (the jitter moves seeds
    // by less than half a unit; a through-stone reaches the faces).
    let index = SeedGrid::new(&seeds, 2.5 + 0.5 * ny as Real);
    let mut planes = Vec::new();
    let mut corners = Vec::new();
    for (s, seed) in seeds.iter().enumerate() {
        planes.clear();
        box_planes(grid_size, &mut planes);
        for t in index.near(seed.at) {
            if t != s {
                // Power bisector: 2 (s_t − s_s)·x ≤ |s_t|² − |s_s|² − w_t + w_s.
                let other = &seeds[t];
                let normal = 2.0 * (other.at - seed.at);
                let offset = other.at.length_squared() - seed.at.length_squared() - other.weight + seed.weight;
                planes.push((normal, offset));
            }
        }
        cell_corners(&planes, 1.0, &mut corners);
        for c in &mut corners {
            *c *= spacing;
        }
        blocks.push(RigidBlock::from_vertices(&seed.name, &corners, spec.density)?.with_material(spec.material));
    }
    Ok(blocks)
}

/// A seed of the power diagram (grid units): its point, its weight and its stone's name.
struct Seed {
    at: Vector,
    weight: Real,
    name: String,
}

/// The six faces of the box `[0, size]` as planes `n·x ≤ d`.
fn box_planes(size: Vector, planes: &mut Vec<(Vector, Real)>) {
    planes.extend([
        (-Vector::X, 0.0),
        (Vector::X, size.x),
        (-Vector::Y, 0.0),
        (Vector::Y, size.y),
        (-Vector::Z, 0.0),
        (Vector::Z, size.z),
    ]);
}

/// The corners of the convex polytope `{x : n·x ≤ d}` of `planes` (bounded: the box is among
/// them): every point where three planes meet and that lies within all the others, to a
/// tolerance of `1e-9 × scale`. Corners closer than that to one found before are dropped.
fn cell_corners(planes: &[(Vector, Real)], scale: Real, corners: &mut Vec<Vector>) {
    corners.clear();
    let tolerance = 1e-9 * scale;
    let m = planes.len();
    for a in 0..m {
        for b in a + 1..m {
            let ab = planes[a].0.cross(planes[b].0);
            if ab.length_squared() < 1e-24 * planes[a].0.length_squared() * planes[b].0.length_squared() {
                continue;
            }
            for c in b + 1..m {
                let (na, nb, nc) = (planes[a].0, planes[b].0, planes[c].0);
                let det = na.dot(nb.cross(nc));
                if det.abs() < 1e-12 * na.length() * nb.length() * nc.length() {
                    continue;
                }
                // Cramer's rule for n_a·x = d_a, n_b·x = d_b, n_c·x = d_c.
                let x = (nb.cross(nc) * planes[a].1 + nc.cross(na) * planes[b].1 + na.cross(nb) * planes[c].1) / det;
                let inside = planes.iter().all(|(n, d)| n.dot(x) - d <= tolerance * n.length());
                if inside && corners.iter().all(|p| (*p - x).length() > tolerance) {
                    corners.push(x);
                }
            }
        }
    }
}

/// Seeds in cubic cells of side `reach`, to find those near a point.
struct SeedGrid {
    reach: Real,
    cells: std::collections::HashMap<(i64, i64, i64), Vec<usize>>,
}

impl SeedGrid {
    fn new(seeds: &[Seed], reach: Real) -> Self {
        let mut cells: std::collections::HashMap<(i64, i64, i64), Vec<usize>> = std::collections::HashMap::new();
        for (k, seed) in seeds.iter().enumerate() {
            cells.entry(Self::cell(seed.at, reach)).or_default().push(k);
        }
        Self { reach, cells }
    }

    fn cell(p: Vector, reach: Real) -> (i64, i64, i64) {
        let c = (p / reach).floor();
        (c.x as i64, c.y as i64, c.z as i64)
    }

    /// The seeds within the 27 cells around `p`, in increasing order.
    fn near(&self, p: Vector) -> Vec<usize> {
        let (x, y, z) = Self::cell(p, self.reach);
        let mut found = Vec::new();
        for dx in -1..=1 {
            for dy in -1..=1 {
                for dz in -1..=1 {
                    if let Some(list) = self.cells.get(&(x + dx, y + dy, z + dz)) {
                        found.extend_from_slice(list);
                    }
                }
            }
        }
        found.sort_unstable();
        found
    }
}

/// SplitMix64: a small, well-mixed generator, so that a spec's wall is the same everywhere.
struct SplitMix(u64);

impl SplitMix {
    fn next(&mut self) -> u64 {
        self.0 = self.0.wrapping_add(0x9e37_79b9_7f4a_7c15);
        let mut z = self.0;
        z = (z ^ (z >> 30)).wrapping_mul(0xbf58_476d_1ce4_e5b9);
        z = (z ^ (z >> 27)).wrapping_mul(0x94d0_49bb_1331_11eb);
        z ^ (z >> 31)
    }

    /// Uniform in `[0, 1)`.
    fn unit(&mut self) -> Real {
        (self.next() >> 11) as Real / (1u64 << 53) as Real
    }

    /// Uniform in `[-1, 1)`.
    fn signed(&mut self) -> Real {
        2.0 * self.unit() - 1.0
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::block::Block;

    /// The lowest and highest corner of a block's vertices (world).
    fn bounds(b: &RigidBlock) -> (Vector, Vector) {
        let pose = b.state().pose;
        b.shape().vertices().iter().map(|v| pose.transform_point(*v)).fold(
            (Vector::splat(Real::INFINITY), Vector::splat(Real::NEG_INFINITY)),
            |(lo, hi), p| (lo.min(p), hi.max(p)),
        )
    }

    /// The stones fill the wall's box exactly (no gap, no overlap: Voronoi cells), each stone is
    /// within the box, and the same spec gives the same stones.
    #[test]
    fn stones_fill_the_box_and_are_reproducible() {
        for (jitter, through) in [(0.0, 0.0), (0.3, 0.1), (0.45, 0.5)] {
            let spec = RubbleWallSpec {
                jitter,
                through_stones: through,
                ..RubbleWallSpec::default()
            };
            let blocks = rubble_wall(&spec).expect("wall");
            let volume: Real = blocks[1..].iter().map(|b| b.shape().volume()).sum();
            let expected = spec.length * spec.thickness * spec.height;
            assert!((volume - expected).abs() < 1e-9 * expected, "{volume} vs {expected}");
            for b in &blocks[1..] {
                let (lo, hi) = bounds(b);
                assert!(lo.min_element() > -1e-9 && hi.x < spec.length + 1e-9);
                assert!(hi.y < spec.thickness + 1e-9 && hi.z < spec.height + 1e-9);
            }
            let again = rubble_wall(&spec).expect("wall");
            assert!(blocks
                .iter()
                .zip(&again)
                .all(|(a, b)| a.state().pose == b.state().pose && a.shape().volume() == b.shape().volume()));
        }
    }

    /// Through-stones span the thickness; with none asked for there are none.
    #[test]
    fn through_stones_span_the_thickness() {
        let spec = RubbleWallSpec {
            through_stones: 0.3,
            ..RubbleWallSpec::default()
        };
        let blocks = rubble_wall(&spec).expect("wall");
        let through: Vec<_> = blocks.iter().filter(|b| b.name().starts_with("through")).collect();
        assert!(!through.is_empty());
        for b in through {
            let (lo, hi) = bounds(b);
            assert!(lo.y < 1e-9 && hi.y > spec.thickness - 1e-9, "{}", b.name());
        }
        let none = rubble_wall(&RubbleWallSpec {
            through_stones: 0.0,
            ..spec
        })
        .expect("wall");
        assert!(none.iter().all(|b| !b.name().starts_with("through")));
    }

    #[test]
    fn bad_specs_are_refused() {
        let bad = [
            RubbleWallSpec {
                stone_size: 0.0,
                ..RubbleWallSpec::default()
            },
            RubbleWallSpec {
                jitter: 0.5,
                ..RubbleWallSpec::default()
            },
            RubbleWallSpec {
                through_stones: -0.1,
                ..RubbleWallSpec::default()
            },
            RubbleWallSpec {
                leaves: 0,
                ..RubbleWallSpec::default()
            },
            RubbleWallSpec {
                stone_size: 1e-4,
                ..RubbleWallSpec::default()
            },
        ];
        for spec in bad {
            assert!(
                matches!(
                    rubble_wall(&spec),
                    Err(Error::InvalidParameter { .. } | Error::TooLarge { .. })
                ),
                "{spec:?}"
            );
        }
    }
}
