//! [`MortarJoint`] on its own, driven sub-contact by sub-contact: its curves and dissipation
//! against their closed forms, unloading, the brittle limit against `CoulombSlip`, the
//! coupling, dilatancy, the parameters and the law contract.

use super::*;

use crate::law::{conformance, CoulombSlip, CoulombState, JointAxes};
use crate::math::Vector;

/// kn 1e11 Pa/m, ks 4e10 Pa/m, φ 35° → 30°, f_t 0.2 MPa with G_f^I 10 N/m, c 0.3 MPa with
/// G_f^II 50 N/m (Lourenço's masonry joints, stiffened): no snap-back (`f_t²/G_f^I` = 4e9 and
/// `c²/G_f^II` = 1.8e9 Pa/m, below the stiffnesses), so each step's return is on the curve.
fn mortar(softening: Softening) -> MortarJoint {
    MortarJoint::builder(1e11, 4e10, 35.0)
        .residual_friction(30.0)
        .tension(2e5, 10.0)
        .cohesion(3e5, 50.0)
        .softening(softening)
        .build()
        .unwrap()
}

/// One sub-contact driven by prescribed displacements, with the books the contact kernel keeps
/// (`contact/law_update.rs`, the same expressions): the work done on the springs, the
/// dissipation, and the fracture work.
pub(super) struct Driver<'a> {
    pub(super) law: &'a MortarJoint,
    pub(super) area: Real,
    pub(super) gap: Real,
    pub(super) force: JointForce,
    pub(super) state: MortarState,
    pub(super) status: JointStatus,
    /// `Σ −½ (F⁻ + F)·Δu` (J).
    pub(super) work: Real,
    /// What the kernel books as dissipated, fracture apart (J).
    pub(super) friction: Real,
    /// What the kernel books as fracture (J).
    pub(super) fracture: Real,
    /// The law's fracture work, before the kernel's bound (J).
    pub(super) consumed: Real,
}

impl<'a> Driver<'a> {
    pub(super) fn new(law: &'a MortarJoint, area: Real) -> Self {
        Self {
            law,
            area,
            gap: 0.0,
            force: JointForce::default(),
            state: MortarState::default(),
            status: JointStatus::Elastic,
            work: 0.0,
            friction: 0.0,
            fracture: 0.0,
            consumed: 0.0,
        }
    }

    /// One step to the normal displacement `gap` with the shear increment `du` (along `t₁`).
    pub(super) fn step(&mut self, gap: Real, du: Real) -> JointStatus {
        let du_s = Vector2::new(du, 0.0);
        let step = JointStep {
            area: self.area,
            normal_displacement: gap,
            normal_increment: gap - self.gap,
            shear_increment: du_s,
            axes: JointAxes::from_normal(Vector::Z),
            dt: 1e-5,
        };
        let (before, state_before) = (self.force, self.state);
        let status = self.law.update(&step, &mut self.force, &mut self.state);
        let f = self.force;
        let work = -0.5 * ((before.normal + f.normal) * (gap - self.gap) + (before.shear + f.shear).dot(du_s));
        self.work += work;
        let law = self.law;
        if self.state != state_before {
            let lost = work
                - (law.elastic_energy(self.area, &f, &self.state)
                    - law.elastic_energy(self.area, &before, &state_before));
            let consumed = law.fracture_work(self.area, &state_before, &self.state);
            self.consumed += consumed;
            let fracture = if consumed > 0.0 {
                consumed.min(lost.max(0.0))
            } else {
                0.0
            };
            self.fracture += fracture;
            self.friction += lost - fracture;
        } else if status == JointStatus::Sliding || (status == JointStatus::Open && before.shear != Vector2::ZERO) {
            let w = -0.5 * (before.shear + f.shear).dot(du_s);
            self.friction += w - 0.5 * (f.shear.length_squared() - before.shear.length_squared())
                / (law.shear_stiffness() * self.area);
        }
        self.gap = gap;
        self.status = status;
        status
    }

    pub(super) fn elastic(&self) -> Real {
        self.law.elastic_energy(self.area, &self.force, &self.state)
    }
}

/// Pure mode I: a sub-contact opened in 1e-8 m steps to 4 mm traces `σ = f_t0 r(f_t0 κ/G_f^I)`
/// with `κ = u − σ/kn` (to 1e-9 of `f_t0`: the return's root), and dissipates `G_f^I` per unit
/// area, whatever the area (the law is per unit area): the law's fracture work
/// `G_f^I A (1 − ε)` to round-off; the fracture booked within 1e-6 (the step that reaches the
/// peak part-way books the trapezoid of a kinked curve, short of the law's integral by at most
/// `½ k_n Δu²` = 5e-6 J/m², 5e-7 of `G_f^I`); all that the kernel books (work on the springs
/// less their energy) within 1e-5 (the trapezoidal rule over the curve, 3e-9, and that step).
#[test]
fn mode_i_dissipates_the_fracture_energy_per_unit_area() {
    for softening in [Softening::Exponential, Softening::Linear] {
        let law = mortar(softening);
        for area in [1e-4, 0.01, 2.5] {
            let mut d = Driver::new(&law, area);
            let mut peak: Real = 0.0;
            for k in 1..=400_000 {
                let u = 1e-8 * k as Real;
                d.step(u, 0.0);
                let sigma = -d.force.normal / area;
                peak = peak.max(sigma);
                if d.state.crack_opening > 0.0 && sigma > 0.0 {
                    let kappa = u - sigma / law.normal_stiffness();
                    let expected = 2e5 * softening.remaining(2e5 * kappa / 10.0);
                    assert!(
                        (sigma - expected).abs() < 1e-9 * 2e5,
                        "{softening:?} u {u}: {sigma} vs {expected}"
                    );
                    assert!((d.state.crack_opening - kappa).abs() < 1e-9 * u);
                }
            }
            assert!(
                (peak - 2e5).abs() < 1e-9 * 2e5,
                "the peak is the tensile strength: {peak}"
            );
            let g = 10.0 * area;
            assert!(
                (d.consumed - g).abs() < 1e-9 * g,
                "{softening:?} A {area}: consumed {} vs {g}",
                d.consumed
            );
            assert!(
                (d.fracture - g).abs() < 1e-6 * g,
                "{softening:?} A {area}: fracture {} vs {g}",
                d.fracture
            );
            let total = d.fracture + d.friction;
            assert!(
                (total - g).abs() < 1e-5 * g,
                "{softening:?} A {area}: dissipated {total} vs {g}"
            );
            assert!(d.friction.abs() < 1e-5 * g, "{}", d.friction);
            // Cracked through: open, no force, no energy; all the work dissipated.
            assert_eq!(d.status, JointStatus::Open);
            assert_eq!((d.force, d.elastic()), (JointForce::default(), 0.0));
            assert!((d.work - total).abs() < 1e-12 * g);
            assert!(law.stays_open(area, 4e-3, &d.state) && law.is_failed(&d.state));
        }
    }
}

/// Pure mode II at zero normal stress (`u_n = 0` exactly): the shear stress traces
/// `τ = c₀ r(c₀ κ/G_f^II)` and the joint dissipates `G_f^II` per unit area, all of it
/// fracture work (no normal stress, no friction work): the law's to round-off, the booked
/// within 2e-6 (the peak step, `½ k_s Δu²` = 5e-5 J/m², 1e-6 of `G_f^II`).
#[test]
fn mode_ii_at_zero_normal_stress_dissipates_its_fracture_energy() {
    for softening in [Softening::Exponential, Softening::Linear] {
        let law = mortar(softening);
        let area = 0.04;
        let mut d = Driver::new(&law, area);
        let du = 5e-8;
        for k in 1..=200_000 {
            d.step(0.0, du);
            let tau = d.force.shear.length() / area;
            if d.state.plastic_slip > 0.0 && tau > 0.0 {
                let kappa = k as Real * du - tau / law.shear_stiffness();
                let expected = 3e5 * softening.remaining(3e5 * kappa / 50.0);
                assert!(
                    (tau - expected).abs() < 1e-9 * 3e5,
                    "{softening:?} at {k}: {tau} vs {expected}"
                );
                assert_eq!(d.status, JointStatus::Sliding);
            }
        }
        let g = 50.0 * area;
        assert!(
            (d.consumed - g).abs() < 1e-9 * g,
            "{softening:?}: {} vs {g}",
            d.consumed
        );
        assert!(
            (d.fracture - g).abs() < 2e-6 * g,
            "{softening:?}: {} vs {g}",
            d.fracture
        );
        assert!(d.friction.abs() < 1e-5 * g, "{softening:?}: friction {}", d.friction);
        // The cohesion gone, the joint at zero normal stress carries nothing: open.
        assert_eq!((d.status, d.force), (JointStatus::Open, JointForce::default()));
    }
}

/// The closed form of mode II under a constant compression `σ` (exponential softening, no
/// dilatancy): with `D = c₀κ/G`, `τ(κ) = c₀ e^{−D} + σ (e^{−D} tan φ₀ + (1 − e^{−D}) tan φ_r)`;
/// the fracture work `G (1 − e^{−D})`, the friction work
/// `σ tan φ_r κ + σ (tan φ₀ − tan φ_r)(G/c₀)(1 − e^{−D})`, and the work done on the joint after
/// a slip `δ = κ + τ(κ)/k_s` their sum plus `τ²/(2k_s)`.
fn mode_ii_closed_form(law: &MortarJoint, sigma: Real, kappa: Real) -> (Real, Real, Real, Real) {
    let (c, g) = (law.cohesion(), law.mode_ii_fracture_energy());
    let (t0, tr) = (law.friction_angle().tan(), law.residual_friction_angle().tan());
    let r = (-c * kappa / g).exp();
    let tau = c * r + sigma * (r * t0 + (1.0 - r) * tr);
    let fracture = g * (1.0 - r);
    let friction = sigma * tr * kappa + sigma * (t0 - tr) * (g / c) * (1.0 - r);
    let work = fracture + friction + 0.5 * tau * tau / law.shear_stiffness();
    (tau, fracture, friction, work)
}

/// Mode II under a constant compression (0.5 MPa, `u_n` held): the shear stress, the plastic
/// slip, the fracture and friction works and the work done on the joint after each slip `δ`
/// match the law's closed form ([`mode_ii_closed_form`], `κ` solved from `δ` by bisection),
/// the works to 1e-5 (the step that reaches the peak part-way books the trapezoid of a kinked
/// curve, at most `½ k_s Δu²` = 5e-5 J/m², 2e-6 of the works at the first check; the
/// trapezoidal rule over 5e-8 m steps on a curve of scale `G/c₀` = 1.7e-4 m, 1e-8).
#[test]
fn mode_ii_under_compression_matches_the_closed_form() {
    let law = mortar(Softening::Exponential);
    let (area, sigma) = (0.04, 5e5);
    let gap = -sigma / law.normal_stiffness();
    let mut d = Driver::new(&law, area);
    d.step(gap, 0.0);
    let start_work = d.work;
    let du = 5e-8;
    let mut checked = 0;
    for k in 1..=40_000 {
        d.step(gap, du);
        let delta = k as Real * du;
        assert!(
            (d.force.normal - sigma * area).abs() < 1e-9 * sigma * area,
            "the normal stress stays"
        );
        if d.state.plastic_slip == 0.0 {
            continue;
        }
        // κ from δ: δ − κ − τ(κ)/k_s falls with κ (no snap-back).
        let (mut lo, mut hi) = (0.0, delta);
        for _ in 0..200 {
            let mid = 0.5 * (lo + hi);
            if delta - mid - mode_ii_closed_form(&law, sigma, mid).0 / law.shear_stiffness() > 0.0 {
                lo = mid;
            } else {
                hi = mid;
            }
        }
        let kappa = 0.5 * (lo + hi);
        let (tau, fracture, friction, work) = mode_ii_closed_form(&law, sigma, kappa);
        let scale = law.cohesion() + sigma;
        assert!((d.force.shear.length() / area - tau).abs() < 1e-9 * scale, "δ {delta}");
        assert!((d.state.plastic_slip - kappa).abs() < 1e-9 * delta, "δ {delta}");
        if k % 1000 == 0 {
            let e = (fracture + friction) * area;
            assert!(
                (d.fracture - fracture * area).abs() < 1e-5 * e,
                "δ {delta}: {} vs {}",
                d.fracture,
                fracture * area
            );
            assert!(
                (d.friction - friction * area).abs() < 1e-5 * e,
                "δ {delta}: {} vs {}",
                d.friction,
                friction * area
            );
            let w = d.work - start_work;
            assert!(
                (w - work * area).abs() < 1e-5 * work * area,
                "δ {delta}: {w} vs {}",
                work * area
            );
            checked += 1;
        }
    }
    assert!(checked > 30);
    // At 2 mm of slip the cohesion is gone (D = 12): on the residual friction.
    let residual = sigma * law.residual_friction_angle().tan();
    assert!((d.force.shear.length() / area - residual).abs() < 1e-4 * residual);
}

/// Unloading halfway down the tension curve returns on `k_n` to the crack's opening, where the
/// crack carries nothing; reloading climbs the same line to the strength it left, and goes on
/// down the curve; none of it changes the state. The same in shear: a reversal halfway down
/// the cohesion's curve unloads on `k_s` with no slip until the other side's strength.
#[test]
fn unloading_and_reloading_are_on_the_elastic_stiffness() {
    let law = mortar(Softening::Exponential);
    let kn = law.normal_stiffness();
    let area = 0.01;
    let mut d = Driver::new(&law, area);
    let mut u = 0.0;
    // Open to D = ln 2 (half the strength): u = κ + σ/kn, κ = (G/f_t) ln 2.
    let kappa = 10.0 / 2e5 * std::f64::consts::LN_2;
    let target = kappa + 1e5 / kn;
    while u < target {
        u = (u + 1e-8).min(target);
        d.step(u, 0.0);
    }
    let (state, sigma) = (d.state, -d.force.normal / area);
    assert!((sigma - 1e5).abs() < 1e-6 * 1e5 && (state.crack_opening - kappa).abs() < 1e-9);
    // Unload to closed, on k_n to the crack's opening, then nothing, then compression.
    for k in 1..=200 {
        let v = target - 1e-8 * k as Real;
        let status = d.step(v, 0.0);
        assert_eq!(d.state, state, "unloading changes nothing");
        let expected = if v > state.crack_opening {
            -kn * (v - state.crack_opening) * area
        } else if v > 0.0 {
            0.0
        } else {
            -kn * v * area
        };
        assert!(
            (d.force.normal - expected).abs() < 1e-9 * 1e5 * area,
            "u {v}: {} vs {expected}",
            d.force.normal
        );
        if v > state.crack_opening {
            assert_eq!(status, JointStatus::Elastic);
        }
    }
    // Reload: the same line up to (a step short of) the strength left, then down the curve.
    for k in 1..200 {
        let v = target - 2e-6 + 1e-8 * k as Real;
        assert_eq!(d.step(v, 0.0), JointStatus::Elastic);
        assert_eq!(d.state, state);
        if v > state.crack_opening {
            assert!((d.force.normal + kn * (v - state.crack_opening) * area).abs() < 1e-9 * 1e5 * area);
        }
    }
    d.step(target + 1e-7, 0.0);
    assert!(d.state.crack_opening > state.crack_opening);
    assert!(-d.force.normal / area < 1e5);
    // Nothing dissipated by the cycle beyond the curve's own work.
    let e = 10.0 * area * law.softening.integral(0.0, law.softening_parameter(&d.state));
    assert!((d.fracture - e).abs() < 1e-4 * e, "{} vs {e}", d.fracture);

    // Shear: slip to D = ln 2 at zero normal stress, then reverse.
    let ks = law.shear_stiffness();
    let mut d = Driver::new(&law, area);
    let kappa = 50.0 / 3e5 * std::f64::consts::LN_2;
    while d.state.plastic_slip < kappa {
        d.step(0.0, 1e-8);
    }
    let (state, tau) = (d.state, d.force.shear.x);
    assert!(tau < 0.0 && (-tau / area - 1.5e5).abs() < 1e-3 * 1.5e5);
    for k in 1..=100 {
        let status = d.step(0.0, -1e-8);
        assert_eq!((status, d.state), (JointStatus::Elastic, state));
        assert!((d.force.shear.x - (tau + ks * area * 1e-8 * k as Real)).abs() < 1e-9 * tau.abs());
    }
}

/// A crack closed after it opened through carries compression (`−k_n u_n A`, its faces touching
/// at `u_n = 0`) and friction at the residual angle, with no cohesion.
#[test]
fn a_closed_crack_carries_compression_and_friction() {
    let law = mortar(Softening::Linear);
    let area = 0.01;
    let mut d = Driver::new(&law, area);
    for k in 1..=2000 {
        d.step(1e-6 * k as Real, 0.0);
    }
    assert_eq!(law.strengths(&d.state).remaining, 0.0);
    let status = d.step(-1e-6, 0.0);
    assert_eq!(status, JointStatus::Elastic);
    let n = 1e11 * 1e-6 * area;
    assert!((d.force.normal - n).abs() < 1e-12 * n);
    for _ in 0..200 {
        d.step(-1e-6, 1e-7);
    }
    assert_eq!(d.status, JointStatus::Sliding);
    assert!((d.force.shear.length() - n * 30f64.to_radians().tan()).abs() < 1e-9 * n);
}

/// With both fracture energies zero the joint is `CoulombSlip`'s, bit for bit: the same forces,
/// statuses and failures (and the same dissipation books, no fracture work) along opening,
/// closing and sliding histories under compression and tension, for the same parameters.
#[test]
fn brittle_limit_is_coulomb_slip() {
    for (friction, residual, c, ft) in [(35.0, 30.0, 3e5, 2e5), (30.0, 30.0, 1e5, 5e4), (40.0, 25.0, 2e5, 0.0)] {
        let mortar = MortarJoint::builder(1e10, 4e9, friction)
            .residual_friction(residual)
            .tension(ft, 0.0)
            .cohesion(c, 0.0)
            .build()
            .unwrap();
        let coulomb = CoulombSlip::new(1e10, 4e9, friction, residual, c, ft).unwrap();
        // The same regime, but that the mortar's covers tension below its strength.
        let regime = mortar.elastic_regime().map(|r| ElasticRegime {
            tensile_strength: 0.0,
            ..r
        });
        assert_eq!(regime, coulomb.elastic_regime());
        assert_eq!(mortar.elastic_regime().unwrap().tensile_strength, ft);
        let mut histories: Vec<Vec<(Real, Real)>> = Vec::new();
        // Opening from compression through the tensile strength, and back.
        histories.push(
            (0..200)
                .map(|k| (-2e-5 + 2e-7 * k as Real, 0.0))
                .chain((0..200).map(|k| (2e-5 - 2e-7 * k as Real, 0.0)))
                .collect(),
        );
        // Sliding under compressions and a tension, then opening and closing.
        for gap in [-1e-4, -1e-5, -1e-7, 5e-6] {
            histories.push(
                (0..300)
                    .map(|k| (gap, 1e-6 * (0.02 * k as Real).cos()))
                    .chain((0..50).map(|k| (gap + 1e-6 * k as Real, 0.0)))
                    .chain((0..50).map(|k| (gap + 5e-5 - 2e-6 * k as Real, -3e-7)))
                    .collect(),
            );
        }
        let mut failures = 0;
        for history in histories {
            let (mut f, mut s) = (JointForce::default(), MortarState::default());
            let (mut g, mut t) = (JointForce::default(), CoulombState::default());
            for (k, &(gap, du)) in history.iter().enumerate() {
                let step = JointStep {
                    area: 0.02,
                    normal_displacement: gap,
                    normal_increment: 0.0,
                    shear_increment: Vector2::new(du, 0.3 * du),
                    axes: JointAxes::from_normal(Vector::Z),
                    dt: 1e-5,
                };
                let (s0, t0) = (s, t);
                let a = mortar.update(&step, &mut f, &mut s);
                let b = coulomb.update(&step, &mut g, &mut t);
                let bits = |f: &JointForce| [f.normal.to_bits(), f.shear.x.to_bits(), f.shear.y.to_bits()];
                assert_eq!((a, bits(&f)), (b, bits(&g)), "step {k} {step:?}: {f:?} vs {g:?}");
                assert_eq!(mortar.is_failed(&s), t.failed, "step {k}");
                assert_eq!(s != s0, t != t0, "step {k}: the state changes when Coulomb's does");
                failures += usize::from(t != t0);
                assert_eq!(mortar.fracture_work(0.02, &s0, &s), 0.0);
                assert_eq!(mortar.stays_open(0.02, gap, &s), coulomb.stays_open(0.02, gap, &t));
            }
        }
        // Bonded joints fail in tension or shear in four of the five histories; the joint
        // without tensile strength in shear once.
        assert_eq!(failures, if ft > 0.0 { 4 } else { 1 }, "{friction}° {c} {ft}");
    }
}

/// Lourenço–Rots' coupling: an opening of `κ_t` leaves the cohesion at `c₀ e^{−κ_t/α G/f_t}`…
/// that is `f_t/f_t0 = c/c₀ = exp(−f_t0 (κ_t + α κ_s)/G_f^I)` with `α = G_f^I c₀/(G_f^II f_t0)`,
/// and the friction at `r tan φ₀ + (1 − r) tan φ_r`.
#[test]
fn opening_erodes_cohesion_and_slip_erodes_tension() {
    let law = mortar(Softening::Exponential);
    let alpha = 10.0 * 3e5 / (50.0 * 2e5);
    for (crack, slip) in [(3e-5, 0.0), (0.0, 1e-4), (2e-5, 7e-5)] {
        let s = law.strengths(&MortarState {
            crack_opening: crack,
            plastic_slip: slip,
            ..MortarState::default()
        });
        let r = (-(2e5 / 10.0) * (crack + alpha * slip)).exp();
        assert!((s.tensile - 2e5 * r).abs() < 1e-9 * 2e5);
        assert!((s.cohesion - 3e5 * r).abs() < 1e-9 * 3e5);
        let tan = r * 35f64.to_radians().tan() + (1.0 - r) * 30f64.to_radians().tan();
        assert!((s.tan_friction - tan).abs() < 1e-15);
    }
    // Driven: a slip at zero normal stress, the shear unloaded, then an opening: the tension
    // peaks at what the slip left (within a step's fall down the curve, 0.2 %).
    let area = 0.01;
    let mut d = Driver::new(&law, area);
    while d.state.plastic_slip < 1e-4 {
        d.step(0.0, 1e-8);
    }
    let back = d.force.shear.x / (law.shear_stiffness() * area);
    d.step(0.0, back);
    assert!(d.force.shear.length() < 1e-6 * 3e5 * area);
    let left = law.strengths(&d.state).tensile;
    assert!((left - 2e5 * (-3e5 * d.state.plastic_slip / 50.0).exp()).abs() < 1e-9 * 2e5);
    let mut peak: Real = 0.0;
    for k in 1..=100 {
        d.step(1e-7 * k as Real, 0.0);
        peak = peak.max(-d.force.normal / area);
    }
    assert!(peak <= left * (1.0 + 1e-12) && peak > 0.99 * left, "{peak} vs {left}");
}

/// Tension and shear at once (a corner of the two surfaces): each step ends within both
/// strengths of its end state, to round-off, and the plastic opening and slip only grow.
#[test]
fn mixed_mode_steps_end_within_both_strengths() {
    for softening in [Softening::Exponential, Softening::Linear] {
        let law = mortar(softening);
        let area = 0.01;
        let mut d = Driver::new(&law, area);
        let mut last = MortarState::default();
        for k in 1..=20_000 {
            d.step(1e-7 * k as Real, 2e-7);
            let s = law.strengths(&d.state);
            let sigma = d.force.normal / area;
            let tau = d.force.shear.length() / area;
            assert!(
                -sigma <= s.tensile * (1.0 + 1e-9) + 1e-6,
                "{softening:?} {k}: {sigma} vs {s:?}"
            );
            assert!(
                tau <= (s.cohesion + sigma * s.tan_friction).max(0.0) * (1.0 + 1e-9) + 1e-6,
                "{k}"
            );
            assert!(d.state.crack_opening >= last.crack_opening && d.state.plastic_slip >= last.plastic_slip);
            last = d.state;
        }
        assert_eq!(d.status, JointStatus::Open);
        // The law's fracture work lies between the two fracture energies (a mix of the two
        // modes); the booked is at most it (under tension the Coulomb line's `σ tan φ` takes
        // from the shear's work).
        assert!(
            d.consumed >= 10.0 * area * (1.0 - 1e-9) && d.consumed <= 50.0 * area,
            "{}",
            d.consumed
        );
        assert!(
            d.fracture > 0.0 && d.fracture <= d.consumed,
            "{} {}",
            d.fracture,
            d.consumed
        );
    }
}

/// Dilatancy: slipping under a held normal displacement raises the compression by
/// `k_n u_d`, with `u_d` growing as `tan ψ₀ (G/c₀)(1 − e^{−c₀κ/G})` and no further once the
/// slip has ground it off.
#[test]
fn dilatancy_raises_the_compression_and_saturates() {
    let law = MortarJoint::builder(1e11, 4e10, 35.0)
        .residual_friction(30.0)
        .cohesion(3e5, 50.0)
        .dilatancy(10.0)
        .build()
        .unwrap();
    let area = 0.01;
    let gap = -2e-6;
    let mut d = Driver::new(&law, area);
    for _ in 0..30_000 {
        d.step(gap, 1e-7);
        let ud = law.dilatant_opening(&d.state);
        let expected = 10f64.to_radians().tan() * (50.0 / 3e5) * -(-3e5 * d.state.plastic_slip / 50.0).exp_m1();
        assert!((ud - expected).abs() < 1e-12 * expected.max(1e-9));
        assert!((d.force.normal - 1e11 * (ud - gap) * area).abs() < 1e-6 * d.force.normal);
    }
    // At 3 mm of slip, D = 18: all but e^{−18} = 1.5e-8 of the most.
    let most = 10f64.to_radians().tan() * 50.0 / 3e5;
    assert!((law.dilatant_opening(&d.state) - most).abs() < 2e-8 * most);
    assert!(d.friction > 0.0 && d.fracture > 0.0);
}

/// Every bad parameter is refused by name.
#[test]
fn bad_parameters_are_named() {
    let named = |law: Result<MortarJoint>, name: &str| {
        let e = law.unwrap_err();
        assert!(e.to_string().contains(name), "{e} should name {name}");
    };
    named(MortarJoint::builder(-1.0, 1e9, 30.0).build(), "normal_stiffness");
    named(MortarJoint::builder(1e9, 0.0, 30.0).build(), "shear_stiffness");
    named(MortarJoint::builder(1e9, 1e9, 90.0).build(), "friction_angle");
    named(
        MortarJoint::builder(1e9, 1e9, 30.0).residual_friction(-1.0).build(),
        "residual_friction_angle",
    );
    named(
        MortarJoint::builder(1e9, 1e9, 30.0).tension(-1.0, 1.0).build(),
        "tensile_strength",
    );
    named(
        MortarJoint::builder(1e9, 1e9, 30.0).tension(1e5, Real::NAN).build(),
        "mode_i_fracture_energy",
    );
    named(
        MortarJoint::builder(1e9, 1e9, 30.0)
            .cohesion(Real::INFINITY, 1.0)
            .build(),
        "cohesion",
    );
    named(
        MortarJoint::builder(1e9, 1e9, 30.0).cohesion(1e5, -2.0).build(),
        "mode_ii_fracture_energy",
    );
    named(
        MortarJoint::builder(1e9, 1e9, 30.0).dilatancy(10.0).build(),
        "dilatancy_angle",
    );
    named(
        MortarJoint::builder(1e9, 1e9, 30.0)
            .cohesion(1e5, 0.0)
            .dilatancy(10.0)
            .build(),
        "dilatancy_angle",
    );
    let capped = |cap: CompressionCap| MortarJoint::builder(1e9, 1e9, 30.0).compression_cap(cap).build();
    named(capped(CompressionCap::new(0.0, 1.0)), "cap_strength");
    named(capped(CompressionCap::new(1e6, -1.0)), "cap_fracture_energy");
    named(
        capped(CompressionCap::new(1e6, 1.0).with_shear_factor(Real::NAN)),
        "cap_shear_factor",
    );
    named(
        capped(CompressionCap::new(1e6, 1.0).with_peak_closure(-1e-4)),
        "cap_peak_closure",
    );

    assert!(MortarJoint::builder(1e9, 1e9, 30.0).build().is_ok());
}

/// The softening shapes: `r(0) = 1`, `∫₀^∞ r = 1` (to the exponential's cut), and the integral
/// over any piece as the difference of the whole.
#[test]
fn softening_shapes_hold_their_unit_integral() {
    for s in [Softening::Exponential, Softening::Linear] {
        assert_eq!(s.remaining(0.0), 1.0);
        assert_eq!(s.remaining(1e3), 0.0);
        assert!((s.integral(0.0, 1e3) - 1.0).abs() <= Real::EPSILON);
        for (a, b) in [(0.0, 0.3), (0.3, 1.7), (1.7, 40.0)] {
            let sum = s.integral(0.0, a) + s.integral(a, b - a);
            assert!((sum - s.integral(0.0, b)).abs() < 1e-15);
        }
    }
    assert_eq!(Softening::Linear.remaining(2.0), 0.0);
    assert_eq!(Softening::Exponential.remaining(EXPONENTIAL_END), 0.0);
    assert!(Softening::Exponential.remaining(EXPONENTIAL_END * (1.0 - 1e-15)) >= Real::EPSILON * 0.99);
}

fn laws() -> Vec<MortarJoint> {
    let base = || MortarJoint::builder(4e9, 1.6e9, 35.0).residual_friction(28.0);
    vec![
        base().tension(2e5, 10.0).cohesion(3e5, 50.0).build().unwrap(),
        base()
            .tension(2e5, 10.0)
            .cohesion(3e5, 50.0)
            .softening(Softening::Linear)
            .build()
            .unwrap(),
        base()
            .tension(2e5, 10.0)
            .cohesion(3e5, 50.0)
            .dilatancy(12.0)
            .build()
            .unwrap(),
        // Snap-back: f_t²/G_f^I = 4e11 > kn.
        base().tension(2e5, 0.1).cohesion(3e5, 0.2).build().unwrap(),
        base().tension(2e5, 0.0).cohesion(3e5, 0.0).build().unwrap(),
        base().cohesion(3e5, 50.0).build().unwrap(),
        base().tension(1e5, 20.0).build().unwrap(),
        base().build().unwrap(),
        // Crushing: a cap with hardening, and one on the normal stress alone, without tension.
        base()
            .tension(2e5, 10.0)
            .cohesion(3e5, 50.0)
            .compression_cap(CompressionCap::new(2e6, 100.0).with_peak_closure(1e-4))
            .build()
            .unwrap(),
        base()
            .compression_cap(CompressionCap::new(1e6, 0.0).with_shear_factor(0.0))
            .build()
            .unwrap(),
    ]
}

/// Intact, softening, brittle, dilatant, dry and crushing joints keep the law contract
/// (`elastic_regime` and `stays_open` agree with `update`; energies and fracture work not
/// negative; see [`crate::law::conformance`]).
#[test]
fn conforms_to_the_law_contract() {
    for law in laws() {
        let report = conformance::check(&law).unwrap_or_else(|e| panic!("{law:?}: {e}"));
        if law.elastic_regime().is_some() {
            assert!(report.regime_stood > 1000, "{law:?}: {report:?}");
        } else {
            assert_eq!(report.regime_stood, 0);
        }
        assert!(report.open_promised > 100, "{law:?}: {report:?}");
        // Only the dry joint without a cap has nothing to lose.
        let dry = law.tensile_strength() == 0.0 && law.cohesion() == 0.0 && law.compression_cap().is_none();
        assert_eq!(report.states == 1, dry, "{law:?}: {report:?}");
        assert_eq!(conformance::check(&crate::law::AnyLaw::from(law)), Ok(report));
    }
}

/// A node contact starts unbonded (`ConstitutiveLaw::unbonded_state`): no tensile strength, no
/// cohesion, the residual friction, exactly, for every shape and a brittle joint; by slip for a
/// joint with cohesion alone; the virgin state for a dry joint and for cohesion with dilatancy
/// (whose slipped state would carry the dilatant opening).
#[test]
fn the_unbonded_state_has_no_bond_left() {
    let brittle = MortarJoint::builder(1e11, 4e10, 35.0)
        .residual_friction(30.0)
        .tension(2e5, 0.0)
        .cohesion(3e5, 0.0)
        .build()
        .unwrap();
    let cohesive = MortarJoint::builder(1e11, 4e10, 35.0)
        .residual_friction(30.0)
        .cohesion(3e5, 50.0)
        .build()
        .unwrap();
    for law in [
        mortar(Softening::Exponential),
        mortar(Softening::Linear),
        brittle,
        cohesive,
    ] {
        let state = law.unbonded_state();
        let s = law.strengths(&state);
        assert_eq!((s.remaining, s.tensile, s.cohesion), (0.0, 0.0, 0.0), "{law:?}");
        assert_eq!(s.tan_friction, 30f64.to_radians().tan(), "{law:?}");
        assert_eq!(law.dilatant_opening(&state), 0.0);
        assert_eq!(state.crushing, 0.0);
        // The crack is opened just to the end of the curve, no further.
        let d = law.softening_parameter(&state);
        assert!(
            d.is_infinite() || d <= law.softening().end() * (1.0 + 4.0 * Real::EPSILON),
            "{d}"
        );
        // Pressed, it carries compression and friction; pulled, nothing.
        let step = |u: Real, du: Vector2| JointStep {
            normal_displacement: u,
            normal_increment: 0.0,
            shear_increment: du,
            area: 1e-2,
            axes: JointAxes::from_normal(Vector::Z),
            dt: 1e-5,
        };
        let (mut f, mut st) = (JointForce::default(), state);
        assert_eq!(
            law.update(&step(-1e-6, Vector2::ZERO), &mut f, &mut st),
            JointStatus::Elastic
        );
        assert_eq!(f.normal, 1e11 * 1e-6 * 1e-2);
        assert_eq!(
            law.update(&step(-1e-6, Vector2::new(1e-4, 0.0)), &mut f, &mut st),
            JointStatus::Sliding
        );
        assert!((f.shear.length() - 30f64.to_radians().tan() * f.normal).abs() < 1e-12 * f.normal);
        let mut f = JointForce::default();
        assert_eq!(
            law.update(&step(1e-9, Vector2::ZERO), &mut f, &mut st),
            JointStatus::Open
        );
        assert_eq!(f, JointForce::default());
    }
    let dry = MortarJoint::builder(1e11, 4e10, 35.0).build().unwrap();
    assert_eq!(dry.unbonded_state(), MortarState::default());
    let dilatant = MortarJoint::builder(1e11, 4e10, 35.0)
        .cohesion(3e5, 50.0)
        .dilatancy(10.0)
        .build()
        .unwrap();
    assert_eq!(dilatant.unbonded_state(), MortarState::default());
    // CoulombSlip: failed when bonded, virgin when dry.
    let bonded = CoulombSlip::new(1e11, 4e10, 35.0, 30.0, 3e5, 2e5).unwrap();
    assert_eq!(bonded.unbonded_state(), CoulombState { failed: true });
    assert_eq!(
        CoulombSlip::dry(1e11, 4e10, 35.0).unwrap().unbonded_state(),
        CoulombState::default()
    );
}
