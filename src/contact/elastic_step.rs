//! The sub-contacts of a contact without dashpot forces whose law has an [`ElasticRegime`]: the
//! elastic step taken directly where it stands, the law's update elsewhere, and the way through a
//! joint whose cells are all closed (a joint at rest), four cells at a time. The equations are in
//! `docs/theory.md` ("Sub-contact kinematics", "Exact integration over the cells").

use super::closed_lanes::{closed_groups, ClosedJoint, LaneBuild};
use super::lanes::{face_gap, increment, Kinematics, LaneSums, LANES};
use super::law_update::{stays_separated, update_with_law};
use super::moments::ForceMoments;
use super::spread::{cell_response, tension_free, CellResponse, CellRule, ExactCells};
use super::{CellSummary, SubContact};
use crate::law::{ConstitutiveLaw, ElasticRegime, JointAxes, JointStatus};
use crate::math::{Real, Vector2};

/// The sub-contacts of a contact without dashpot forces, for a law with an [`ElasticRegime`]:
/// a virgin sub-contact whose trial forces stand, or slide in a regime that slides
/// ([`ElasticRegime::step`]), takes them directly (a slide booked as `update_with_law` books
/// it); the others (open, failed, sliding in a regime that does not) go through the law exactly
/// as in the one-at-a-time loop. `face` holds the gap
/// coefficients (large displacements), `None` for gaps carried incrementally. Returns the
/// spring-force sums in the joint axes, taken in sub-contact order, the energy the law
/// dissipated (fracture work apart), the spread energy and the fracture work.
#[allow(clippy::too_many_arguments)]
#[inline(always)]
pub(super) fn update_elastic_first<L: ConstitutiveLaw>(
    subs: &mut [SubContact<L::State>],
    law: &L,
    regime: &ElasticRegime,
    kinematics: &Kinematics,
    face: Option<(Real, Real, Real)>,
    exact: Option<ExactCells>,
    whole: WholeContact<'_>,
    axes: JointAxes,
    dt: Real,
    lanes: LaneBuild,
) -> (ForceMoments, Real, Real, Real) {
    let virgin = L::State::default();
    let mut sums = ForceMoments::default();
    let mut dissipated = 0.0;
    let mut fracture = 0.0;
    let mut spread_energy = 0.0;
    // `Σ J_xx`, `Σ J_yy` of the all-closed cells in the elastic regime, for their spread energy.
    let mut closed_moments = Vector2::ZERO;
    // A contact whose cells are all closed (a joint at rest) takes a shorter way through them,
    // doing the operations of the loop below for such cells (each cell gets the same bits):
    // each virgin cell's force is the law's elastic step at its anchor gap, with no test of the
    // cell, four cells at a time and then one at a time (the forces summed per lane, then in
    // cell order). At the first cell that does not fit (a failed state, a law leaving its
    // regime) the loop below takes over from it, with the `Σ J` of the cells before it.
    let mut start = 0;
    if let (Some(g), Some(e), WholeContact::Closed(cells)) = (face, exact, whole) {
        // A law that carries tension has its virgin cells taken at their anchors (no exact
        // moments), but closed all over they are in its elastic regime all the same.
        // Four cells at a time while they fit (`closed_lanes.rs`), then one at a time.
        let mut lane_sums = LaneSums::default();
        let (groups, _) = subs.as_chunks_mut::<LANES>();
        let joint = ClosedJoint {
            regime,
            kinematics,
            gap: g,
            virgin: &virgin,
        };
        start = LANES * closed_groups(lanes, groups, &joint, &mut lane_sums, &mut dissipated);
        sums = lane_sums.total().0;
        for sub in subs[start..].iter_mut() {
            if sub.state != virgin {
                break;
            }
            let (x, y) = (sub.plane.x, sub.plane.y);
            let [_, du_1, du_2] = increment(kinematics, x, y);
            let gap = face_gap(g, x, y);
            let du_s = Vector2::new(du_1, du_2);
            let Some((force, status)) = regime.step(sub.area, gap, du_s, sub.force.shear) else {
                break;
            };
            take_elastic_step(regime, sub, (force, status), gap, du_s, &mut dissipated);
            sums.add_joint(&force, sub.plane);
            start += 1;
        }
        closed_moments = if !e.virgin_without_tension {
            Vector2::ZERO
        } else if start == subs.len() {
            cells.closed_moments
        } else {
            subs[..start]
                .iter()
                .fold(Vector2::ZERO, |m, sub| m + cell_moments(sub.area, sub.half()))
        };
    }
    // An open, unloaded virgin cell that the law keeps open only takes its smallest gap
    // ([`stays_open_cell`]).
    let open_cells = match (face, exact) {
        (Some(g), Some(e)) if e.virgin_without_tension => Some((g, e.slope.abs())),
        _ => None,
    };
    // A joint that opens from its first cell on (a joint standing open: a quarter of a settled
    // wall's cells) takes those cells in a loop of its own, doing the loop below's skip.
    if let (Some((g, slope)), WholeContact::Mixed) = (open_cells, whole) {
        for sub in subs.iter_mut() {
            if !stays_open_cell(law, sub, &virgin, g, slope) {
                break;
            }
            start += 1;
        }
    }
    for sub in subs[start..].iter_mut() {
        let (x, y) = (sub.plane.x, sub.plane.y);
        if let Some((g, slope)) = open_cells {
            if stays_open_cell(law, sub, &virgin, g, slope) {
                continue;
            }
        }
        let [du_n, du_1, du_2] = increment(kinematics, x, y);
        let is_virgin = sub.state == virgin;
        let cell = match (face, exact) {
            (Some(g), Some(e))
                if if is_virgin {
                    e.virgin_without_tension
                } else {
                    tension_free(law, &sub.state)
                } =>
            {
                let anchor_gap = face_gap(g, x, y);
                let half = sub.half();
                let spread = e.slope.x.abs() * half.x + e.slope.y.abs() * half.y;
                if anchor_gap < 0.0 && anchor_gap <= -spread {
                    Cell::Closed(anchor_gap, half)
                } else {
                    Cell::Response(cell_response(anchor_gap, e.slope, half, sub.area))
                }
            }
            (Some(g), _) => Cell::Response(CellResponse::at_anchor(face_gap(g, x, y))),
            (None, _) => Cell::Response(CellResponse::at_anchor(sub.gap + du_n)),
        };
        let gap = match cell {
            Cell::Closed(gap, _) => gap,
            Cell::Response(c) => c.law_gap,
        };
        let du_s = Vector2::new(du_1, du_2);
        if is_virgin {
            if let Some((force, status)) = regime.step(sub.area, gap, du_s, sub.force.shear) {
                take_elastic_step(regime, sub, (force, status), gap, du_s, &mut dissipated);
                match cell {
                    Cell::Closed(_, half) => {
                        // `N c = −k_n J s` and `½ k_n J s²`, `J = A h²/3`: summed over the
                        // contact's all-closed cells as `Σ J` (the slope is the contact's).
                        sums.add_joint(&force, sub.plane);
                        closed_moments += cell_moments(sub.area, half);
                    }
                    Cell::Response(c) => exact.add(&mut sums, &mut spread_energy, sub, &c),
                }
                continue;
            }
        }
        if face.is_some() && stays_separated(law, sub, gap) {
            sub.gap = gap;
            continue;
        }
        let (_, lost, consumed) = update_with_law(law, sub, gap, du_n, du_s, axes, dt);
        dissipated += lost;
        fracture += consumed;
        let response = match (cell, exact) {
            (Cell::Closed(anchor_gap, half), Some(e)) => cell_response(anchor_gap, e.slope, half, sub.area),
            (Cell::Closed(anchor_gap, _), None) => CellResponse::at_anchor(anchor_gap),
            (Cell::Response(c), _) => c,
        };
        exact.add(&mut sums, &mut spread_energy, sub, &response);
    }
    // The all-closed cells' moments, `−k_n s Σ J`, and spread energy, `½ k_n (J_xx s_x² + J_yy s_y²)`,
    // summed once.
    if let Some(e) = exact {
        sums.per_x.x -= e.normal_stiffness * e.slope.x * closed_moments.x;
        sums.per_y.x -= e.normal_stiffness * e.slope.y * closed_moments.y;
        spread_energy += 0.5
            * e.normal_stiffness
            * (closed_moments.x * e.slope.x * e.slope.x + closed_moments.y * e.slope.y * e.slope.y);
    }
    (sums, dissipated, spread_energy, fracture)
}

/// Whether `sub` is an open, unloaded `virgin` cell that the law keeps open all over (the
/// gap over its rectangle, `face_gap(g, x, y) ∓ (|s_x| h_x + |s_y| h_y)` for the slope's
/// magnitudes `slope`, positive): if so it takes its smallest gap and needs nothing else (the
/// elastic step gives nothing for a positive gap, and `stays_separated` holds).
#[inline(always)]
fn stays_open_cell<L: ConstitutiveLaw>(
    law: &L,
    sub: &mut SubContact<L::State>,
    virgin: &L::State,
    g: (Real, Real, Real),
    slope: Vector2,
) -> bool {
    if !(sub.status == JointStatus::Open
        && sub.force.normal == 0.0
        && sub.force.shear == Vector2::ZERO
        && sub.state == *virgin)
    {
        return false;
    }
    let anchor_gap = face_gap(g, sub.plane.x, sub.plane.y);
    let half = sub.half();
    let spread = slope.x * half.x + slope.y * half.y;
    let gap = anchor_gap - spread;
    if anchor_gap >= spread && gap > 0.0 && law.stays_open(sub.area, gap, &sub.state) {
        sub.gap = gap;
        true
    } else {
        false
    }
}

/// Stores the elastic regime's step (`force`, `status`) at the law gap `gap` in `sub`, with its
/// slip while sliding, and adds the energy a slide dissipated to `dissipated`.
#[inline(always)]
fn take_elastic_step<S>(
    regime: &ElasticRegime,
    sub: &mut SubContact<S>,
    (force, status): (crate::law::JointForce, JointStatus),
    gap: Real,
    du_s: Vector2,
    dissipated: &mut Real,
) {
    if status == JointStatus::Sliding {
        *dissipated += slide_dissipation(regime, sub, &force, du_s);
        sub.slip += du_s.length();
    }
    sub.force = force;
    sub.gap = gap;
    sub.status = status;
}

/// The energy a slide of `sub` to `force` dissipates, as `update_with_law` books a slide: the
/// shear spring's work over the increment `du_s` less the change of its energy.
#[inline(always)]
fn slide_dissipation<S>(
    regime: &ElasticRegime,
    sub: &SubContact<S>,
    force: &crate::law::JointForce,
    du_s: Vector2,
) -> Real {
    let before = sub.force.shear;
    let work = -0.5 * (before + force.shear).dot(du_s);
    let ks_area = regime.shear_stiffness * sub.area;
    if ks_area > 0.0 {
        work - 0.5 * (force.shear.length_squared() - before.length_squared()) / ks_area
    } else {
        work
    }
}

/// One third.
const THIRD: Real = 1.0 / 3.0;

/// A cell's `J = A h²/3` per axis (its second moments about its centre), as the step sums them
/// for its all-closed cells.
#[inline(always)]
pub(crate) fn cell_moments(area: Real, half: Vector2) -> Vector2 {
    area * THIRD * (half * half)
}

/// A face-face contact's cells as a whole, from the gap `face_gap(g, x, y)` over the box they
/// cover (its largest value is at a corner of the box).
#[derive(Clone, Copy)]
pub(super) enum WholeContact<'a> {
    /// Negative over the whole box, by a margin far above the round-off of the cells' own
    /// test, so that each cell would also find itself all closed: the cells need no test.
    Closed(&'a CellSummary),
    /// Not known to be closed everywhere: each cell tests itself.
    Mixed,
}

impl<'a> WholeContact<'a> {
    #[inline(always)]
    pub(super) fn of(g: (Real, Real, Real), cells: &'a CellSummary) -> Self {
        if closed_over(g, (cells.lo, cells.hi)) {
            Self::Closed(cells)
        } else {
            Self::Mixed
        }
    }
}

/// Whether the gap `face_gap(g, x, y)` is negative over the whole box `(lo, hi)` (its largest
/// value is at a corner), by a margin far above the round-off of the cells' own tests, so that
/// each cell in the box would also find itself all closed.
#[inline(always)]
pub(super) fn closed_over(g: (Real, Real, Real), (lo, hi): (Vector2, Vector2)) -> bool {
    let slope = Vector2::new(-g.1, -g.2);
    let (low, high) = (slope * lo, slope * hi);
    let largest = g.0 + low.x.max(high.x) + low.y.max(high.y);
    let scale = g.0.abs() + (slope.abs() * lo.abs().max(hi.abs())).element_sum();
    largest < -1e-9 * scale
}

/// A cell as the elastic-regime loop sees it: all closed (the gap at the anchor and the half
/// sizes: its force and moments are linear in them), or its [`CellResponse`].
#[derive(Clone, Copy)]
enum Cell {
    Closed(Real, Vector2),
    Response(CellResponse),
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::math::Vector;

    /// The whole-contact test agrees with the cells' own tests: a box of cells is `Closed` only
    /// when every cell's test finds it all closed, and is `Closed` whenever they all are by more
    /// than the margin; a box the line `g = 0` crosses, or touches within round-off, is `Mixed`.
    #[test]
    fn whole_contact_classes_agree_with_each_cells_test() {
        use crate::contact::CellSummary;
        // Cells of 0.05 × 0.02 m (half sizes 0.025, 0.01) covering [-0.2, 0.2] × [-0.05, 0.05].
        let cells: Vec<(Vector2, Vector2)> = (0..8)
            .flat_map(|i| (0..5).map(move |j| (i, j)))
            .map(|(i, j)| {
                let centre = Vector2::new(-0.175 + 0.05 * i as Real, -0.04 + 0.02 * j as Real);
                (centre, Vector2::new(0.025, 0.01))
            })
            .collect();
        let summary = CellSummary {
            lo: Vector2::new(-0.2, -0.05),
            hi: Vector2::new(0.2, 0.05),
            closed_moments: Vector2::ZERO,
            area_moments: [0.0; 6],
        };
        let cell_closed = |g: (Real, Real, Real), (c, h): (Vector2, Vector2)| {
            let anchor_gap = face_gap(g, c.x, c.y);
            let spread = g.1.abs() * h.x + g.2.abs() * h.y;
            anchor_gap < 0.0 && anchor_gap <= -spread
        };
        // Tilted planes at several depths: from wholly closed through crossing to wholly open.
        for &(gx, gy) in &[(1e-3_f64, -4e-4_f64), (-2e-3, 0.0), (0.0, 5e-3)] {
            let reach = gx.abs() * 0.2 + gy.abs() * 0.05;
            for k in -40..=40 {
                let g0 = reach * k as Real / 20.0;
                let g = (g0, gx, gy);
                match WholeContact::of(g, &summary) {
                    WholeContact::Closed(_) => assert!(cells.iter().all(|&c| cell_closed(g, c)), "{g:?}"),
                    WholeContact::Mixed => assert!(
                        !cells.iter().all(|&c| cell_closed(g, c)) || g0 + reach > -1e-9 * (g0.abs() + reach),
                        "{g:?}: all closed by a margin, yet mixed"
                    ),
                }
            }
            // Touching zero at a corner: not taken for closed.
            assert!(matches!(
                WholeContact::of((-reach, gx, gy), &summary),
                WholeContact::Mixed
            ));
        }
    }

    /// The all-closed way through a joint gives each cell the bits of the cell-by-cell loop, and
    /// sums that agree with its sums to round-off (they are taken per lane); its two builds
    /// (arrays, AVX) give the same bits, sums included. For a dry joint whose cells stick and
    /// slide, a linear elastic one, and a cohesive one whose failed cells and slides (outside the
    /// elastic regime's cover) send the rest of the joint back to that loop, at several cell
    /// counts (groups of four and a remainder).
    #[test]
    fn the_all_closed_way_gives_each_cell_the_bits_of_the_cell_by_cell_loop() {
        use crate::contact::CellSummary;
        use crate::law::AnyState;
        use crate::law::{AnyLaw, CoulombSlip, CoulombState, JointForce, LinearElastic};
        let kinematics = Kinematics {
            at_origin: Vector::new(-2e-7, 3e-6, -1e-6),
            per_x: Vector::new(1e-6, -4e-6, 2e-6),
            per_y: Vector::new(-3e-6, 1e-6, 5e-6),
        };
        let g = (-4e-5, 1e-4, -2e-4);
        let axes = JointAxes::from_normal(Vector::Z);
        let cells = |count: usize, failed: &[usize]| -> Vec<SubContact<AnyState>> {
            (0..count)
                .map(|k| SubContact {
                    plane: Vector2::new(-0.075 + 0.05 * (k % 4) as Real, -0.05 + 0.025 * (k / 4) as Real),
                    area: 0.05 * 0.025,
                    gap: -4e-5,
                    // Some cells near their strength, so that a few slide.
                    force: JointForce {
                        normal: 100.0,
                        shear: Vector2::new(40.0 + 5.0 * k as Real, -8.0 + (k % 3) as Real),
                    },
                    slip: 0.0,
                    half: [0.025, 0.0125],
                    status: JointStatus::Elastic,
                    cell: [(k % 4) as u16, (k / 4) as u16],
                    state: AnyState {
                        coulomb: CoulombState {
                            failed: failed.contains(&k),
                        },
                        ..AnyState::default()
                    },
                })
                .collect()
        };
        let dry = AnyLaw::Coulomb(CoulombSlip::dry(1e9, 4e8, 30.0).expect("law"));
        let cohesive = AnyLaw::Coulomb(CoulombSlip::new(1e9, 4e8, 35.0, 30.0, 2e4, 0.0).expect("law"));
        // Carrying tension: its virgin cells are taken at their anchors, closed or not.
        let bonded = AnyLaw::Coulomb(CoulombSlip::new(1e9, 4e8, 35.0, 30.0, 2e4, 1e4).expect("law"));
        let mortar = AnyLaw::Mortar(
            crate::law::MortarJoint::builder(1e9, 4e8, 35.0)
                .tension(1e4, 10.0)
                .cohesion(2e4, 50.0)
                .build()
                .expect("law"),
        );
        let elastic = AnyLaw::Elastic(LinearElastic {
            normal_stiffness: 1e9,
            shear_stiffness: 4e8,
        });
        let mut slid = 0;
        for count in [4, 14, 16] {
            for (law, failed) in [
                (dry, vec![]),
                (elastic, vec![]),
                (cohesive, vec![]),
                (cohesive, vec![5, 9]),
                (bonded, vec![]),
                (bonded, vec![5, 9]),
                (mortar, vec![]),
            ] {
                let regime = law.elastic_regime().expect("a regime");
                let exact = ExactCells::of(&law, Some(g));
                let start = cells(count, &failed);
                let summary = CellSummary::of(&start);
                let whole = WholeContact::of(g, &summary);
                assert!(
                    matches!(whole, WholeContact::Closed(_)),
                    "the joint is closed everywhere"
                );
                let mut builds = vec![LaneBuild::Portable];
                #[cfg(target_arch = "x86_64")]
                if std::arch::is_x86_feature_detected!("avx2") {
                    builds.push(LaneBuild::Avx2);
                }
                let run = |subs: &mut [SubContact<AnyState>], whole, build| {
                    update_elastic_first(
                        subs,
                        &law,
                        &regime,
                        &kinematics,
                        Some(g),
                        exact,
                        whole,
                        axes,
                        1e-4,
                        build,
                    )
                };
                let mut slow = start.clone();
                let b = run(&mut slow, WholeContact::Mixed, LaneBuild::Portable);
                slid += slow.iter().filter(|s| s.status == JointStatus::Sliding).count();
                let mut first = None;
                for build in builds {
                    let mut fast = start.clone();
                    let a = run(&mut fast, whole, build);
                    assert_eq!(fast, slow, "{law:?}, {count} cells, failed {failed:?}, {build:?}");
                    assert!(a.0.matches(&b.0), "{:?} vs {:?}", a.0, b.0);
                    assert_eq!(a.1.to_bits(), b.1.to_bits(), "dissipated in cell order");
                    assert!((a.2 - b.2).abs() <= 1e-12 * b.2.abs(), "spread energy");
                    let bits = (a.0, a.1.to_bits(), a.2.to_bits());
                    assert_eq!(*first.get_or_insert(bits), bits, "the builds agree bit for bit");
                }
            }
        }
        assert!(slid > 10, "{slid} cells slid");
    }
}
