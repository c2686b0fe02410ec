//! Joints open in part (hinges): the cells closed over their rectangles stepped as a whole
//! while they stick, the open ones while they stay open, and one range of cells (those the
//! line `g = 0` crosses) one by one (`docs/theory.md` §3.1, "Joints open in part").

use super::{JointLevel, STRENGTH_SHARE};
use crate::contact::lanes::{face_gap, Kinematics};
use crate::contact::{CellSummary, SubContact};
use crate::law::{ElasticRegime, JointStatus};
use crate::math::{Real, Vector, Vector2};

/// A joint open in part enters joint-level stepping when at least one in this many of its
/// cells are stepped as a whole ([`JointLevel::enter_partial`]): each of them saves its cell's
/// step, and the range stepped one by one costs what it would cost anyway, plus one pass for
/// its area moments. With one in two (the first version), 89 % of the static arch's entry
/// attempts failed on a hinge open over more than half of its face; with one in eight its
/// baseline case runs 2.36–2.58 s against 2.71–2.87 s (`docs/performance.md`).
const MIN_CLOSED_SHARE: usize = 8;

/// Which cells of a joint open in part lie outside its span at either end
/// ([`JointLevel::span`]): the cells closed all over, stepped as a whole while they stick, are
/// at both ends or at one; in the second case the other end may hold the joint's open cells,
/// stepped as a whole while the gap stays positive over their box
/// ([`HingeRecord::open_box`]): a hinge whose line `g = 0` runs along the face grid's columns
/// (contiguous in cell order) leaves only the column it crosses to be stepped one by one.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Default)]
#[cfg_attr(feature = "serde", derive(serde::Serialize, serde::Deserialize))]
#[cfg_attr(feature = "serde", serde(rename_all = "snake_case"))]
pub(crate) enum SpanEnds {
    /// Closed cells at both ends (or at one, the span reaching the other end).
    #[default]
    Closed,
    /// The cells before the span are open, those after it closed.
    OpenBefore,
    /// The cells before the span are closed, those after it open.
    OpenAfter,
}

/// What a joint open in part ([`JointLevel::span`] not empty) needs besides its
/// [`JointLevel`], set when it enters and read-only until it leaves. Kept in the contact's
/// [`ContactReference`](crate::contact::ContactReference), which the step reads only for such joints, so that the record
/// every contact streams through memory at every step does not grow for the few hinges.
#[derive(Debug, Clone, Copy, PartialEq, Default)]
#[cfg_attr(feature = "serde", derive(serde::Serialize, serde::Deserialize))]
#[cfg_attr(feature = "serde", serde(deny_unknown_fields))]
pub(crate) struct HingeRecord {
    /// The box (plane coordinates, lower and upper corner) of the closed cells stepped as a
    /// whole. Derived from the cells like the fields below ([`HingeRecord::measure`]), so not
    /// written; files of version 15 hold it, and it is measured again when they are read.
    #[cfg_attr(feature = "serde", serde(default, skip_serializing))]
    pub(crate) closed_box: (Vector2, Vector2),
    /// The gap coefficients when the joint entered, `g_e`.
    pub(crate) entry_gap: (Real, Real, Real),
    /// The least room the closed cells stepped as a whole had when the joint entered,
    /// `m = minᵢ (share · (c + tan φ k_n (−g_e(xᵢ, yᵢ))) − |F⁰ᵢ|/Aᵢ)` (Pa): they stick while
    /// `k_s |U| + share · tan φ k_n (g − g_e) ≤ m` at the corners of `closed_box`
    /// ([`partial_corners_stick`]).
    pub(crate) room: Real,
    /// The box of the cells stepped as a whole because they are open ([`SpanEnds`]; empty
    /// when there are none): the gap must stay positive over it
    /// ([`JointLevel::open_over`]). Derived from the cells (at entry, and when a checkpoint is
    /// read), not stored.
    #[cfg_attr(feature = "serde", serde(skip))]
    pub(crate) open_box: (Vector2, Vector2),
    /// The area moments and `Σ J` ([`CellSummary`]) of the closed cells stepped as a whole:
    /// the joint's less those of its other cells, summed in their order. Geometric, so taken
    /// once when the joint enters (or a checkpoint is read), not at every step. Not stored.
    #[cfg_attr(feature = "serde", serde(skip))]
    pub(crate) closed_moments: ([Real; 6], Vector2),
}

impl HingeRecord {
    /// Sets what the record derives from the joint's cells `own` (their summary `cells`) and
    /// its `joint` record: the closed cells' box and moments and the open cells' box.
    pub(crate) fn measure<S>(&mut self, own: &[SubContact<S>], cells: &CellSummary, joint: &JointLevel) {
        let (span, n) = (joint.span_range(), own.len());
        let (others, open) = match joint.ends {
            SpanEnds::Closed => (span.clone(), 0..0),
            SpanEnds::OpenBefore => (0..span.end, 0..span.start),
            SpanEnds::OpenAfter => (span.start..n, span.end..n),
        };
        self.closed_moments = cells.without(&own[others]);
        let open = CellSummary::of(&own[open]);
        self.open_box = (open.lo, open.hi);
        let (before, after) = match joint.ends {
            SpanEnds::Closed => (0..span.start, span.end..n),
            SpanEnds::OpenBefore => (0..0, span.end..n),
            SpanEnds::OpenAfter => (0..span.start, n..n),
        };
        let (before, after) = (CellSummary::of(&own[before]), CellSummary::of(&own[after]));
        self.closed_box = (before.lo.min(after.lo), before.hi.max(after.hi));
    }
}

/// Whether every closed cell stepped as a whole of a joint open in part still sticks: at the four
/// corners of the box they cover, `k_s |U| + share · tan φ k_n (g − g_e) ≤ m` for the room `m`
/// and gap `g_e` they had when the joint entered (`hinge`). Each cell had
/// `|F⁰ᵢ|/Aᵢ ≤ share · (c + tan φ k_n (−g_e)) − m`, so the test bounds
/// `|F⁰ᵢ|/Aᵢ + k_s |U|` by `share · (c + tan φ k_n (−g))` at its anchor; the left side less
/// the right is convex in `(x, y)`, so the corners bound every anchor in the box. A per-cell
/// room, where the test of a joint closed all over ([`corners_stick`](super::corners_stick)) takes the largest stress
/// against the weakest corner: a hinge's cells next to the line `g = 0` carry little compression.
#[inline]
pub(super) fn partial_corners_stick(
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

impl JointLevel {
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
    /// negative by the margin of [`WholeContact::of`](crate::contact::elastic_step::WholeContact::of),
    /// and stick by the corner test over it; they are at least [`MIN_CLOSED_SHARE`] of the
    /// cells. When they are all at one end, the cells at the other end that are open over
    /// their rectangles, unloaded and virgin, with the gap positive over their box
    /// ([`JointLevel::open_over`]), are stepped as a whole too ([`SpanEnds`]; the law keeping
    /// a virgin cell open at any opening is the caller's to know). The cells left in the range
    /// (those the line `g = 0` crosses, and any between them and the others) are stepped one
    /// by one. The joint and its [`HingeRecord`] (measured over `cells`, the joint's summary);
    /// `None` otherwise (also when every cell fits: that joint is closed all over,
    /// [`JointLevel::enter`]).
    #[inline(never)]
    pub(in crate::contact) fn enter_partial<S: PartialEq + Default>(
        own: &[SubContact<S>],
        cells: &CellSummary,
        regime: &ElasticRegime,
        g: (Real, Real, Real),
        slope: Vector2,
        kinematics: &Kinematics,
    ) -> Option<(Self, HingeRecord)> {
        let virgin = S::default();
        let spread = |sub: &SubContact<S>| {
            let half = sub.half();
            slope.x.abs() * half.x + slope.y.abs() * half.y
        };
        let fits = |sub: &SubContact<S>| {
            let gap = face_gap(g, sub.plane.x, sub.plane.y);
            sub.status == JointStatus::Elastic
                && sub.state == virgin
                && gap < 0.0
                && gap <= -spread(sub)
                && sub.area > 0.0
        };
        // As `elastic_step::stays_open_cell` keeps a cell open.
        let open_fits = |sub: &&SubContact<S>| {
            let (gap, spread) = (face_gap(g, sub.plane.x, sub.plane.y), spread(sub));
            sub.status == JointStatus::Open
                && sub.force.normal == 0.0
                && sub.force.shear == Vector2::ZERO
                && sub.state == virgin
                && gap >= spread
                && gap - spread > 0.0
        };
        let n = own.len();
        let first = own.iter().position(|s| !fits(s))?;
        let last = own.iter().rposition(|s| !fits(s)).map_or(first, |l| l + 1);
        let whole = n - (last - first);
        if whole * MIN_CLOSED_SHARE < n || u16::try_from(n).is_err() {
            return None;
        }
        // The open cells at the end the closed ones leave, one at least kept in the range.
        let (mut ends, mut span) = (SpanEnds::Closed, (first, last));
        if first == 0 {
            let open = own[..last - 1].iter().take_while(open_fits).count();
            if open > 0 {
                (ends, span) = (SpanEnds::OpenBefore, (open, last));
            }
        } else if last == n {
            let open = own[first + 1..].iter().rev().take_while(open_fits).count();
            if open > 0 {
                (ends, span) = (SpanEnds::OpenAfter, (first, n - open));
            }
        }
        let mut held = [Vector2::ZERO; 3];
        let mut held_stress: Real = 0.0;
        let mut room = Real::INFINITY;
        for sub in own[..first].iter().chain(&own[last..]) {
            let f = sub.force.shear;
            held[0] += f;
            held[1] += f * sub.plane.x;
            held[2] += f * sub.plane.y;
            let stress = f.length() / sub.area;
            held_stress = held_stress.max(stress);
            let compression = -regime.normal_stiffness * face_gap(g, sub.plane.x, sub.plane.y);
            room = room.min(STRENGTH_SHARE * (regime.cohesion + regime.tan_friction * compression) - stress);
        }
        let mut joint = Self {
            active: true,
            open: false,
            span: (span.0 as u16, span.1 as u16),
            ends,
            held,
            held_stress,
            field: [Vector2::ZERO; 3],
            stiffness: (regime.normal_stiffness, regime.shear_stiffness),
            gap: g,
        };
        let mut hinge = HingeRecord {
            entry_gap: g,
            room,
            ..HingeRecord::default()
        };
        hinge.measure(own, cells, &joint);
        // Open cells whose box the gap does not keep open (a line `g = 0` across the columns)
        // stay in the range.
        if ends != SpanEnds::Closed && !Self::open_over(hinge.open_box, g) {
            (joint.ends, joint.span) = (SpanEnds::Closed, (first as u16, last as u16));
            hinge.measure(own, cells, &joint);
        }
        let closed = crate::contact::elastic_step::closed_over(g, hinge.closed_box);
        // Its cells must have room for two more steps like this one, or the joint would leave
        // again at once (a joint whose cells next to the line `g = 0` stick with nothing to
        // spare, entering and leaving at every step, its cells scanned and written each time).
        let tangential = |v: Vector| Vector2::new(v.y, v.z) * 2.0;
        let ahead = [
            tangential(kinematics.at_origin),
            tangential(kinematics.per_x),
            tangential(kinematics.per_y),
        ];
        (closed && partial_corners_stick(&hinge, regime, g, &ahead)).then_some((joint, hinge))
    }
}

#[cfg(test)]
mod tests {
    use super::super::tests::{cell, elastic_steps};
    use super::*;
    use crate::contact::joint_level::StickTest;
    use crate::law::{ConstitutiveLaw, CoulombSlip, JointForce};

    /// A hinge: a 5 × 3 grid of cells (columns contiguous in cell order) whose first column is
    /// open and second crossed by the line `g = 0`. The open column and the three closed ones
    /// are stepped as a whole for 50 steps, the crossed column one by one: the closed cells'
    /// sums (the joint's moments less the other cells') and each cell as the joint gives it
    /// are what their own steps give; the open column's box test fails as soon as the gap
    /// closes one of its corners; the corner test fails before any closed cell would slide.
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
                    // As the cells' own loop leaves an open cell: its smallest gap.
                    c.status = JointStatus::Open;
                    c.force = JointForce::default();
                    c.gap = gap - (s * c.half().x + 0.0 * c.half().y);
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
        let (mut joint, hinge) =
            JointLevel::enter_partial(&cells, &summary, &regime, g, slope, &still).expect("enters");
        assert_eq!(joint.span, (3, 6), "the straddling column");
        assert_eq!(joint.ends, SpanEnds::OpenBefore, "the open column as a whole");
        assert!((hinge.closed_box.0 - Vector2::new(0.15, -0.05)).length() < 1e-8);
        assert!((hinge.closed_box.1 - Vector2::new(0.45, 0.25)).length() < 1e-8);
        assert!((hinge.open_box.0 - Vector2::new(-0.05, -0.05)).length() < 1e-8);
        assert!((hinge.open_box.1 - Vector2::new(0.05, 0.25)).length() < 1e-8);
        assert_eq!(hinge.closed_moments, summary.without(&cells[..6]));
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
            assert!(JointLevel::open_over(hinge.open_box, g), "step {step}: stays open");
            let (moments, j) = hinge.closed_moments;
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
        assert_eq!(
            own[..span.end],
            cells[..span.end],
            "the open cells as their own loop keeps them, the span's their own"
        );

        // The open column closes where its gap reaches zero at a corner: at `x = 0.05` when the
        // line `g = 0` has moved there; the box test fails for any line a little beyond.
        let nearly = (0.05 * s * (1.0 + 1e-6), s, 0.0);
        let beyond = (0.05 * s * (1.0 - 1e-6), s, 0.0);
        assert!(JointLevel::open_over(hinge.open_box, nearly));
        assert!(!JointLevel::open_over(hinge.open_box, beyond));

        // Pushed sideways until a cell stepped as a whole would slide: the test fails first.
        let (mut joint, hinge) =
            JointLevel::enter_partial(&cells, &summary, &regime, g, slope, &still).expect("enters");
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
