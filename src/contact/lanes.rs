//! The sub-contact loop four sub-contacts at a time, for contacts without dashpot forces.
//!
//! The kinematics (`Δu = Δu₀ + D a`, `Δu_n`, `Δu_s`, the face gap), the turn of last step's shear
//! force into the new plane and the force moments `Σ F`, `Σ F aᵀ` are computed lane-wise on four
//! sub-contacts, which the compiler turns into packed floating-point instructions; the law runs
//! lane by lane (it is generic and branches). Each lane performs exactly the operations of the
//! one-at-a-time loop in [`super::kernel`], in the same order, so a sub-contact's forces do not
//! depend on which loop updated it; the moments are summed per lane and the lanes added in a
//! fixed order, so the totals do not depend on the number of threads.

use std::ops::{Add, Mul, Sub};

use super::kernel::stays_separated;
use super::{SubContact, SubContactRecord};
use crate::constitutive::{ConstitutiveLaw, JointForce, JointStatus, JointStep};
use crate::math::{Matrix, Real, Vector};

/// Sub-contacts per group.
pub(crate) const LANES: usize = 4;

/// Four values, one per lane.
#[derive(Debug, Clone, Copy, Default)]
struct F4([Real; LANES]);

impl F4 {
    #[inline(always)]
    fn splat(x: Real) -> Self {
        Self([x; LANES])
    }
    #[inline(always)]
    fn from_fn(f: impl FnMut(usize) -> Real) -> Self {
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

/// A vector per lane.
#[derive(Debug, Clone, Copy, Default)]
struct V4 {
    x: F4,
    y: F4,
    z: F4,
}

impl V4 {
    #[inline(always)]
    fn splat(v: Vector) -> Self {
        Self {
            x: F4::splat(v.x),
            y: F4::splat(v.y),
            z: F4::splat(v.z),
        }
    }
    #[inline(always)]
    fn gather(f: impl Fn(usize) -> Vector) -> Self {
        Self {
            x: F4::from_fn(|l| f(l).x),
            y: F4::from_fn(|l| f(l).y),
            z: F4::from_fn(|l| f(l).z),
        }
    }
    #[inline(always)]
    fn lane(&self, l: usize) -> Vector {
        Vector::new(self.x.0[l], self.y.0[l], self.z.0[l])
    }
    /// `self · v` for a vector `v` common to the lanes, as glam's `(x + y) + z`.
    #[inline(always)]
    fn dot(&self, v: &V4) -> F4 {
        self.x * v.x + self.y * v.y + self.z * v.z
    }
    #[inline(always)]
    fn scale(&self, s: F4) -> Self {
        Self {
            x: self.x * s,
            y: self.y * s,
            z: self.z * s,
        }
    }
    #[inline(always)]
    fn sum(self) -> Vector {
        Vector::new(self.x.sum(), self.y.sum(), self.z.sum())
    }
}

impl Add for V4 {
    type Output = Self;
    #[inline(always)]
    fn add(self, o: Self) -> Self {
        Self {
            x: self.x + o.x,
            y: self.y + o.y,
            z: self.z + o.z,
        }
    }
}

impl Sub for V4 {
    type Output = Self;
    #[inline(always)]
    fn sub(self, o: Self) -> Self {
        Self {
            x: self.x - o.x,
            y: self.y - o.y,
            z: self.z - o.z,
        }
    }
}

/// What the loop needs of the contact, computed once per contact (see `update_contact`).
#[derive(Debug, Clone, Copy)]
pub(crate) struct ContactFrame {
    /// Normal of this step.
    pub n: Vector,
    /// `Δu₀` and `D` of `Δu = Δu₀ + D a`.
    pub du0: Vector,
    pub d: Matrix,
    /// Face gap `g₀ − q·a` (face-face, large displacements), else incremental.
    pub face_gap: Option<(Real, Vector)>,
    /// Turn of last step's shear force: `s ← s − m (n·s)`.
    pub shear_turn: Option<Vector>,
    pub dt: Real,
}

/// Per-lane sums of a contact's spring forces and normal forces.
#[derive(Debug, Clone, Copy, Default)]
pub(crate) struct LaneSums {
    force: V4,
    first: [V4; 3],
    normal: F4,
}

impl LaneSums {
    /// The lane sums added in lane order: `(Σ F, Σ F aᵀ, Σ F_n)`.
    pub fn total(self) -> (Vector, Matrix, Real) {
        (
            self.force.sum(),
            Matrix::from_cols(self.first[0].sum(), self.first[1].sum(), self.first[2].sum()),
            self.normal.sum(),
        )
    }
}

/// Updates four sub-contacts (and their records) of a contact without dashpot forces, adding
/// their spring forces to `sums`. The same operations as the one-at-a-time loop, lane-wise.
#[inline(always)]
pub(crate) fn update_group<L: ConstitutiveLaw>(
    group: &mut [SubContact<L::State>],
    records: &mut [SubContactRecord],
    law: &L,
    frame: &ContactFrame,
    sums: &mut LaneSums,
) {
    debug_assert!(group.len() == LANES && records.len() == LANES);
    let n = frame.n;
    let nv = V4::splat(n);
    let a = V4::gather(|l| group[l].anchor);
    // du = du₀ + D a, as glam's `du₀ + ((D.x a.x + D.y a.y) + D.z a.z)`.
    let d = &frame.d;
    let da = V4::splat(d.x_axis).scale(a.x) + V4::splat(d.y_axis).scale(a.y) + V4::splat(d.z_axis).scale(a.z);
    let du = V4::splat(frame.du0) + da;
    let du_n = nv.dot(&du);
    let du_s = du - nv.scale(du_n);
    let gap = match frame.face_gap {
        Some((g0, q)) => F4::splat(g0) - V4::splat(q).dot(&a),
        None => F4::from_fn(|l| group[l].gap) + du_n,
    };
    let mut shear = V4::gather(|l| group[l].force.shear);
    if let Some(m) = frame.shear_turn {
        shear = shear - V4::splat(m).scale(nv.dot(&shear));
    }
    let (mut fn_, mut fs) = (F4::default(), V4::default());
    for l in 0..LANES {
        let sub = &mut group[l];
        let gap = gap.0[l];
        // A separated sub-contact that stays open: no force, no update (as the scalar loop).
        if frame.face_gap.is_some() && stays_separated(law, sub, gap) {
            sub.gap = gap;
            continue;
        }
        let du_s = du_s.lane(l);
        let mut force = JointForce {
            normal: sub.force.normal,
            shear: shear.lane(l),
        };
        let step = JointStep {
            area: sub.area,
            normal_displacement: gap,
            normal_increment: du_n.0[l],
            shear_increment: du_s,
            normal: n,
            dt: frame.dt,
        };
        let status = law.update(&step, &mut force, &mut sub.state);
        if status == JointStatus::Sliding {
            records[l].slip += du_s.length();
        }
        sub.force = force;
        sub.gap = gap;
        sub.status = status;
        fn_.0[l] = force.normal;
        fs.x.0[l] = force.shear.x;
        fs.y.0[l] = force.shear.y;
        fs.z.0[l] = force.shear.z;
    }
    // Spring force n F_n + F_s, and its moments, lane-wise.
    let f = nv.scale(fn_) + fs;
    sums.normal = sums.normal + fn_;
    sums.force = sums.force + f;
    sums.first[0] = sums.first[0] + f.scale(a.x);
    sums.first[1] = sums.first[1] + f.scale(a.y);
    sums.first[2] = sums.first[2] + f.scale(a.z);
}
