//! Mortared joints that crack and soften by their fracture energies (`MortarJoint`, issue 44),
//! in models: a joint pulled open or sheared through dissipates its fracture energy per unit
//! area whatever the sub-contact density and however its face is split between blocks; the
//! work under a constant compression is the law's closed form; unloading is elastic; with no
//! fracture energy the answer is `CoulombSlip`'s bit for bit; the energy books carry the
//! fracture work and balance through cracking and sliding; checkpoints and scenes carry the law.

use crate::common;

use voussoir::io::scene::Scene;
use voussoir::law::{CompressionCap, MortarJoint, MortarState, Softening};
use voussoir::model::reseal_checkpoint;
use voussoir::prelude::*;

/// Stiffnesses of the joints (Pa/m): stiff mortar joints, no snap-back for the strengths and
/// fracture energies below (`f²/G_f` at most 2e10 Pa/m).
const KN: Real = 1e11;
const KS: Real = 4e10;

/// Tensile strength and cohesion (Pa).
const FT: Real = 2e5;
const C: Real = 3e5;

/// A mortar joint with fracture energies `g_i`, `g_ii` (J/m²), φ 35° → 30°.
fn mortar(g_i: Real, g_ii: Real, softening: Softening) -> MortarJoint {
    MortarJoint::builder(KN, KS, 35.0)
        .residual_friction(30.0)
        .tension(FT, g_i)
        .cohesion(C, g_ii)
        .softening(softening)
        .build()
        .expect("valid mortar joint")
}

/// Parameters with `per_edge` sub-contacts per edge, a fixed step of 1e-4 s (the driven blocks
/// have no dynamics) and gravity `g` (m/s², downwards).
fn driven_parameters(per_edge: u16, g: Real) -> ModelParameters {
    ModelParameters {
        gravity: Vector::new(0.0, 0.0, -g),
        contact: ContactParameters {
            density: SubContactDensity::PerEdge(per_edge),
            ..ContactParameters::default()
        },
        time_step: TimeStep::Fixed(1e-4),
        ..ModelParameters::default()
    }
}

/// A 0.2 × 0.2 × 0.1 m layer on the fixed slab, its bottom at `z` (m), split into
/// `split × split` blocks, each driven at `velocity` (rotations fixed) from the start.
fn driven_layer<L: ConstitutiveLaw>(model: &mut Model<L>, split: usize, z: Real, velocity: Vector) -> Vec<BlockId> {
    let h = 0.2 / split as Real;
    let mut ids = Vec::new();
    for i in 0..split {
        for j in 0..split {
            let lo = Vector::new(-0.1 + h * i as Real, -0.1 + h * j as Real, z);
            let block = RigidBlock::cuboid(&format!("layer {i} {j}"), lo, lo + Vector::new(h, h, 0.1), 2500.0)
                .expect("block")
                .with_fixity(Fixity::velocity(velocity))
                .with_velocity(velocity, Vector::ZERO);
            ids.push(model.add_block(block).expect("block added"));
        }
    }
    ids
}

/// The joint's area (m²).
const AREA: Real = 0.04;

/// A 0.2 m square layer bonded to the slab by `law`, pulled straight up at 1 mm/s (1e-7 m a
/// step, 1 % of `G_f^I/f_t`) by 0.6 mm: the energies at the end.
fn pull_off(law: MortarJoint, per_edge: u16, split: usize) -> Energies {
    let mut model = common::model_with(driven_parameters(per_edge, 9.81), law);
    model.set_damping(Damping::None).expect("undamped");
    model.add_block(common::fixed_slab("slab")).expect("slab");
    driven_layer(&mut model, split, 0.0, Vector::new(0.0, 0.0, 1e-3));
    model.run_steps(6000).expect("run");
    // Cracked through: every sub-contact to the slab carries nothing and has lost its strength.
    let slab = BlockId(0);
    let mut cells = 0;
    for contact in model.contacts().filter(|c| c.blocks().0 == slab) {
        for s in contact.subcontacts() {
            assert_eq!(s.normal_force(), 0.0);
            assert_eq!(law.strengths(s.law_state()).remaining, 0.0);
            cells += 1;
        }
    }
    assert_eq!(cells, split * split * per_edge as usize * per_edge as usize);
    model.energies()
}

/// Pure mode I: the layer pulled off the slab dissipates `G_f^I·A` within 1 %, at 5, 15 and 30
/// sub-contacts per edge and with the joint's face split over 1, 4 and 16 blocks, by
/// exponential and by linear softening: the fracture booked, all that the joints dissipated,
/// and the work it took to pull the layer off (the supports' and gravity's, less what is
/// left in the springs: nothing). Measured: the fracture `G_f^I·A (1 − 7e-13)` in every
/// exponential case (`1 − 3e-11` linear), the same at every density and split to 1e-14; all
/// the dissipation and the work `1 + 1.0e-5` (exponential: the trapezoidal rule over the
/// convex curve, booked as friction).
#[test]
fn mode_i_dissipates_g_f_a_at_any_density_and_split() {
    let g = 2.0;
    let expected = g * AREA;
    let mut ratios = Vec::new();
    for (per_edge, split, softening) in [
        (5, 1, Softening::Exponential),
        (15, 1, Softening::Exponential),
        (30, 1, Softening::Exponential),
        (15, 2, Softening::Exponential),
        (15, 4, Softening::Exponential),
        (15, 1, Softening::Linear),
        (5, 4, Softening::Linear),
    ] {
        let e = pull_off(mortar(g, 10.0, softening), per_edge, split);
        let work = e.boundary_work + e.gravity_work + e.initial_kinetic - e.kinetic - e.damping - e.elastic;
        let case = format!("{per_edge} per edge, {} blocks, {softening:?}", split * split);
        for (what, value) in [
            ("fracture", e.fracture),
            ("dissipated", e.fracture + e.friction),
            ("work", work),
        ] {
            let ratio = value / expected;
            println!("{case}: {what} / (G_f^I A) − 1 = {:+.2e}", ratio - 1.0);
            assert!(
                (ratio - 1.0).abs() < 0.01,
                "{case}: {what} {value} J vs G_f^I·A = {expected} J"
            );
        }
        assert!(e.friction.abs() < 1e-3 * expected, "{case}: friction {}", e.friction);
        assert!(e.balance_error().abs() < 1e-3 * expected, "{case}: {e:?}");
        ratios.push((softening, e.fracture / expected));
    }
    // The same answer at every density and split, to round-off and the step's sampling.
    for softening in [Softening::Exponential, Softening::Linear] {
        let r: Vec<Real> = ratios
            .iter()
            .filter(|(s, _)| *s == softening)
            .map(|(_, r)| *r)
            .collect();
        let spread = r.iter().fold(0.0, |m: Real, a| m.max((a - r[0]).abs()));
        assert!(spread < 1e-9, "{softening:?}: {r:?}");
    }
}

/// The layer pushed straight down into the slab at 1 mm/s (1e-7 m a step) by 0.6 mm through a
/// joint with a compression cap (f_m 2 MPa, G_c 100 N/m: `Δκ` = 61 µm, with hardening over
/// `κ_p` = 20 µm): the energies at the end and the joint's normal force.
fn pushed_in(per_edge: u16, split: usize) -> (Energies, Real, CompressionCap) {
    let cap = CompressionCap::new(2e6, 100.0).with_peak_closure(2e-5);
    let law = MortarJoint::builder(KN, KS, 35.0)
        .tension(FT, 2.0)
        .cohesion(C, 10.0)
        .compression_cap(cap)
        .build()
        .expect("valid capped joint");
    let mut model = common::model_with(driven_parameters(per_edge, 0.0), law);
    model.set_damping(Damping::None).expect("undamped");
    model.add_block(common::fixed_slab("slab")).expect("slab");
    driven_layer(&mut model, split, 0.0, Vector::new(0.0, 0.0, -1e-3));
    model.run_steps(6000).expect("run");
    let slab = BlockId(0);
    let mut normal = 0.0;
    for contact in model.contacts().filter(|c| c.blocks().0 == slab) {
        for s in contact.subcontacts() {
            normal += s.normal_force();
        }
    }
    (model.energies(), normal, cap)
}

/// Crushing, per unit area: pushed 0.6 mm in, the joint carries its residual `f_m/7` over its
/// area (to 1e-9), and books `A ∫₀^κ σ_c` as fracture (`CompressionCap::work_to`, `κ` the depth
/// less the residual's elastic closure), within 2e-4 (measured −9.6e-5: the books take each
/// 0.1 µm step by the trapezoidal rule, short of the curve's integral where it bends, most
/// steeply at the first yield), at 5 and 15 per edge and over 1, 4 and 16
/// blocks, the same in every case to 1e-9; of it, `G_c·A` is over the residual past the peak
/// (to the exponential's tail, e^{−25}). Nothing is booked as friction (no shear).
#[test]
fn crushing_dissipates_the_cap_energy_at_any_density_and_split() {
    let mut booked = Vec::new();
    for (per_edge, split) in [(5, 1), (15, 1), (15, 2), (5, 4)] {
        let (e, normal, cap) = pushed_in(per_edge, split);
        let case = format!("{per_edge} per edge, {} blocks", split * split);
        let residual = cap.residual();
        assert!(
            (normal - residual * AREA).abs() < 1e-9 * residual * AREA,
            "{case}: {normal} N"
        );
        let kappa = 0.6e-3 - residual / KN;
        let expected = AREA * cap.work_to(kappa);
        println!("{case}: fracture / (A ∫σ_c) − 1 = {:+.2e}", e.fracture / expected - 1.0);
        assert!(
            (e.fracture - expected).abs() < 2e-4 * expected,
            "{case}: {} vs {expected}",
            e.fracture
        );
        let over = expected - AREA * (cap.work_to(cap.peak_closure) + residual * (kappa - cap.peak_closure));
        assert!((over - cap.fracture_energy * AREA).abs() < 1e-9 * cap.fracture_energy * AREA);
        assert!(e.friction.abs() < 1e-4 * expected, "{case}: friction {}", e.friction);
        assert!(e.balance_error().abs() < 1e-4 * expected, "{case}: {e:?}");
        booked.push(e.fracture);
    }
    let spread = booked.iter().fold(0.0, |m: Real, b| m.max((b - booked[0]).abs()));
    assert!(spread < 1e-9 * booked[0], "{booked:?}");
}

/// Pure mode II at zero normal stress (no gravity, the layer slid along the slab face at
/// 1 mm/s): `G_f^II·A` within 1 %, at 5 and 15 per edge and over 1 and 4 blocks, all of it
/// fracture (no normal stress: no friction work); the joint left carrying nothing.
#[test]
fn mode_ii_at_zero_normal_stress_dissipates_g_f_ii_a() {
    let g_ii = 10.0;
    let expected = g_ii * AREA;
    for (per_edge, split) in [(5, 1), (15, 1), (15, 2)] {
        let law = mortar(2.0, g_ii, Softening::Exponential);
        let mut model = common::model_with(driven_parameters(per_edge, 0.0), law);
        model.set_damping(Damping::None).expect("undamped");
        model.add_block(common::fixed_slab("slab")).expect("slab");
        driven_layer(&mut model, split, 0.0, Vector::new(1e-3, 0.0, 0.0));
        // 1.5 mm: D = c κ/G_f^II = 45 beyond the exponential's end.
        model.run_steps(15_000).expect("run");
        let e = model.energies();
        let ratio = e.fracture / expected;
        println!(
            "mode II, {per_edge} per edge, {} blocks: fracture / (G_f^II A) − 1 = {:+.2e}, friction {:.2e} of it",
            split * split,
            ratio - 1.0,
            e.friction / expected
        );
        assert!((ratio - 1.0).abs() < 0.01, "{e:?}");
        assert!(e.friction.abs() < 1e-3 * expected, "{e:?}");
        let carried: Real = model
            .contacts()
            .filter(|c| c.blocks().0 == BlockId(0))
            .map(|c| c.resultant().length())
            .sum();
        assert_eq!(carried, 0.0);
    }
}

/// The law's closed form under a constant compression `σ` (exponential softening): at plastic
/// slip `κ`, with `r = e^{−c κ/G}`, the shear stress, the fracture work and the friction work
/// per unit area (see `src/law/mortar/tests.rs`).
fn mode_ii_closed_form(law: &MortarJoint, sigma: Real, kappa: Real) -> (Real, Real, Real) {
    let (c, g) = (law.cohesion(), law.mode_ii_fracture_energy());
    let (t0, tr) = (law.friction_angle().tan(), law.residual_friction_angle().tan());
    let r = (-c * kappa / g).exp();
    let tau = c * r + sigma * (r * t0 + (1.0 - r) * tr);
    let fracture = g * (1.0 - r);
    let friction = sigma * tr * kappa + sigma * (t0 - tr) * (g / c) * (1.0 - r);
    (tau, fracture, friction)
}

/// Mode II under a constant compression of 0.5 MPa (the layer set 5 µm into the slab, no
/// gravity, slid at 1 mm/s): after each slip `δ` the joint's shear force, the fracture and the
/// friction booked match the law's closed form (`κ` solved from `δ = κ + τ(κ)/k_s`) within
/// 1 %; measured within 4e-13, 4e-14 and 5e-6 (the friction's trapezoidal rule over 1e-7 m
/// steps and the step that reaches the peak part-way).
#[test]
fn mode_ii_under_compression_follows_the_closed_form() {
    let sigma = 5e5;
    let law = mortar(2.0, 10.0, Softening::Exponential);
    let mut model = common::model_with(driven_parameters(15, 0.0), law);
    model.set_damping(Damping::None).expect("undamped");
    model.add_block(common::fixed_slab("slab")).expect("slab");
    driven_layer(&mut model, 1, -sigma / KN, Vector::new(1e-3, 0.0, 0.0));
    let mut worst: (Real, Real, Real) = (0.0, 0.0, 0.0);
    for k in 1..=20 {
        model.run_steps(500).expect("run");
        let delta = 1e-7 * (500 * k) as Real;
        let (mut lo, mut hi) = (0.0, delta);
        for _ in 0..200 {
            let mid = 0.5 * (lo + hi);
            if delta - mid - mode_ii_closed_form(&law, sigma, mid).0 / KS > 0.0 {
                lo = mid;
            } else {
                hi = mid;
            }
        }
        let kappa = 0.5 * (lo + hi);
        let (tau, fracture, friction) = mode_ii_closed_form(&law, sigma, kappa);
        let contact = model.contact_between(BlockId(0), BlockId(1)).expect("the joint");
        assert!((contact.normal_force() - sigma * AREA).abs() < 1e-6 * sigma * AREA);
        let shear = contact.resultant().x.abs();
        let e = model.energies();
        let errors = (
            (shear / (tau * AREA) - 1.0).abs(),
            (e.fracture / (fracture * AREA) - 1.0).abs(),
            (e.friction / (friction * AREA) - 1.0).abs(),
        );
        println!(
            "δ {delta:.1e}: shear, fracture, friction errors {:.2e} {:.2e} {:.2e}",
            errors.0, errors.1, errors.2
        );
        worst = (worst.0.max(errors.0), worst.1.max(errors.1), worst.2.max(errors.2));
    }
    assert!(worst.0 < 0.01 && worst.1 < 0.01 && worst.2 < 0.01, "{worst:?}");
}

/// Unloading halfway down the tension curve (the layer driven back down once the joint's
/// stress has fallen to half its strength) returns on `k_n A` to the crack's opening, where it
/// carries nothing, with no fracture; driven up again, the joint climbs the same line back to
/// the strength it left, and softens on from there. (The force a step reports is the one at
/// the poses it started from: a reversal shows a step later.)
#[test]
fn unloading_halfway_returns_on_the_elastic_stiffness() {
    let law = mortar(2.0, 10.0, Softening::Exponential);
    let mut model = common::model_with(driven_parameters(15, 0.0), law);
    model.set_damping(Damping::None).expect("undamped");
    model.add_block(common::fixed_slab("slab")).expect("slab");
    let layer = driven_layer(&mut model, 1, 0.0, Vector::new(0.0, 0.0, 1e-3))[0];
    let force = |m: &Model<MortarJoint>| m.contact_between(BlockId(0), layer).expect("joint").normal_force();
    // Up to half the strength: σ = f_t/2 at u = (G/f_t) ln 2 + f_t/(2 kn) = 7.9 µm.
    model
        .run_until(1000, |m| -force(m) < 0.5 * FT * AREA && m.energies().fracture > 0.0)
        .expect("run");
    model
        .set_prescribed_velocity(layer, Vector::new(0.0, 0.0, -1e-3))
        .expect("down");
    model.step().expect("the last step up");
    let (top, fracture) = (force(&model), model.energies().fracture);
    assert!(
        fracture > 0.3 * 2.0 * AREA && -top < 0.5 * FT * AREA,
        "{fracture} {top}"
    );
    // Each step of 1e-7 m on the elastic line takes kn·A·1e-7 = 400 N of the tension off.
    let step = KN * AREA * 1e-7;
    let mut last = top;
    let mut unloaded = 0;
    for i in 1..=30 {
        model.step().expect("step");
        let f = force(&model);
        if f < 0.0 {
            assert!((f - last - step).abs() < 1e-6 * step, "{f} after {last}");
            assert!((f - (top + i as Real * step)).abs() < 1e-6 * top.abs());
            unloaded += 1;
        } else {
            assert_eq!(f, 0.0, "the crack open, carrying nothing");
        }
        last = f;
        assert_eq!(model.energies().fracture, fracture, "no fracture while unloading");
    }
    assert!(unloaded >= 9, "{unloaded}");
    // Up again: the same line back to a step short of the top, with no fracture.
    model
        .set_prescribed_velocity(layer, Vector::new(0.0, 0.0, 1e-3))
        .expect("up");
    model.step().expect("the last step down");
    for j in 1..=30 {
        model.step().expect("step");
        let f = force(&model);
        let expected = top + (31 - j) as Real * step;
        assert!(
            f == 0.0 && expected >= 0.0 || (f - expected).abs() < 1e-6 * top.abs(),
            "{j}: {f} vs {expected}"
        );
        assert_eq!(model.energies().fracture, fracture, "no fracture while reloading");
    }
    model.run_steps(3).expect("on");
    assert!(model.energies().fracture > fracture && -force(&model) < -top);
}

/// A bonded cube on the slab under gravity and a load (`load`, N, at its centroid), with `law`.
fn loaded_cube<L: ConstitutiveLaw>(law: L, load: Vector) -> Model<L> {
    let mut model = common::model(law);
    model.set_damping(Damping::None).expect("undamped");
    model.add_block(common::fixed_slab("slab")).expect("slab");
    let cube = model.add_block(common::cube("cube", Vector::ZERO)).expect("cube");
    model
        .set_load(
            cube,
            Wrench {
                force: load,
                moment: Vector::ZERO,
            },
        )
        .expect("load");
    model
}

/// With no fracture energy the joint is `CoulombSlip`'s, bit for bit: a bonded cube pulled off
/// the slab and one pushed off sideways (under its weight) fail, fly or slide exactly as with
/// `CoulombSlip` of the same strengths — every block and contact state and every energy term
/// — and book no fracture work.
#[test]
fn with_no_fracture_energy_the_answer_is_coulomb_slips() {
    let brittle = MortarJoint::builder(KN, KS, 35.0)
        .residual_friction(30.0)
        .tension(FT, 0.0)
        .cohesion(C, 0.0)
        .build()
        .expect("law");
    let coulomb = CoulombSlip::new(KN, KS, 35.0, 30.0, C, FT).expect("law");
    // Beyond f_t·A = 8 kN up, and beyond c·A + W tan 35° = 12 kN sideways.
    for load in [Vector::new(0.0, 0.0, 9e3), Vector::new(1.4e4, 0.0, 0.0)] {
        let mut a = loaded_cube(brittle, load);
        let mut b = loaded_cube(coulomb, load);
        let mut failed = false;
        for _ in 0..40 {
            a.run_steps(25).expect("run");
            b.run_steps(25).expect("run");
            assert_eq!(
                common::fingerprint(&a),
                common::fingerprint(&b),
                "load {load}, t {}",
                a.time()
            );
            assert_eq!(a.energies().fracture, 0.0);
            failed |= a
                .contacts()
                .any(|c| c.subcontacts().any(|s| brittle.is_failed(s.law_state())));
        }
        assert!(failed, "the joint failed under {load}");
        assert!(a.energies().friction > 0.0);
    }
}

/// The energy books through cracking and sliding: a pier of three bonded cubes pushed over by
/// a load at its top (the base joint cracks open at the heel, the pier rocks and its joints
/// slide), undamped. `input − accounted` stays within 1 % of the largest term after every
/// step (measured: 2e-6), the fracture booked is positive and at most the
/// fracture energy of the joints' area, and friction does not go negative.
#[test]
fn the_balance_holds_through_cracking_and_sliding() {
    let law = MortarJoint::builder(1e10, 4e9, 35.0)
        .residual_friction(30.0)
        .tension(2e4, 2.0)
        .cohesion(3e4, 10.0)
        .build()
        .expect("law");
    let mut model = common::model(law);
    model.set_damping(Damping::None).expect("undamped");
    model.add_block(common::fixed_slab("slab")).expect("slab");
    let mut top = BlockId(0);
    for k in 0..3 {
        top = model
            .add_block(common::cube(
                &format!("cube {k}"),
                Vector::new(0.0, 0.0, 0.2 * k as Real),
            ))
            .expect("cube");
    }
    // 300 N at 0.5 m: 150 N·m against the base's cracking moment f_t b²d/6 + N b/2 = 86 N·m.
    model
        .set_load(
            top,
            Wrench {
                force: Vector::new(300.0, 0.0, 0.0),
                moment: Vector::ZERO,
            },
        )
        .expect("load");
    let (mut scale, mut worst): (Real, Real) = (0.0, 0.0);
    while model.time() < 0.15 {
        model.step().expect("step");
        let e = model.energies();
        scale = scale.max(
            [
                e.kinetic,
                e.elastic,
                e.friction,
                e.fracture,
                e.gravity_work,
                e.load_work,
                e.input(),
            ]
            .into_iter()
            .fold(0.0, |m: Real, x| m.max(x.abs())),
        );
        if scale > 1e-6 {
            worst = worst.max(e.balance_error().abs() / scale);
        }
        assert!(e.friction >= -1e-9 * scale, "{e:?}");
    }
    let e = model.energies();
    println!("pier: worst balance {worst:.2e} of the largest term; {e:?}");
    assert!(worst < 0.01, "{worst}");
    assert!(e.fracture > 0.0 && e.fracture <= 10.0 * AREA * 3.0, "{e:?}");
    // The base joint cracked at the heel.
    let base = model.contact_between(BlockId(0), BlockId(1)).expect("base joint");
    assert!(base.subcontacts().any(|s| law.is_failed(s.law_state())));
}

/// A dynamic pull-off (a free cube under a constant upward load of 1.5 times its joint's
/// strength and weight, undamped): the crack runs through in a few hundred steps as the cube
/// accelerates off; the fracture booked is `G_f^I·A` within 1 % and the balance holds within
/// 1 % of the largest term at every step (measured: 0.9988 — the step that reaches the peak
/// part-way books the trapezoid of a kinked curve, below its integral — and 6e-7).
#[test]
fn a_dynamic_pull_off_books_g_f_a_and_keeps_the_balance() {
    // G_f^I/f_t = 0.1 mm: the crack runs over many steps even as the cube speeds up; by the
    // tolerance (1 mm), where the contact is dropped, D = 10 and e^{−10} of G_f^I is left.
    let g = 20.0;
    let law = mortar(g, 50.0, Softening::Exponential);
    let weight = 2500.0 * 0.008 * 9.81;
    let mut model = loaded_cube(law, Vector::new(0.0, 0.0, 1.5 * (FT * AREA + weight)));
    let (mut scale, mut worst): (Real, Real) = (0.0, 0.0);
    let cube = BlockId(1);
    while model.block(cube).expect("cube").state().pose.translation.z < 0.1 + 2e-3 {
        model.step().expect("step");
        let e = model.energies();
        scale = scale.max(
            [e.kinetic, e.fracture, e.load_work, e.input()]
                .into_iter()
                .fold(0.0, |m: Real, x| m.max(x.abs())),
        );
        worst = worst.max(e.balance_error().abs() / scale.max(1e-6));
    }
    let e = model.energies();
    let ratio = e.fracture / (g * AREA);
    println!(
        "dynamic pull-off: fracture / (G_f^I A) = {ratio:.5}, worst balance {worst:.2e}, {} steps",
        model.step_count()
    );
    assert!((ratio - 1.0).abs() < 0.01, "{e:?}");
    assert!(worst < 0.01, "{worst}");
    assert_eq!(model.contacts().count(), 0, "the cube is off");
}

/// Checkpoints and scenes carry the law: a `Model<MortarJoint>` saved mid-crack continues bit
/// for bit (states, forces, every energy term, fracture included); a scene of a
/// `Model<AnyLaw>` with a mortar joint reads back the same law; a checkpoint written before
/// `Energies::fracture` existed loads with it at zero.
#[test]
fn checkpoints_and_scenes_carry_the_mortar_joint() {
    let law = mortar(20.0, 50.0, Softening::Linear);
    let weight = 2500.0 * 0.008 * 9.81;
    let mut model = loaded_cube(law, Vector::new(0.0, 0.0, 1.5 * (FT * AREA + weight)));
    model
        .run_until(100_000, |m| m.energies().fracture > 0.2)
        .expect("cracking");
    let text = model.to_checkpoint_string().expect("saved");
    let mut restored = Model::<MortarJoint>::from_checkpoint_str(&text).expect("restored");
    assert_eq!(restored.law_table().laws(), model.law_table().laws());
    let states = |m: &Model<MortarJoint>| -> Vec<MortarState> {
        m.contacts()
            .flat_map(|c| c.subcontacts().map(|s| *s.law_state()).collect::<Vec<_>>())
            .collect()
    };
    assert_eq!(states(&restored), states(&model));
    assert!(states(&model).iter().any(|s| s.crack_opening > 0.0));
    for _ in 0..4 {
        model.run_steps(50).expect("run");
        restored.run_steps(50).expect("run");
        assert_eq!(common::fingerprint(&restored), common::fingerprint(&model));
        assert_eq!(
            restored.energies().fracture.to_bits(),
            model.energies().fracture.to_bits()
        );
    }

    // A scene of mixed laws.
    let mut mixed: Model<AnyLaw> = Model::new(ModelParameters::default()).expect("model");
    mixed
        .set_joint_law(MaterialId(0), MaterialId(0), law.into())
        .expect("mortar");
    mixed
        .set_joint_law(
            MaterialId(0),
            MaterialId(1),
            CoulombSlip::dry(KN, KS, 30.0).expect("dry").into(),
        )
        .expect("dry");
    mixed.add_block(common::fixed_slab("slab")).expect("slab");
    mixed.add_block(common::cube("cube", Vector::ZERO)).expect("cube");
    let text = Scene::from_model(&mixed).to_json().expect("scene");
    assert!(
        text.contains("\"Mortar\"") && text.contains("mode_i_fracture_energy"),
        "{text}"
    );
    let back = Scene::<AnyLaw>::from_json(&text).expect("read").build().expect("built");
    assert_eq!(back.law_table().laws(), mixed.law_table().laws());
    assert_eq!(
        back.law_table().get(MaterialId(0), MaterialId(0)),
        Some(&AnyLaw::from(law))
    );

    // An older checkpoint: no `fracture` among its energies.
    let mut coulomb = loaded_cube(
        CoulombSlip::new(KN, KS, 35.0, 30.0, C, FT).expect("law"),
        Vector::new(1.4e4, 0.0, 0.0),
    );
    coulomb.run_steps(300).expect("run");
    let mut doc: serde_json::Value =
        serde_json::from_str(&coulomb.to_checkpoint_string().expect("saved")).expect("json");
    let energy = doc["energy"].as_object_mut().expect("the energies");
    assert!(energy.remove("fracture").is_some());
    let old = reseal_checkpoint(&doc.to_string()).expect("resealed");
    let loaded = Model::<CoulombSlip>::from_checkpoint_str(&old).expect("an older checkpoint loads");
    assert_eq!(loaded.energies().fracture, 0.0);
    assert_eq!(common::fingerprint(&loaded), common::fingerprint(&coulomb));
}
