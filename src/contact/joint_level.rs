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
//! A joint open in part (a hinge) is stepped the same way for its cells closed all over, and
//! cell by cell for one range of its cells that holds the open ones and those the line
//! `g = 0` crosses ([`JointLevel::span`]): the closed cells' moments are the joint's less the
//! range's, and their stick test takes each cell's room at entry, not the largest stress
//! against the weakest corner ([`partial_corners_stick`]).

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

/// A joint open in part enters joint-level stepping when at least one in this many of its
/// cells are stepped as a whole ([`JointLevel::enter_partial`]): each of them saves its cell's
/// step, and the range stepped one by one costs what it would cost anyway, plus one pass for
/// its area moments. With one in two (the first version), 89 % of the static arch's entry
/// attempts failed on a hinge open over more than half of its face; with one in eight its
/// baseline case runs 2.36–2.58 s against 2.71–2.87 s (`docs/performance.md`).
const MIN_CLOSED_SHARE: usize = 8;

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
    /// own, in order) are stepped one by one every step, and the others, all closed, as a
    /// whole; `held` and `field` are theirs, and the rest of what they need is the contact's
    /// [`HingeRecord`]. Empty for a joint closed all over or open all over. (Two `u16` fit in
    /// the record's padding after the flags: a joint of more than 65,535 cells is not stepped
    /// so.)
    #[cfg_attr(feature = "serde", serde(default))]
    pub(crate) span: (u16, u16),
    /// `Σ F⁰ᵢ`, `Σ F⁰ᵢ xᵢ`, `Σ F⁰ᵢ yᵢ` of the shear forces the cells hold (tangent components;
    /// N, N·m, N·m).
    pub(crate) held: [Vector2; 3],
    /// `maxᵢ |F⁰ᵢ|/Aᵢ` (Pa).
    pub(crate) held_stress: Real,
    /// `U_o`, `U_x`, `U_y`: the tangential displacement since the cells were written, as an
    /// affine field over the anchor plane (m, m/m, m/m).
    pub(crate) field: [Vector2; 3],
    /// The normal and shear stiffnesses the joint is stepped with (Pa/m): its law's.
    pub(crate) stiffness: (Real, Real),
    /// The gap coefficients of the last step (`face_gap`), for the cells' gaps and normal forces.
    pub(crate) gap: (Real, Real, Real),
}

/// What a joint open in part ([`JointLevel::span`] not empty) needs besides its
/// [`JointLevel`], set when it enters and read-only until it leaves. Kept in the contact's
/// [`super::ContactReference`], which the step reads only for such joints, so that the record
/// every contact streams through memory at every step does not grow for the few hinges.
#[derive(Debug, Clone, Copy, PartialEq, Default)]
#[cfg_attr(feature = "serde", derive(serde::Serialize, serde::Deserialize))]
#[cfg_attr(feature = "serde", serde(deny_unknown_fields))]
pub(crate) struct HingeRecord {
    /// The box (plane coordinates, lower and upper corner) of the cells stepped as a whole.
    pub(crate) closed_box: (Vector2, Vector2),
    /// The gap coefficients when the joint entered, `g_e`.
    pub(crate) entry_gap: (Real, Real, Real),
    /// The least room the cells stepped as a whole had when the joint entered,
    /// `m = minᵢ (share · (c + tan φ k_n (−g_e(xᵢ, yᵢ))) − |F⁰ᵢ|/Aᵢ)` (Pa): they stick while
    /// `k_s |U| + share · tan φ k_n (g − g_e) ≤ m` at the corners of `closed_box`
    /// ([`partial_corners_stick`]).
    pub(crate) room: Real,
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

/// Whether every cell stepped as a whole of a joint open in part still sticks: at the four
/// corners of the box they cover, `k_s |U| + share · tan φ k_n (g − g_e) ≤ m` for the room `m`
/// and gap `g_e` they had when the joint entered (`hinge`). Each cell had
/// `|F⁰ᵢ|/Aᵢ ≤ share · (c + tan φ k_n (−g_e)) − m`, so the test bounds
/// `|F⁰ᵢ|/Aᵢ + k_s |U|` by `share · (c + tan φ k_n (−g))` at its anchor; the left side less
/// the right is convex in `(x, y)`, so the corners bound every anchor in the box. A per-cell
/// room, where the test of a joint closed all over ([`corners_stick`]) takes the largest stress
/// against the weakest corner: a hinge's cells next to the line `g = 0` carry little compression.
#[inline]
fn partial_corners_stick(
    hinge: &HingeRecord,
    regime: &ElasticRegime,
    g: (Real, Real, Real),
    field: &[Vector2; 3],
) -> bool {
    let (kn, ks) = (regime.normal_stiffness, regime.shear_stiffness);
    let ((lo, hi), entry_gap, room) = (hinge.closed_box, hinge.entry_gap, hinge.room);
    let weakening = STRENGTH_SHARE * regime.tan_friction * kn;
    [(lo.x, lo.y), (hi.x, lo.y), (lo.x, hi.y), (hi.x, hi.y)]
        .into_iter()
        .all(|(x, y)| {
            let left = room - weakening * (face_gap(g, x, y) - face_gap(entry_gap, x, y));
            let u = field[0] + field[1] * x + field[2] * y;
            left >= 0.0 && ks * ks * u.length_squared() <= left * left
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
        (Self::open_over(cells, g) && own.iter().all(unloaded)).then_some(Self {
            active: true,
            open: true,
            gap: g,
            ..Self::default()
        })
    }

    /// Whether the gap `face_gap(g, x, y)` is positive over the whole box the cells cover (its
    /// smallest value is at a corner), by a margin far above the round-off of the cells' own
    /// tests, so that each cell would also find itself open all over.
    #[inline]
    pub(super) fn open_over(cells: &CellSummary, g: (Real, Real, Real)) -> bool {
        let slope = Vector2::new(-g.1, -g.2);
        let (lo, hi) = (slope * cells.lo, slope * cells.hi);
        let smallest = g.0 + lo.x.min(hi.x) + lo.y.min(hi.y);
        let scale = g.0.abs() + (slope.abs() * cells.lo.abs().max(cells.hi.abs())).element_sum();
        smallest > 1e-9 * scale
    }

    /// One step of a joint stepped as a whole because it is open: `true` (and the gap
    /// coefficients kept) while it stays open all over at `g`, else `false` (then its cells must
    /// be written and stepped one by one).
    #[inline]
    pub(super) fn step_open(&mut self, cells: &CellSummary, g: (Real, Real, Real)) -> bool {
        let open = Self::open_over(cells, g);
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

    /// Whether the joint is open in part: some of its cells are stepped one by one.
    #[inline]
    pub(crate) fn is_partial(&self) -> bool {
        self.span.1 > self.span.0
    }

    /// The range of the joint's own cells stepped one by one (empty unless it is open in part).
    #[inline]
    pub(crate) fn span_range(&self) -> std::ops::Range<usize> {
        self.span.0 as usize..self.span.1 as usize
    }

    /// The joint as the cells `own` leave it after a step, when it is open in part (a hinge):
    /// the cells outside one range of them are all closed over their rectangles at the gap
    /// coefficients `g` (slope `slope`), elastic and virgin, cover a box over which the gap is
    /// negative by the margin of [`WholeContact::of`](super::elastic_step::WholeContact::of),
    /// and stick by the corner test over it; they are at least [`MIN_CLOSED_SHARE`] of the cells. The cells
    /// in the range (those the line `g = 0` crosses, the open ones, and any between them) are
    /// stepped one by one. The joint and its [`HingeRecord`]; `None` otherwise (also when every
    /// cell fits: that joint is closed all over, [`JointLevel::enter`]).
    #[inline(never)]
    pub(super) fn enter_partial<S: PartialEq + Default>(
        own: &[SubContact<S>],
        regime: &ElasticRegime,
        g: (Real, Real, Real),
        slope: Vector2,
        kinematics: &Kinematics,
    ) -> Option<(Self, HingeRecord)> {
        let virgin = S::default();
        let fits = |sub: &SubContact<S>| {
            let half = sub.half();
            let spread = slope.x.abs() * half.x + slope.y.abs() * half.y;
            let gap = face_gap(g, sub.plane.x, sub.plane.y);
            sub.status == JointStatus::Elastic && sub.state == virgin && gap < 0.0 && gap <= -spread && sub.area > 0.0
        };
        let first = own.iter().position(|s| !fits(s))?;
        let last = own.iter().rposition(|s| !fits(s)).map_or(first, |l| l + 1);
        let whole = own.len() - (last - first);
        if whole * MIN_CLOSED_SHARE < own.len() || u16::try_from(own.len()).is_err() {
            return None;
        }
        let mut lo = Vector2::splat(Real::INFINITY);
        let mut hi = Vector2::splat(Real::NEG_INFINITY);
        let mut held = [Vector2::ZERO; 3];
        let mut held_stress: Real = 0.0;
        let mut room = Real::INFINITY;
        for sub in own[..first].iter().chain(&own[last..]) {
            let half = sub.half();
            lo = lo.min(sub.plane - half);
            hi = hi.max(sub.plane + half);
            let f = sub.force.shear;
            held[0] += f;
            held[1] += f * sub.plane.x;
            held[2] += f * sub.plane.y;
            let stress = f.length() / sub.area;
            held_stress = held_stress.max(stress);
            let compression = -regime.normal_stiffness * face_gap(g, sub.plane.x, sub.plane.y);
            room = room.min(STRENGTH_SHARE * (regime.cohesion + regime.tan_friction * compression) - stress);
        }
        let hinge = HingeRecord {
            closed_box: (lo, hi),
            entry_gap: g,
            room,
        };
        let closed = super::elastic_step::closed_over(g, (lo, hi));
        // Its cells must have room for two more steps like this one, or the joint would leave
        // again at once (a joint whose cells next to the line `g = 0` stick with nothing to
        // spare, entering and leaving at every step, its cells scanned and written each time).
        let tangential = |v: Vector| Vector2::new(v.y, v.z) * 2.0;
        let ahead = [
            tangential(kinematics.at_origin),
            tangential(kinematics.per_x),
            tangential(kinematics.per_y),
        ];
        let joint = Self {
            active: true,
            open: false,
            span: (first as u16, last as u16),
            held,
            held_stress,
            field: [Vector2::ZERO; 3],
            stiffness: (regime.normal_stiffness, regime.shear_stiffness),
            gap: g,
        };
        (closed && partial_corners_stick(&hinge, regime, g, &ahead)).then_some((joint, hinge))
    }

    /// A cell's force, gap and status as the joint stands (its own when the joint is not
    /// stepped as a whole): what the cell-by-cell step would have left in it, to round-off.
    #[inline]
    pub(crate) fn live<S>(&self, index: usize, sub: &SubContact<S>) -> (JointForce, Real, JointStatus) {
        if !self.active || self.span_range().contains(&index) {
            return (sub.force, sub.gap, sub.status);
        }
        if self.open {
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

    fn cell(x: Real, y: Real, area: Real, shear: Vector2) -> SubContact<CoulombState> {
        SubContact {
            plane: Vector2::new(x, y),
            area,
            gap: -1e-5,
            force: JointForce { normal: 1.0, shear },
            slip: 0.0,
            half: [0.05, 0.05],
            status: JointStatus::Elastic,
            state: CoulombState::default(),
        }
    }

    /// Each of `cells` takes its own elastic step (which must leave it elastic); returns the
    /// sums of their forces.
    fn elastic_steps(
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

    /// A hinge: a 5 × 3 grid of cells (columns contiguous in cell order) whose first column is
    /// open and second crossed by the line `g = 0`. The cells outside the first two columns are
    /// stepped as a whole for 50 steps: their sums (the joint's moments less the span's) and
    /// each cell as the joint gives it are what their own elastic steps give; the corner test
    /// fails before any of them would slide.
    #[test]
    fn a_hinge_steps_its_closed_cells_as_a_whole() {
        let law = CoulombSlip::dry(1e9, 4e8, 30.0).expect("law");
        let regime = law.elastic_regime().expect("regime");
        // `g = −s (x − 0.12)`: open for x < 0.12, closed beyond.
        let s = 1e-4;
        let g = (0.12 * s, s, 0.0);
        let slope = Vector2::new(-g.1, -g.2);
        let mut cells: Vec<_> = (0..15)
            .map(|k| {
                let (x, y) = (0.1 * (k / 3) as Real, 0.1 * (k % 3) as Real);
                let gap = face_gap(g, x, y);
                let mut c = cell(x, y, 0.01, Vector2::ZERO);
                c.gap = gap;
                if x < 0.05 {
                    c.status = JointStatus::Open;
                    c.force = JointForce::default();
                } else {
                    // A tenth of what the anchor's compression allows, varied over the cells.
                    let allowed = 30.0_f64.to_radians().tan() * 1e9 * (-gap).max(0.0) * 0.01;
                    c.force = JointForce {
                        normal: 1e9 * (-gap).max(0.0) * 0.01,
                        shear: Vector2::new(0.1 * allowed, -0.03 * allowed * (k % 3) as Real),
                    };
                }
                c
            })
            .collect();
        let summary = CellSummary::of(&cells);
        let still = Kinematics {
            at_origin: Vector::ZERO,
            per_x: Vector::ZERO,
            per_y: Vector::ZERO,
        };
        let (mut joint, hinge) = JointLevel::enter_partial(&cells, &regime, g, slope, &still).expect("enters");
        assert_eq!(joint.span, (0, 6), "the open and the straddling column");
        assert!((hinge.closed_box.0 - Vector2::new(0.15, -0.05)).length() < 1e-8);
        assert!((hinge.closed_box.1 - Vector2::new(0.45, 0.25)).length() < 1e-8);
        let span = joint.span_range();
        let mut own = cells.clone();
        for step in 0..50 {
            let t = step as Real;
            let kinematics = Kinematics {
                at_origin: Vector::new(0.0, 2e-9 * (0.1 * t).sin(), -1e-9),
                per_x: Vector::new(0.0, 3e-9, 1e-9 * (0.3 * t).cos()),
                per_y: Vector::new(0.0, -1e-9, 2e-9),
            };
            assert!(
                joint.advance(StickTest::Hinge(&hinge), &regime, &kinematics, g),
                "step {step}: sticks"
            );
            let (moments, j) = summary.without(&own[span.clone()]);
            let (joint_sums, _) = joint.sums(&moments, j, None);
            let cell_sums = elastic_steps(&mut cells[span.end..], &regime, &kinematics, g);
            assert!(
                joint_sums.matches(&cell_sums),
                "step {step}: {joint_sums:?} vs {cell_sums:?}"
            );
        }
        for (i, (a, b)) in own.iter().zip(&cells).enumerate() {
            let (force, gap, _) = joint.live(i, a);
            assert!((force.normal - b.force.normal).abs() <= 1e-12 * b.force.normal.abs().max(1.0));
            assert!((force.shear - b.force.shear).length() < 1e-12 * b.force.shear.length().max(1.0));
            assert_eq!(gap.to_bits(), b.gap.to_bits());
        }
        joint.write_cells(&mut own);
        assert!(!joint.active);
        assert_eq!(own[..span.end], cells[..span.end], "the span's cells are their own");

        // Pushed sideways until a cell stepped as a whole would slide: the test fails first.
        let (mut joint, hinge) = JointLevel::enter_partial(&cells, &regime, g, slope, &still).expect("enters");
        let push = Kinematics {
            at_origin: Vector::new(0.0, 1e-8, 0.0),
            per_x: Vector::ZERO,
            per_y: Vector::ZERO,
        };
        let mut steps = 0;
        while joint.advance(StickTest::Hinge(&hinge), &regime, &push, g) {
            steps += 1;
            for c in cells[span.end..].iter_mut() {
                let gap = face_gap(g, c.plane.x, c.plane.y);
                let (force, status) = regime
                    .step(c.area, gap, Vector2::new(1e-8, 0.0), c.force.shear)
                    .expect("regime");
                assert_eq!(
                    status,
                    JointStatus::Elastic,
                    "step {steps}: a cell the joint holds slides"
                );
                c.force = force;
            }
            assert!(steps < 100_000, "never left");
        }
        // The weakest cell, next to the line, had 0.9 of its strength to spare.
        assert!(steps > 0);
    }
}
