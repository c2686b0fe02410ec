//! The step of a node contact (vertex–face, edge–edge, edge–face, partly overlapping faces):
//! every node of both blocks pressed out of the other block along the normal of the face it lies
//! deepest under, with the laws' shear and friction on top (`docs/theory.md` §2.2 and §3, "Node
//! contacts").
//!
//! A node is a material point of its block (its key names it, [`NodeId`]); its gap is its signed
//! distance from the other block, `g = max_f (m_f·q − d_f)` ([`deepest_face`]). The normal force
//! `k_n A (−g)` along that face's outward normal, applied at the node (and its opposite to the
//! other block at the same point), is the gradient of `½ k_n A min(g, 0)²`, a function of the two
//! poses alone: the work of the normal forces around any closed path is zero, whichever face a
//! node lies under and whichever contact kind the pair had before.
//!
//! Shear forces are stored as components along tangents fixed in the other block's body frame
//! for one of its faces (`plane_basis` of its normal, the face's index in `plane.x`), so that
//! they turn with the block. A node at its point acts in the plane of the face it lies deepest
//! under; when it passes under another face, its shear force is turned onto the new plane by the
//! smallest rotation, which keeps its magnitude. A node integrated over its strips and pressed
//! acts in the plane normal to its load's resultant, which turns continuously as the load moves
//! from face to face: its shear is turned onto that plane from the stored face's at each step,
//! and back onto the plane of the loaded face closest to it after the step.

use super::kernel::{plane_turn, ContactStep, KernelContext};
use super::law_update::{stays_separated, update_with_law};
use super::spread::tension_free;
use super::{ContactPair, ContactReference, ContactWrench, DisplacementMode, SubContact};
use crate::block::BlockState;
use crate::geometry::{deepest_two, spacing, NodeId, NodeRule, NodeStrips, Polyhedron, Strip, StripLoad, SubKey};
use crate::law::{ConstitutiveLaw, JointAxes, JointStatus};
use crate::math::{plane_basis, Matrix, Real, Vector, Vector2};

/// One block of a node contact as the step sees it: its state, rotation matrix and shape.
pub(crate) type NodeBlock<'a> = (&'a BlockState, &'a Matrix, &'a Polyhedron);

/// Where a node is and how it is pressed: its world point, the face of the other block it lies
/// deepest under, its gap to it (m, positive = out) and the joint axes there (normal from `a` to
/// `b`, tangent fixed in the other block).
#[derive(Debug, Clone, Copy)]
pub(crate) struct NodeFrame {
    pub point: Vector,
    pub face: usize,
    pub gap: Real,
    /// The signed distance from the plane of the next deepest face (m): the node turns to
    /// that face where it reaches `gap`.
    pub next_gap: Real,
    pub axes: JointAxes,
}

/// The joint axes of a node on `b` (`on_b`) or `a` under the face of outward normal
/// `face_normal` (body frame of the other block, rotated by `rotation`).
#[inline]
fn node_axes(on_b: bool, rotation: &Matrix, face_normal: Vector) -> JointAxes {
    let m = *rotation * face_normal;
    JointAxes {
        // The other block's outward normal points at the node's block: from a to b when the
        // node is on b.
        normal: if on_b { m } else { -m },
        tangent: *rotation * plane_basis(face_normal).0,
    }
}

/// The frame of node `id` of the contact between `a` and `b` at their current poses.
#[inline]
pub(crate) fn node_frame(id: NodeId, a: NodeBlock<'_>, b: NodeBlock<'_>) -> NodeFrame {
    let (host, other) = if id.on_b { (b, a) } else { (a, b) };
    let point = host.0.pose.translation + *host.1 * id.point(host.2);
    let q = other.1.transpose() * (point - other.0.pose.translation);
    let (face, gap, next_gap) = deepest_two(other.2, q);
    NodeFrame {
        point,
        face,
        gap,
        next_gap,
        axes: node_axes(id.on_b, other.1, other.2.faces()[face].normal),
    }
}

/// The normal stiffness `k_n` (per unit area) with which node contacts of `law` are integrated
/// over the surface each node stands for, if they are: in large-displacement mode, with
/// [`NodeRule::Integrated`], for a law whose normal spring is linear (its elastic regime). The
/// step (`update_nodes`) and detection (which lets only such node contacts turn back into
/// joints, `docs/theory.md` §6) ask the same question here.
pub(crate) fn integrated_stiffness<L: ConstitutiveLaw>(
    law: &L,
    mode: DisplacementMode,
    rule: NodeRule,
) -> Option<Real> {
    (mode == DisplacementMode::Large && rule == NodeRule::Integrated)
        .then(|| law.elastic_regime().map(|r| r.normal_stiffness))
        .flatten()
        .filter(|k| *k > 0.0)
}

/// The world point of node `id` and the joint axes its stored forces are composed in: those of
/// face `face` of the other block (the face it was pressed out of at its last step).
pub(crate) fn stored_node_frame(id: NodeId, face: usize, a: NodeBlock<'_>, b: NodeBlock<'_>) -> (Vector, JointAxes) {
    let (host, other) = if id.on_b { (b, a) } else { (a, b) };
    let point = host.0.pose.translation + *host.1 * id.point(host.2);
    (point, node_axes(id.on_b, other.1, other.2.faces()[face].normal))
}

/// The shear components `shear` of a node on `b` (`on_b`) or `a`, stored along the tangents of
/// the plane of normal `from` (body frame of the other block: the turn does not depend on its
/// pose), turned onto the plane of normal `to` by the smallest rotation, which keeps their
/// magnitude.
pub(crate) fn turned_shear(shear: Vector2, on_b: bool, from: Vector, to: Vector) -> Vector2 {
    let (old, new) = (
        node_axes(on_b, &Matrix::IDENTITY, from),
        node_axes(on_b, &Matrix::IDENTITY, to),
    );
    let s = old.shear(shear);
    let s = match plane_turn(old.normal, new.normal) {
        Some(m) => s - m * new.normal.dot(s),
        None => s,
    };
    new.components(s)
}

/// Updates one node contact for one step (see the module): every node's gap, axes and forces,
/// and returns the contact's wrench on the two blocks and its energy increments. Sums run in
/// node order. The node geometry follows the blocks in either displacement mode; in
/// small-displacement mode the gap is carried incrementally.
#[allow(clippy::too_many_arguments)]
pub(crate) fn update_nodes<L: ConstitutiveLaw>(
    pair: &mut ContactPair,
    reference: &mut ContactReference,
    subs: &mut [SubContact<L::State>],
    dashpot_forces: &mut [Vector],
    a: NodeBlock<'_>,
    b: NodeBlock<'_>,
    law: &L,
    ctx: KernelContext,
    watch: bool,
) -> ContactStep {
    let (sa, sb) = (a.0, b.0);
    let (xa, xb) = (sa.pose.translation, sb.pose.translation);
    let dt = ctx.dt;
    let (damped, cn, cs) = ctx.dashpot_coefficients(law.stiffness());
    let dashpots = damped || pair.dashpots;
    // Damped, the model keeps the dashpot forces; otherwise they are all zero, and an empty
    // list stands for them (a new contact, or one after Rayleigh damping was switched off,
    // still takes the dashpots' loop and order of sums).
    debug_assert!(!damped || dashpot_forces.len() == subs.len(), "dashpot forces not kept");
    let threshold = ctx.impact_speed * dt;
    let reach = ctx.impact_horizon / dt;
    let mut step = ContactStep::default();
    let (mut force, mut moment_a, mut moment_b) = (Vector::ZERO, Vector::ZERO, Vector::ZERO);
    let (mut spring_sum, mut dashpot_sum, mut normal_force) = (0.0, 0.0, 0.0);
    let mut fastest: Real = 0.0;
    // Nodes integrated over their strips (`geometry/narrow_phase/strips.rs`): in
    // large-displacement mode, for a law whose normal spring is linear (`k_n` per unit area)
    // and, in the node's state, carries no tension; elsewhere at their points.
    let integrated = integrated_stiffness(law, ctx.mode, ctx.node_rule);
    // The node spacing, which the strips' widths follow (integrated only).
    let h = integrated.map_or(0.0, |_| spacing(a.2, b.2, ctx.node_density));
    // Their strips depend on the shapes alone: built at the contact's first integrated step
    // since its detection. The nodes' keys are the contact's (`NodeRecord`).
    let areas: &[SubContact<L::State>] = subs;
    let (keys, strips) = reference.node_keys_and_strips(integrated.map(|_| {
        |keys: &[SubKey]| {
            let nodes = keys
                .iter()
                .zip(areas.iter())
                .map(|(k, s)| (NodeId::from_key(*k), s.area));
            NodeStrips::build(nodes, (a.2, b.2), h)
        }
    }));
    debug_assert_eq!(keys.len(), subs.len(), "a node contact's keys");
    let integrated = integrated.filter(|_| strips.is_some());
    let mut spread_energy = 0.0;
    for (i, (sub, key)) in subs.iter_mut().zip(keys).enumerate() {
        let id = NodeId::from_key(*key);
        let frame = node_frame(id, a, b);
        // Integrated (large-displacement mode, a linear normal spring, no tension in the
        // node's state), a node within `h` of the other block (its pieces lie within that of
        // it: `Strip::reach`) is pressed by its pieces' load, if they carry one.
        let integrate = integrated.is_some() && tension_free(law, &sub.state) && frame.gap <= h;
        let pressed = integrate
            .then(|| strip_load(id, a, b, strips.map_or(&[][..], |s| s.of(i)), frame.face))
            .filter(|load| load.load > 0.0 && sub.area > 0.0);
        // Pressed, its normal is that of its load's resultant: it turns continuously as the
        // load moves from one face of the other block to another (a node on an edge of the
        // other block), and its stored shear turns with it by the smallest rotation. The shear
        // is kept between steps in the plane of a face of the other block (`sub.plane.x`, the
        // one closest to the normal), turned from there onto the normal's plane at each step
        // and back after it: the face is a matter of storage, the shear applied depends on the
        // normal alone. Not pressed, the node's shear acts in the plane of the face its point
        // lies deepest under, turned onto it from the last when that changes.
        let other = if id.on_b { a } else { b };
        let last_face = sub.plane.x as usize;
        let faces = other.2.faces();
        let resultant = pressed.and_then(|load| {
            let length = load.force.length();
            (length > 1e-9 * load.load).then(|| load.force / length)
        });
        let axes = match resultant {
            Some(normal) => {
                if sub.force.shear != Vector2::ZERO {
                    sub.force.shear = turned_shear(sub.force.shear, id.on_b, faces[last_face].normal, normal);
                }
                node_axes(id.on_b, other.1, normal)
            }
            None => {
                if frame.face != last_face && sub.force.shear != Vector2::ZERO {
                    sub.force.shear = turned_shear(
                        sub.force.shear,
                        id.on_b,
                        faces[last_face].normal,
                        faces[frame.face].normal,
                    );
                }
                sub.plane.x = frame.face as Real;
                frame.axes
            }
        };
        // Where a pressed node's shear is kept after its step: the loaded face whose normal
        // lies closest to the resultant's (one has `m·n > 0`: `n` is a positive sum of them).
        let keep_in = resultant.map(|normal| {
            let loaded = pressed.iter().flat_map(|load| load.loaded_faces());
            let face = loaded
                .map(|f| (f, faces[f].normal.dot(normal)))
                .fold(None, |best: Option<(usize, Real)>, (f, c)| match best {
                    Some(b) if b.1 >= c => Some(b),
                    _ => Some((f, c)),
                })
                .map_or(frame.face, |(f, _)| f);
            (face, normal)
        });
        let keep = |sub: &mut SubContact<L::State>| {
            if let Some((face, normal)) = keep_in {
                if sub.force.shear != Vector2::ZERO {
                    sub.force.shear = turned_shear(sub.force.shear, id.on_b, normal, faces[face].normal);
                }
                sub.plane.x = face as Real;
            }
        };
        let p = frame.point;
        let v_rel =
            (sb.velocity + sb.angular_velocity.cross(p - xb)) - (sa.velocity + sa.angular_velocity.cross(p - xa));
        let du = v_rel * dt;
        let du_n = axes.normal.dot(du);
        let du_s = axes.components(du);
        fastest = fastest.max(v_rel.length_squared());
        let gap = match (ctx.mode, pressed) {
            (DisplacementMode::Large, Some(load)) => -load.load / sub.area,
            // Open, an integrated node reports the gap at its point (its pieces are out of the
            // other block; the point, on their boundary, is not inside it), as a point node
            // does: the impact probe watches it close as before.
            (DisplacementMode::Large, None) if integrate => frame.gap.max(Real::MIN_POSITIVE),
            (DisplacementMode::Large, None) => frame.gap,
            (DisplacementMode::Small, _) => sub.gap + du_n,
        };
        // The impact probe: the spring's kink (closing or opening fast), and, for a loaded
        // node, the turn of its normal to another face (a kink of the potential inside the
        // other block), approached fast: `gap − next_gap` changes by at most `2|Δu|` a step.
        let moved = du.length();
        let turn = frame.gap < 0.0 && moved > threshold && frame.gap - frame.next_gap < 2.0 * reach * moved;
        step.impact |= turn
            || (du_n.abs() > threshold
                && (gap > 0.0) != (du_n > 0.0)
                && gap.abs() < reach * du_n.abs()
                && law.stays_open(sub.area, gap.abs(), &sub.state));
        if (!dashpots || dashpot_forces.get(i).is_none_or(|d| *d == Vector::ZERO)) && stays_separated(law, sub, gap) {
            sub.gap = gap;
            keep(sub);
            continue;
        }
        let before = axes.force(&sub.force);
        let (status, lost, fracture) = update_with_law(law, sub, gap, du_n, du_s, axes, dt);
        step.dissipated += lost;
        step.fracture += fracture;
        let spring = axes.force(&sub.force);
        keep(sub);
        spring_sum += (before + spring).dot(du);
        normal_force += sub.force.normal;
        let mut total = spring;
        // Integrated, the normal force is the strips' pressure, each part along the normal of
        // the face it lies under and where it acts: a force at the node and a couple about it
        // (on the node's block; their opposites on the other), and the energy its spread
        // stores beyond the law's `F_n²/(2 k_n A)`.
        let mut couple = Vector::ZERO;
        if let (Some(load), Some(kn)) = (pressed, integrated) {
            if sub.force.normal > 0.0 && status != JointStatus::Open {
                let side = if id.on_b { 1.0 } else { -1.0 };
                let scale = side * sub.force.normal / load.load;
                total += (*other.1 * load.force) * scale - axes.normal * sub.force.normal;
                couple = (*other.1 * load.moment) * scale;
                spread_energy += kn * (load.energy - 0.5 * load.load * load.load / sub.area);
            }
        }
        if dashpots {
            let mut dashpot = Vector::ZERO;
            if damped && status != JointStatus::Open {
                dashpot -= axes.normal * (cn * sub.area * du_n);
                if status != JointStatus::Sliding {
                    dashpot -= axes.shear(du_s) * (cs * sub.area);
                }
            }
            let held = dashpot_forces.get(i).copied().unwrap_or(Vector::ZERO);
            dashpot_sum += (held + dashpot).dot(du);
            if let Some(d) = dashpot_forces.get_mut(i) {
                *d = dashpot;
            }
            total += dashpot;
        }
        // The force on b at the node, its opposite on a.
        force += total;
        moment_b += (p - xb).cross(total) + couple;
        moment_a -= (p - xa).cross(total) + couple;
    }
    pair.dashpots = damped;
    pair.spread_energy = spread_energy;
    pair.normal_force = normal_force;
    // The contact's normal for its views: along its resultant while it carries one.
    let length = force.length();
    if length > 0.0 && length.is_finite() {
        let axes = JointAxes::from_normal(force / length);
        (pair.normal, pair.tangent) = (axes.normal, axes.tangent);
    }
    step.impact &= fastest > ctx.impact_speed * ctx.impact_speed;
    step.busy = watch && normal_force > 0.0 && fastest > ctx.impact_speed * ctx.impact_speed;
    step.wrench = ContactWrench {
        force,
        moment_a,
        moment_b,
    };
    step.work = -0.5 * spring_sum;
    step.dashpot_work = -0.5 * dashpot_sum;
    step
}

/// The load of node `id`'s strips `strips` (`geometry/narrow_phase/strips.rs`) in the other
/// block, per unit `k_n`, in the other block's body frame, with moments about the node; `near`
/// is the face of the other block the node lies deepest under.
fn strip_load(id: NodeId, a: NodeBlock<'_>, b: NodeBlock<'_>, strips: &[Strip], near: usize) -> StripLoad {
    let (host, other) = if id.on_b { (b, a) } else { (a, b) };
    // Host body frame to the other's body frame: q = R_oᵀ (x_h + R_h x − x_o).
    let turn = other.1.transpose() * *host.1;
    let shift = other.1.transpose() * (host.0.pose.translation - other.0.pose.translation);
    let about = turn * id.point(host.2) + shift;
    let mut load = StripLoad::default();
    for s in strips {
        load.add(
            other.2,
            (turn * s.centre + shift, turn * s.u, turn * s.v),
            s,
            about,
            near,
        );
    }
    load
}
