//! One sub-contact through its joint law: the update every sub-contact loop (scalar or in lanes)
//! goes through, with the energy it dissipates, and the skip test for open sub-contacts.

use super::SubContact;
use crate::law::{ConstitutiveLaw, JointAxes, JointStatus, JointStep};
use crate::math::{Real, Vector2};

/// Calls the law on one sub-contact with this step's gap and increments, and stores what it
/// returns: forces and state (by the law), gap, status, and the slip while sliding. Every
/// sub-contact loop goes through here, so a sub-contact's update does not depend on the loop.
///
/// Returns the status and the energy the law dissipated (`docs/theory.md` §6), as the part
/// that is not fracture work and the fracture work: zero for an elastic or open step; for a
/// step that changed the law's state (a failure, softening), the work done on the springs
/// over the step (trapezoidal rule) less the change of their elastic energy,
/// `−½ (F⁻ + F)·Δu − (E(F) − E(F⁻))` (the normal part over the change of the stored gap, or
/// for a step with fracture work over the step's normal increment), of which the law's
/// [`ConstitutiveLaw::fracture_work`] (when positive, and at most the whole when that is
/// positive, else none) is fracture work; for a sliding step, that of the shear spring alone,
/// `−½ (F_s⁻ + F_s)·Δu_s − (|F_s|² − |F_s⁻|²)/(2 k_s A)`, the work of the slip — the normal
/// spring stays elastic while the joint slides; for a step that opens a joint holding a shear
/// force, the same: the shear spring's energy, which the law drops with the contact, is lost.
/// A law without fracture work (the default) gets exactly its whole dissipation in the first
/// part (`x − 0.0` is `x`, bit for bit).
#[inline(always)]
pub(crate) fn update_with_law<L: ConstitutiveLaw>(
    law: &L,
    sub: &mut SubContact<L::State>,
    gap: Real,
    du_n: Real,
    du_s: Vector2,
    axes: JointAxes,
    dt: Real,
) -> (JointStatus, Real, Real) {
    let step = JointStep {
        area: sub.area,
        normal_displacement: gap,
        normal_increment: du_n,
        shear_increment: du_s,
        axes,
        dt,
    };
    let before = sub.force;
    let state_before = sub.state.clone();
    let status = law.update(&step, &mut sub.force, &mut sub.state);
    let f = &sub.force;
    let mut fracture = 0.0;
    let dissipated = if sub.state != state_before {
        let consumed = law.fracture_work(sub.area, &state_before, &sub.state);
        // The normal spring's work over the change of its gap (geometric in large-displacement
        // mode), so that the time integration's error is not booked as dissipation; over the
        // step's displacement for a step that softens, whose work is all the crack's: re-detection
        // seeds the gaps of the sub-contacts it carries over with the gaps at the poses it
        // finds, so that the change of the gap over its step is lost.
        let normal_increment = if consumed > 0.0 { du_n } else { gap - sub.gap };
        let work = -0.5 * ((before.normal + f.normal) * normal_increment + (before.shear + f.shear).dot(du_s));
        let lost =
            work - (law.elastic_energy(sub.area, f, &sub.state) - law.elastic_energy(sub.area, &before, &state_before));
        if consumed > 0.0 {
            fracture = consumed.min(lost.max(0.0));
        }
        lost - fracture
    } else if status == JointStatus::Sliding || (status == JointStatus::Open && before.shear != Vector2::ZERO) {
        let work = -0.5 * (before.shear + f.shear).dot(du_s);
        let ks_area = law.stiffness().shear * sub.area;
        if ks_area > 0.0 {
            work - 0.5 * (f.shear.length_squared() - before.shear.length_squared()) / ks_area
        } else {
            work
        }
    } else {
        0.0
    };
    if status == JointStatus::Sliding {
        sub.slip += du_s.length();
    }
    sub.gap = gap;
    sub.status = status;
    (status, dissipated, fracture)
}

/// Whether a sub-contact at geometric gap `gap` may skip its update: it is open with zero force
/// and the law says it stays so ([`ConstitutiveLaw::stays_open`]).
#[inline(always)]
pub(crate) fn stays_separated<L: ConstitutiveLaw>(law: &L, sub: &SubContact<L::State>, gap: Real) -> bool {
    sub.status == JointStatus::Open
        && sub.force.normal == 0.0
        && sub.force.shear == Vector2::ZERO
        && law.stays_open(sub.area, gap, &sub.state)
}
