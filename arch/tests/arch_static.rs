//! The quasi-static arch test: behaviour that must hold whatever the calibration.
//!
//! Runs five cases of `scenarios::arch_static` in parallel (about 20 s in release on 2 cores),
//! loading to 6 mm (the baseline peaks near 1 mm).

use rayon::prelude::*;
use voussoir::contact::DisplacementMode;
use voussoir_arch::scenarios::arch_static::{run, StaticCase, StaticResult};

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
        case("35", |c| c.friction_deg = 35.0),
        case("small", |c| c.mode = DisplacementMode::Small),
        case("slow", |c| c.rate = 5e-3),
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
    let (p27, p305, p35) = (r[0].peak_load, r[1].peak_load, r[2].peak_load);
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
    // With hinges only (35°), the four-hinge mechanism softens: the load falls after the peak.
    // (At this loading rate the 35° case is near the change of mechanism that slower rates show,
    // where joint 13 slides, issue 17; the softening is checked when the mechanism at the peak
    // is hinges only.)
    let end35 = r[2].curve.last().expect("samples").smoothed_load;
    if r[2].mechanism_at_peak.sliding_joints.is_empty() {
        assert!(
            end35 < 0.9 * p35,
            "35°: end load {end35} not below 90 % of the peak {p35}"
        );
    }
    // Capacity grows with the friction angle.
    assert!(p27 < p305 && p305 < p35, "peaks {p27} {p305} {p35}");
    // At 27° a joint slides at the peak (the paper: pure sliding).
    assert!(
        !r[0].mechanism_at_peak.sliding_joints.is_empty(),
        "27°: {}",
        r[0].mechanism_at_peak.describe()
    );
    // Small and large displacements give close peaks (the peak is at ~1 mm, where geometry has
    // barely changed): within 10 %.
    assert!(
        (r[3].peak_load / p305 - 1.0).abs() < 0.10,
        "small {} vs large {}",
        r[3].peak_load,
        p305
    );
    // Halving the rate from 1e-2 to 5e-3 m/s changes the quasi-static peak by less than 10 %
    // (measured: 3 %); the inertial oscillation is what remains.
    assert!(
        (r[4].peak_load / p305 - 1.0).abs() < 0.10,
        "slow {} vs {}",
        r[4].peak_load,
        p305
    );
}
