//! Central difference (paper eqs. 3–4) for rigid blocks with the full inertia tensor.

use super::{Damping, Integrator, StepDurations, StepRecord};
use crate::block::{Block, BlockState, Dof, Fixity, RigidBlock, Wrench};
use crate::geometry::MassProperties;
use crate::math::{rotation_from_vector, Matrix, Real, Vector};

/// Explicit central difference: velocities at half steps, positions at full steps.
///
/// Translation: `v⁺ = [(1 − a·Δt/2)·v⁻ + Δt·F/m] / (1 + a·Δt/2)`.
/// Rotation is integrated on the angular momentum `L` (world frame), which carries the gyroscopic
/// term exactly: `L⁺ = [(1 − a·Δt/2)·L⁻ + Δt·M] / (1 + a·Δt/2)`, `ω⁺ = R'·I⁻¹·R'ᵀ·L⁺` with the
/// mid-step rotation `R' = exp(ω⁺·Δt/2)·R`, then
/// `R ← exp(ω⁺·Δt)·R`. With no moment, `L` is conserved to round-off. `a` is the Rayleigh mass
/// coefficient; local damping modifies `F` and `M` per component before the update.
#[derive(Debug, Clone, Copy, PartialEq, Default)]
pub struct CentralDifference {
    /// The damping model.
    pub damping: Damping,
}

impl CentralDifference {
    /// Central difference with the given damping.
    pub fn new(damping: Damping) -> Self {
        Self { damping }
    }
}

impl Integrator for CentralDifference {
    fn advance_block(
        &self,
        state: &mut BlockState,
        mass: &MassProperties,
        fixity: &Fixity,
        wrench: &Wrench,
        step: StepDurations,
    ) -> StepRecord {
        advance_block(state, mass, fixity, wrench, step, self.damping)
    }

    /// The blocks of the chunk in order, compiled for AVX2 where the processor has it (the
    /// same IEEE operations, no fused multiply-add: bit-identical to
    /// [`advance_block`](Integrator::advance_block)).
    fn advance_chunk(
        &self,
        blocks: &mut [RigidBlock],
        wrenches: &[Wrench],
        step: StepDurations,
        records: &mut [StepRecord],
    ) {
        #[cfg(target_arch = "x86_64")]
        if crate::dispatch::has_avx2() {
            // SAFETY: the processor has AVX2 (checked by `dispatch::has_avx2`).
            unsafe { advance_chunk_avx2(blocks, wrenches, records, step, self.damping) };
            return;
        }
        advance_chunk(blocks, wrenches, records, step, self.damping);
    }

    fn damping(&self) -> Damping {
        self.damping
    }

    fn boxed_clone(&self) -> Box<dyn Integrator> {
        Box::new(*self)
    }

    fn checkpoint_damping(&self) -> Option<Damping> {
        Some(self.damping)
    }
}

#[inline(always)]
fn advance_chunk(
    blocks: &mut [RigidBlock],
    loads: &[Wrench],
    records: &mut [StepRecord],
    dt: StepDurations,
    damping: Damping,
) {
    for ((block, load), rec) in blocks.iter_mut().zip(loads).zip(records) {
        // A free block's fixity is the constant (its own sits on a cache line the step need
        // not read).
        let fixity = if block.is_free() { Fixity::FREE } else { *block.fixity() };
        let mass = block.mass_properties();
        *rec = advance_block(&mut block.state, &mass, &fixity, load, dt, damping);
    }
}

/// [`advance_chunk`] compiled for AVX2 (see `dispatch`): bit-identical results.
///
/// # Safety
/// The processor must support AVX2.
#[cfg(target_arch = "x86_64")]
#[target_feature(enable = "avx2")]
unsafe fn advance_chunk_avx2(
    blocks: &mut [RigidBlock],
    loads: &[Wrench],
    records: &mut [StepRecord],
    dt: StepDurations,
    damping: Damping,
) {
    advance_chunk(blocks, loads, records, dt, damping);
}

#[inline]
fn local_damp(f: Vector, v: Vector, alpha: Real, dofs: &[Dof; 3]) -> Vector {
    let mut out = f;
    for i in 0..3 {
        if matches!(dofs[i], Dof::Free) {
            out[i] -= alpha * f[i].abs() * sign(v[i]);
        }
    }
    out
}

#[inline]
fn sign(x: Real) -> Real {
    if x > 0.0 {
        1.0
    } else if x < 0.0 {
        -1.0
    } else {
        0.0
    }
}

#[inline(always)]
fn advance_block(
    state: &mut BlockState,
    mass_properties: &MassProperties,
    fixity: &Fixity,
    load: &Wrench,
    steps: StepDurations,
    damping: Damping,
) -> StepRecord {
    // The impulse over the kick; the mid-step rotation and the move over the drift.
    let StepDurations { kick, drift } = steps;
    let mass = mass_properties.mass;
    let (alpha, a) = match damping {
        Damping::Local { alpha } => (alpha, 0.0),
        Damping::Rayleigh { mass, .. } => (0.0, mass),
        Damping::None => (0.0, 0.0),
    };
    let s0 = *state;
    let (c1, c2) = (1.0 - 0.5 * a * kick, 1.0 / (1.0 + 0.5 * a * kick));

    // Translation.
    let f = local_damp(load.force, s0.velocity, alpha, &fixity.translation);
    let mut v = (s0.velocity * c1 + f * (kick / mass)) * c2;
    let mut reaction = Wrench::default();
    for i in 0..3 {
        if let Some(p) = fixity.translation[i].prescribed() {
            v[i] = p;
            reaction.force[i] = mass * (p - s0.velocity[i]) / kick - load.force[i];
        }
    }
    // Rotation.
    let m = local_damp(load.moment, s0.angular_velocity, alpha, &fixity.rotation);
    let mut l = (s0.angular_momentum * c1 + m * kick) * c2;
    // ω(t+Δt/2) = R(t+Δt/2)·I⁻¹·R(t+Δt/2)ᵀ·L(t+Δt/2), with R(t+Δt/2) = exp(ω·Δt/2)·R(t): solved by
    // fixed-point iteration (contraction ~ |ω|Δt/2). Evaluating at R(t) instead makes the
    // rotation update first order and pumps energy into a free asymmetric spinner.
    // Rotations as matrices (two products each, with the transpose for the inverse), the
    // principal inertia inverted once.
    let inverse_inertia = Vector::ONE / mass_properties.principal_inertia;
    let r0 = s0.pose.rotation;
    let inertia_inverse_times = |m: &Matrix, v: Vector| *m * ((m.transpose() * v) * inverse_inertia);
    // ω₀ = A₀·L with A₀ = R·I⁻¹·Rᵀ at R(t); then the first-order start: turning the frame by
    // θ = ω₀·Δt/2 changes ω by θ×ω₀ − A₀·(θ×L), and θ×ω₀ = 0, so
    // ω₁ = ω₀ − (Δt/2)·A₀·(ω₀×L), within O(θ²)·|ω| of the fixed point (one exact pass less).
    let m0 = Matrix::from_quat(r0);
    let w0 = inertia_inverse_times(&m0, l);
    let mut w = w0 - inertia_inverse_times(&m0, (0.5 * drift * w0).cross(l));
    // The iteration contracts by about |ω|Δt/2 per pass: it stops when the next correction
    // would fall below round-off (at once for a block of masonry moving slowly, after three
    // exact passes at most).
    let mut change = (w - w0).length();
    for _ in 0..3 {
        if change * (0.5 * drift * w.length()) <= Real::EPSILON * w.length() {
            break;
        }
        let next = inertia_inverse_times(&Matrix::from_quat(rotation_from_vector(0.5 * drift * w) * r0), l);
        change = (next - w).length();
        w = next;
    }
    let mut constrained = false;
    for i in 0..3 {
        if let Some(p) = fixity.rotation[i].prescribed() {
            w[i] = p;
            constrained = true;
        }
    }
    if constrained {
        // The world inertia at the pose before the move: `R I Rᵀ ω`.
        l = r0 * (mass_properties.principal_inertia * (r0.inverse() * w));
        for i in 0..3 {
            if fixity.rotation[i].prescribed().is_some() {
                reaction.moment[i] = (l[i] - s0.angular_momentum[i]) / kick - load.moment[i];
            }
        }
    }
    let mean_velocity = 0.5 * (v + s0.velocity);
    let mean_angular_velocity = 0.5 * (w + s0.angular_velocity);
    // Damping actually applied: from the momentum balance of the free degrees of freedom.
    let mut damping_wrench = Wrench::default();
    if alpha > 0.0 {
        damping_wrench.force = f - load.force;
        damping_wrench.moment = m - load.moment;
    } else if a > 0.0 {
        damping_wrench.force = -a * mass * mean_velocity;
        damping_wrench.moment = -a * 0.5 * (l + s0.angular_momentum);
    }
    for i in 0..3 {
        if !matches!(fixity.translation[i], Dof::Free) {
            damping_wrench.force[i] = 0.0;
        }
        if !matches!(fixity.rotation[i], Dof::Free) {
            damping_wrench.moment[i] = 0.0;
        }
    }

    let st = state;
    st.velocity = v;
    st.angular_velocity = w;
    st.angular_momentum = l;
    st.pose.translation += v * drift;
    let angle = w * drift;
    if angle.length_squared() > 0.0 {
        st.pose.rotation = (rotation_from_vector(angle) * st.pose.rotation).normalize();
    }
    StepRecord {
        reaction,
        damping: damping_wrench,
        mean_velocity,
        mean_angular_velocity,
    }
}
