//! The quasi-static arch test: behaviour that must hold whatever the calibration.
//!
//! Runs six cases of `scenarios::arch_static` in parallel, quasi-statically (servo loading, the
//! default), loading to 6 mm (about 10 s in release on 2 cores).

use rayon::prelude::*;
use voussoir::contact::DisplacementMode;
use voussoir::math::Real;
use voussoir_arch::scenarios::arch_static::{run, ServoLoading, StaticCase, StaticResult};

fn case(label: &str, change: impl Fn(&mut StaticCase)) -> StaticCase {
    let mut c = StaticCase {
        label: label.into(),
        max_displacement: 6e-3,
        stop_fraction: 0.0,
        ..StaticCase::baseline()
    };
    change(&mut c);
    c
}

#[test]
fn static_arch_behaves_like_an_arch() {
    let cases = [
        case("27", |c| c.friction_deg = 27.0),
        case("30.5", |_| {}),
        case("40", |c| c.friction_deg = 40.0),
        case("small", |c| c.mode = DisplacementMode::Small),
        case("30.5 refined", |_| {}).refined(),
        StaticCase {
            max_displacement: 6e-3,
            stop_fraction: 0.0,
            ..StaticCase::rate_study(5e-2)
        },
    ];
    let r: Vec<StaticResult> = cases
        .par_iter()
        .map(|c| run(c, None, |_| Ok(())).expect("run"))
        .collect();
    for x in &r {
        println!(
            "{:>6}: peak {:.3} kN at {:.2} mm (raw {:.3}); at peak {}; end load {:.3} kN",
            x.case.label,
            x.peak_load / 1e3,
            x.displacement_at_peak * 1e3,
            x.raw_peak_load / 1e3,
            x.mechanism_at_peak.describe(),
            x.curve.last().map_or(0.0, |s| s.smoothed_load / 1e3)
        );
    }
    let (p27, p305, p40) = (r[0].peak_load, r[1].peak_load, r[2].peak_load);
    // The test: 2.71 kN. The model's parameters are the paper's, not fitted to this number, so
    // the tolerance is that of the issue (±20 %); measured: 2.79 kN (+3.0 %).
    assert!((p305 / 2710.0 - 1.0).abs() < 0.20, "baseline peak {p305} N vs 2710 N");
    // The load rises from zero to (nearly) its peak at a small displacement: the arch is stiff
    // before the mechanism forms. (Where the mechanism slides, the load then stays on a plateau
    // within round-off-sensitive wiggles of 2 %, so the displacement at the very peak is not a
    // robust measure; the displacement at which 95 % of it is first reached is.)
    for x in &r {
        assert!(
            x.curve[0].load < 0.2 * x.peak_load,
            "{}: load starts at {}",
            x.case.label,
            x.curve[0].load
        );
        let near_peak = x
            .curve
            .iter()
            .find(|s| s.smoothed_load >= 0.95 * x.peak_load)
            .map_or(f64::INFINITY, |s| s.displacement);
        assert!(
            near_peak < 5e-3,
            "{}: 95 % of the peak first at {} m",
            x.case.label,
            near_peak
        );
    }
    // With hinges only (40°), the four-hinge mechanism softens: the load falls after the peak
    // (measured: to 50 % of it by 4.4 mm).
    assert!(
        r[2].mechanism_at_peak.sliding_joints.is_empty(),
        "40°: {}",
        r[2].mechanism_at_peak.describe()
    );
    let end40 = r[2].curve.last().expect("samples").load;
    assert!(
        end40 < 0.9 * p40,
        "40°: end load {end40} not below 90 % of the peak {p40}"
    );
    // Capacity grows with the friction angle.
    assert!(p27 < p305 && p305 < p40, "peaks {p27} {p305} {p40}");
    // At 27° a joint slides at the peak (the paper: pure sliding).
    assert!(
        !r[0].mechanism_at_peak.sliding_joints.is_empty(),
        "27°: {}",
        r[0].mechanism_at_peak.describe()
    );
    // Small and large displacements give close peaks (the load reaches its plateau at 1–2 mm,
    // where geometry has barely changed): within 5 % (measured over 12 mm: 0.6 %).
    assert!(
        (r[3].peak_load / p305 - 1.0).abs() < 0.05,
        "small {} vs large {}",
        r[3].peak_load,
        p305
    );
    // Quasi-static: half the servo's increment and threshold move the peak by less than the
    // 3 % `arch_static` holds every default case to (measured over 12 mm: 0.7 %).
    assert!(
        (r[4].peak_load / p305 - 1.0).abs() < 0.03,
        "refined {} vs {}",
        r[4].peak_load,
        p305
    );
    // Loaded at 5e-2 m/s (the rate the paper ran its studies at), inertia more than doubles
    // the peak (measured: 6.0 kN); the servo's answer is what a slow test measures.
    assert!(r[5].peak_load > 1.5 * p305, "5e-2 m/s: {} vs {}", r[5].peak_load, p305);
}

/// **The hinge-governed capacity does not depend on the joints' discretisation.** The
/// reference arch at φ = 35° (four hinges, no sliding: the limit analysis gives 5.853 kN) at 15
/// sub-contacts per edge (the paper's) and at the refined 29, through
/// [`SubContactDensity::check_convergence`]. With sub-contacts at points the peak moved by 3 %
/// (5685 / 5519 N at 15 / 30, 5960 N at 5).
///
/// The capacity compared is the peak of the load averaged over 0.2 mm of plate travel (ten
/// settled states): the settled states themselves scatter by ±0.6 % about the curve (the
/// servo's 1e-3 unbalanced-force ratio), so that the peak of single states is the largest of
/// that scatter, and a change of round-off alone (summing the same terms in another order)
/// moved it by 0.5 % at 29 per edge (5453.6 → 5481.0 N). Averaged, the same change moves it by
/// 0.16 % (5431.4 → 5440.2 N), and refining moves it by 0.05 % (measured 5437.7 / 5440.2 N at
/// 15 / 29 per edge). The tolerance, 0.5 %, is a sixth of what the point rule gave and three
/// times that round-off scatter.
#[test]
fn hinge_capacity_converges_with_the_subcontact_density() {
    use voussoir::geometry::SubContactDensity;
    let base = case("35", |c| {
        c.friction_deg = 35.0;
        c.max_displacement = 8e-3;
        c.stop_fraction = 0.5;
        c.smoothing_window = 2e-4;
    });
    let check = SubContactDensity::PerEdge(base.per_edge)
        .check_convergence(|density| {
            let SubContactDensity::PerEdge(per_edge) = density else {
                unreachable!("per-edge densities")
            };
            let r = run(
                &StaticCase {
                    per_edge,
                    ..base.clone()
                },
                None,
                |_| Ok(()),
            )?;
            println!(
                "{per_edge} per edge: peak {:.1} N at {:.2} mm",
                r.peak_load,
                r.displacement_at_peak * 1e3
            );
            Ok(r.peak_load)
        })
        .expect("runs");
    println!(
        "peak {:.1} N, refined {:.1} N: {:.3} %",
        check.value,
        check.refined,
        100.0 * check.relative_change()
    );
    assert!(check.converged(0.005), "{check:?}");
}

/// **What the joint stiffness governs** (`docs/theory.md` §4.1, the README's "Choosing kn, ks
/// and the sub-contact density"): the capacity the sliding of joints sets does not depend on
/// kn, the capacity hinges set does. The reference arch at kn 4 GPa/m (the paper's) and 40 GPa/m,
/// the servo's increment and the averaging window scaled by 1/kn (the displacements are):
/// measured 2.781 / 2.795 kN at φ 30.5° (+0.5 %) and 5.438 / 6.031 kN at φ 35° (+11 %). A soft
/// hinge's compressed zone takes a fraction of the joint's depth from the thrust's lever arm;
/// a sliding joint's limit is a ratio of forces. Tolerances: 2 % for the sliding case (three
/// times the scatter of single settled states); more than 5 % for the hinges (half the
/// measured change).
#[test]
fn hinge_governed_capacity_depends_on_kn_and_sliding_governed_does_not() {
    let peak = |friction_deg: Real, kn: Real| {
        let scale = 4e9 / kn;
        let c = case("kn", |c| {
            c.friction_deg = friction_deg;
            c.kn = kn;
            c.ks = 0.4 * kn;
            c.max_displacement = 8e-3 * scale;
            c.stop_fraction = 0.5;
            c.smoothing_window = 2e-4 * scale;
            c.servo = Some(ServoLoading {
                increment: ServoLoading::DEFAULT.increment * scale,
                ..ServoLoading::DEFAULT
            });
        });
        let r = run(&c, None, |_| Ok(())).expect("run");
        println!(
            "φ {friction_deg}° kn {kn:e}: {:.1} N at {:.3} mm",
            r.peak_load,
            r.displacement_at_peak * 1e3
        );
        r.peak_load
    };
    let (sliding_soft, sliding_stiff) = (peak(30.5, 4e9), peak(30.5, 4e10));
    assert!(
        (sliding_stiff / sliding_soft - 1.0).abs() < 0.02,
        "{sliding_soft} → {sliding_stiff}"
    );
    let (hinges_soft, hinges_stiff) = (peak(35.0, 4e9), peak(35.0, 4e10));
    assert!(hinges_stiff > 1.05 * hinges_soft, "{hinges_soft} → {hinges_stiff}");
}

/// A loading plate that slides off instead of loading the arch is an error, not a capacity of
/// zero. Free to slide horizontally (as in the test), the plate rests on voussoir 5's sloping
/// extrados (20.7°) through its joint's shear springs; with ks 0.4 GPa/m (ks/kn 0.1) they let it
/// slide off as the servo lowers it: 3 mm of travel at zero load, which the run reported as a
/// peak of 0.3 N.
#[test]
fn a_plate_that_slides_off_is_an_error_not_a_zero_capacity() {
    let c = case("soft shear", |c| c.ks = 0.4e9);
    let err = run(&c, None, |_| Ok(())).expect_err("the plate slides off");
    let message = err.to_string();
    assert!(
        message.contains("slid off") && message.contains("plate's own weight"),
        "{message}"
    );
}

/// **The test's mechanism softens; the one the model forms at a uniform 30.5° does not**
/// (`docs/benchmarks/arch-static.md`, "The test's mechanism, forced"). With φ 30.5° on every
/// joint the arch's cheapest mechanism slides at joints 4, 5 and 13 (its limit analysis: 2.755
/// kN), and the load stays on that plateau to 12 mm (measured 2.79 kN at the peak, −1 % at 12
/// mm). With joints 5 and 13 at 40° (`joint_friction`) only joint 4 can slide, and the arch
/// forms the test's mechanism, three rotational hinges and one sliding joint under the load.
/// That mechanism carries more (measured 5.09 kN) and loses it with geometry, as the test did
/// (−35 % by 12 mm): measured 2.17 kN at 12 mm, −57 %.
///
/// Bounds: the forced mechanism ends below 65 % of its peak (the test's own loss; measured
/// 43 %), the uniform one above 95 % (measured 99 %; the settled states scatter by ±0.7 %
/// along a sliding plateau).
#[test]
fn the_tests_mechanism_softens_and_the_sliding_one_does_not() {
    let to_12mm = |c: &mut StaticCase| c.max_displacement = 12e-3;
    let cases = [
        case("uniform 30.5°", to_12mm),
        case("joints 5 and 13 at 40°", |c| {
            to_12mm(c);
            c.joint_friction = [(5, 40.0), (13, 40.0)].into();
        }),
    ];
    let r: Vec<StaticResult> = cases
        .par_iter()
        .map(|c| run(c, None, |_| Ok(())).expect("run"))
        .collect();
    fn end(x: &StaticResult) -> &voussoir_arch::scenarios::arch_static::Sample {
        x.curve.last().expect("samples")
    }
    for x in &r {
        println!(
            "{}: peak {:.3} kN at {:.2} mm, {}; {:.3} kN at {:.2} mm; limit analysis {:.3} kN, {}",
            x.case.label,
            x.peak_load / 1e3,
            x.displacement_at_peak * 1e3,
            x.mechanism_at_peak.describe(),
            end(x).load / 1e3,
            end(x).displacement * 1e3,
            x.limit.load / 1e3,
            x.limit.mechanism.describe()
        );
        assert!(end(x).displacement > 11.9e-3, "{}: stopped early", x.case.label);
    }
    let (uniform, forced) = (&r[0], &r[1]);
    assert!(
        forced.mechanism_at_peak.sliding_joints == [4] && forced.limit.mechanism.sliding_joints == [4],
        "forced: {} (limit analysis: {})",
        forced.mechanism_at_peak.describe(),
        forced.limit.mechanism.describe()
    );
    assert!(
        forced.mechanism_at_peak.hinges.len() >= 3,
        "forced: {}",
        forced.mechanism_at_peak.describe()
    );
    assert!(
        end(forced).load < 0.65 * forced.peak_load,
        "forced: {} N at 12 mm from a peak of {} N",
        end(forced).load,
        forced.peak_load
    );
    for joint in [5, 13] {
        assert!(
            uniform.mechanism_at_end.sliding_joints.contains(&joint),
            "uniform: {}",
            uniform.mechanism_at_end.describe()
        );
    }
    assert!(
        end(uniform).load > 0.95 * uniform.peak_load,
        "uniform: {} N at 12 mm from a peak of {} N",
        end(uniform).load,
        uniform.peak_load
    );
}
