//! The hot loop: joint kinematics, law update and dashpots at one sub-contact; resultants per pair.

use super::{ContactPair, DisplacementMode, SubContact};
use crate::block::BlockState;
use crate::constitutive::{ConstitutiveLaw, JointStatus, JointStep};
use crate::geometry::{ContactKind, Polyhedron};
use crate::math::{Real, Vector};

/// Read-only data shared by all sub-contacts of a step.
#[derive(Debug, Clone, Copy)]
pub(crate) struct KernelContext {
    pub dt: Real,
    /// Rayleigh stiffness-proportional coefficient `b` (s).
    pub stiffness_damping: Real,
    pub mode: DisplacementMode,
}

/// Updates the pair's plane from the current poses (large-displacement mode).
pub(crate) fn update_pair_geometry(
    pair: &mut ContactPair,
    sa: &BlockState,
    sb: &BlockState,
    shape_a: &Polyhedron,
    shape_b: &Polyhedron,
) {
    match pair.kind {
        ContactKind::FaceFace { face_a, face_b } => {
            let fa = &shape_a.faces()[face_a as usize];
            let fb = &shape_b.faces()[face_b as usize];
            let na = sa.pose.rotation * fa.normal;
            let nb = sb.pose.rotation * fb.normal;
            pair.normal = (na - nb).normalize();
            // Plane of the other face in world coordinates.
            let (host_n, other_n, other_off, other_pose) = if pair.host_is_a {
                (na, nb, fb.offset, &sb.pose)
            } else {
                (nb, na, fa.offset, &sa.pose)
            };
            pair.host_normal = host_n;
            pair.other_normal = other_n;
            pair.other_offset = other_off + other_n.dot(other_pose.translation);
        }
        ContactKind::Point { normal_local } => {
            pair.normal = sa.pose.rotation * normal_local;
        }
    }
}

/// One step of one sub-contact: kinematics, law, dashpots, energy increments.
#[inline]
pub(crate) fn update_subcontact<L: ConstitutiveLaw>(
    sub: &mut SubContact<L::State>,
    pair: &ContactPair,
    sa: &BlockState,
    sb: &BlockState,
    law: &L,
    ctx: KernelContext,
) {
    let n = pair.normal;
    let (p, xa, xb, geometric_gap) = match ctx.mode {
        DisplacementMode::Large => {
            let host = if pair.host_is_a { sa } else { sb };
            let p = host.pose.transform_point(sub.anchor);
            let gap = match pair.kind {
                ContactKind::FaceFace { .. } => {
                    Some((pair.other_offset - pair.other_normal.dot(p)) / pair.other_normal.dot(pair.host_normal))
                }
                ContactKind::Point { .. } => None,
            };
            (p, sa.pose.translation, sb.pose.translation, gap)
        }
        DisplacementMode::Small => (sub.point, pair.ref_a, pair.ref_b, None),
    };
    let v_rel = (sb.velocity + sb.angular_velocity.cross(p - xb)) - (sa.velocity + sa.angular_velocity.cross(p - xa));
    let du = v_rel * ctx.dt;
    let du_n = n.dot(du);
    let du_s = du - n * du_n;
    let gap = geometric_gap.unwrap_or(sub.gap + du_n);

    // Keep last step's shear force in the current plane, with its magnitude.
    let fs = sub.force.shear;
    let magnitude = fs.length();
    if magnitude > 0.0 {
        let projected = fs - n * n.dot(fs);
        let len = projected.length();
        sub.force.shear = if len > 0.0 {
            projected * (magnitude / len)
        } else {
            Vector::ZERO
        };
    }
    let step = JointStep {
        area: sub.area,
        normal_displacement: gap,
        normal_increment: du_n,
        shear_increment: du_s,
        normal: n,
        dt: ctx.dt,
    };
    let status = law.update(&step, &mut sub.force, &mut sub.state);
    if status == JointStatus::Sliding {
        sub.slip += du_s.length();
    }
    let spring = n * sub.force.normal + sub.force.shear;
    let mut dashpot = Vector::ZERO;
    if ctx.stiffness_damping > 0.0 && status != JointStatus::Open {
        let k = law.stiffness();
        let c = ctx.stiffness_damping * sub.area;
        dashpot -= n * (c * k.normal * du_n / ctx.dt);
        if status != JointStatus::Sliding {
            dashpot -= du_s * (c * k.shear / ctx.dt);
        }
    }
    sub.work = -0.5 * (sub.spring + spring).dot(du);
    // Trapezoidal, like the spring work: last step's dashpot force is `total − spring`.
    sub.dashpot_work = -0.5 * (sub.total - sub.spring + dashpot).dot(du);
    sub.spring = spring;
    sub.total = spring + dashpot;
    sub.point = p;
    sub.gap = gap;
    sub.status = status;
    sub.elastic = law.elastic_energy(sub.area, &sub.force, &sub.state);
}

/// Sums a pair's sub-contacts into its resultant and moments (fixed order: deterministic).
#[inline]
pub(crate) fn sum_contact<S>(
    pair: &mut ContactPair,
    subs: &[SubContact<S>],
    sa: &BlockState,
    sb: &BlockState,
    mode: DisplacementMode,
) {
    let (xa, xb) = match mode {
        DisplacementMode::Large => (sa.pose.translation, sb.pose.translation),
        DisplacementMode::Small => (pair.ref_a, pair.ref_b),
    };
    let mut force = Vector::ZERO;
    let mut moment_a = Vector::ZERO;
    let mut moment_b = Vector::ZERO;
    let (mut normal, mut work, mut dashpot, mut elastic) = (0.0, 0.0, 0.0, 0.0);
    for s in subs {
        force += s.total;
        moment_b += (s.point - xb).cross(s.total);
        moment_a -= (s.point - xa).cross(s.total);
        normal += s.force.normal;
        work += s.work;
        dashpot += s.dashpot_work;
        elastic += s.elastic;
    }
    pair.force = force;
    pair.moment_a = moment_a;
    pair.moment_b = moment_b;
    pair.normal_force = normal;
    pair.work = work;
    pair.dashpot_work = dashpot;
    pair.elastic = elastic;
}
