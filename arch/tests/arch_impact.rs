//! The impact tests: behaviour that must hold whatever the calibration (a few seconds in release).

use rayon::prelude::*;
use voussoir::block::Block;
use voussoir::geometry::NodeRule;
use voussoir_arch::scenarios::arch_impact::{
    build, run, setups, ImpactCase, ImpactResult, ImpactorGuide, Release, GRAVITY,
};

/// Two cases run side by side, without frames.
fn run_both(cases: [ImpactCase; 2]) -> Vec<ImpactResult> {
    cases
        .par_iter()
        .map(|c| run(c, None, |_| Ok(())).expect("run"))
        .collect()
}

fn pick(name: &str) -> ImpactCase {
    ImpactCase::baseline(setups().into_iter().find(|s| s.name == name).expect("setup"))
}

#[test]
fn impact_energy_momentum_and_outcomes() {
    // The heaviest test, and a light drop: the M60 impactor from 5 cm (30 J, a quarter of the
    // lightest test); and the heaviest with the seat variant.
    let mut light = pick("M60H20");
    light.setup.height = 0.05;
    light.label = "M60H5".into();
    let seat = ImpactCase {
        guide: ImpactorGuide::SeatConstrained,
        duration: 0.3,
        ..pick("M80H45")
    };
    let cases = [pick("M80H45"), light, seat];
    let r: Vec<ImpactResult> = cases
        .par_iter()
        .map(|c| run(c, None, |_| Ok(())).expect("run"))
        .collect();
    for x in &r {
        let case = &x.case;
        // Released at the speed of the fall at the measured gap, the impactor strikes at √(2gH):
        // the speed is read at the step before the first contact force, at most g·dt slower
        // (g·dt ≈ 1e-3 m/s at dt ≈ 1e-4 s).
        let expected = (2.0 * GRAVITY * case.drop_height()).sqrt();
        println!(
            "{} ({:?}): gap {:.3} mm, released at {:.4} m/s, strikes at {:.4} m/s vs √(2gH) {expected:.4} at {:.4} s; \
             momentum {:.2} kg·m/s; energy {:.1} J; max disp {:.1} mm; collapsed {}; |energy error| ≤ {:.3} J",
            case.label,
            case.guide,
            x.release_gap * 1e3,
            x.release_velocity,
            x.contact_speed,
            x.contact_time,
            case.setup.mass * x.contact_speed,
            0.5 * case.setup.mass * x.contact_speed.powi(2),
            x.max_disp * 1e3,
            x.collapsed,
            x.max_energy_error
        );
        assert!(
            x.contact_time > 0.0 && x.contact_time < 0.01,
            "contact at {} s",
            x.contact_time
        );
        assert!(
            (x.contact_speed - expected).abs() <= GRAVITY * x.contact_dt + 1e-6,
            "{} vs {expected} (dt at contact {})",
            x.contact_speed,
            x.contact_dt
        );
        // Energy is neither created nor lost beyond the work done: |kinetic + elastic + dissipated
        // − input| within 1 % of the impact energy over the run, collapse included.
        assert!(
            x.max_energy_error < 0.01 * x.kinetic_energy,
            "energy error {} J for an impact of {} J",
            x.max_energy_error,
            x.kinetic_energy
        );
    }
    // The response grows with the impact energy (357 J against 30 J), and the light drop leaves
    // the arch standing. Whether the heavy tests collapse is the benchmark's comparison with the
    // experiment (`docs/benchmarks/arch-impact.md`), not a property to assert here. The
    // first-impact peak of a linear system struck by a mass grows as √E (`δ = v √(m/k)` =
    // `√(2E/k)`): the ring's, which hinges, within a factor 2 of that (measured 3.69 against
    // √(357.6/29.9) = 3.46). The later maxima come from the ring falling back after its rebound
    // and are not ordered so simply (`docs/benchmarks/arch-impact.md`).
    let expected = (r[0].kinetic_energy / r[1].kinetic_energy).sqrt();
    let ratio = r[0].first_peak_disp / r[1].first_peak_disp;
    println!(
        "first-impact peaks: heavy {:.2} mm, light {:.2} mm, ratio {ratio:.2} (√E ratio {expected:.2})",
        r[0].first_peak_disp * 1e3,
        r[1].first_peak_disp * 1e3
    );
    assert!(
        ratio > 0.5 * expected && ratio < 2.0 * expected,
        "first-impact peaks: heavy {} m vs light {} m (ratio {ratio}, √E ratio {expected})",
        r[0].first_peak_disp,
        r[1].first_peak_disp
    );
    assert!(!r[1].collapsed, "the light drop (M60H5) must leave the arch standing");
}

/// **A collapse driven beyond the tests' drops keeps its books with integrated nodes** (issue 43,
/// item 6): M75H20 dropped from 75 and 100 mm above the test's height (sloped base). As the
/// ring collapses, loaded hinges open past the face angle tolerance and turn into node contacts;
/// with point nodes that change of kind made 7.12 J of the 204 J blow at +75 mm (3.5 %), with
/// the nodes' springs integrated over the surface they stand for the books close within
/// 0.07–0.08 J (measured), against the 1 % every impact run is held to. (Integrated, the +75 mm
/// drop stands at 35 mm; the +100 mm one collapses.)
#[test]
fn a_collapse_beyond_the_tests_drops_keeps_its_books_with_integrated_nodes() {
    let case = |offset: f64| ImpactCase {
        node_rule: NodeRule::Integrated,
        height_offset: offset,
        ..pick("M75H20")
    };
    let r = run_both([case(0.075), case(0.1)]);
    for x in &r {
        println!(
            "M75H20 +{:.0} mm, integrated nodes: max disp {:.1} mm, collapsed {}, |energy error| ≤ {:.3} J of {:.1} J",
            x.case.height_offset * 1e3,
            x.max_disp * 1e3,
            x.collapsed,
            x.max_energy_error,
            x.kinetic_energy
        );
        assert!(
            x.max_energy_error < 0.01 * x.kinetic_energy,
            "+{} m: energy error {} J for an impact of {} J",
            x.case.height_offset,
            x.max_energy_error,
            x.kinetic_energy
        );
    }
    assert!(r[1].collapsed, "the +100 mm drop collapses the ring");
}

/// The default impactor is a free block (no constrained degree of freedom) held in place only by
/// the contacts with the fixed frame blocks: it stays within the clearance (plus the spring
/// deflection of the guide joint), and the frictionless guide pushes along the normal of the
/// impactor's face that a frame block's edge presses: horizontally, but for the impactor's tilt.
#[test]
fn frame_guided_impactor_is_free_and_guided_by_contacts() {
    // Under both node rules: integrated, the shear plane of a node on the other block's edge
    // was once round-off's choice, and the impactor drifted 7.3 µm across the width.
    for rule in NodeRule::ALL {
        frame_guided(rule);
    }
}

fn frame_guided(node_rule: NodeRule) {
    let case = ImpactCase {
        duration: 0.3,
        node_rule,
        ..pick("M60H30")
    };
    assert_eq!(case.guide, ImpactorGuide::Frame, "the frame guide is the default");
    let m = build(&case).expect("build");
    assert!(m.seat.is_none());
    assert_eq!(m.frame.len(), 4, "two frame blocks along the span, two across");
    for &f in &m.frame {
        assert!(m.model.blocks()[f.index()].fixity().is_fixed());
    }
    let (impactor, frame) = (m.impactor, m.frame.clone());
    let x0 = m.model.blocks()[impactor.index()].state().pose.translation;
    // (free throughout, largest |Fx|, largest |Fy| of the guide on the impactor, largest |Δx|)
    let mut seen = (true, 0.0f64, 0.0f64, 0.0f64);
    let r = run(&case, Some(case.sample_interval), |model| {
        let b = &model.blocks()[impactor.index()];
        let s = &mut seen;
        s.0 &= b.fixity().is_free();
        for &f in &frame {
            if let Some(c) = model.contact_between(impactor, f) {
                // Force on the frame block (the later one); on the impactor it is the opposite.
                let force = c.resultant();
                s.1 = s.1.max(force.x.abs());
                s.2 = s.2.max(force.y.abs());
            }
        }
        s.3 = s.3.max((b.state().pose.translation.x - x0.x).abs());
        Ok(())
    })
    .expect("run");
    let (free, fx, fy, dx) = seen;
    let clearance = case.guide_clearance;
    println!(
        "{node_rule}: impactor free: {free}; guide force |Fx| ≤ {fx:.0} N, |Fy| ≤ {fy:.2} N; drift x ≤ {:.3} mm (sampled by run: {:.3} mm), \
         z {:.2e} m; rotation ≤ {:.2e} rad; clearance {:.2} mm",
        dx * 1e3,
        r.max_impactor_drift[0] * 1e3,
        r.max_impactor_drift[1],
        r.max_impactor_rotation,
        clearance * 1e3
    );
    assert!(
        free,
        "the impactor must have no constrained degree of freedom after release"
    );
    // The sloped extrados pushes the impactor along the span: the guide must take it.
    assert!(fx > 1e3, "the guide carried no horizontal force ({fx} N)");
    // Frictionless guide: the vertical force is the normal's tilt with the impactor's rotation.
    assert!(
        fy <= 0.02 * fx,
        "frictionless guide pushed vertically: {fy} N against {fx} N"
    );
    // Within the clearance, plus the deflection of the guide joint (at most 1 mm here: a force
    // of tens of kN on a 4 GPa/m joint of a few hundredths of a square metre).
    assert!(dx <= clearance + 1e-3, "drift {dx} m beyond clearance {clearance} m");
    assert!(
        r.max_impactor_drift[1] < 1e-6,
        "drift across the width {}",
        r.max_impactor_drift[1]
    );
}

/// Releasing the impactor just above the arch at the speed of the fall gives the same first
/// impact as dropping it from the full height.
#[test]
fn release_just_above_equals_full_drop() {
    let above = ImpactCase {
        duration: 0.03,
        ..pick("M60H20")
    };
    // The same 30 ms after contact: the fall from H takes √(2H/g) more.
    let full = ImpactCase {
        release: Release::FullHeight,
        duration: above.duration + (2.0 * above.drop_height() / GRAVITY).sqrt(),
        ..above.clone()
    };
    let r = run_both([above, full]);
    let (a, f) = (&r[0], &r[1]);
    println!(
        "just above: strikes at {:.4} m/s, first peak {:.3} mm, max over 30 ms {:.3} mm; full height: released {:.4} m above, \
         strikes at {:.4} m/s after {:.4} s, first peak {:.3} mm, max {:.3} mm",
        a.contact_speed,
        a.first_peak_disp * 1e3,
        a.max_disp * 1e3,
        f.release_gap,
        f.contact_speed,
        f.contact_time,
        f.first_peak_disp * 1e3,
        f.max_disp * 1e3
    );
    // A free fall of H: √(2H/g) (the impactor does not touch the frame on the way down).
    let fall = (2.0 * f.release_gap / GRAVITY).sqrt();
    assert!(
        (f.contact_time - fall).abs() < 2.0 * f.contact_dt,
        "{} vs {fall} (time step at contact {})",
        f.contact_time,
        f.contact_dt
    );
    assert!((f.contact_speed / a.contact_speed - 1.0).abs() < 1e-3);
    assert!((f.first_peak_disp / a.first_peak_disp - 1.0).abs() < 0.02);
    assert!((f.max_disp / a.max_disp - 1.0).abs() < 0.02);
}

/// A settled state perturbed at round-off (gravity changed by 1e-12 of itself while the arch
/// settles, restored before the release) gives the same first impact to far better than the
/// drop heights' spread; a perturbation beyond round-off is refused.
#[test]
fn a_settled_state_perturbed_at_round_off_gives_the_same_first_impact() {
    let base = ImpactCase {
        duration: 0.03,
        ..pick("M60H20")
    };
    let perturbed = ImpactCase {
        settle_perturbation: 1e-12,
        ..base.clone()
    };
    let r = run_both([base, perturbed]);
    let (a, b) = (&r[0], &r[1]);
    println!(
        "first peak {:.6} / {:.6} mm, impact energy {} / {} J",
        a.first_peak_disp * 1e3,
        b.first_peak_disp * 1e3,
        a.kinetic_energy,
        b.kinetic_energy
    );
    assert_eq!(a.kinetic_energy, b.kinetic_energy);
    assert!((a.first_peak_disp / b.first_peak_disp - 1.0).abs() < 1e-6);
    let beyond = ImpactCase {
        settle_perturbation: 1e-5,
        ..pick("M60H20")
    };
    let e = beyond.validate().expect_err("refused");
    assert!(e.to_string().contains("settle_perturbation"), "{e}");
}

/// The choices' names are written once (`named_choices!`): each parses from its name in any
/// case, and an unknown name lists them; the command line offers the same names.
#[test]
fn choices_parse_from_their_one_set_of_names() {
    use voussoir_arch::scenarios::arch_impact::{ImpactorBase, Release};
    for g in ImpactorGuide::ALL {
        assert_eq!(g.name().parse::<ImpactorGuide>(), Ok(*g));
        assert_eq!(g.name().to_uppercase().parse::<ImpactorGuide>(), Ok(*g));
    }
    for b in ImpactorBase::ALL {
        assert_eq!(b.name().parse::<ImpactorBase>(), Ok(*b));
    }
    for r in Release::ALL {
        assert_eq!(r.name().parse::<Release>(), Ok(*r));
    }
    assert_eq!(
        "rope".parse::<ImpactorGuide>().unwrap_err(),
        "guide \"rope\": expected \"frame\" or \"seat\""
    );
    assert_eq!(Release::JustAbove.name(), "above");
}

/// **A loaded node contact turns back into a joint without moving the books** (issue 43, item 6;
/// `docs/theory.md` §6): M60H20's central run with integrated nodes, the balance
/// `accounted − input` read after every step. When a loaded node contact between two blocks
/// turns back into a face joint at a re-detection, the cells take the nodes' forces, with the
/// shear scaled down where the cells' springs would store more than the nodes' did. Unscaled,
/// the cells stored 0.494 J where the nodes stored 0.341 J, and the cells' first step booked the
/// difference as friction (measured: the balance moved by up to 0.275 J in one such step). The
/// step of the turn-back and the one after it are checked; every other step of the run sets the
/// yardstick. Scaled (measured: 13 loaded node contacts turn back), the worst checked step moves
/// the balance by 0.023 J, the worst other step by 0.012 J. The bound: a checked step moves it
/// by at most four times the worst other step and by less than 0.05 % of the impact energy
/// (0.061 J), 2.6 times the measured worst and under a quarter of the unscaled handover's.
#[test]
fn integrated_node_contacts_turn_back_into_joints_within_the_books() {
    use std::collections::HashSet;
    use voussoir::geometry::ContactKind;
    // Sampled at every step: a sample interval far below the step, and the frame callback
    // (which the run calls at its samples) due at every one of them.
    let case = ImpactCase {
        node_rule: NodeRule::Integrated,
        sample_interval: 1e-9,
        ..pick("M60H20")
    };
    // The loaded node contacts after the last step: those the next re-detection may turn back
    // (`ContactPair::may_turn_back` asks for a normal force).
    let mut loaded_nodes: HashSet<(usize, usize)> = HashSet::new();
    let mut balance_before: Option<f64> = None;
    // Steps left to check after a turn-back: its own and the cells' first after it.
    let mut checking = 0_u32;
    let (mut turn_backs, mut worst_checked, mut worst_other) = (0usize, 0.0_f64, 0.0_f64);
    let r = run(&case, Some(1e-12), |m| {
        let balance = m.energies().balance_error();
        let mut loaded = HashSet::new();
        let mut turned = false;
        for c in m.contacts() {
            let (a, b) = c.blocks();
            let pair = (a.index(), b.index());
            match c.kind() {
                ContactKind::Nodes if c.normal_force() > 0.0 => {
                    loaded.insert(pair);
                }
                ContactKind::FaceFace { .. } if loaded_nodes.contains(&pair) => turned = true,
                _ => {}
            }
        }
        if turned {
            turn_backs += 1;
            checking = 2;
        }
        if let Some(before) = balance_before {
            let moved = (balance - before).abs();
            if checking > 0 {
                worst_checked = worst_checked.max(moved);
            } else {
                worst_other = worst_other.max(moved);
            }
        }
        checking = checking.saturating_sub(1);
        balance_before = Some(balance);
        loaded_nodes = loaded;
        Ok(())
    })
    .expect("run");
    println!(
        "M60H20, integrated: {turn_backs} loaded node contacts turned back, worst checked step {worst_checked:.4} J; \
         other steps {worst_other:.4} J; books within {:.3} J of {:.1} J",
        r.max_energy_error, r.kinetic_energy
    );
    assert!(
        turn_backs > 0,
        "the run must turn loaded node contacts back into joints to test them"
    );
    assert!(
        worst_checked <= 4.0 * worst_other && worst_checked < 5e-4 * r.kinetic_energy,
        "a turn-back moved the books by {worst_checked} J (other steps at most {worst_other} J, impact {} J)",
        r.kinetic_energy
    );
}
