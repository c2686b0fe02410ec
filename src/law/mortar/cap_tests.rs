//! [`MortarJoint`]'s compression cap on its own, sub-contact by sub-contact: the curve and its
//! work against their closed forms, crushing per unit area, unloading on `k_n`, the return onto
//! the ellipse with associated flow, shear lowering the cap, and the corner with Coulomb.

use super::tests::Driver;
use super::*;

/// `∫₀^κ σ_c` by Simpson's rule over `n` panels.
fn simpson(cap: &CompressionCap, a: Real, b: Real, n: usize) -> Real {
    let h = (b - a) / n as Real;
    let mut sum = cap.strength_at(a) + cap.strength_at(b);
    for i in 1..n {
        let w = if i % 2 == 1 { 4.0 } else { 2.0 };
        sum += w * cap.strength_at(a + h * i as Real);
    }
    sum * h / 3.0
}

/// Lourenço's J4D cap: f_m 10.5 MPa, G_c 5 N/mm, κ_p 0.09 mm.
fn j4d_cap() -> CompressionCap {
    CompressionCap::new(10.5e6, 5000.0).with_peak_closure(0.09e-3)
}

/// The curve: `f_m/3` at 0, `f_m` at `κ_p`, `f_m/2` at `κ_p + Δκ`, the residual `f_m/7` far
/// beyond, continuous with a continuous slope where the parabola meets the exponential; its
/// work `∫₀^κ σ_c` against Simpson's rule on the curve (to 1e-6 of it: the square root's
/// infinite slope at 0 limits Simpson), and `G_c` as the area over the residual from the peak
/// (to 1e-12).
#[test]
fn the_cap_curve_and_its_work_are_the_closed_forms() {
    for cap in [
        j4d_cap(),
        CompressionCap::new(4e6, 400.0),
        CompressionCap::new(4e6, 0.0).with_peak_closure(1e-4),
    ] {
        let (fm, kp, dk) = (cap.strength, cap.peak_closure, cap.softening_length());
        let close = |a: Real, b: Real| (a - b).abs() <= 1e-12 * fm;
        assert!(close(cap.strength_at(0.0), if kp > 0.0 { fm / 3.0 } else { fm }));
        assert!(close(cap.strength_at(kp), fm));
        assert!(close(cap.strength_at(kp + 1.0), fm / 7.0));
        if dk > 0.0 {
            assert!(close(cap.strength_at(kp + dk), fm / 2.0));
            // Slopes either side of `κ_p + Δκ`: both −f_m/Δκ.
            let d = 1e-6 * dk;
            let left = (cap.strength_at(kp + dk - d) - cap.strength_at(kp + dk - 2.0 * d)) / d;
            let right = (cap.strength_at(kp + dk + 2.0 * d) - cap.strength_at(kp + dk + d)) / d;
            assert!((left + fm / dk).abs() < 1e-4 * fm / dk, "{left}");
            assert!((right + fm / dk).abs() < 1e-4 * fm / dk, "{right}");
            // G_c: the area over the residual from the peak on.
            let far = kp + 60.0 * dk;
            let g = cap.work_to(far) - cap.work_to(kp) - fm / 7.0 * (far - kp);
            assert!((g - cap.fracture_energy).abs() < 1e-12 * cap.fracture_energy, "{g}");
        }
        let end = kp + 4.0 * dk + 1e-4;
        let mut knots = vec![0.0, 0.3 * kp, kp, kp + 0.5 * dk, kp + dk, kp + 2.0 * dk, end];
        knots.dedup();
        for w in knots.windows(2) {
            let (a, b) = (w[0], w[1]);
            if b <= a {
                continue;
            }
            let exact = cap.work_to(b) - cap.work_to(a);
            // A brittle cap jumps to its residual at `κ_p`, which Simpson would sample.
            let numeric = if dk == 0.0 && a >= kp {
                fm / 7.0 * (b - a)
            } else {
                simpson(&cap, a, b, 20_000)
            };
            assert!(
                (exact - numeric).abs() < 1e-6 * fm * (b - a),
                "{cap:?} on [{a}, {b}]: {exact} vs {numeric}"
            );
        }
    }
}

/// J4D's joint in series with the bricks (kn 62.7 N/mm³, ks 27.5 N/mm³), its cap, and a high
/// cohesion so that Coulomb stays out of the way unless a test wants it.
fn capped(cap: CompressionCap, cohesion: Real) -> MortarJoint {
    MortarJoint::builder(62.7e9, 27.5e9, 36.87)
        .tension(0.25e6, 18.0)
        .cohesion(cohesion, 125.0)
        .compression_cap(cap)
        .build()
        .unwrap()
}

/// Uniaxial crushing: a sub-contact pushed in 1e-8 m steps to 5 mm follows the curve,
/// `σ = σ_c(κ_c)` with `κ_c = −u − σ/k_n`, from the first yield at `f_m/3` (to 1e-9 of `f_m`:
/// the return's root); the law's fracture work is `A ∫σ_c dκ_c` to round-off, and all that
/// the kernel would book (work on the spring less its energy) within 1e-5 of it (the
/// trapezoidal rule). Per unit area: the same at 1 cm² and 1 dm².
#[test]
fn crushing_follows_the_curve_and_dissipates_per_unit_area() {
    let cap = j4d_cap();
    let law = capped(cap, 0.35e6);
    let mut per_area = Vec::new();
    for area in [1e-4, 1e-2] {
        let mut d = Driver::new(&law, area);
        let mut first_yield = None;
        for k in 1..=500_000 {
            let gap = -1e-8 * k as Real;
            d.step(gap, 0.0);
            let sigma = d.force.normal / area;
            let kappa = d.state.crushing;
            if kappa > 0.0 {
                first_yield.get_or_insert(sigma);
                assert!(
                    (sigma - cap.strength_at(kappa)).abs() < 1e-9 * cap.strength,
                    "step {k}: {sigma}"
                );
                assert!(
                    (kappa - (-gap - sigma / law.normal_stiffness())).abs() < 1e-12,
                    "step {k}"
                );
            } else {
                assert!(
                    (sigma - law.normal_stiffness() * -gap).abs() < 1e-6,
                    "elastic at step {k}"
                );
            }
        }
        let y = first_yield.expect("it crushed");
        assert!(
            (y - cap.strength / 3.0).abs() < 1e-3 * cap.strength,
            "first yield at {y}"
        );
        let kappa = d.state.crushing;
        let expected = area * cap.work_to(kappa);
        assert!(
            (d.consumed - expected).abs() < 1e-9 * expected,
            "{} vs {expected}",
            d.consumed
        );
        let booked = d.fracture + d.friction;
        assert!((booked - expected).abs() < 1e-5 * expected, "{booked} vs {expected}");
        assert!((d.fracture - expected).abs() < 1e-5 * expected);
        // Crushed far into the residual (e^{−20} of the exponential left): the energy over the
        // residual since the peak is G_c.
        let g =
            (d.consumed - area * (cap.work_to(cap.peak_closure) + cap.residual() * (kappa - cap.peak_closure))) / area;
        assert!((g - cap.fracture_energy).abs() < 1e-6 * cap.fracture_energy, "G_c: {g}");
        per_area.push(d.fracture / area);
    }
    assert!((per_area[0] - per_area[1]).abs() < 1e-9 * per_area[0], "{per_area:?}");
}

/// Unloading from the softening branch is on `k_n` to the crushed closure and changes no state;
/// reloading meets the cap where it was left, and the joint then carries tension from the
/// crushed position on (the bond is not the cap's).
#[test]
fn unloading_from_crushing_is_elastic() {
    let cap = CompressionCap::new(10e6, 2000.0);
    let law = capped(cap, 0.35e6);
    let mut d = Driver::new(&law, 1e-2);
    let mut gap = 0.0;
    while d.state.crushing < cap.softening_length() {
        gap -= 1e-8;
        d.step(gap, 0.0);
    }
    let (state, kappa) = (d.state, d.state.crushing);
    let top = cap.strength_at(kappa);
    let kn = law.normal_stiffness();
    // Unload by 60 % of the elastic closure, then reload to where it was.
    let back = 0.6 * top / kn;
    let (start, fracture) = (gap, d.fracture);
    for k in 1..=100 {
        d.step(start + back * k as Real / 100.0, 0.0);
        assert_eq!(d.state, state);
        let sigma = d.force.normal / 1e-2;
        assert!((sigma - kn * (-d.gap - kappa)).abs() < 1e-6 * top);
    }
    for k in (0..100).rev() {
        d.step(start + back * k as Real / 100.0, 0.0);
        assert_eq!(d.state, state);
    }
    assert_eq!(d.fracture, fracture);
    // Beyond the crushed position the bond carries tension again.
    d.step(-kappa + 1e-6, 0.0);
    assert!(d.force.normal < 0.0, "{:?}", d.force);
    assert_eq!(d.state.crushing, kappa);
}

/// One step beyond the cap under shear: the stresses end on the ellipse
/// `σ² + C_ss τ² = σ_c(κ_c)²` (to 1e-9), the plastic increments are along its normal
/// (`Δu_s^p / Δu_n^p = C_ss τ/σ`, associated flow, to 1e-9), and the crushing is the normal
/// plastic closure; with `C_ss = 0` the shear is left alone.
#[test]
fn the_cap_return_is_onto_the_ellipse_with_associated_flow() {
    for css in [LOURENCO_SHEAR_FACTOR, 2.0, 0.0] {
        let cap = CompressionCap::new(10e6, 3000.0)
            .with_peak_closure(5e-5)
            .with_shear_factor(css);
        // A cohesion that keeps the Coulomb line away.
        let law = capped(cap, 1e9);
        let (kn, ks) = (law.normal_stiffness(), law.shear_stiffness());
        for (overlap, shear) in [(1.6e-4, 2e-5), (2.5e-4, 6e-5), (6e-5, 8e-5)] {
            let mut d = Driver::new(&law, 1e-2);
            d.step(0.0, shear);
            let (tau_t, sigma_t) = (ks * shear, kn * overlap);
            d.step(-overlap, 0.0);
            let (sigma, tau, kappa) = (d.force.normal / 1e-2, d.force.shear.length() / 1e-2, d.state.crushing);
            assert!(cap.exceeded(sigma_t, tau_t, 0.0), "the trial is beyond the cap");
            assert!(kappa > 0.0);
            let sc = cap.strength_at(kappa);
            let f = (sigma * sigma + css * tau * tau).sqrt();
            assert!((f - sc).abs() < 1e-9 * cap.strength, "C_ss {css}: {f} vs {sc}");
            assert!((kappa - (sigma_t - sigma) / kn).abs() < 1e-15);
            let slip = (tau_t - tau) / ks;
            if css == 0.0 {
                assert_eq!(tau, tau_t);
            } else {
                assert!(
                    (slip / kappa - css * tau / sigma).abs() < 1e-9 * (css * tau / sigma),
                    "C_ss {css}"
                );
            }
            // Sliding when the cap's flow has a shear part, else at the strength without slip.
            let sliding = if css > 0.0 {
                JointStatus::Sliding
            } else {
                JointStatus::Elastic
            };
            assert_eq!(d.status, sliding);
            // Only the crushing: the cap's shear does not soften the cohesion.
            assert_eq!((d.state.plastic_slip, d.state.crack_opening), (0.0, 0.0));
        }
    }
}

/// Shear lowers the crushing strength: held at a shear stress `τ₀`, a joint compressed step
/// by step first yields at `σ = √(σ_c(0)² − C_ss τ₀²)` (to the step's 1e-8 m), not at `σ_c(0)`.
#[test]
fn shear_lowers_the_cap() {
    let cap = CompressionCap::new(10e6, 3000.0);
    let law = capped(cap, 1e9);
    let (kn, ks) = (law.normal_stiffness(), law.shear_stiffness());
    let tau0 = 2.5e6;
    let mut d = Driver::new(&law, 1e-2);
    d.step(0.0, tau0 / ks);
    let mut gap = 0.0;
    let mut yielded = None;
    while yielded.is_none() {
        gap -= 1e-8;
        let before = d.force.normal / 1e-2;
        d.step(gap, 0.0);
        if d.state.crushing > 0.0 {
            yielded = Some(before + kn * 1e-8);
        }
    }
    let expected = (cap.strength.powi(2) - cap.shear_factor * tau0 * tau0).sqrt();
    let got = yielded.unwrap();
    assert!((got - expected).abs() <= kn * 1e-8, "{got} vs {expected}");
    assert!(expected < 0.7 * cap.strength);
}

/// A step beyond both the Coulomb line and the cap ends within both (to 1e-9 of `f_m`), its
/// slip softening the cohesion and its closure crushing.
#[test]
fn a_step_beyond_coulomb_and_the_cap_ends_within_both() {
    let cap = CompressionCap::new(10e6, 3000.0);
    let law = capped(cap, 0.35e6);
    let (kn, ks) = (law.normal_stiffness(), law.shear_stiffness());
    let mut d = Driver::new(&law, 1e-2);
    d.step(-9e6 / kn, 0.0);
    d.step(-9.6e6 / kn, 9e6 / ks);
    let (sigma, tau) = (d.force.normal / 1e-2, d.force.shear.length() / 1e-2);
    assert!(d.state.crushing > 0.0 && d.state.plastic_slip > 0.0, "{:?}", d.state);
    let s = law.strengths(&d.state);
    assert!(
        tau <= s.cohesion + sigma * s.tan_friction + 1e-9 * cap.strength,
        "Coulomb: {tau} at {sigma}"
    );
    let f = (sigma * sigma + cap.shear_factor * tau * tau).sqrt();
    assert!(
        f <= s.compressive + 1e-9 * cap.strength,
        "cap: {f} vs {}",
        s.compressive
    );
}

/// `G_c = 0` is brittle: past the first yield the joint carries its residual `f_m/7` at once.
#[test]
fn a_brittle_cap_drops_to_its_residual() {
    let cap = CompressionCap::new(10e6, 0.0);
    let law = capped(cap, 0.35e6);
    let mut d = Driver::new(&law, 1e-2);
    let mut gap = 0.0;
    while d.state.crushing == 0.0 {
        gap -= 1e-7;
        d.step(gap, 0.0);
    }
    d.step(gap - 1e-7, 0.0);
    assert!((d.force.normal / 1e-2 - cap.residual()).abs() < 1e-9 * cap.strength);
}

/// The serialised law carries its cap (with defaults for the shear factor and the hardening),
/// and an earlier file's `compressive_strength` (a flag that changed no force) loads and is
/// dropped.
#[cfg(feature = "serde")]
#[test]
fn the_cap_round_trips_and_the_old_flag_is_dropped() {
    let law = capped(j4d_cap(), 0.35e6);
    let text = serde_json::to_string(&law).unwrap();
    assert_eq!(serde_json::from_str::<MortarJoint>(&text).unwrap(), law);
    let short = r#"{"normal_stiffness": 1e10, "shear_stiffness": 4e9, "friction_deg": 30.0,
        "compression_cap": {"strength": 5e6, "fracture_energy": 100.0}}"#;
    let read: MortarJoint = serde_json::from_str(short).unwrap();
    let cap = read.compression_cap().unwrap();
    assert_eq!((cap.shear_factor, cap.peak_closure), (LOURENCO_SHEAR_FACTOR, 0.0));
    let old = r#"{"normal_stiffness": 1e10, "shear_stiffness": 4e9, "friction_deg": 30.0,
        "compressive_strength": 8e6}"#;
    let read: MortarJoint = serde_json::from_str(old).unwrap();
    assert_eq!(read, MortarJoint::builder(1e10, 4e9, 30.0).build().unwrap());
    assert!(!serde_json::to_string(&read).unwrap().contains("compressive_strength"));
    let bad = r#"{"normal_stiffness": 1e10, "shear_stiffness": 4e9, "friction_deg": 30.0,
        "compression_cap": {"strength": -5e6, "fracture_energy": 100.0}}"#;
    let e = serde_json::from_str::<MortarJoint>(bad).unwrap_err();
    assert!(e.to_string().contains("cap_strength"), "{e}");
}
