//! The sub-contact loop four sub-contacts at a time, for contacts without dashpot forces.
//!
//! The kinematics (the displacement increment in the joint axes, affine in the anchor's plane
//! coordinates, and the face gap) and the force sums `Σ f`, `Σ f x`, `Σ f y` are computed
//! lane-wise on four sub-contacts, which the compiler turns into packed floating-point
//! instructions; the law runs lane by lane (it is generic and branches). The kinematics are one
//! generic function ([`increment`], [`face_gap`]) for a lane group and for a single sub-contact,
//! so a sub-contact's forces do not depend on which loop updated it; the sums are kept per lane
//! and the lanes added in a fixed order, so the totals do not depend on the number of threads.

use std::ops::{Add, Mul, Sub};

use super::law_update::{stays_separated, update_with_law};
use super::moments::ForceMoments;
use super::SubContact;
use crate::law::{ConstitutiveLaw, JointAxes};
use crate::math::{Real, Vector, Vector2};

/// Sub-contacts per group.
pub(crate) const LANES: usize = 4;

/// Four values, one per lane.
#[derive(Debug, Clone, Copy, Default)]
pub(crate) struct F4(pub(crate) [Real; LANES]);

impl F4 {
    #[inline(always)]
    pub(crate) fn splat(x: Real) -> Self {
        Self([x; LANES])
    }
    #[inline(always)]
    pub(crate) fn from_fn(f: impl FnMut(usize) -> Real) -> Self {
        Self(std::array::from_fn(f))
    }
    /// Lanes added in order: `((l₀ + l₁) + l₂) + l₃`.
    #[inline(always)]
    fn sum(self) -> Real {
        ((self.0[0] + self.0[1]) + self.0[2]) + self.0[3]
    }
}

impl Add for F4 {
    type Output = Self;
    #[inline(always)]
    fn add(self, o: Self) -> Self {
        Self(std::array::from_fn(|l| self.0[l] + o.0[l]))
    }
}

impl Sub for F4 {
    type Output = Self;
    #[inline(always)]
    fn sub(self, o: Self) -> Self {
        Self(std::array::from_fn(|l| self.0[l] - o.0[l]))
    }
}

impl Mul for F4 {
    type Output = Self;
    #[inline(always)]
    fn mul(self, o: Self) -> Self {
        Self(std::array::from_fn(|l| self.0[l] * o.0[l]))
    }
}

/// A number type the kinematics are written for: one sub-contact ([`Real`]) or a lane group.
pub(crate) trait Lane: Copy + Add<Output = Self> + Sub<Output = Self> + Mul<Output = Self> {
    /// The value `x` (in every lane).
    fn splat(x: Real) -> Self;
}

impl Lane for Real {
    #[inline(always)]
    fn splat(x: Real) -> Self {
        x
    }
}

impl Lane for F4 {
    #[inline(always)]
    fn splat(x: Real) -> Self {
        F4::splat(x)
    }
}

/// The displacement increment of a contact's sub-contacts over a step, in the joint axes
/// `(n, t₁, t₂)`: affine in the anchor's plane coordinates `(x, y)`,
/// `Δu = Δu_o + x Δu_x + y Δu_y` (see `update_contact`).
#[derive(Debug, Clone, Copy)]
pub(crate) struct Kinematics {
    /// At the plane origin.
    pub at_origin: Vector,
    /// Per unit of `x`.
    pub per_x: Vector,
    /// Per unit of `y`.
    pub per_y: Vector,
}

/// `[Δu_n, Δu_t₁, Δu_t₂]` at plane coordinates `(x, y)`, each as `(o + p_x x) + p_y y`.
#[inline(always)]
pub(crate) fn increment<T: Lane>(k: &Kinematics, x: T, y: T) -> [T; 3] {
    let at = |o: Real, px: Real, py: Real| (T::splat(o) + T::splat(px) * x) + T::splat(py) * y;
    [
        at(k.at_origin.x, k.per_x.x, k.per_y.x),
        at(k.at_origin.y, k.per_x.y, k.per_y.y),
        at(k.at_origin.z, k.per_x.z, k.per_y.z),
    ]
}

/// The face-face gap `(g_o − g_x x) − g_y y` at plane coordinates `(x, y)`.
#[inline(always)]
pub(crate) fn face_gap<T: Lane>(g: (Real, Real, Real), x: T, y: T) -> T {
    (T::splat(g.0) - T::splat(g.1) * x) - T::splat(g.2) * y
}

/// What the loop needs of the contact, computed once per contact (see `update_contact`).
#[derive(Debug, Clone, Copy)]
pub(crate) struct ContactFrame {
    /// The joint axes of this step.
    pub axes: JointAxes,
    pub kinematics: Kinematics,
    /// Face gap `(g_o, g_x, g_y)` (face-face, large displacements), else incremental.
    pub face_gap: Option<(Real, Real, Real)>,
    pub dt: Real,
}

/// A contact's force sums in the joint axes ([`ForceMoments`] of `f = (F_n, F_t₁, F_t₂)`), per
/// lane.
#[derive(Debug, Clone, Copy, Default)]
pub(crate) struct LaneSums {
    pub(crate) force: [F4; 3],
    pub(crate) per_x: [F4; 3],
    pub(crate) per_y: [F4; 3],
    /// Energy dissipated by the law, in sub-contact order: fracture work apart.
    dissipated: Real,
    fracture: Real,
}

impl LaneSums {
    /// Adds four forces `f = (F_n, F_t₁, F_t₂)` at plane coordinates `(x, y)`, lane-wise.
    #[inline(always)]
    pub(crate) fn add(&mut self, f: [F4; 3], x: F4, y: F4) {
        for (k, f) in f.into_iter().enumerate() {
            self.force[k] = self.force[k] + f;
            self.per_x[k] = self.per_x[k] + f * x;
            self.per_y[k] = self.per_y[k] + f * y;
        }
    }

    /// The lane sums added in lane order, the dissipated energy and the fracture work.
    pub fn total(self) -> (ForceMoments, Real, Real) {
        let v = |s: [F4; 3]| Vector::new(s[0].sum(), s[1].sum(), s[2].sum());
        (
            ForceMoments {
                force: v(self.force),
                per_x: v(self.per_x),
                per_y: v(self.per_y),
            },
            self.dissipated,
            self.fracture,
        )
    }
}

/// Updates four sub-contacts of a contact without dashpot forces, adding
/// their spring forces to `sums`. The same operations as the one-at-a-time loop, lane-wise.
#[inline(always)]
pub(crate) fn update_group<L: ConstitutiveLaw>(
    group: &mut [SubContact<L::State>; LANES],
    law: &L,
    frame: &ContactFrame,
    sums: &mut LaneSums,
) {
    let x = F4::from_fn(|l| group[l].plane.x);
    let y = F4::from_fn(|l| group[l].plane.y);
    let [du_n, du_1, du_2] = increment(&frame.kinematics, x, y);
    let gap = match frame.face_gap {
        Some(g) => face_gap(g, x, y),
        None => F4::from_fn(|l| group[l].gap) + du_n,
    };
    for (l, sub) in group.iter_mut().enumerate() {
        let gap = gap.0[l];
        // A separated sub-contact that stays open: no force, no update (as the scalar loop).
        if frame.face_gap.is_some() && stays_separated(law, sub, gap) {
            sub.gap = gap;
            continue;
        }
        let du_s = Vector2::new(du_1.0[l], du_2.0[l]);
        let (_, lost, fracture) = update_with_law(law, sub, gap, du_n.0[l], du_s, frame.axes, frame.dt);
        sums.dissipated += lost;
        sums.fracture += fracture;
    }
    // The forces as the law left them (zero where skipped), read back lane by lane.
    let f = [
        F4::from_fn(|l| group[l].force.normal),
        F4::from_fn(|l| group[l].force.shear.x),
        F4::from_fn(|l| group[l].force.shear.y),
    ];
    sums.add(f, x, y);
}
