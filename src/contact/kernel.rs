//! The hot loop: one contact at a time — its plane, then its sub-contacts in order (kinematics,
//! law, dashpot), summed into the contact's resultant, moments and energy increments in the same
//! pass. The equations are in `docs/theory.md` ("Sub-contact kinematics").

use super::elastic_step::{closed_over, update_elastic_first, WholeContact};
use super::joint_level::StickTest;
use super::lanes::{face_gap, increment, update_group, ContactFrame, Kinematics, LaneSums, LANES};
use super::law_update::{stays_separated, update_with_law};
use super::moments::{ForceMoments, Lever};
use super::spread::{CellResponse, CellRule, ExactCells};
use super::{
    ContactPair, ContactReference, ContactWrench, DisplacementMode, HingeRecord, JointLevel, LaneBuild, SideRecord,
    SmallReference, SpanEnds, SubContact,
};
use crate::block::BlockMotion;
use crate::law::{ConstitutiveLaw, ElasticRegime, JointAxes, JointStatus};
use crate::math::{Matrix, Pose, Real, Vector, Vector2};

/// What a contact's update returns besides what it stores in the contact: its wrench on the two
/// blocks and its energy increments over the step.
#[derive(Debug, Clone, Copy, Default)]
pub(crate) struct ContactStep {
    pub wrench: ContactWrench,
    /// Work done on the joint springs (J), trapezoidal rule.
    pub work: Real,
    /// Energy the law dissipated at the sub-contacts that slid or changed state (J), its
    /// fracture work apart.
    pub dissipated: Real,
    /// The law's fracture work at the sub-contacts that changed state (J,
    /// [`ConstitutiveLaw::fracture_work`]).
    pub fracture: Real,
    /// Work of the dashpot forces (J, negative: dissipated).
    pub dashpot_work: Real,
    /// Whether a sub-contact is about to close or open fast (see [`KernelContext::impact_speed`]).
    pub impact: bool,
    /// For a watched contact (see [`update_contact`]): whether it carries a normal force and
    /// the relative speed over it may exceed the probe's speed (an impact still under way).
    pub busy: bool,
}

/// Read-only data shared by all contacts of a step.
#[derive(Debug, Clone, Copy)]
pub(crate) struct KernelContext {
    /// The step that brought the blocks to their current poses (`Δt_{n−½}`): the displacement
    /// increments are the velocities times it.
    pub dt: Real,
    /// The impact probe: a sub-contact whose normal speed exceeds this (m/s) and that will
    /// cross the spring's kink (close or open) within [`impact_horizon`](Self::impact_horizon)
    /// at that speed marks its contact as impacting. Infinite: no probe.
    pub impact_speed: Real,
    /// The probe's look-ahead (s).
    pub impact_horizon: Real,
    /// Rayleigh stiffness-proportional coefficient `b` (s).
    pub stiffness_damping: Real,
    pub mode: DisplacementMode,
    /// How the all-closed joints' cells are computed (the same bits either way).
    pub lanes: super::LaneBuild,
    /// Whether closed, sticking joints are stepped as a whole (`joint_level/`).
    pub joint_level: bool,
    /// The grid spacing of node contacts' nodes comes from this ([`crate::geometry::ContactParameters::density`]):
    /// a node's strips are as wide as at its detection.
    pub node_density: crate::geometry::SubContactDensity,
    /// How node contacts' normal springs act ([`crate::geometry::NodeRule`]).
    pub node_rule: crate::geometry::NodeRule,
    /// The model's step count: a joint open in part tries to enter joint-level stepping at
    /// one step in [`PARTIAL_ENTRY_PERIOD`] (its own, from its blocks).
    pub step: u64,
}

/// A joint open in part whose cells could be stepped as a whole tries one step in this many
/// ([`JointLevel::enter_partial`] scans its cells): a joint that cannot enter (its closed cells
/// too few, or without room) is not scanned at every step, on a moving scene that holds
/// thousands of them. (At every step, the static arch's hinges entered twice as often for 4 %
/// more steps stepped so: a joint that enters right after leaving leaves again.) Which step is
/// the joint's own, from its blocks' indices and the model's step count, so that a restarted
/// run tries at the same steps.
pub(crate) const PARTIAL_ENTRY_PERIOD: u64 = 8;

impl KernelContext {
    /// Whether Rayleigh stiffness damping is on, and the dashpot coefficients per unit area for
    /// joint stiffness `k`, normal and shear (zero without it): `b k / Δt`.
    #[inline]
    pub(crate) fn dashpot_coefficients(&self, k: crate::law::JointStiffness) -> (bool, Real, Real) {
        if self.stiffness_damping > 0.0 {
            (
                true,
                self.stiffness_damping * k.normal / self.dt,
                self.stiffness_damping * k.shear / self.dt,
            )
        } else {
            (false, 0.0, 0.0)
        }
    }
}

/// Updates one contact for one step: its plane and axes (large-displacement mode), the forces of
/// its sub-contacts (`subs` and `dashpot_forces` are the contact's own ranges; `dashpot_forces` may be empty
/// when the contact has no dashpot forces and is not damped), and returns its
/// resultant, moments about both centroids and energy increments. Sums run in a fixed order — in
/// sub-contact order, or, four at a time, per lane, the lanes added in order, then the remaining
/// sub-contacts — so the result does not depend on how contacts are spread over threads.
///
/// Everything common to the contact is computed once: the joint axes `(n, t₁, t₂)` turned with
/// the plane, and the displacement increment in those axes as a field affine in the anchor's
/// plane coordinates `(x, y)`, `Δu = Δu_o + x Δu_x + y Δu_y`, and so is the geometric gap. A
/// sub-contact then costs six multiplications for its kinematics, its shear force needs no
/// turning (its components follow the turning tangents), and its force enters the contact's
/// resultant, moment and work through the sums `Σ f`, `Σ f x`, `Σ f y` (see [`ForceMoments`]).
/// Without dashpot forces the sub-contacts go four at a time (`lanes.rs`), with the same
/// operations per sub-contact.
///
/// The impact probe (see [`KernelContext::impact_speed`]) marks the contact when a sub-contact
/// is about to cross the spring's kink fast; `host_radius` bounds the anchors' lever arms for
/// its quick test, and a `watch`ed contact (one the probe marked since the refinement began)
/// reports whether it is still loaded and moving.
#[allow(clippy::too_many_arguments)]
#[inline(always)]
pub(crate) fn update_contact<L: ConstitutiveLaw>(
    pair: &mut ContactPair,
    reference: &mut ContactReference,
    small: Option<&SmallReference>,
    subs: &mut [SubContact<L::State>],
    dashpot_forces: &mut [Vector],
    sa: &BlockMotion,
    sb: &BlockMotion,
    law: &L,
    ctx: KernelContext,
    host_radius: Real,
    watch: bool,
) -> ContactStep {
    // The axes of the previous step, in which the stored spring forces were composed.
    let previous_axes = pair.axes();
    debug_assert_eq!(small.is_some(), ctx.mode == DisplacementMode::Small);
    let host = pair.frame(small, &sa.pose, &sb.pose);
    let (xa, xb) = SmallReference::centroids(small, &sa.pose, &sb.pose);
    let xh = host.translation;
    // Large displacements: the gap of the anchor p is its signed distance from the other
    // block's plane m·x = d (m its outward normal, turning with it), gap = m·p − d; with
    // p = x_h + r, gap = g₀ − q·r for g₀ = m·x_h − d and q = −m. The joint normal is m,
    // oriented from a to b, so that the normal force is the gradient of the spring energy.
    let mut face_plane = None;
    if ctx.mode == DisplacementMode::Large {
        let (m, g0) = other_face_plane(pair, (&sa.pose, &sa.rotation), (&sb.pose, &sb.rotation));
        pair.normal = if pair.host_is_a { -m } else { m };
        face_plane = Some((g0, -m));
        pair.tangent = turned_tangent(previous_axes, pair.normal);
    }
    let axes = pair.axes();
    let (n, t1, t2) = (axes.normal, axes.tangent, axes.tangent_2());
    let rotation = match ctx.mode {
        DisplacementMode::Large if pair.host_is_a => sa.rotation,
        DisplacementMode::Large => sb.rotation,
        DisplacementMode::Small => Matrix::from_quat(host.rotation),
    };
    // v_rel(p) = v_b + ω_b × (p − x_b) − v_a − ω_a × (p − x_a) = v₀ + (ω_b − ω_a) × r.
    let dw = sb.angular_velocity - sa.angular_velocity;
    let v0 = sb.velocity - sa.velocity + sb.angular_velocity.cross(xh - xb) - sa.angular_velocity.cross(xh - xa);
    let dt = ctx.dt;
    // Displacement increments over the step at the anchor a = o + x u + y v (host body frame),
    // r = R a: du = v₀Δt + (ΔωΔt) × r = w_o + x w_x + y w_y (world), then in the joint axes.
    let plane = pair.anchors;
    let lever = Lever {
        origin: rotation * plane.origin,
        u: rotation * plane.u,
        v: rotation * plane.v,
    };
    let dwdt = dw * dt;
    let increments = Lever {
        origin: v0 * dt + dwdt.cross(lever.origin),
        u: dwdt.cross(lever.u),
        v: dwdt.cross(lever.v),
    };
    let in_axes = |v: Vector| Vector::new(n.dot(v), t1.dot(v), t2.dot(v));
    let kinematics = Kinematics {
        at_origin: in_axes(increments.origin),
        per_x: in_axes(increments.u),
        per_y: in_axes(increments.v),
    };
    // Face gap at the anchor: g₀ − q·r = (g₀ − q·R o) − x q·R u − y q·R v.
    let face_gap_coefficients = face_plane.map(|(g0, q)| (g0 - q.dot(lever.origin), q.dot(lever.u), q.dot(lever.v)));
    let exact = ExactCells::of(law, face_gap_coefficients);
    let mut spread_energy = 0.0;
    let (damped, cn, cs) = ctx.dashpot_coefficients(law.stiffness());
    // Last step's dashpot forces still owe the second half of their work (also in the step
    // after Rayleigh damping was switched off).
    let dashpots = damped || pair.dashpots;
    // Damped, the model keeps the dashpot forces; otherwise they are all zero, and an empty
    // list stands for them (a new contact, or one after Rayleigh damping was switched off,
    // still takes the dashpots' loop and order of sums).
    debug_assert!(!damped || dashpot_forces.len() == subs.len(), "dashpot forces not kept");

    // Spring-force sums in the joint axes.
    let mut sums = ForceMoments::default();
    let mut dashpot_moments = ForceMoments::default();
    // Σ (F_before + F_after)·du for the dashpots (times −½ at the end).
    let mut dashpot_sum = 0.0;
    // Without dashpot forces, four sub-contacts at a time; the rest (and everything when there
    // are dashpots) one at a time, continuing the sums of the groups.
    let mut done = 0;
    let mut dissipated = 0.0;
    let mut fracture = 0.0;
    let elastic_regime = if dashpots { None } else { law.elastic_regime() };
    // A joint stepped as a whole (`joint_level/`) takes the joint-level step while it stays
    // closed and sticking (or open, or both in parts); otherwise its cells are written and
    // stepped one by one below.
    let mut whole_joint = false;
    if pair.joint.active {
        if let (true, Some(regime), Some(g)) = (ctx.joint_level, elastic_regime.as_ref(), face_gap_coefficients) {
            if pair.joint.open {
                // Open all over: nothing to sum (the sums and spread energy stay zero).
                whole_joint = exact.is_some_and(|e| e.virgin_without_tension) && pair.joint.step_open(&pair.cells, g);
            } else if pair.joint.is_partial() {
                // Open in part: the closed cells stepped as a whole while they stay closed and
                // stick, the open ones at one end (if any) while they stay open, the others
                // (`span`) one by one (`joint_level/hinge.rs`). Only a hinge reads its record in
                // the reference (boxed: a joint open in part always has it).
                let hinge = reference.hinge();
                if let Some(step) = exact
                    .filter(|e| e.virgin_without_tension)
                    .zip(hinge)
                    .and_then(|(e, hinge)| {
                        step_hinge(pair, hinge, subs, law, regime, &kinematics, g, e, axes, dt, ctx.lanes)
                    })
                {
                    (sums, dissipated, spread_energy, fracture) = step;
                    whole_joint = true;
                }
            } else if let WholeContact::Closed(cells) = WholeContact::of(g, &pair.cells) {
                if let Some(step) = pair.joint.step(cells, regime, &kinematics, g, exact) {
                    (sums, spread_energy) = step;
                    whole_joint = true;
                }
            }
        }
        if !whole_joint {
            pair.joint.write_cells(subs);
        }
    }
    if whole_joint {
        done = subs.len();
    } else if let Some(regime) = elastic_regime {
        // Two call sites, so that each is compiled for its kind of gap.
        (sums, dissipated, spread_energy, fracture) = match face_gap_coefficients {
            Some(g) => {
                let whole = WholeContact::of(g, &pair.cells);
                let step = update_elastic_first(
                    subs,
                    law,
                    &regime,
                    &kinematics,
                    Some(g),
                    exact,
                    whole,
                    axes,
                    dt,
                    ctx.lanes,
                );
                // A joint closed all over whose cells all stuck in the elastic regime is
                // stepped as a whole from the next step on.
                // So is a joint open all over whose cells all stayed open and unloaded, for a
                // law that keeps a virgin cell open at any opening.
                let (s, lost, _, consumed) = step;
                if ctx.joint_level && lost == 0.0 && consumed == 0.0 {
                    let entered = match whole {
                        WholeContact::Closed(_) => {
                            let shear = |v: Vector| Vector2::new(v.y, v.z);
                            let held = [shear(s.force), shear(s.per_x), shear(s.per_y)];
                            JointLevel::enter(subs, &pair.cells, &regime, g, held)
                        }
                        WholeContact::Mixed => match exact {
                            Some(e) if e.virgin_without_tension => {
                                let turn = (u64::from(pair.a) * 7 + u64::from(pair.b) * 3 + ctx.step)
                                    .is_multiple_of(PARTIAL_ENTRY_PERIOD);
                                JointLevel::enter_open(subs, &pair.cells, g).or_else(|| {
                                    let (joint, hinge) = turn
                                        .then(|| {
                                            JointLevel::enter_partial(
                                                subs,
                                                &pair.cells,
                                                &regime,
                                                g,
                                                e.slope,
                                                &kinematics,
                                            )
                                        })
                                        .flatten()?;
                                    // The box is allocated at the contact's first entry
                                    // since its detection, and reused after.
                                    reference.keep(SideRecord::Hinge(hinge));
                                    Some(joint)
                                })
                            }
                            _ => None,
                        },
                    };
                    if let Some(joint) = entered {
                        pair.joint = joint;
                    }
                }
                step
            }
            None => update_elastic_first(
                subs,
                law,
                &regime,
                &kinematics,
                None,
                None,
                WholeContact::Mixed,
                axes,
                dt,
                ctx.lanes,
            ),
        };
        done = subs.len();
    } else if !dashpots {
        let frame = ContactFrame {
            axes,
            kinematics,
            face_gap: face_gap_coefficients,
            dt,
        };
        let mut lanes = LaneSums::default();
        let (groups, _) = subs.as_chunks_mut::<LANES>();
        for group in groups.iter_mut() {
            update_group(group, law, &frame, &mut lanes);
        }
        done = groups.len() * LANES;
        (sums, dissipated, fracture) = lanes.total();
    }
    for (i, sub) in subs.iter_mut().enumerate().skip(done) {
        let (x, y) = (sub.plane.x, sub.plane.y);
        let cell = face_gap_coefficients.map(|g| exact.cell(law, sub, face_gap(g, x, y)));
        let face = cell.map(|c| c.law_gap);
        // A separated sub-contact that the law says stays open with no force and no change of
        // state needs neither kinematics nor an update (nor a dashpot: it had none and gets none).
        if let Some(gap) = face {
            if (!dashpots || dashpot_forces.get(i).is_none_or(|d| *d == Vector::ZERO)) && stays_separated(law, sub, gap)
            {
                sub.gap = gap;
                continue;
            }
        }
        let [du_n, du_1, du_2] = increment(&kinematics, x, y);
        let du_s = Vector2::new(du_1, du_2);
        let gap = face.unwrap_or(sub.gap + du_n);
        let (status, lost, consumed) = update_with_law(law, sub, gap, du_n, du_s, axes, dt);
        dissipated += lost;
        fracture += consumed;
        match cell {
            Some(cell) => exact.add(&mut sums, &mut spread_energy, sub, &cell),
            None => sums.add_joint(&sub.force, sub.plane),
        }
        if dashpots {
            let mut dashpot = Vector::ZERO;
            if damped && status != JointStatus::Open {
                dashpot -= n * (cn * sub.area * du_n);
                if status != JointStatus::Sliding {
                    dashpot -= axes.shear(du_s) * (cs * sub.area);
                }
            }
            let du = n * du_n + t1 * du_1 + t2 * du_2;
            let held = dashpot_forces.get(i).copied().unwrap_or(Vector::ZERO);
            dashpot_sum += (held + dashpot).dot(du);
            dashpot_moments.add(dashpot, sub.plane);
            if let Some(d) = dashpot_forces.get_mut(i) {
                *d = dashpot;
            }
        }
    }
    pair.dashpots = damped;
    let springs = sums.to_world(&axes);
    // Joint work by the trapezoidal rule, Σ (F_before + F_after)·du summed through the moments
    // (the two sets of moments added first: one set of dot products).
    let spring_sum = pair.springs.plus(&springs).work(&increments);
    pair.springs = springs;
    pair.spread_energy = spread_energy;
    let total = if dashpots {
        springs.plus(&dashpot_moments)
    } else {
        springs
    };
    let force = total.force;
    let moment_host = total.moment(&lever);
    // Moments about the centroids: Σ (p − x)×F with p = x_h + r on block b, −F on block a.
    let (moment_a, moment_b) = if pair.host_is_a {
        (-moment_host, moment_host + (xa - xb).cross(force))
    } else {
        (-(moment_host + (xb - xa).cross(force)), moment_host)
    };
    pair.normal_force = sums.force.x;
    // The impact probe: first a bound of the relative speed over the host's anchors
    // (|r| ≤ the host's radius; (|v₀| + |Δω| r)² ≤ 2 (|v₀|² + |Δω|² r²), no square root), so
    // that a quiet contact costs a few operations; then, out of line, each sub-contact.
    let fast = 2.0 * (v0.length_squared() + dw.length_squared() * (host_radius * host_radius))
        > ctx.impact_speed * ctx.impact_speed;
    let impact = fast && impact_probe(subs, law, &kinematics, ctx, face_gap_coefficients.zip(exact));
    // A contact the probe marked keeps the step refined while it is loaded and moving: a
    // bound of the relative speed, so that a block rocking on a loaded edge whose sub-contacts
    // barely move keeps it too (the step must not change while springs are loaded).
    let busy = watch && fast && pair.normal_force > 0.0;
    ContactStep {
        wrench: ContactWrench {
            force,
            moment_a,
            moment_b,
        },
        work: -0.5 * spring_sum,
        dissipated,
        fracture,
        dashpot_work: -0.5 * dashpot_sum,
        impact,
        busy,
    }
}

/// A step of a joint open in part (a hinge, [`JointLevel::span`] not empty) without dashpot
/// forces, at the gap coefficients `g`: its closed cells outside the span as a whole while they
/// stay closed over `hinge.closed_box` and stick ([`JointLevel::advance`]), its open cells
/// outside the span (if any, [`SpanEnds`]) while they stay open over `hinge.open_box`, the
/// span's cells one by one. The spring-force sums in the joint axes, the energy dissipated, the spread energy and
/// the fracture work, as [`update_elastic_first`] returns them; `None`, with nothing changed,
/// when the joint must leave. Kept out of line: the contact pass inlines the cell loop at its
/// two call sites in [`update_contact`], and a third copy for the few hinges cost every contact
/// about 3 % more instructions.
#[allow(clippy::too_many_arguments)]
#[inline(never)]
fn step_hinge<L: ConstitutiveLaw>(
    pair: &mut ContactPair,
    hinge: &HingeRecord,
    subs: &mut [SubContact<L::State>],
    law: &L,
    regime: &ElasticRegime,
    kinematics: &Kinematics,
    g: (Real, Real, Real),
    exact: ExactCells,
    axes: JointAxes,
    dt: Real,
    lanes: LaneBuild,
) -> Option<(ForceMoments, Real, Real, Real)> {
    let open_stay_open = pair.joint.ends == SpanEnds::Closed || JointLevel::open_over(hinge.open_box, g);

    if !(open_stay_open
        && closed_over(g, hinge.closed_box)
        && pair.joint.advance(StickTest::Hinge(hinge), regime, kinematics, g))
    {
        return None;
    }
    let span = pair.joint.span_range();
    let (span_sums, lost, span_spread, consumed) = update_elastic_first(
        &mut subs[span.clone()],
        law,
        regime,
        kinematics,
        Some(g),
        Some(exact),
        WholeContact::Mixed,
        axes,
        dt,
        lanes,
    );
    let (moments, j) = hinge.closed_moments;
    let (whole_sums, whole_spread) = pair.joint.sums(&moments, j, Some(exact));
    Some((whole_sums.plus(&span_sums), lost, whole_spread + span_spread, consumed))
}

/// Whether a sub-contact of the contact is about to cross the spring's kink fast: its normal
/// speed (this step's increment over `ctx.dt`) beyond `ctx.impact_speed`, its gap (as updated
/// this step) closing or opening within `ctx.impact_horizon`, where the law has a kink: the
/// sub-contact would be open at that gap with no force (a spring carrying tension, or a law that
/// does not say, `stays_open` false, has no kink to resolve).
#[cold]
#[inline(never)]
fn impact_probe<L: ConstitutiveLaw>(
    subs: &[SubContact<L::State>],
    law: &L,
    kinematics: &Kinematics,
    ctx: KernelContext,
    cells: Option<((Real, Real, Real), ExactCells)>,
) -> bool {
    let threshold = ctx.impact_speed * ctx.dt;
    let reach = ctx.impact_horizon / ctx.dt;
    let crosses = |s: &SubContact<L::State>, gap: Real, du_n: Real| {
        (gap > 0.0) != (du_n > 0.0) && gap.abs() < reach * du_n.abs() && law.stays_open(s.area, gap.abs(), &s.state)
    };
    subs.iter().any(|s| {
        let du_n = increment(kinematics, s.plane.x, s.plane.y)[0];
        if du_n.abs() <= threshold {
            return false;
        }
        match cells {
            // A cell integrated over its rectangle has two kinks: where its first corner
            // closes (or its last opens) and where it closes whole (or starts to open), the
            // gaps at its corners nearest and farthest, `ū ∓ (|s_x| h_x + |s_y| h_y)`.
            Some((g, e)) if s.half != [0.0; 2] => {
                let anchor_gap = face_gap(g, s.plane.x, s.plane.y);
                let half = s.half();
                let spread = e.slope.x.abs() * half.x + e.slope.y.abs() * half.y;
                crosses(s, anchor_gap - spread, du_n) || crosses(s, anchor_gap + spread, du_n)
            }
            _ => crosses(s, s.gap, du_n),
        }
    })
}

/// Sets the gaps of a face-face contact's sub-contacts to those the step gives their laws at the
/// blocks' `poses` (a cell's [`CellResponse::law_gap`]; the gap at the anchor otherwise), as
/// detection seeds them with the gap at the anchor: the law's books (the work of a step that
/// changes its state) start from the gap the law saw.
pub(crate) fn seed_law_gaps<L: ConstitutiveLaw>(
    pair: &ContactPair,
    own: &mut [SubContact<L::State>],
    law: &L,
    (pose_a, pose_b): (&Pose, &Pose),
) {
    let g = face_gap_coefficients(pair, pose_a, pose_b);
    let exact = ExactCells::of(law, Some(g));
    for sub in own {
        sub.gap = exact.cell(law, sub, face_gap(g, sub.plane.x, sub.plane.y)).law_gap;
    }
}

/// A face-face contact's spring moments (world) and spread energy as the step sums them, at the
/// blocks' `poses` (`None`: small displacements, the forces at the anchors).
pub(crate) fn spring_moments<L: ConstitutiveLaw>(
    pair: &ContactPair,
    own: &[SubContact<L::State>],
    law: &L,
    poses: Option<(&Pose, &Pose)>,
) -> (ForceMoments, Real) {
    let coefficients = poses.map(|(pose_a, pose_b)| face_gap_coefficients(pair, pose_a, pose_b));
    let exact = ExactCells::of(law, coefficients);
    let (mut sums, mut spread_energy) = (ForceMoments::default(), 0.0);
    for sub in own {
        let cell = match coefficients {
            Some(g) => exact.cell(law, sub, face_gap(g, sub.plane.x, sub.plane.y)),
            None => CellResponse::at_anchor(sub.gap),
        };
        exact.add(&mut sums, &mut spread_energy, sub, &cell);
    }
    (sums.to_world(&pair.axes()), spread_energy)
}

/// The gap coefficients `(g_o, g_x, g_y)` of a face-face contact at the blocks' poses: the gap
/// at anchor-plane coordinates `(x, y)` is [`face_gap`] of them, as in the step.
pub(crate) fn face_gap_coefficients(pair: &ContactPair, pose_a: &Pose, pose_b: &Pose) -> (Real, Real, Real) {
    let (ra, rb) = (Matrix::from_quat(pose_a.rotation), Matrix::from_quat(pose_b.rotation));
    let (m, g0) = other_face_plane(pair, (pose_a, &ra), (pose_b, &rb));
    let r = if pair.host_is_a { ra } else { rb };
    let (plane, q) = (pair.anchors, -m);
    (g0 - q.dot(r * plane.origin), q.dot(r * plane.u), q.dot(r * plane.v))
}

/// The plane of the face a face-face contact's gaps are measured to (fixed in the block that is
/// not the host) at the blocks' poses: its outward normal `m` (world) and `m·x_h − d`, the
/// host centroid's signed distance from it.
#[inline(always)]
pub(crate) fn other_face_plane(
    pair: &ContactPair,
    (pose_a, rotation_a): (&Pose, &Matrix),
    (pose_b, rotation_b): (&Pose, &Matrix),
) -> (Vector, Real) {
    let (rotation_other, x_other, x_host) = if pair.host_is_a {
        (rotation_b, pose_b.translation, pose_a.translation)
    } else {
        (rotation_a, pose_a.translation, pose_b.translation)
    };
    let m = *rotation_other * pair.plane_normal;
    let d = pair.plane_offset + m.dot(x_other);
    (m, m.dot(x_host) - d)
}

/// The first tangent of `previous` turned into the plane normal to `normal` by the smallest
/// rotation taking the old normal to the new one (see [`plane_turn`]), then made normal to
/// `normal` and of unit length again against round-off.
#[inline]
fn turned_tangent(previous: JointAxes, normal: Vector) -> Vector {
    let Some(m) = plane_turn(previous.normal, normal) else {
        return previous.tangent;
    };
    let t = previous.tangent - m * normal.dot(previous.tangent);
    (t - normal * normal.dot(t)).normalize()
}

/// How a vector in the plane normal to `from` turns into the plane normal to `to` (unit
/// vectors) by the smallest rotation taking `from` to `to`: `s ↦ s − (to·s) m` with
/// `m = (from + to)/(1 + from·to)`, `None` when the planes are the same.
///
/// The smallest rotation is `R = I − (a+b)(a+b)ᵀ/(1+c) + 2 b aᵀ` (`a = from`, `b = to`,
/// `c = a·b`); for `s·a = 0` it reduces to the above. It keeps the magnitude of `s` and its
/// direction relative to the plane.
#[inline]
pub(super) fn plane_turn(from: Vector, to: Vector) -> Option<Vector> {
    if from == to {
        return None;
    }
    let c = from.dot(to);
    // Opposite normals are not a physical step; keep the vector rather than divide by zero.
    (c > -1.0 + 1e-12).then(|| (from + to) / (1.0 + c))
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::math::Rotation;

    #[test]
    fn plane_turn_keeps_in_plane_vectors_in_plane_with_their_length() {
        let from = Vector::new(0.1, -0.3, 0.9).normalize();
        let to = Vector::new(-0.2, 0.25, 0.95).normalize();
        let m = plane_turn(from, to).expect("a turn");
        let turn = |s: Vector| s - m * to.dot(s);
        // The smallest rotation (axis from × to) applied to an in-plane vector.
        let axis = from.cross(to).normalize();
        let angle = from.dot(to).clamp(-1.0, 1.0).acos();
        let rotation = Rotation::from_axis_angle(axis, angle);
        for s in [from.cross(Vector::X), from.cross(Vector::Y), axis, from.cross(axis)] {
            let s = s.normalize() * 3.0;
            let t = turn(s);
            assert!(t.dot(to).abs() < 1e-14, "in the new plane");
            assert!((t.length() - 3.0).abs() < 1e-14, "same magnitude");
            assert!((t - rotation * s).length() < 1e-14, "the smallest rotation");
        }
        assert!(plane_turn(to, to).is_none());
        assert!(plane_turn(to, -to).is_none());
    }

    /// Over many small turns of the plane the tangent stays a unit vector in the plane and is
    /// carried as the stored shear vector used to be — by the smallest rotation each step — so
    /// shear components along the tangents describe the same turned force.
    #[test]
    fn turned_tangent_follows_the_plane_as_the_shear_force_did() {
        let mut axes = JointAxes::from_normal(Vector::new(0.2, -0.1, 0.97).normalize());
        // A shear force as a world vector, turned the old way, and as components.
        let mut shear = axes.tangent * 3.0 - axes.tangent_2() * 4.0;
        let components = axes.components(shear);
        for k in 0..2000 {
            let t = k as Real * 0.01;
            let n = Vector::new(0.2 + 0.1 * t.sin(), -0.1 + 0.3 * (0.7 * t).cos(), 0.97).normalize();
            if let Some(m) = plane_turn(axes.normal, n) {
                shear -= m * n.dot(shear);
            }
            axes = JointAxes {
                normal: n,
                tangent: turned_tangent(axes, n),
            };
        }
        assert!((axes.tangent.length() - 1.0).abs() < 1e-14);
        assert!(axes.tangent.dot(axes.normal).abs() < 1e-14);
        assert!(
            (axes.shear(components) - shear).length() < 1e-12,
            "{} vs {}",
            axes.shear(components),
            shear
        );
    }
}
