//! Issue 43 on the reference arch with its loading plate (`scenarios::arch_static`;
//! `docs/benchmarks/collapse.md`).
//!
//! * **The bound.** At φ 35° the rigid-block limit analysis of the arch (5.853 kN) is a sliding
//!   mechanism (joints 4, 5 and 13, no hinges), associative: by Radenković's theorem it bounds
//!   the DEM's non-associative capacity from above. The stiff-joint DEM read above it (+3 % in
//!   the issue, +0.9 % at 400 GPa/m today) at the servo's default threshold: its "settled"
//!   states carry out-of-balance forces (up to 4 N a block), and the limit mechanism turns
//!   them into load, because it moves the right half of the arch 9 times faster than the plate.
//!   The virtual work of the DEM's state on the limit mechanism accounts for the excess to
//!   round-off; with a tighter threshold the excess is gone. The limit analysis already has the
//!   DEM's plate: the same block, in contact with the extrados, free to slide and turn, loaded
//!   at its centroid — as the DEM's plate is, whose servo prescribes its vertical velocity only.
//! * **The soft joint's loss.** At the paper's kn (4 GPa/m) the arch carries 5.47 kN at φ 35°
//!   and 40°, where the rigid analysis gives 5.85 and 17.7 kN: the limit analysis of the blocks
//!   as they stand at the DEM's peak, with the joints at the hinges shrunk by the Winkler offset
//!   `c/3` of their compressed strips, gives the DEM's capacity within 1 %.

#[path = "../../tests/support/planar_limit.rs"]
mod planar_limit;

use planar_limit::{turn, PlanarAnswer, PlanarLimit};
use rayon::prelude::*;
use voussoir::analysis::{classify_joints, JointRef, MechanismCriteria};
use voussoir::block::{Block, BlockId};
use voussoir::build::arch::{Arch, ArchSpec};
use voussoir::math::{Real, Vector};
use voussoir::model::Model;
use voussoir_arch::scenarios::arch_static::{build, limit_analysis, run, ServoLoading, StaticCase};

const PLATE: BlockId = BlockId(15);
const LOADED: BlockId = BlockId(5);

fn case(friction_deg: Real, kn: Real, travel: Real, increment: Real, ratio: Real) -> StaticCase {
    StaticCase {
        label: format!("φ {friction_deg}° kn {kn:e} ratio {ratio:e}"),
        friction_deg,
        kn,
        ks: 0.4 * kn,
        max_displacement: travel,
        servo: Some(ServoLoading {
            increment,
            max_unbalanced_ratio: ratio,
        }),
        ..StaticCase::baseline()
    }
}

/// The DEM's load on voussoir 5 at a settled state, the limit analysis of that state, and the
/// virtual work of the DEM's forces on the limit mechanism.
#[derive(Debug, Clone, Copy, Default)]
struct Audit {
    /// The plate's force on voussoir 5 (N).
    load: Real,
    /// The limit analysis of the blocks as they stand (N, the same quantity).
    limit: Real,
    /// Power of the blocks' out-of-balance forces and moments on the limit mechanism (W, the
    /// plate moving down at 1 m/s; the plate's vertical force is the servo's, not a residual).
    residual: Real,
    /// Power of the DEM's contact forces on the mechanism's relative velocities, each
    /// sub-contact's force where it acts (W): the dissipation of the DEM's forces in the limit
    /// mechanism, non-negative at every contact when the forces lie in the analysis's cones.
    contacts: Real,
    /// The least power of one contact (W).
    least_contact: Real,
    /// The fastest block speed of the mechanism (m/s per m/s of plate travel).
    fastest: Real,
}

/// Virtual work: for each block, equilibrium residual · mechanism velocity, summed, equals the
/// work of gravity, of the servo and of the contact forces on the mechanism; the analysis's
/// multiplier is minus the work of the dead loads, so
/// `load − limit = residual − contacts` (the plate's weight cancels).
fn audit(m: &Model, joints: &[JointRef]) -> Audit {
    let load = m.contact_between(PLATE, LOADED).map_or(0.0, |c| c.resultant().y);
    let (limit, mechanism) = limit_analysis(m, PLATE, joints).expect("a limit analysis of the state");
    let g = m.parameters().gravity;
    let mut a = Audit {
        load,
        limit: limit.load,
        least_contact: Real::INFINITY,
        ..Audit::default()
    };
    for (k, b) in m.blocks().iter().enumerate() {
        let id = BlockId(k as u32);
        let (v, w) = mechanism.block_velocity(id).expect("a block of the model");
        a.fastest = a.fastest.max(v.length());
        if b.fixity().is_fixed() {
            continue;
        }
        let wrench = m.contact_wrench(id).unwrap();
        let f = wrench.force + g * b.mass_properties().mass;
        a.residual += if id == PLATE {
            f.x * v.x + wrench.moment.z * w.z
        } else {
            f.dot(v) + wrench.moment.dot(w)
        };
    }
    for c in m.contacts() {
        let (ba, bb) = c.blocks();
        let relative = |p: Vector| mechanism.point_velocity(bb, p).unwrap() - mechanism.point_velocity(ba, p).unwrap();
        let power: Real = c
            .subcontacts()
            .map(|s| {
                (s.axes().normal * s.normal_force()).dot(relative(s.normal_force_point()))
                    + s.shear_force().dot(relative(s.point()))
            })
            .sum();
        a.contacts += power;
        a.least_contact = a.least_contact.min(power);
    }
    a
}

/// The audit of the state of highest load of a run of `c`.
fn audit_at_peak(c: &StaticCase) -> Audit {
    let joints = Arch::new(&ArchSpec::reference(c.width)).unwrap().joint_refs();
    let mut peak = Audit::default();
    run(c, Some(c.servo.unwrap().increment), |m| {
        let load = m.contact_between(PLATE, LOADED).map_or(0.0, |c| c.resultant().y);
        if load > peak.load {
            peak = audit(m, &joints);
        }
        Ok(())
    })
    .unwrap();
    peak
}

/// **The reference arch at φ 35° does not exceed its associative bound** (deliverable 1,
/// issue 43): stiff joints (kn 400 GPa/m, 100× the paper's), the plate advancing 2 µm at a
/// time over 0.6 mm, at the servo's default threshold (1e-3) and at 1e-4.
///
/// At every state the DEM's contact forces lie within the limit analysis's cones and polygons
/// — each contact's power on the limit mechanism is non-negative (to round-off) — so the DEM's
/// load exceeds the limit load by at most the power of its out-of-balance forces, by the
/// virtual-work identity `load − limit = residual − contacts`, checked to 1e-6 of the load
/// (round-off: it is the sum of the blocks' equilibrium equations). Measured (2026-11-28):
/// 1e-3: 5898 N against the limit analysis of that state, 5854 N (+0.75 %); the out-of-balance
/// forces do 189 W on the mechanism (the right half of the arch moves at 9 m/s per m/s of plate
/// travel in it), the contact forces 145 W; 1e-4: 5665 N, 3.2 % below its 5855 N, the
/// out-of-balance forces 2 W, the contact forces 192 W — the DEM's non-dilatant sliding joints
/// do not follow the associative mechanism, and the bound is not reached. About 4.5 s.
#[test]
fn reference_arch_stays_below_its_associative_bound() {
    let cases = [case(35.0, 4e11, 6e-4, 2e-6, 1e-3), case(35.0, 4e11, 6e-4, 2e-6, 1e-4)];
    let audits: Vec<Audit> = cases.par_iter().map(audit_at_peak).collect();
    for (c, a) in cases.iter().zip(&audits) {
        println!(
            "{}: peak {:.1} N, limit analysis of that state {:.1} N ({:+.2} %); power of the out-of-balance forces \
             {:.2} W, of the contact forces {:.2} W (least contact {:.3e} W); fastest block {:.2} m/s",
            c.label,
            a.load,
            a.limit,
            100.0 * (a.load / a.limit - 1.0),
            a.residual,
            a.contacts,
            a.least_contact,
            a.fastest
        );
        let scale = a.load * a.fastest;
        assert!(
            a.least_contact > -1e-6 * scale,
            "{}: a contact outside the cones: {a:?}",
            c.label
        );
        assert!(
            ((a.load - a.limit) - (a.residual - a.contacts)).abs() < 1e-6 * a.load,
            "{}: virtual work {a:?}",
            c.label
        );
        assert!(
            a.load - a.limit <= a.residual.max(0.0) + 1e-6 * a.load,
            "{}: {a:?}",
            c.label
        );
    }
    // With the tighter threshold the out-of-balance forces are too small to carry the state
    // past the bound.
    assert!(audits[1].load < audits[1].limit, "{:?}", audits[1]);
}

/// One joint at the DEM's peak: its compression resultant's distance from the nearer end of its
/// contact segment, the Winkler offset `c/3`, `c = √(2N/(kn d φ))`, from its force and its
/// relative rotation, and its segment's ends (intrados first).
#[derive(Debug)]
struct JointReading {
    inside: Real,
    winkler: Real,
    ends: [Vector; 2],
    /// The joint's area-weighted mean accumulated slip (m), as [`classify_joints`] reads it.
    slip: Real,
}

fn read_joints(m: &Model, pl: &PlanarLimit, arch: &Arch, kn: Real) -> Vec<JointReading> {
    let (states, _) = classify_joints(m, &arch.joint_refs(), &MechanismCriteria::default());
    (0..=arch.spec.voussoirs)
        .map(|j| {
            let (a, b) = (BlockId(j as u32), BlockId(j as u32 + 1));
            let c = m.contact_between(a, b).expect("every joint in contact");
            let seg = pl
                .segments
                .iter()
                .find(|s| s.blocks == (a, b))
                .expect("a segment per joint");
            let intrados = arch.joints[j].intrados + m.block(a).unwrap().displacement_of(arch.joints[j].intrados);
            let flat = |v: Vector| Vector::new(v.x, v.y, 0.0);
            let ends = if (seg.ends[0] - flat(intrados)).length() < (seg.ends[1] - flat(intrados)).length() {
                seg.ends
            } else {
                [seg.ends[1], seg.ends[0]]
            };
            let p = flat(c.application_point().expect("a compressed joint"));
            let along = (ends[1] - ends[0]).normalize();
            let s = (p - ends[0]).dot(along);
            let phi = (turn(m, b) - turn(m, a)).abs();
            JointReading {
                inside: s.min((ends[1] - ends[0]).length() - s),
                winkler: (2.0 * c.normal_force() / (kn * arch.spec.width * phi)).sqrt() / 3.0,
                ends,
                slip: states
                    .iter()
                    .find(|s| s.joint == j)
                    .expect("every joint classified")
                    .slip,
            }
        })
        .collect()
}

/// The hinges of a planar mechanism (joint, about its intrados end).
fn mechanism_hinges(
    m: &Model,
    pl: &PlanarLimit,
    answer: &PlanarAnswer,
    readings: &[JointReading],
) -> Vec<(usize, bool)> {
    let velocity = |k: usize, p: Vector| {
        let [vx, vy, w] = answer.velocities[k];
        let c = m.blocks()[k].state().pose.translation;
        Vector::new(vx - w * (p.y - c.y), vy + w * (p.x - c.x), 0.0)
    };
    let openings: Vec<(usize, [Real; 2])> = readings
        .iter()
        .enumerate()
        .map(|(j, r)| {
            let s = pl
                .segments
                .iter()
                .find(|s| s.blocks == (BlockId(j as u32), BlockId(j as u32 + 1)))
                .unwrap();
            let open = |e: Vector| s.normal.dot(velocity(j + 1, e) - velocity(j, e));
            (j, [open(r.ends[0]), open(r.ends[1])])
        })
        .collect();
    let scale = openings.iter().flat_map(|o| o.1).fold(0.0, |a: Real, b| a.max(b.abs()));
    openings
        .into_iter()
        .filter(|o| (o.1[0] - o.1[1]).abs() > 1e-3 * scale)
        .map(|(j, open)| (j, open[0] < open[1]))
        .collect()
}

/// The planar limit load (N on voussoir 5, with the plate's weight) of `pl` with the joints at
/// the hinges of its mechanism shrunk by their Winkler offsets, the hinge mechanism of joints
/// that do not slide (friction 45°) as the first guess, repeated while the mechanism moves to
/// joints not yet shrunk; and the shrunk hinges.
fn winkler_limit(
    m: &Model,
    mut pl: PlanarLimit,
    readings: &[JointReading],
    plate_weight: Real,
) -> (Real, Vec<(usize, bool)>) {
    let live = [(PLATE, m.blocks()[PLATE.index()].state().pose.translation, -Vector::Y)];
    let mut locked = pl.clone();
    for s in &mut locked.segments {
        s.friction = 1.0;
    }
    let mut hinges = mechanism_hinges(m, &locked, &locked.solve(&live), readings);
    let mut shrunk: Vec<(usize, bool)> = Vec::new();
    let mut load = Real::NAN;
    for _ in 0..6 {
        let new: Vec<(usize, bool)> = hinges.iter().filter(|h| !shrunk.contains(h)).copied().collect();
        if new.is_empty() {
            break;
        }
        for (j, intrados) in new {
            let r = &readings[j];
            pl.segment_mut(BlockId(j as u32), BlockId(j as u32 + 1))
                .unwrap()
                .shrink_at(if intrados { r.ends[0] } else { r.ends[1] }, r.winkler);
            shrunk.push((j, intrados));
        }
        let answer = pl.solve(&live);
        load = answer.multiplier + plate_weight;
        hinges = mechanism_hinges(m, &pl, &answer, readings);
    }
    (load, shrunk)
}

/// **The soft joint's loss on the reference arch** (deliverable 2, issue 43): at the paper's kn
/// (4 GPa/m), φ 35° (the case) and 40° (hinges only), loaded by the servo at a tight
/// threshold (3e-5, 20 µm) to 2.8 mm:
///
/// 1. every joint partly open at the peak (resultant outside the middle third) has its
///    resultant `c/3` inside the end of its contact, `c = √(2N/(kn d φ))`, to 2 % plus the
///    joint's mean accumulated slip (measured: within 0.3 % at every such joint at 40° and
///    35° but joint 5 at 35°, the loaded voussoir's joint, which slipped 0.39 mm on average:
///    2.9 %, 0.19 mm inside the closed form. A joint that slipped has its
///    cells follow the overlap only at re-detections, `docs/theory.md` §2.2, and how far
///    they lag moves with round-off: 1.8 % on the build before the time step's area moments
///    came from the anchor plane; the other joints slipped 0.005–0.4 mm on average);
/// 2. the planar limit analysis of the blocks as they stand at the peak (checked against the
///    library's to 1e-6), with the joints at its mechanism's hinges shrunk by those `c/3`, gives
///    the DEM's peak within 1 % (measured: φ 35°: 5455 N against 5474 N, −0.34 %; φ 40°:
///    5466 N against 5474 N, −0.15 %; hinges 0i 5e 9i 13e shrunk by 30–34, 7, 7 and 8 mm);
/// 3. neither effect alone does: the rigid analysis of the deformed blocks (P-Δ alone: 5911 and
///    10300 N) and the offsets on the arch as built (5676 and 7600 N) both stay more than 2 %
///    (twice the tolerance of the combined) above the peak.
///
/// About 6 s (both cases in parallel).
#[test]
fn reference_arch_soft_joint_loss_is_winkler_with_p_delta() {
    let cases = [case(35.0, 4e9, 2.8e-3, 2e-5, 3e-5), case(40.0, 4e9, 2.8e-3, 2e-5, 3e-5)];
    cases.par_iter().for_each(|c| {
        let arch = Arch::new(&ArchSpec::reference(c.width)).unwrap();
        let mut peak = (0.0, String::new());
        let result = run(c, Some(c.servo.unwrap().increment), |m| {
            let load = m.contact_between(PLATE, LOADED).map_or(0.0, |c| c.resultant().y);
            if load > peak.0 {
                peak = (load, m.to_checkpoint_string()?);
            }
            Ok(())
        })
        .unwrap();
        let m: Model = Model::from_checkpoint_str(&peak.1).unwrap();
        let plate_weight = m.blocks()[PLATE.index()].mass_properties().mass * m.parameters().gravity.length();
        let free_plate = [(PLATE, [true, true, true])];
        let deformed = PlanarLimit::from_model(&m, &free_plate);
        let readings = read_joints(&m, &deformed, &arch, c.kn);
        let mut worst = (0, 0.0);
        for (j, r) in readings.iter().enumerate() {
            if r.inside < arch.spec.thickness / 3.0 {
                let error = (r.inside / r.winkler - 1.0).abs();
                if error > worst.1 {
                    worst = (j, error);
                }
                // A joint that slipped has its cells lag the overlap between re-detections
                // (`docs/theory.md` §2.2): its resultant may sit off the closed form by up to
                // how far the overlap moved, the joint's slip.
                let allowed = 0.02 * r.winkler + r.slip;
                assert!((r.inside - r.winkler).abs() < allowed, "{}: joint {j}: {r:?}", c.label);
            }
        }
        println!(
            "{}: partly open joints {:?}; resultant against c/3: worst {:.2} % at joint {}",
            c.label,
            readings
                .iter()
                .enumerate()
                .filter(|(_, r)| r.inside < arch.spec.thickness / 3.0)
                .map(|(j, r)| format!(
                    "{j}:{:.2}/{:.2}mm slip {:.3}mm",
                    r.inside * 1e3,
                    r.winkler * 1e3,
                    r.slip * 1e3
                ))
                .collect::<Vec<_>>(),
            100.0 * worst.1,
            worst.0
        );
        let live = [(PLATE, m.blocks()[PLATE.index()].state().pose.translation, -Vector::Y)];
        let rigid_deformed = deformed.solve(&live).multiplier + plate_weight;
        // The library's programme on the same blocks, without its dead-load check: whether the
        // dead loads alone are carried by the contact polygons the blocks have at the peak of
        // a hinge mechanism moves with round-off. At φ 40° they were on the build before joints
        // open in part were stepped as a whole, and are not on this one (printed below); a
        // change of the cells' clipping had flipped it too (`docs/performance.md`). The
        // multiplier is what this test compares.
        let library = {
            use voussoir::analysis::limit::{LimitOptions, LimitProblem, LiveLoad};
            use voussoir::block::{Dof, Fixity};
            let mut problem = LimitProblem::from_model(&m).unwrap();
            problem
                .set_fixity(
                    PLATE,
                    Fixity {
                        translation: [Dof::Free, Dof::Free, Dof::Fixed],
                        rotation: [Dof::Fixed, Dof::Fixed, Dof::Free],
                    },
                )
                .unwrap();
            let live = LiveLoad {
                block: PLATE,
                point: m.blocks()[PLATE.index()].state().pose.translation,
                force: -Vector::Y,
            };
            let options = LimitOptions {
                check_dead_load: false,
                ..LimitOptions::default()
            };
            let dead = problem.dead_load(&options).unwrap();
            println!(
                "{}: at the peak the dead loads alone are carried: {}",
                c.label, dead.carried
            );
            problem.solve(&[live], &options).unwrap().multiplier + plate_weight
        };
        assert!(
            (rigid_deformed / library - 1.0).abs() < 1e-6,
            "planar {rigid_deformed} vs library {library}"
        );
        let (winkler_p_delta, hinges) = winkler_limit(&m, deformed, &readings, plate_weight);
        let mut built = build(c).unwrap();
        built.model.step().unwrap();
        let as_built = PlanarLimit::from_model(&built.model, &free_plate);
        let (winkler_alone, _) = winkler_limit(&built.model, as_built, &readings, plate_weight);
        let dem = result.peak_load;
        println!(
            "{}: DEM peak {dem:.1} N at {:.2} mm (rigid limit analysis of the arch {:.1} N); limit analysis of the \
             blocks at the peak {rigid_deformed:.1} N, with the Winkler offsets at hinges {:?} {winkler_p_delta:.1} N \
             ({:+.2} %); the offsets on the arch as built {winkler_alone:.1} N",
            c.label,
            result.displacement_at_peak * 1e3,
            result.limit.load,
            hinges
                .iter()
                .map(|&(j, i)| format!("{j}{}:{:.1}mm", if i { "i" } else { "e" }, readings[j].winkler * 1e3))
                .collect::<Vec<_>>(),
            100.0 * (winkler_p_delta / dem - 1.0)
        );
        assert!((winkler_p_delta / dem - 1.0).abs() < 0.01, "{}", c.label);
        assert!(rigid_deformed > 1.02 * dem && winkler_alone > 1.02 * dem, "{}", c.label);
    });
}
