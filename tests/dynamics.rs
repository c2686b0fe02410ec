//! Dynamics verified against closed forms, through the public API only.
//!
//! * a block on its joint springs is a one-degree-of-freedom oscillator: period, energy, and the
//!   logarithmic decrement under Rayleigh damping;
//! * a free asymmetric rigid body conserves its angular momentum and kinetic energy;
//! * a slender block released from a tilt rocks as Housner's rigid block;
//! * a cube dropped on an edge and on a corner lands without interpenetrating its support and
//!   comes to rest on a face.
//!
//! Every reference value is computed here from its formula; nothing is copied from a run.

use crate::common;

use std::f64::consts::PI;

use voussoir::prelude::*;

/// Density of every block (kg/m³): stone.
const RHO: Real = 2500.0;

/// World positions of a block's vertices.
fn world_vertices(b: &RigidBlock) -> impl Iterator<Item = Vector> + '_ {
    b.shape().vertices().iter().map(move |v| b.world_point(*v))
}

/// Vertex of the parabola through three equally spaced samples `(y0, y1, y2)` at `x1 − h, x1,
/// x1 + h`: the time and value of a sampled extremum, without the O(h²) error of the raw sample.
fn parabolic_peak(x1: Real, h: Real, y0: Real, y1: Real, y2: Real) -> (Real, Real) {
    let den = y0 - 2.0 * y1 + y2;
    if den == 0.0 {
        return (x1, y1);
    }
    let s = 0.5 * (y0 - y2) / den;
    (x1 + s * h, y1 - 0.25 * (y0 - y2) * s)
}

// ---------------------------------------------------------------------------------------------
// 1–2. A block on its joint springs.
// ---------------------------------------------------------------------------------------------

/// A 0.2 m cube (m = 20 kg) resting face to face on the fixed base with a [`LinearElastic`]
/// joint, no gravity, launched downwards at `v0`.
///
/// Why `LinearElastic` and no gravity: the joint then has the same stiffness `K = kn·A` in
/// compression and in tension, so the cube is an exact linear oscillator about its initial
/// position (where the joint carries no force), with amplitude `v0/ω` on both sides. A Coulomb
/// joint would need a gravity preload larger than the dynamic force to stay closed; the
/// oscillator would then be the same but half of its cycle would test nothing new.
///
/// The shear stiffness plays no role in a vertical motion; rotations are not excited because the
/// sub-contact grid is symmetric.
struct Oscillator {
    model: Model<LinearElastic>,
    cube: BlockId,
    mass: Real,
    /// `K = kn·A` (N/m).
    stiffness: Real,
    z0: Real,
}

impl Oscillator {
    const EDGE: Real = 0.2;
    const KN: Real = 1e8;

    /// Natural circular frequency `ω = √(K/m) = √(kn·a²/(ρ·a³))` (rad/s).
    fn natural_omega() -> Real {
        (Self::KN / (RHO * Self::EDGE)).sqrt()
    }

    fn new(damping: Damping, v0: Real, time_step: TimeStep) -> Result<Self> {
        let a = Self::EDGE;
        let params = ModelParameters {
            gravity: Vector::ZERO,
            time_step,
            ..ModelParameters::default()
        };
        let mut model = common::model_with(
            params,
            LinearElastic {
                normal_stiffness: Self::KN,
                shear_stiffness: Self::KN,
            },
        );
        model.set_damping(damping)?;
        model.add_block(common::fixed_slab("base"))?;
        let cube = model.add_block(
            RigidBlock::cuboid(
                "cube",
                Vector::new(-a / 2.0, -a / 2.0, 0.0),
                Vector::new(a / 2.0, a / 2.0, a),
                RHO,
            )?
            .with_velocity(Vector::new(0.0, 0.0, -v0), Vector::ZERO),
        )?;
        let z0 = model.block(cube)?.state().pose.translation.z;
        Ok(Self {
            model,
            cube,
            mass: RHO * a * a * a,
            stiffness: Self::KN * a * a,
            z0,
        })
    }

    /// Natural circular frequency `ω = √(K/m)` (rad/s).
    fn omega(&self) -> Real {
        (self.stiffness / self.mass).sqrt()
    }

    /// One step; returns `(t, z − z0)` after it.
    fn step(&mut self) -> Result<(Real, Real)> {
        self.model.step()?;
        let z = self.model.block(self.cube)?.state().pose.translation.z;
        Ok((self.model.time(), z - self.z0))
    }
}

/// Times at which the sampled signal crosses zero upwards (linear interpolation).
fn upward_crossings(samples: &[(Real, Real)]) -> Vec<Real> {
    samples
        .windows(2)
        .filter(|w| w[0].1 < 0.0 && w[1].1 >= 0.0)
        .map(|w| w[0].0 + (w[1].0 - w[0].0) * w[0].1 / (w[0].1 - w[1].1))
        .collect()
}

/// **Undamped oscillator: period and energy.**
///
/// The cube on its joint springs oscillates vertically with `T = 2π√(m/K)`, `K = kn·A`.
///
/// Explicit central difference shortens the period of a linear oscillator to `T_cd = 2π/ω_cd`,
/// `ω_cd = (2/Δt)·asin(ωΔt/2)`, i.e. by `≈ (ωΔt)²/24`. Two runs of 100 periods:
///
/// * at a step chosen for accuracy, `Δt = 0.25/ω` (25 steps per period): `(ωΔt)²/24 = 0.26 %`,
///   so the period must match the closed form `2π√(m/K)` within the 1 % asked for;
/// * at the model's automatic step (whatever the stability bound and safety factor give), where
///   the continuous closed form is not a fair target, the period must match the discrete closed
///   form `T_cd` — as it must at the fixed step too.
///
/// The measured period (upward zero crossings averaged over 100 periods, each located to `O(Δt²)`
/// by interpolation) must match `T_cd` to 1e-4: this checks that the integrator is exactly
/// central difference with the step it reports.
///
/// Energy, drift < 0.5 % over 100 periods: central difference conserves exactly
/// `H = ½m·v⁻·v⁺ + ½K·x²` (half-step velocities around level n). The model reports kinetic energy
/// at the mean velocity `(v⁻+v⁺)/2`, so `E = kinetic + elastic = H + ½K·x²·(ωΔt)²/4`, which
/// oscillates between `H = E₀` (at x = 0) and `E₀ / (1 − (ωΔt)²/4)` (at the turning points): a
/// ripple of `(ωΔt)²/4`, not a drift. Every sample must lie in that envelope (+0.1 % for
/// round-off) and the mean energy of the last ten periods may differ from that of the first ten
/// by at most 0.5 %.
#[test]
fn undamped_block_on_springs_period_and_energy() -> Result<()> {
    let accurate = TimeStep::Fixed(0.25 / Oscillator::natural_omega());
    let mut failures = Vec::new();
    for (label, time_step) in [("Δt = 0.25/ω", accurate), ("automatic Δt", TimeStep::default())] {
        failures.extend(free_oscillation(label, time_step, time_step == accurate)?);
    }
    assert!(failures.is_empty(), "{failures:#?}");
    Ok(())
}

/// One undamped run of 100 periods; returns the failed checks.
fn free_oscillation(label: &str, time_step: TimeStep, check_continuous: bool) -> Result<Vec<String>> {
    let v0 = 0.01;
    let mut osc = Oscillator::new(Damping::None, v0, time_step)?;
    let omega = osc.omega();
    let period = 2.0 * PI / omega;
    let e0 = 0.5 * osc.mass * v0 * v0;
    let mut failures = Vec::new();

    let mut samples = Vec::new();
    let mut energies = Vec::new();
    while osc.model.time() < 100.0 * period {
        samples.push(osc.step()?);
        let e = osc.model.energies();
        energies.push((osc.model.time(), e.kinetic + e.elastic));
    }
    let dt = osc.model.dt();
    let crossings = upward_crossings(&samples);
    assert!(
        crossings.len() >= 95,
        "{label}: only {} upward crossings",
        crossings.len()
    );
    let measured = (crossings[crossings.len() - 1] - crossings[0]) / (crossings.len() - 1) as Real;
    let omega_cd = 2.0 / dt * (0.5 * omega * dt).asin();
    let period_cd = 2.0 * PI / omega_cd;
    println!(
        "{label}: ωΔt = {:.3}; period measured {measured:.6e} s, 2π√(m/K) = {period:.6e} s ({:+.3} %), \
         central-difference closed form {period_cd:.6e} s ({:+.2e})",
        omega * dt,
        100.0 * (measured / period - 1.0),
        measured / period_cd - 1.0,
    );
    if check_continuous && (measured / period - 1.0).abs() >= 0.01 {
        failures.push(format!("{label}: period {measured} s vs 2π√(m/K) = {period} s"));
    }
    if (measured / period_cd - 1.0).abs() >= 1e-4 {
        failures.push(format!(
            "{label}: period {measured} s vs central difference {period_cd} s"
        ));
    }

    let ripple = 1.0 / (1.0 - 0.25 * (omega * dt).powi(2));
    let (lo, hi) = (e0 * (1.0 - 1e-3), e0 * ripple * (1.0 + 1e-3));
    let (e_min, e_max) = energies.iter().fold((Real::INFINITY, Real::NEG_INFINITY), |(a, b), e| {
        (a.min(e.1), b.max(e.1))
    });
    let mean = |from: Real, to: Real| {
        let s: Vec<Real> = energies
            .iter()
            .filter(|e| e.0 >= from && e.0 < to)
            .map(|e| e.1)
            .collect();
        s.iter().sum::<Real>() / s.len() as Real
    };
    let drift = (mean(90.0 * period, 100.0 * period) - mean(0.0, 10.0 * period)) / e0;
    println!(
        "{label}: energy E0 = {e0:.6e} J, samples in [{:.6}, {:.6}]·E0, envelope [1, {ripple:.6}]·E0; \
         drift (mean of last 10 vs first 10 periods) {drift:+.3e}",
        e_min / e0,
        e_max / e0
    );
    if e_min < lo || e_max > hi {
        failures.push(format!(
            "{label}: energy [{e_min}, {e_max}] J left its envelope [{lo}, {hi}] J"
        ));
    }
    if drift.abs() >= 5e-3 {
        failures.push(format!("{label}: energy drift {drift}"));
    }
    Ok(failures)
}

/// **Rayleigh damping of the oscillator: logarithmic decrement.**
///
/// With damping ratio ξ the free response decays by `δ = ln(x_k / x_{k+1}) = 2πξ/√(1−ξ²)` per
/// period, so `ξ = δ/√(4π² + δ²)`. Three ways of asking for ξ = 5 % at the oscillator's own
/// frequency `f = ω/2π`: stiffness-proportional (`b = ξ/(πf)`, a dashpot `b·kn·A` at each
/// sub-contact), mass-proportional (`a = 4πfξ`, a body force `−a·m·v`) and both halves
/// (`a = ξω`, `b = ξ/ω`). Each must give ξ within 5 %.
///
/// δ is measured over ten periods from positive peaks located by parabolic interpolation (their
/// `O(Δt²)` sampling error would otherwise be up to 1 % per peak). The 5 % tolerance covers the
/// discretisation: the explicit dashpot acts on the velocity half a step late, which raises the
/// decay rate by a factor `≈ 1 + ξωΔt` (about 1 %), and the period is shortened by
/// `(ωΔt)²/24` (0.4 %).
#[test]
fn rayleigh_damped_block_log_decrement() -> Result<()> {
    let xi = 0.05;
    let f = Oscillator::natural_omega() / (2.0 * PI);
    let variants = [
        ("stiffness-proportional", Damping::rayleigh_stiffness(xi, f)?),
        ("mass-proportional", Damping::rayleigh_mass(xi, f)?),
        ("mass + stiffness", Damping::rayleigh(xi, f)?),
    ];
    let mut failures = Vec::new();
    for (name, damping) in variants {
        let mut osc = Oscillator::new(damping, 0.01, TimeStep::default())?;
        let period = 2.0 * PI / osc.omega();
        let mut samples = Vec::new();
        while osc.model.time() < 12.0 * period {
            samples.push(osc.step()?);
        }
        let dt = osc.model.dt();
        let peaks: Vec<(Real, Real)> = samples
            .windows(3)
            .filter(|w| w[1].1 > 0.0 && w[1].1 >= w[0].1 && w[1].1 > w[2].1)
            .map(|w| parabolic_peak(w[1].0, dt, w[0].1, w[1].1, w[2].1))
            .collect();
        assert!(peaks.len() >= 11, "{name}: only {} peaks", peaks.len());
        let n = 10;
        let delta = (peaks[0].1 / peaks[n].1).ln() / n as Real;
        let measured = delta / (4.0 * PI * PI + delta * delta).sqrt();
        println!(
            "{name}: ξ target {xi}, measured {measured:.5} ({:+.2} %), Δt = {dt:.3e} s, ωΔt = {:.3}",
            100.0 * (measured / xi - 1.0),
            osc.omega() * dt
        );
        if (measured / xi - 1.0).abs() > 0.05 {
            failures.push(format!("{name}: ξ = {measured} vs {xi}"));
        }
    }
    assert!(failures.is_empty(), "{failures:?}");
    Ok(())
}

// ---------------------------------------------------------------------------------------------
// 3. Free rigid-body rotation.
// ---------------------------------------------------------------------------------------------

/// **A free asymmetric block: angular momentum and kinetic energy.**
///
/// An irregular convex hexahedron (three distinct principal moments, principal axes not along
/// the world axes) spins with no contacts and no gravity, starting from an angular velocity that
/// is not along a principal axis, so it tumbles (ω wanders in the body and in the world). Exact
/// motion: world angular momentum `L` and kinetic energy `½ω·L` are constant.
///
/// * `L` (state): integrated from a zero moment, so it must stay constant to round-off (1e-12).
/// * Consistency: `L` recomputed as `R·I·Rᵀ·ω` from the current pose and angular velocity. ω is a
///   half-step quantity and the pose a full-step one, so they differ by a rotation of at most
///   `θ = |ω|Δt`; for a rotation `Q` by θ and `S = R·I·Rᵀ`, `‖QSQᵀ − S‖ ≤ θ·(I_max − I_min)`, hence
///   the bound `|L − R·I·Rᵀ·ω| ≤ Δt·(I_max − I_min)·|ω|²` (+ round-off), checked every step.
/// * Energy over ~30 revolutions (20 s, 2·10⁵ steps of 1e-4 s, |ω|Δt ≈ 1e-3): a second-order,
///   time-reversible update has a bounded energy error of order `(|ω|Δt)² ≈ 1e-6` with no secular
///   growth. The tolerance 1e-4 is a hundred times that, and it is what a user needs to trust a
///   long tumbling run; a first-order rotation update gains energy at every step and fails it.
///   Both the block's `½ω·L` and the model's reported kinetic energy are checked.
#[test]
fn free_asymmetric_block_conserves_momentum_and_energy() -> Result<()> {
    let dt = 1e-4;
    let params = ModelParameters {
        gravity: Vector::ZERO,
        time_step: TimeStep::Fixed(dt),
        ..ModelParameters::default()
    };
    let mut model: Model = Model::new(params)?;
    let corners = [
        Vector::new(0.0, 0.0, 0.0),
        Vector::new(0.5, 0.05, 0.0),
        Vector::new(0.1, 0.3, 0.02),
        Vector::new(0.55, 0.28, -0.05),
        Vector::new(0.02, 0.0, 0.12),
        Vector::new(0.45, 0.02, 0.15),
        Vector::new(0.08, 0.31, 0.14),
        Vector::new(0.5, 0.33, 0.1),
    ];
    let w0 = Vector::new(3.0, -5.0, 7.0);
    let block = RigidBlock::from_vertices("tumbler", &corners, RHO)?.with_velocity(Vector::ZERO, w0);
    let inertia = block.mass_properties().principal_inertia;
    let (i_min, i_max) = (inertia.min_element(), inertia.max_element());
    assert!(
        (inertia.x - inertia.y)
            .abs()
            .min((inertia.y - inertia.z).abs())
            .min((inertia.x - inertia.z).abs())
            > 0.1 * i_max,
        "not asymmetric enough: {inertia:?}"
    );
    let id = model.add_block(block)?;
    let l0 = model.block(id)?.state().angular_momentum;
    // L = R·I·Rᵀ·ω from the pose, with the principal inertia.
    let momentum_of = |b: &RigidBlock| {
        let s = b.state();
        let r = s.pose.rotation;
        r * (inertia * (r.inverse() * s.angular_velocity))
    };
    assert!((momentum_of(model.block(id)?) - l0).length() <= 1e-12 * l0.length());
    assert!(
        w0.cross(l0).length() > 0.1 * w0.length() * l0.length(),
        "ω is (nearly) along a principal axis: the test would be trivial"
    );
    let e0 = 0.5 * w0.dot(l0);

    let (mut l_err, mut consistency, mut e_err, mut reported_err, mut turns) = (0.0, 0.0, 0.0, 0.0, 0.0);
    while model.time() < 20.0 {
        model.step()?;
        let b = model.block(id)?;
        let s = b.state();
        let w = s.angular_velocity;
        turns += w.length() * model.dt() / (2.0 * PI);
        l_err = Real::max(l_err, (s.angular_momentum - l0).length() / l0.length());
        let bound = dt * (i_max - i_min) * w.length_squared() + 1e-12 * l0.length();
        consistency = Real::max(consistency, (momentum_of(b) - s.angular_momentum).length() / bound);
        e_err = Real::max(e_err, (b.kinetic_energy() / e0 - 1.0).abs());
        reported_err = Real::max(reported_err, (model.energies().kinetic / e0 - 1.0).abs());
    }
    println!(
        "{turns:.1} revolutions: max |ΔL|/|L0| = {l_err:.2e}; max |L − R·I·Rᵀ·ω| / bound = {consistency:.3}; \
         max |ΔE|/E0: ½ω·L {e_err:.3e}, reported kinetic {reported_err:.3e}; final ½ω·L / E0 − 1 = {:+.3e}",
        model.block(id)?.kinetic_energy() / e0 - 1.0
    );
    assert!(turns > 20.0, "only {turns} revolutions");
    assert!(l_err <= 1e-12, "angular momentum not conserved: {l_err}");
    assert!(
        consistency <= 1.0,
        "L inconsistent with R·I·Rᵀ·ω: {consistency} × the bound"
    );
    assert!(e_err <= 1e-4, "kinetic energy (½ω·L) drifted by {e_err:.3e}");
    assert!(
        reported_err <= 1e-4,
        "reported kinetic energy drifted by {reported_err:.3e}"
    );
    Ok(())
}

// ---------------------------------------------------------------------------------------------
// 4. Rocking.
// ---------------------------------------------------------------------------------------------

/// **Housner's rocking block: time to the first impact and the impact restitution.**
///
/// A 0.2 m × 0.2 m × 1 m block (b/h = 0.2, slenderness α = atan(b/h) = 11.3°, half-diagonal
/// R = 0.51 m) on the fixed base, released from rest tilted about its bottom edge by θ0 = α/2.
/// Rocking about a corner: `I₀θ̈ = −mgR·sin(α − θ)` with `I₀ = (4/3)mR²` for a rectangular block,
/// i.e. `θ̈ = −p²·sin(α − θ)`, `p = √(3g/(4R))`. Linearised (Housner 1963), the block reaches
/// θ = 0 after `t = (1/p)·acosh(1/(1 − θ0/α))` (0.347 s here). Contacts are stiff
/// (kn = ks = 1e10 Pa/m: the static compression under the pivot, ~0.1 mm, is a few 1e-4 of b) and friction is
/// 45° (> α, no sliding); no damping. Contact parameters are the defaults.
///
/// Time to impact, tolerance 10 %: the linearisation changes t by about α²/6 (< 1 %; the
/// nonlinear rigid reference, integrated here with RK4, is printed) and the contact compliance
/// by much less; 10 % leaves room for the finite contact stiffness and the discretisation of the
/// joint, but not for a pivot displaced from the edge.
///
/// Restitution: Housner's perfectly plastic impact on the opposite corner keeps a fraction
/// `e_H = 1 − 1.5·sin²α` of the angular velocity. The measured fraction is inferred from the
/// amplitude θ1 reached after the impact, by energy conservation of the rigid rocking motion:
/// `e = √[(cos(α − θ1) − cos α) / (cos(α − θ0) − cos α)]`. Soft undamped contacts are not
/// Housner's impact: the springs give back what they store and only the energy scattered into
/// vibration is lost, so e is expected between e_H and 1. Asserted loosely: `0 < e ≤ 1.01`
/// (energy cannot be created; 1 % for the measurement of θ1, which includes the elastic
/// compression) and `e ≥ e_H − 0.1`.
///
/// Also checked every step: no vertex of the block goes below the base top by more than the
/// contact tolerance (1 mm); the static compression under the hinge is ~0.1 mm.
#[test]
fn rocking_block_follows_housner() -> Result<()> {
    rocking("face-face hinge (default contact parameters)", None)
}

/// **Housner's rocking block on edge–face contacts.**
///
/// The same block, release and checks as [`rocking_block_follows_housner`], with the face-angle
/// tolerance of contact detection lowered to 2° (below θ0 = 5.65°) so that the tilted block
/// touches the base through an edge–face (point) contact along its bottom edge, as in Housner's
/// model, instead of a face–face joint that is partly open. The contact representation changes
/// twice per half cycle (edge–face while tilted by more than 2°, face–face near the impact), on
/// both edges; the rigid-body answer must not depend on it.
#[test]
fn rocking_block_on_edge_contacts_follows_housner() -> Result<()> {
    rocking("edge-face hinge (face-angle tolerance 2°)", Some(2f64.to_radians()))
}

/// The rocking experiment; `face_angle` overrides the contact detection's face-angle tolerance.
fn rocking(label: &str, face_angle: Option<Real>) -> Result<()> {
    let (b, d, h) = (0.2, 0.2, 1.0);
    let g = 9.81;
    let alpha = Real::atan(b / h);
    let r = 0.5 * Real::hypot(b, h);
    let p = (3.0 * g / (4.0 * r)).sqrt();
    let theta0 = 0.5 * alpha;
    let t_housner = (1.0 / (1.0 - theta0 / alpha)).acosh() / p;
    // Nonlinear rigid reference: θ̈ = −p²·sin(α − θ) from rest at θ0, RK4 until θ = 0.
    let t_rigid = {
        let f = |th: Real| -p * p * (alpha - th).sin();
        let (mut t, mut th, mut om, hs) = (0.0, theta0, 0.0, 1e-5);
        while th > 0.0 {
            let (k1x, k1v) = (om, f(th));
            let (k2x, k2v) = (om + 0.5 * hs * k1v, f(th + 0.5 * hs * k1x));
            let (k3x, k3v) = (om + 0.5 * hs * k2v, f(th + 0.5 * hs * k2x));
            let (k4x, k4v) = (om + hs * k3v, f(th + hs * k3x));
            let th_new = th + hs / 6.0 * (k1x + 2.0 * k2x + 2.0 * k3x + k4x);
            om += hs / 6.0 * (k1v + 2.0 * k2v + 2.0 * k3v + k4v);
            t += if th_new > 0.0 { hs } else { hs * th / (th - th_new) };
            th = th_new;
        }
        t
    };

    let mut params = ModelParameters::default();
    if let Some(angle) = face_angle {
        params.contact.face_angle_tolerance = angle;
    }
    let tolerance = params.contact.tolerance;
    let mut model = common::model_with(params, CoulombSlip::dry(1e10, 1e10, 45.0)?);
    model.set_damping(Damping::None)?;
    model.add_block(common::fixed_slab("base"))?;
    let upright = RigidBlock::cuboid(
        "column",
        Vector::new(-b / 2.0, -d / 2.0, 0.0),
        Vector::new(b / 2.0, d / 2.0, h),
        RHO,
    )?;
    // Material points on the block's axis, to measure its tilt whatever its principal frame.
    let (foot, head) = (
        upright.local_point(Vector::ZERO),
        upright.local_point(Vector::new(0.0, 0.0, h)),
    );
    // Tilt about the bottom edge x = b/2, z = 0 (along y): the opposite bottom edge lifts.
    let pivot = Vector::new(b / 2.0, 0.0, 0.0);
    let tilt =
        Pose::from_translation(pivot) * Pose::rotation(Vector::new(0.0, theta0, 0.0)) * Pose::from_translation(-pivot);
    let centroid_local = upright.local_point(Vector::new(0.0, 0.0, 0.5 * h));
    let id = model.add_block(upright.transformed(tilt))?;
    let height0 = model.block(id)?.world_point(centroid_local).z;
    let angle = |m: &Model| -> Result<Real> {
        let blk = m.block(id)?;
        let axis = blk.world_point(head) - blk.world_point(foot);
        Ok(axis.x.atan2(axis.z))
    };
    assert!((angle(&model)? - theta0).abs() < 1e-12);
    let lowest = world_vertices(model.block(id)?)
        .map(|v| v.z)
        .fold(Real::INFINITY, Real::min);
    assert!(
        lowest.abs() < 1e-12,
        "the bottom edge must touch the base: lowest vertex at {lowest}"
    );

    // Release; find the first crossing of θ = 0.
    let depth = |m: &Model| -> Result<Real> {
        Ok(-world_vertices(m.block(id)?)
            .map(|v| v.z)
            .fold(Real::INFINITY, Real::min))
    };
    let mut deepest: Real = 0.0;
    let mut prev = theta0;
    let mut w_before: Real = 0.0;
    let t_impact = loop {
        model.step()?;
        deepest = deepest.max(depth(&model)?);
        let th = angle(&model)?;
        w_before = w_before.max(model.block(id)?.state().angular_velocity.length());
        if th <= 0.0 {
            break model.time() - model.dt() * th / (th - prev);
        }
        if model.time() > 3.0 * t_housner {
            panic!("no impact within {} s (θ = {th})", model.time());
        }
        prev = th;
    };
    // Rock on the other edge until θ comes back to zero; record the amplitude, and at it the
    // centroid's height and the joints' elastic energy.
    let mut theta1: Real = 0.0;
    let (mut height1, mut elastic1) = (0.0, 0.0);
    while model.time() < t_impact + 4.0 * t_housner {
        model.step()?;
        deepest = deepest.max(depth(&model)?);
        let th = angle(&model)?;
        if -th > theta1 {
            theta1 = -th;
            height1 = model.block(id)?.world_point(centroid_local).z;
            elastic1 = model.energies().elastic;
        }
        if th >= 0.0 && theta1 > 0.0 {
            break;
        }
    }
    let potential = |th: Real| (alpha - th).cos() - alpha.cos();
    // Velocity restitution from the amplitude (the rigid block's potential at θ).
    let e = (potential(theta1) / potential(theta0)).sqrt();
    // And from the energy of the rocking motion at that amplitude: the centroid's rise above
    // its upright height and the hinge's elastic energy, over the rise at release. With elastic
    // joints the block at the far amplitude sinks into the base at its hinge, by
    // `deepest` below: the rigid potential at θ₁ overstates its energy by `m g` times that sink
    // (with kn 1e10 Pa/m and a converged hinge, 0.3 mm: 1 % of the rocking energy), so
    // energy created at the impact is measured here.
    let mass = RHO * b * d * h;
    let energy_ratio = (mass * g * (height1 - 0.5 * h) + elastic1) / (mass * g * (height0 - 0.5 * h));
    let e_energy = energy_ratio.sqrt();
    let e_housner = 1.0 - 1.5 * alpha.sin().powi(2);
    let w_rigid = (2.0 * g * r * potential(theta0) / (4.0 / 3.0 * r * r)).sqrt();
    println!("{label}:");
    println!(
        "time to first impact: measured {t_impact:.4} s, Housner {t_housner:.4} s ({:+.1} %), nonlinear rigid {t_rigid:.4} s; \
         Δt = {:.2e} s",
        100.0 * (t_impact / t_housner - 1.0),
        model.dt()
    );
    println!(
        "angular velocity before impact: {w_before:.4} rad/s (rigid: {w_rigid:.4}); amplitude after impact {theta1:.4} rad \
         (θ0 = {theta0:.4}); velocity restitution measured {e:.4}, Housner 1 − 1.5 sin²α = {e_housner:.4} \
         (energy: {:.4} vs {:.4}); from the energy at the amplitude {e_energy:.4}",
        e * e,
        e_housner * e_housner
    );
    println!("deepest vertex below the base top: {deepest:.3e} m (contact tolerance {tolerance:e} m)");
    assert!(
        (t_impact / t_housner - 1.0).abs() <= 0.10,
        "time to first impact {t_impact} s vs Housner {t_housner} s"
    );
    assert!(
        e_energy > 0.0 && e_energy <= 1.01,
        "restitution {e_energy} outside (0, 1]: energy created at the impact"
    );
    assert!(e >= e_housner - 0.1, "restitution {e} far below Housner's {e_housner}");
    assert!(
        deepest <= tolerance,
        "a corner of the block went {deepest} m into the base"
    );
    Ok(())
}

// ---------------------------------------------------------------------------------------------
// 5. Cube drops.
// ---------------------------------------------------------------------------------------------

/// The deepest a cube of side `a` turned by `rotation` can sink with its lowest corner or edge
/// into the base on the first impact, dropped from `drop` (m) with weight `weight` (N), on
/// joints of normal stiffness `kn` (Pa/m): where the springs it compresses store all of
/// `weight · (drop + d)`.
///
/// Node contacts integrated over the surface each node stands for ([`NodeRule::Integrated`],
/// `docs/theory.md` §2.2) press a corner or an edge sinks into a bed of springs whose pressed
/// area grows with the depth `d`. Around a corner whose three edges rise at slopes `aᵢ` (the
/// vertical components of their unit directions), the surface within `d` of the base on the two
/// faces of edges `i`, `j` is a triangle of legs `d/aᵢ`, `d/aⱼ`, over which `∫ (d − h)² dA =
/// d⁴/(12 aᵢ aⱼ)`; at the cube's half weight (each block's nodes stand for half), the cube's own
/// surface stores `kn d⁴ (a₁ + a₂ + a₃)/(48 a₁ a₂ a₃)` (`3 kn d⁴/16` with the body diagonal
/// vertical). Along a level edge of length `a` whose faces rise at `a₁`, `a₂`: `kn a d³ (1/a₁ +
/// 1/a₂)/12`. The base's own nodes under the corner store more, and rotation and damping take
/// their share, so the depth at which the cube's part alone equals the whole work of gravity
/// bounds the sinking.
fn first_impact_depth(rotation: Rotation, a: Real, kn: Real, weight: Real, drop: Real) -> Real {
    let slopes = [Vector::X, Vector::Y, Vector::Z].map(|e| (rotation * e).z.abs());
    let level = slopes.iter().position(|&s| s < 1e-9);
    let stored = |d: Real| match level {
        None => {
            let [a1, a2, a3] = slopes;
            kn * d.powi(4) * (a1 + a2 + a3) / (48.0 * a1 * a2 * a3)
        }
        Some(k) => {
            let rising: Real = (0..3).filter(|&i| i != k).map(|i| 1.0 / slopes[i]).sum();
            kn * a * d.powi(3) * rising / 12.0
        }
    };
    // `stored(d) − weight (drop + d)` rises from below zero: bisection.
    let (mut lo, mut hi) = (0.0, a);
    for _ in 0..200 {
        let d = 0.5 * (lo + hi);
        if stored(d) < weight * (drop + d) {
            lo = d;
        } else {
            hi = d;
        }
    }
    hi
}

/// Drops a 0.2 m cube with orientation `rotation` so that its lowest point starts `drop` above
/// the base, its node contacts acting by `rule`, and checks landing and rest. See the tests
/// below.
fn drop_cube(label: &str, rotation: Rotation, rule: NodeRule) -> Result<()> {
    let a = 0.2;
    let drop = 0.05;
    let kn = 1e12;
    let g = 9.81;
    let mass = RHO * a * a * a;
    let mut model = common::model(CoulombSlip::dry(kn, 0.4 * kn, 35.0)?);
    let mut params = *model.parameters();
    params.contact.node_rule = rule;
    model.set_parameters(params)?;
    let tolerance = model.parameters().contact.tolerance;
    // Stiffness-proportional damping: 10 % at the frequency of the cube bouncing on a face.
    let f_contact = (kn * a * a / mass).sqrt() / (2.0 * PI);
    model.set_damping(Damping::rayleigh_stiffness(0.1, f_contact)?)?;
    model.add_block(common::fixed_slab("base"))?;
    let cube = RigidBlock::cuboid("cube", Vector::splat(-a / 2.0), Vector::splat(a / 2.0), RHO)?
        .transformed(Pose::from_rotation(rotation));
    let lowest = world_vertices(&cube).map(|v| v.z).fold(Real::INFINITY, Real::min);
    let id = model.add_block(cube.transformed(Pose::from_translation(Vector::new(0.0, 0.0, drop - lowest))))?;

    // Deepest vertex below the base top and deepest sub-contact, every step.
    let (mut vertex_depth, mut sub_depth, mut landed): (Real, Real, bool) = (0.0, 0.0, false);
    let mut watch = |m: &Model| {
        let blk = m.block(id).expect("cube");
        let low = world_vertices(blk).map(|v| v.z).fold(Real::INFINITY, Real::min);
        vertex_depth = vertex_depth.max(-low);
        for c in m.contacts() {
            for s in c.subcontacts() {
                sub_depth = sub_depth.max(-s.normal_displacement());
                landed |= s.normal_force() > 0.0;
            }
        }
    };
    // Dynamic phase: fall, impact, tumble.
    let dynamic = 1.0;
    model.run_until(u64::MAX, |m| {
        watch(m);
        m.time() >= dynamic
    })?;
    // Settling phase: Cundall local damping (quasi-static) until equilibrium.
    model.set_damping(Damping::local())?;
    let settled = model.run_until(2_000_000, |m| {
        watch(m);
        m.unbalanced_force_ratio() < 1e-6 && m.energies().kinetic < 1e-12 * mass * g * drop
    })?;

    let blk = model.block(id)?;
    let rot = blk.state().pose.rotation;
    let up = blk
        .shape()
        .faces()
        .iter()
        .map(|f| (rot * f.normal).z.abs())
        .fold(0.0, Real::max);
    let tilt = up.min(1.0).acos().to_degrees();
    let z = blk.state().pose.translation.z;
    let compression = mass * g / (kn * a * a);
    let expected = a / 2.0 - compression;
    // At points: a corner impact carried by a single sub-contact from the drop energy,
    // ½·kn·A·δ² = m·g·H, with the default sub-contact spacing (edge/15) for A; the springs are
    // chosen stiff enough for this to stay within the tolerance. Integrated: the corner or edge
    // sinks into springs whose pressed area grows with the depth, bounded by the first impact's
    // closed form.
    let spacing = a / 15.0;
    let corner_estimate = (2.0 * mass * g * drop / (kn * spacing * spacing)).sqrt();
    let bound = match rule {
        NodeRule::Point => tolerance,
        NodeRule::Integrated => first_impact_depth(rotation, a, kn, mass * g, drop),
    };
    println!(
        "{label} ({rule:?}): deepest vertex {vertex_depth:.3e} m, deepest sub-contact {sub_depth:.3e} m (tolerance \
         {tolerance:e} m, corner-impact estimate {corner_estimate:.2e} m, bound {bound:.3e} m); settled {settled} at t = \
         {:.3} s after {} steps (Δt {:.2e} s); face tilt {tilt:.2e}°; centroid height {z:.12} m vs a/2 − mg/(kn·A) = \
         {expected:.12} m",
        model.time(),
        model.step_count(),
        model.dt()
    );
    assert!(landed, "{label}: the cube never touched the base");
    assert!(
        sub_depth <= tolerance,
        "{label}: sub-contact interpenetration {sub_depth} m"
    );
    assert!(
        vertex_depth <= bound,
        "{label} ({rule:?}): a vertex went {vertex_depth} m into the base, beyond {bound} m"
    );
    assert!(settled, "{label}: not at rest after the settling phase");
    assert!(tilt <= 1.0, "{label}: no face within 1° of horizontal (tilt {tilt}°)");
    assert!(
        (z - expected).abs() <= 0.01 * compression,
        "{label}: centroid at {z} m, expected {expected} m"
    );
    Ok(())
}

/// **A cube dropped on an edge comes to rest on a face.**
///
/// The 0.2 m cube (20 kg) is turned 42° about the horizontal x axis — an edge down, 3° from the
/// balanced 45°: exactly on the edge the outcome would be decided by round-off — and dropped from
/// 5 cm onto the base (impact at ≈ 1 m/s). Joint: Coulomb, kn = 1e12 Pa/m, ks = 0.4·kn, φ = 35°.
///
/// Damping (stated): stiffness-proportional Rayleigh damping, 10 % at the bouncing frequency of
/// the cube on a face, for the first second (fall, impact, tumbling: a dynamic run); then
/// Cundall local damping (α = 0.8) to reach static equilibrium (unbalanced-force ratio < 1e-6)
/// without waiting for slow rocking to decay.
///
/// Checked every step of both phases: no vertex of the cube goes below the base top, and no
/// sub-contact closes, by more than the contact tolerance (1 mm). With these springs a corner
/// impact carried by a single sub-contact penetrates ≈ 0.3 mm (estimate printed), an edge impact
/// less. At rest: a face normal within 1° of vertical, and the centroid at `a/2 − mg/(kn·a²)`
/// within 1 % of that compression (at an unbalanced-force ratio of 1e-6 the residual is ~1e-6 of
/// it; a cube resting on an edge instead would be millimetres higher).
#[test]
fn cube_dropped_on_edge_comes_to_rest_on_a_face() -> Result<()> {
    drop_cube("edge", Rotation::from_rotation_x(42f64.to_radians()), NodeRule::Point)
}

/// The cube's corner: down its body diagonal, tilted 3° about the horizontal axis (1, 2, 0) so
/// that it is not balanced on the corner.
fn corner_down() -> Rotation {
    let corner_down = Rotation::from_rotation_arc(Vector::ONE.normalize(), Vector::NEG_Z);
    let imperfection = Rotation::from_axis_angle(Vector::new(1.0, 2.0, 0.0).normalize(), 3f64.to_radians());
    imperfection * corner_down
}

/// **A cube dropped on a corner comes to rest on a face.**
///
/// As the edge drop, with the cube turned so that its body diagonal points down (a corner
/// lowest), then tilted by 3° about the horizontal axis (1, 2, 0) so that it is not balanced on
/// the corner. Same damping, checks and tolerances.
#[test]
fn cube_dropped_on_corner_comes_to_rest_on_a_face() -> Result<()> {
    drop_cube("corner", corner_down(), NodeRule::Point)
}

/// **The edge and corner drops with node contacts integrated** ([`NodeRule::Integrated`]).
///
/// The same drops, checks and tolerances, but for the vertex: a corner or an edge sinks into a
/// bed of springs whose pressed area grows with the depth, so no vertex may go below the base
/// top by more than the first impact can sink it ([`first_impact_depth`], printed: the cube's
/// own springs storing the whole work of gravity; 0.6 mm on the edge, 2.7 mm on the corner).
#[test]
fn cube_drops_with_integrated_nodes_sink_within_the_first_impacts_bound() -> Result<()> {
    drop_cube(
        "edge",
        Rotation::from_rotation_x(42f64.to_radians()),
        NodeRule::Integrated,
    )?;
    drop_cube("corner", corner_down(), NodeRule::Integrated)
}

/// A block whose angular velocity overflows to NaN while its velocity stays finite (a load
/// moment of 1e300 N·m) is reported as diverged at once, not carried on with a NaN state (the
/// speed check took the larger of the two speeds, and `max` hides a NaN; found by the scene
/// fuzzer).
#[test]
fn a_nan_angular_velocity_is_a_divergence() {
    let mut model = common::model(CoulombSlip::dry(1e9, 4e8, 30.0).expect("law"));
    model.add_block(common::fixed_slab("slab")).expect("slab");
    let cube = model.add_block(common::cube("cube", Vector::ZERO)).expect("cube");
    model
        .set_load(
            cube,
            Wrench {
                force: Vector::ZERO,
                moment: Vector::new(0.0, 0.0, 1e300),
            },
        )
        .expect("load");
    let e = model.run_steps(10).expect_err("diverges");
    assert!(matches!(e, Error::Diverged { block, .. } if block == cube), "{e:?}");
    assert_eq!(model.step_count(), 1, "the step that made the NaN is the one reported");
}
