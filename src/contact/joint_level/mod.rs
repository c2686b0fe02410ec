//! Joint-level stepping: a face-face joint whose cells are all closed, virgin and sticking is
//! stepped as a whole, in a number of operations that does not depend on its cells, and its
//! cells are written only when it leaves that state or a reader asks
//! (`docs/theory.md` §3.1, "Joints that stick, stepped as a whole").
//!
//! While a joint sticks, each cell `i` (anchor `(xᵢ, yᵢ)`, area `Aᵢ`) follows its law's elastic
//! regime ([`ElasticRegime`]):
//! - its normal force is `Nᵢ = −k_n Aᵢ g(xᵢ, yᵢ)`, with the gap `g = g_o − g_x x − g_y y` of the
//!   blocks' current poses: it has no history;
//! - its shear force is `Fᵢ = F⁰ᵢ − k_s Aᵢ U(xᵢ, yᵢ)`, where `F⁰ᵢ` is what the cell held when it
//!   was last written and `U = U_o + x U_x + y U_y` the sum of the steps' tangential
//!   displacement increments since, an affine field because each increment is.
//!
//! So the joint's force and moments follow from the cells' area moments (`Σ A`, `Σ A x`, …,
//! [`CellSummary::area_moments`]) and the sums `Σ F⁰ᵢ`, `Σ F⁰ᵢ xᵢ`, `Σ F⁰ᵢ yᵢ`, kept here. The
//! Coulomb condition of a cell, `|Fᵢ| ≤ c Aᵢ + tan φ Nᵢ`, holds if
//! `τ⁰ + k_s |U(xᵢ, yᵢ)| ≤ c + tan φ k_n (−g(xᵢ, yᵢ))` with `τ⁰ = maxᵢ |F⁰ᵢ|/Aᵢ`; the left side
//! less the right is convex in `(x, y)` (a norm of an affine field plus an affine function), so
//! it holds at every anchor if it holds at the four corners of the box the cells cover. When
//! it fails at a corner, the joint's cells are written and the cell-by-cell step takes over.
//!
//! A joint open in part (a hinge, `hinge.rs`) is stepped the same way for its cells closed
//! all over, as a joint open all over is for its open cells at one end, and cell by cell for
//! one range of its cells that holds those the line `g = 0` crosses ([`JointLevel::span`]):
//! the closed cells' moments are the joint's less the other cells', and their stick test takes
//! each cell's room at entry, not the largest stress against the weakest corner
//! ([`partial_corners_stick`]).

mod hinge;

use hinge::partial_corners_stick;
pub(crate) use hinge::{HingeRecord, SpanEnds};

use super::lanes::{face_gap, Kinematics};
use super::moments::ForceMoments;
use super::spread::ExactCells;
use super::{CellSummary, SubContact};
use crate::law::{ElasticRegime, JointForce, JointStatus};
use crate::math::{Real, Vector, Vector2};

/// How much of the strength a corner's bound may reach and the joint still be stepped as a
/// whole: a margin far above the round-off of the bound, so that a cell the joint-level step
/// keeps sticking sticks by the cells' own test too.
const STRENGTH_SHARE: Real = 1.0 - 1e-9;

/// A face-face joint stepped as a whole while it is closed and sticking (see the module's
/// documentation). Kept in its [`super::ContactPair`], so that it moves with it.
#[derive(Debug, Clone, Copy, PartialEq, Default)]
#[cfg_attr(feature = "serde", derive(serde::Serialize, serde::Deserialize))]
#[cfg_attr(feature = "serde", serde(deny_unknown_fields))]
pub(crate) struct JointLevel {
    /// Whether the joint is stepped as a whole: then its cells hold their shear forces as they
    /// were when last written (`F⁰ᵢ`), and [`JointLevel::live`] gives their forces now.
    pub(crate) active: bool,
    /// Whether the joint is stepped as a whole because it is open all over (every cell open,
    /// unloaded and virgin, the gap positive over the whole box, a law that keeps a virgin cell
    /// open at any opening): its cells carry nothing, and only their gaps change.
    pub(crate) open: bool,
    /// A joint open in part (a hinge): its cells `span.0..span.1` (indices among the joint's
    /// own, in order) are stepped one by one every step, and the others as a whole: those
    /// closed all over, whose `held` and `field` these are, and, at one end, those open all
    /// over ([`JointLevel::ends`]); the rest of what they need is the contact's
    /// [`HingeRecord`]. Empty for a joint closed all over or open all over. (Two `u16` fit in
    /// the record's padding after the flags: a joint of more than 65,535 cells is not stepped
    /// so.)
    #[cfg_attr(feature = "serde", serde(default))]
    pub(crate) span: (u16, u16),
    /// Of a joint open in part: whether the cells outside the span at one end are open all
    /// over (unloaded, virgin), stepped as a whole too, carrying nothing, rather than closed
    /// ([`SpanEnds`]). One byte, in the padding with the span.
    #[cfg_attr(feature = "serde", serde(default))]
    pub(crate) ends: SpanEnds,
    /// `Σ F⁰ᵢ`, `Σ F⁰ᵢ xᵢ`, `Σ F⁰ᵢ yᵢ` of the shear forces the cells hold (tangent components;
    /// N, N·m, N·m).
    pub(crate) held: [Vector2; 3],
    /// `maxᵢ |F⁰ᵢ|/Aᵢ` (Pa): the corner test's `τ⁰`. Of a hinge, over its closed cells stepped
    /// as a whole, for the record: its stick test reads each cell's room at entry instead
    /// ([`HingeRecord`]).
    pub(crate) held_stress: Real,
    /// `U_o`, `U_x`, `U_y`: the tangential displacement since the cells were written, as an
    /// affine field over the anchor plane (m, m/m, m/m).
    pub(crate) field: [Vector2; 3],
    /// The normal and shear stiffnesses the joint is stepped with (Pa/m): its law's.
    pub(crate) stiffness: (Real, Real),
    /// The gap coefficients of the last step (`face_gap`), for the cells' gaps and normal forces.
    pub(crate) gap: (Real, Real, Real),
}

/// Whether every cell of a joint whose cells are all closed at the gap coefficients `g` sticks
/// by the corner test (module documentation): `τ⁰ + k_s |U| ≤ share · (c + tan φ k_n (−g))` at
/// the four corners of the box the cells cover, for the largest stress the cells hold, `τ⁰`
/// (`held_stress`), and the tangential displacement field `U` since (`field`).
#[inline]
fn corners_stick(
    (lo, hi): (Vector2, Vector2),
    regime: &ElasticRegime,
    g: (Real, Real, Real),
    held_stress: Real,
    field: &[Vector2; 3],
) -> bool {
    let (kn, ks) = (regime.normal_stiffness, regime.shear_stiffness);
    [(lo.x, lo.y), (hi.x, lo.y), (lo.x, hi.y), (hi.x, hi.y)]
        .into_iter()
        .all(|(x, y)| {
            let compression = -kn * face_gap(g, x, y);
            let strength = regime.cohesion + regime.tan_friction * compression;
            // `τ⁰ + k_s |U| ≤ share · strength`, squared to spare the square root: the room left
            // above `τ⁰` must not be negative, nor NaN (which fails both tests).
            let room = STRENGTH_SHARE * strength - held_stress;
            let u = field[0] + field[1] * x + field[2] * y;
            room >= 0.0 && ks * ks * u.length_squared() <= room * room
        })
}

/// Which corner test a step of the cells stepped as a whole takes ([`JointLevel::advance`]).
#[derive(Clone, Copy)]
pub(super) enum StickTest<'a> {
    /// A joint closed all over, whose cells cover this box: the largest stress they hold
    /// against the weakest corner ([`corners_stick`]).
    Closed((Vector2, Vector2)),
    /// A joint open in part: each cell's room at entry ([`partial_corners_stick`]).
    Hinge(&'a HingeRecord),
}

impl JointLevel {
    /// The joint as the cells `own` leave it after a step in which every one of them took its
    /// law's elastic step (`regime`) as a virgin cell, all closed, and stayed
    /// [`JointStatus::Elastic`], with gap coefficients `gap`; `shear_sums` are the step's sums of
    /// their shear forces. `None` when a cell does not fit (a slide, a state, a zero area that
    /// holds a force), or when the joint as it stands already fails the corner test over the
    /// box of its cells (`cells`): its next joint-level step, which begins with that test, would
    /// hand it back to its cells (a joint closed by round-off and carrying next to nothing, whose
    /// cells stick one by one but whose corners have no strength to spare).
    pub(super) fn enter<S: PartialEq + Default>(
        own: &[SubContact<S>],
        cells: &CellSummary,
        regime: &ElasticRegime,
        gap: (Real, Real, Real),
        shear_sums: [Vector2; 3],
    ) -> Option<Self> {
        let virgin = S::default();
        let mut held_stress: Real = 0.0;
        for sub in own {
            if sub.status != JointStatus::Elastic || sub.state != virgin {
                return None;
            }
            let shear = sub.force.shear.length();
            let stress = if sub.area > 0.0 {
                shear / sub.area
            } else if shear == 0.0 {
                0.0
            } else {
                return None;
            };
            held_stress = held_stress.max(stress);
        }
        let sticks = corners_stick((cells.lo, cells.hi), regime, gap, held_stress, &[Vector2::ZERO; 3]);
        sticks.then_some(Self {
            active: true,
            open: false,
            span: (0, 0),
            ends: SpanEnds::Closed,
            held: shear_sums,
            held_stress,
            field: [Vector2::ZERO; 3],
            stiffness: (regime.normal_stiffness, regime.shear_stiffness),
            gap,
        })
    }

    /// The joint as the cells `own` leave it after a step at gap coefficients `g` over which
    /// the box of the cells (`cells`) is open ([`JointLevel::open_over`]), when every cell is
    /// open, unloaded and virgin (the law keeping virgin cells open at any opening is the
    /// caller's to know); `None` otherwise.
    pub(super) fn enter_open<S: PartialEq + Default>(
        own: &[SubContact<S>],
        cells: &CellSummary,
        g: (Real, Real, Real),
    ) -> Option<Self> {
        let virgin = S::default();
        let unloaded = |sub: &SubContact<S>| {
            sub.status == JointStatus::Open
                && sub.force.normal == 0.0
                && sub.force.shear == Vector2::ZERO
                && sub.state == virgin
        };
        (Self::open_over((cells.lo, cells.hi), g) && own.iter().all(unloaded)).then_some(Self {
            active: true,
            open: true,
            gap: g,
            ..Self::default()
        })
    }

    /// Whether the gap `face_gap(g, x, y)` is positive over the whole box `(lo, hi)` (its
    /// smallest value is at a corner), by a margin far above the round-off of the cells' own
    /// tests, so that each cell would also find itself open all over.
    #[inline]
    pub(crate) fn open_over((lo, hi): (Vector2, Vector2), g: (Real, Real, Real)) -> bool {
        let slope = Vector2::new(-g.1, -g.2);
        let (low, high) = (slope * lo, slope * hi);
        let smallest = g.0 + low.x.min(high.x) + low.y.min(high.y);
        let scale = g.0.abs() + (slope.abs() * lo.abs().max(hi.abs())).element_sum();
        smallest > 1e-9 * scale
    }

    /// One step of a joint stepped as a whole because it is open: `true` (and the gap
    /// coefficients kept) while it stays open all over at `g`, else `false` (then its cells must
    /// be written and stepped one by one).
    #[inline]
    pub(super) fn step_open(&mut self, cells: &CellSummary, g: (Real, Real, Real)) -> bool {
        let open = Self::open_over((cells.lo, cells.hi), g);
        if open {
            self.gap = g;
        }
        open
    }

    /// One step of a joint whose cells are all closed at the gap coefficients `g`: adds the
    /// step's tangential increments (`kinematics`) to the field and, if every cell still sticks
    /// by the corner test, returns the spring-force sums in the joint axes and the spread
    /// energy, as the cells would give them to round-off. `None` (and nothing changed) when a
    /// corner fails, or the regime is not the one the joint was entered with: then the cells
    /// must be written ([`JointLevel::write_cells`]) and stepped one by one.
    #[inline]
    pub(super) fn step(
        &mut self,
        cells: &CellSummary,
        regime: &ElasticRegime,
        kinematics: &Kinematics,
        g: (Real, Real, Real),
        exact: Option<ExactCells>,
    ) -> Option<(ForceMoments, Real)> {
        self.advance(StickTest::Closed((cells.lo, cells.hi)), regime, kinematics, g)
            .then(|| self.sums(&cells.area_moments, cells.closed_moments, exact))
    }

    /// The first half of a step of the cells stepped as a whole: adds the step's tangential
    /// increments (`kinematics`) to the field and takes the gap coefficients `g` if every cell
    /// still sticks by the corner test `test` (and the regime is the one the joint was entered
    /// with); `false`, and nothing changed, otherwise.
    #[inline(always)]
    pub(super) fn advance(
        &mut self,
        test: StickTest<'_>,
        regime: &ElasticRegime,
        kinematics: &Kinematics,
        g: (Real, Real, Real),
    ) -> bool {
        let (kn, ks) = self.stiffness;
        if (kn, ks) != (regime.normal_stiffness, regime.shear_stiffness) {
            return false;
        }
        let tangential = |v: Vector| Vector2::new(v.y, v.z);
        let field = [
            self.field[0] + tangential(kinematics.at_origin),
            self.field[1] + tangential(kinematics.per_x),
            self.field[2] + tangential(kinematics.per_y),
        ];
        let sticks = match test {
            StickTest::Closed(cells_box) => corners_stick(cells_box, regime, g, self.held_stress, &field),
            StickTest::Hinge(hinge) => partial_corners_stick(hinge, regime, g, &field),
        };
        if !sticks {
            return false;
        }
        self.field = field;
        self.gap = g;
        true
    }

    /// The spring-force sums in the joint axes and the spread energy of the cells stepped as a
    /// whole, whose area moments are `area_moments` and `Σ J` `closed_moments`
    /// ([`CellSummary`]), at the field and gap of the last [`JointLevel::advance`].
    #[inline(always)]
    pub(super) fn sums(
        &self,
        area_moments: &[Real; 6],
        closed_moments: Vector2,
        exact: Option<ExactCells>,
    ) -> (ForceMoments, Real) {
        let (kn, ks) = self.stiffness;
        let (g, field) = (self.gap, self.field);
        let [a, ax, ay, axx, axy, ayy] = *area_moments;
        // Σ Nᵢ (1, xᵢ, yᵢ) with Nᵢ = −k_n Aᵢ (g_o − g_x xᵢ − g_y yᵢ).
        let normal = |m0: Real, mx: Real, my: Real| -kn * ((g.0 * m0 - g.1 * mx) - g.2 * my);
        // Σ Fᵢ (1, xᵢ, yᵢ) with Fᵢ = F⁰ᵢ − k_s Aᵢ (U_o + U_x xᵢ + U_y yᵢ).
        let shear =
            |held: Vector2, m0: Real, mx: Real, my: Real| held - ((field[0] * m0 + field[1] * mx) + field[2] * my) * ks;
        let joint = |n: Real, s: Vector2| Vector::new(n, s.x, s.y);
        let mut sums = ForceMoments {
            force: joint(normal(a, ax, ay), shear(self.held[0], a, ax, ay)),
            per_x: joint(normal(ax, axx, axy), shear(self.held[1], ax, axx, axy)),
            per_y: joint(normal(ay, axy, ayy), shear(self.held[2], ay, axy, ayy)),
        };
        // The cells' own second moments about their centres (`−k_n s Σ J` and
        // `½ k_n (J_xx s_x² + J_yy s_y²)`), for a law whose virgin cells are integrated exactly,
        // as the cell-by-cell step adds them (`elastic_step.rs`).
        let mut spread_energy = 0.0;
        if let Some(e) = exact.filter(|e| e.virgin_without_tension) {
            let j = closed_moments;
            sums.per_x.x -= e.normal_stiffness * e.slope.x * j.x;
            sums.per_y.x -= e.normal_stiffness * e.slope.y * j.y;
            spread_energy = 0.5 * e.normal_stiffness * (j.x * e.slope.x * e.slope.x + j.y * e.slope.y * e.slope.y);
        }
        (sums, spread_energy)
    }
    /// Whether the joint's cell `index` is stepped as a whole and open (carrying nothing):
    /// every cell of a joint open all over, and those at a hinge's open end ([`SpanEnds`]).
    #[inline]
    pub(crate) fn holds_open(&self, index: usize) -> bool {
        self.open
            || match self.ends {
                SpanEnds::Closed => false,
                SpanEnds::OpenBefore => index < usize::from(self.span.0),
                SpanEnds::OpenAfter => index >= usize::from(self.span.1),
            }
    }

    /// A cell's force, gap and status as the joint stands (its own when the joint is not
    /// stepped as a whole): what the cell-by-cell step would have left in it, to round-off.
    #[inline]
    pub(crate) fn live<S>(&self, index: usize, sub: &SubContact<S>) -> (JointForce, Real, JointStatus) {
        if !self.active || self.span_range().contains(&index) {
            return (sub.force, sub.gap, sub.status);
        }
        if self.holds_open(index) {
            // As the cells' own loop keeps an open cell (`elastic_step::stays_open_cell`): the
            // gap at its corner nearest to closing.
            let half = sub.half();
            let spread = self.gap.1.abs() * half.x + self.gap.2.abs() * half.y;
            let gap = face_gap(self.gap, sub.plane.x, sub.plane.y) - spread;
            return (sub.force, gap, JointStatus::Open);
        }
        let (kn, ks) = self.stiffness;
        let (x, y) = (sub.plane.x, sub.plane.y);
        let u = (self.field[0] + self.field[1] * x) + self.field[2] * y;
        let gap = face_gap(self.gap, x, y);
        // As `ElasticRegime::step`: `(−k_n g) A`, `F_s − u (k_s A)`.
        let force = JointForce {
            normal: -kn * gap * sub.area,
            shear: sub.force.shear - u * (ks * sub.area),
        };
        (force, gap, JointStatus::Elastic)
    }

    /// Writes the joint's cells `own` as they stand ([`JointLevel::live`]) and leaves
    /// joint-level stepping: the cells hold the joint's history again.
    pub(crate) fn write_cells<S>(&mut self, own: &mut [SubContact<S>]) {
        if !self.active {
            return;
        }
        for (i, sub) in own.iter_mut().enumerate() {
            (sub.force, sub.gap, sub.status) = self.live(i, sub);
        }
        *self = Self::default();
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::law::{ConstitutiveLaw, CoulombSlip, CoulombState};

    pub(super) fn cell(x: Real, y: Real, area: Real, shear: Vector2) -> SubContact<CoulombState> {
        SubContact {
            plane: Vector2::new(x, y),
            area,
            gap: -1e-5,
            force: JointForce { normal: 1.0, shear },
            slip: 0.0,
            half: [0.05, 0.05],
            status: JointStatus::Elastic,
            cell: [0; 2],
            state: CoulombState::default(),
        }
    }

    /// Each of `cells` takes its own elastic step (which must leave it elastic); returns the
    /// sums of their forces.
    pub(super) fn elastic_steps(
        cells: &mut [SubContact<CoulombState>],
        regime: &ElasticRegime,
        kinematics: &Kinematics,
        g: (Real, Real, Real),
    ) -> ForceMoments {
        let mut sums = ForceMoments::default();
        for c in cells.iter_mut() {
            let [_, d1, d2] = super::super::lanes::increment(kinematics, c.plane.x, c.plane.y);
            let gap = face_gap(g, c.plane.x, c.plane.y);
            let (force, status) = regime
                .step(c.area, gap, Vector2::new(d1, d2), c.force.shear)
                .expect("regime");
            assert_eq!(status, JointStatus::Elastic);
            c.force = force;
            c.gap = gap;
            sums.add_joint(&force, c.plane);
        }
        sums
    }

    /// A 4 × 3 grid of cells stepped as a whole for 50 steps gives, cell by cell, what the
    /// elastic regime's own step gives each cell, and the sums of those forces.
    #[test]
    fn the_joint_gives_each_cell_what_its_own_steps_give() {
        let law = CoulombSlip::new(1e9, 4e8, 35.0, 30.0, 2e5, 1e5).expect("law");
        let regime = law.elastic_regime().expect("regime");
        let mut cells: Vec<_> = (0..12)
            .map(|k| {
                let (x, y) = (0.1 * (k % 4) as Real, 0.1 * (k / 4) as Real);
                cell(
                    x,
                    y,
                    0.01 * (1.0 + 0.1 * k as Real),
                    Vector2::new(3.0 - 0.5 * k as Real, 0.2 * k as Real),
                )
            })
            .collect();
        let summary = CellSummary::of(&cells);
        let g = (-2e-5, 1e-5, -3e-5);
        let mut sums = ForceMoments::default();
        for c in &cells {
            sums.add_joint(&c.force, c.plane);
        }
        let held = [
            Vector2::new(sums.force.y, sums.force.z),
            Vector2::new(sums.per_x.y, sums.per_x.z),
            Vector2::new(sums.per_y.y, sums.per_y.z),
        ];
        let mut joint = JointLevel::enter(&cells, &summary, &regime, g, held).expect("enters");
        let mut own = cells.clone();
        for step in 0..50 {
            let t = step as Real;
            let kinematics = Kinematics {
                at_origin: Vector::new(0.0, 1e-9 * (0.1 * t).sin(), -2e-9),
                per_x: Vector::new(0.0, 3e-9, 1e-9 * (0.3 * t).cos()),
                per_y: Vector::new(0.0, -1e-9, 2e-9),
            };
            let (joint_sums, _) = joint.step(&summary, &regime, &kinematics, g, None).expect("sticks");
            let cell_sums = elastic_steps(&mut cells, &regime, &kinematics, g);
            assert!(
                joint_sums.matches(&cell_sums),
                "step {step}: {joint_sums:?} vs {cell_sums:?}"
            );
        }
        joint.write_cells(&mut own);
        assert!(!joint.active);
        for (a, b) in own.iter().zip(&cells) {
            assert_eq!(a.force.normal, b.force.normal, "normal forces have no history");
            assert_eq!(a.gap, b.gap);
            assert!((a.force.shear - b.force.shear).length() < 1e-12 * b.force.shear.length().max(1.0));
        }
    }

    /// The corner test fails as soon as a cell would slide, and not long before: a joint pushed
    /// sideways leaves joint-level stepping at the step the first cell's shear reaches its
    /// strength, within the test's margin.
    #[test]
    fn the_corner_test_fails_when_a_cell_would_slide() {
        let law = CoulombSlip::dry(1e9, 4e8, 30.0).expect("law");
        let regime = law.elastic_regime().expect("regime");
        let cells: Vec<_> = (0..9)
            .map(|k| cell(0.1 * (k % 3) as Real, 0.1 * (k / 3) as Real, 0.01, Vector2::ZERO))
            .collect();
        let summary = CellSummary::of(&cells);
        // A uniform gap: every cell carries 1e4 N, and slides at 1e4 tan 30° N.
        let g = (-1e-3, 0.0, 0.0);
        let mut joint = JointLevel::enter(&cells, &summary, &regime, g, [Vector2::ZERO; 3]).expect("enters");
        let per_step = 1e-6;
        let kinematics = Kinematics {
            at_origin: Vector::new(0.0, per_step, 0.0),
            per_x: Vector::ZERO,
            per_y: Vector::ZERO,
        };
        let strength = 1e4 * 30.0_f64.to_radians().tan();
        let slides_at = strength / (4e8 * 0.01 * per_step);
        let mut steps = 0;
        while joint.step(&summary, &regime, &kinematics, g, None).is_some() {
            steps += 1;
            assert!(steps < 10_000, "never left");
        }
        assert!(
            (steps as Real - slides_at.floor()).abs() <= 1.0,
            "{steps} vs {slides_at}"
        );
    }

    /// A joint enters joint-level stepping only if its corners pass the test as it stands: one
    /// tilted so that its far corners barely touch, with its middle cells holding nearly the
    /// shear their own compression allows (or half of it), sticks cell by cell but would fail
    /// at a corner, and stays with its cells; the same joint holding 1e-4 of that shear, which
    /// its far corners can carry, enters.
    #[test]
    fn a_joint_whose_corners_already_fail_stays_with_its_cells() {
        let law = CoulombSlip::dry(1e9, 4e8, 30.0).expect("law");
        let regime = law.elastic_regime().expect("regime");
        let tan = 30.0_f64.to_radians().tan();
        // The cells' box spans x in [−0.05, 0.25] (anchors 0.1 apart, half sizes 0.05): closed
        // by 1e-6 m at x = −0.05 and by 1e-9 m at x = 0.25, `g = g_o − g_x x`.
        let slope = (1e-6 - 1e-9) / 0.3;
        let g = (-1e-6 + 0.05 * slope, -slope, 0.0);
        let joint_with = |share: Real| {
            let cells: Vec<_> = (0..9)
                .map(|k| {
                    let (x, y) = (0.1 * (k % 3) as Real, 0.1 * (k / 3) as Real);
                    // The middle column's cells hold `share` of what their compression allows.
                    let closed = -face_gap(g, x, y);
                    let shear = if k % 3 == 1 {
                        share * tan * 1e9 * closed * 0.01
                    } else {
                        0.0
                    };
                    cell(x, y, 0.01, Vector2::new(shear, 0.0))
                })
                .collect();
            let summary = CellSummary::of(&cells);
            JointLevel::enter(&cells, &summary, &regime, g, [Vector2::ZERO; 3])
        };
        assert!(
            joint_with(0.99).is_none(),
            "its far corners cannot hold the middle's stress"
        );
        // The far corners carry 1e-9 / 5e-7 of the middle's compression: half the middle's
        // allowance is still far above their strength.
        assert!(joint_with(0.5).is_none());
        assert!(
            joint_with(1e-4).is_some(),
            "a joint with strength to spare at its corners enters"
        );
        assert!(joint_with(0.0).is_some());
    }
}
