//! Issue 43: **hinges at their rigid capacity**, and **the soft joint's loss explained**
//! (`docs/benchmarks/collapse.md`).
//!
//! A joint of linear no-tension springs integrated exactly over its cells is a Winkler joint
//! (`docs/theory.md` §4.1): at a hinge its compressed strip has a width `c = √(2N/(k_n d φ))`
//! (`N` the joint's force, `d` its depth, `φ` its relative rotation) and its resultant sits `c/3`
//! inside the edge. The rigid limit analysis turns its hinges about the edge, so a DEM capacity
//! that hinges govern lies below it by the lever arms `c/3` and by the arch's deformation (P-Δ),
//! and converges to it as `c ∝ k_n^{-1/3}`. Here, on two arches:
//!
//! * the thin semicircle of the issue under a point load (20 voussoirs, ring 0.15 m) and a
//!   thicker semicircle under gravity tilted step by step (12 voussoirs, ring 0.25 m): the DEM
//!   capacity at 100× and 800× the paper's 4 GPa/m, extrapolated by the `k_n^{-1/3}` law
//!   (`λ_∞ = 2 λ(8 k_n) − λ(k_n)`), meets the library's limit analysis within 1 %, and stays
//!   below it at each stiffness;
//! * at the paper's 4 GPa/m, the thin semicircle's capacity (0.545 of the rigid one) is the
//!   limit analysis of its deformed blocks with the joints at the mechanism's hinges shrunk by
//!   their Winkler offsets `c/3`: the Winkler joint with P-Δ, and nothing else.
//!
//! The reference arch with its loading plate is in `arch/tests/collapse.rs`.
//!
//! **How a capacity is measured.** Force control, as the newcomer did: the load (or the
//! tilt) is raised from the last state that stood, and a state stands when
//! `run_to_equilibrium` reaches an unbalanced-force ratio of [`SETTLED`]; it falls when the
//! watched point moves beyond ten times its displacement in the last standing state plus 2 mm
//! (a hinge mechanism near its peak creeps for a long time before it accelerates). The capacity
//! is bracketed by bisection to [`RESOLUTION`] of the limit load, and its estimate is the
//! bracket's middle. The ratio matters: a collapsing mechanism passes through states whose
//! out-of-balance forces are small, and the thin semicircle at 4e11 Pa/m "stands" up to 0.966
//! of the limit load at 1e-3, 0.922 at 1e-4, 0.917 at 1e-5 and 0.916 at 1e-6 (measured); 1e-5
//! is within 0.1 % of the converged value. Two sub-contacts per edge: with the cells integrated
//! exactly a joint's normal force is exact at any density (measured: the same bracket at 2, 3
//! and 5 per edge), and the shear springs do not govern these mechanisms.

use std::ops::Range;

#[path = "support/planar_limit.rs"]
mod planar_limit;

use planar_limit::{turn, PlanarLimit};
use voussoir::analysis::limit::{LimitOptions, LimitProblem, LiveLoad};
use voussoir::build::arch::{AbutmentShape, Arch, ArchSpec};
use voussoir::prelude::*;

/// The paper's normal joint stiffness (Pa/m).
const PAPER_KN: Real = 4e9;
/// Unbalanced-force ratio of a standing state.
const SETTLED: Real = 1e-5;
/// Width of the final bracket of a capacity, as a fraction of the limit load.
const RESOLUTION: Real = 2e-3;
/// Friction angle of the joints (degrees).
const PHI: Real = 35.0;

/// The thin semicircle of issue 43: 20 voussoirs, intrados radius 1 m, ring 0.15 m, depth
/// 0.5 m, 2600 kg/m³.
fn thin_semicircle() -> ArchSpec {
    semicircle(0.15, 20)
}

/// A semicircle of intrados radius 1 m, depth 0.5 m, 2600 kg/m³, on the default abutments.
fn semicircle(thickness: Real, voussoirs: usize) -> ArchSpec {
    ArchSpec {
        span: 2.0,
        rise: 1.0,
        thickness,
        width: 0.5,
        voussoirs,
        density: 2600.0,
        abutment: AbutmentShape::default(),
        voussoir_material: MaterialId(0),
        abutment_material: MaterialId(0),
    }
}

/// The arch's blocks with dry Coulomb joints (φ 35°, ks = 0.4 kn), gravity along −y, local
/// damping 0.8, two sub-contacts per edge.
fn arch_model(arch: &Arch, kn: Real) -> Model {
    let params = ModelParameters {
        gravity: Vector::new(0.0, -9.81, 0.0),
        contact: voussoir::geometry::ContactParameters {
            density: SubContactDensity::PerEdge(2),
            ..Default::default()
        },
        ..ModelParameters::default()
    };
    let mut model: Model = Model::new(params).unwrap();
    model
        .set_joint_law(
            MaterialId(0),
            MaterialId(0),
            CoulombSlip::dry(kn, 0.4 * kn, PHI).unwrap(),
        )
        .unwrap();
    model.set_damping(Damping::Local { alpha: 0.8 }).unwrap();
    for b in &arch.blocks {
        model.add_block(b.clone()).unwrap();
    }
    model
}

/// A capacity bracketed by force control: the multiplier in `lo..hi`, and the last state that
/// stood (at `lo`) as a checkpoint.
struct Capacity {
    bracket: Range<Real>,
    stood: String,
}

impl Capacity {
    fn estimate(&self) -> Real {
        0.5 * (self.bracket.start + self.bracket.end)
    }
}

/// Brackets the largest multiplier that `model` (settled) carries when `apply` sets it, from
/// `0..hi`, each trial starting from the last state that stood; `watch` is a block and a point
/// of it (as built) whose displacement tells a fall.
fn capacity(
    model: &Model,
    apply: impl Fn(&mut Model, Real),
    watch: (BlockId, Vector),
    hi: Real,
    resolution: Real,
) -> Capacity {
    let moved = |m: &Model| m.block(watch.0).unwrap().displacement_of(watch.1).length();
    let (mut stood, mut lo, mut hi, mut d_lo) = (model.to_checkpoint_string().unwrap(), 0.0, hi, moved(model));
    while hi - lo > resolution {
        let mid = 0.5 * (lo + hi);
        let mut m: Model = Model::from_checkpoint_str(&stood).unwrap();
        apply(&mut m, mid);
        let fallen = 10.0 * d_lo + 5e-3;
        let mut stands = false;
        for _ in 0..500 {
            if m.run_to_equilibrium(SETTLED, 2_000).is_ok() {
                stands = true;
                break;
            }
            if moved(&m) > fallen {
                break;
            }
        }
        if stands {
            (lo, d_lo, stood) = (mid, moved(&m), m.to_checkpoint_string().unwrap());
        } else {
            hi = mid;
        }
    }
    Capacity { bracket: lo..hi, stood }
}

/// The point of the extrados over the quarter span (x = −0.5 m, mid-depth) and its voussoir.
fn quarter_span_point(arch: &Arch) -> (BlockId, Vector) {
    let x = -0.25 * arch.spec.span;
    (1..=arch.spec.voussoirs)
        .find_map(|k| {
            let (e0, e1) = (arch.joints[k - 1].extrados, arch.joints[k].extrados);
            ((e0.x - x) * (e1.x - x) <= 0.0)
                .then(|| (arch.voussoir_id(k), e0 + (e1 - e0) * ((x - e0.x) / (e1.x - e0.x))))
        })
        .expect("a voussoir over the quarter span")
}

/// A vertical force `p` (N, downwards) on `block` whose line passes through `point`, as a force
/// and its moment about the block's current centroid.
fn point_load(m: &mut Model, block: BlockId, point: Vector, p: Real) {
    let c = m.block(block).unwrap().state().pose.translation;
    let force = Vector::new(0.0, -p, 0.0);
    m.set_load(
        block,
        Wrench {
            force,
            moment: (point - c).cross(force),
        },
    )
    .unwrap();
}

/// The library's limit analysis of `model` under a vertical unit load through `point`.
fn limit_load(model: &Model, block: BlockId, point: Vector) -> Real {
    LimitProblem::from_model(model)
        .unwrap()
        .solve(
            &[LiveLoad {
                block,
                point,
                force: -Vector::Y,
            }],
            &LimitOptions::default(),
        )
        .unwrap()
        .multiplier
}

/// The capacity of the thin semicircle under the quarter-span point load at `kn`, its limit
/// load (the library's, on the arch as built) and the model as built (stepped once).
fn semicircle_capacity(kn: Real) -> (Capacity, Real, Model) {
    let arch = Arch::new(&thin_semicircle()).unwrap();
    let (block, point) = quarter_span_point(&arch);
    let mut built = arch_model(&arch, kn);
    built.step().unwrap();
    let limit = limit_load(&built, block, point);
    let mut model = arch_model(&arch, kn);
    model.run_to_equilibrium(SETTLED, 1_000_000).unwrap();
    let cap = capacity(
        &model,
        |m, p| point_load(m, block, point, p),
        (block, point),
        1.03 * limit,
        RESOLUTION * limit,
    );
    (cap, limit, built)
}

/// Checks the convergence of two capacities measured at `kn` and `8 kn` to `limit`, and prints
/// them: each below the limit (the rigid analysis bounds the DEM from above), the deficit
/// halved by the eightfold stiffness (the `kn^{-1/3}` law), and the law's extrapolation
/// `2 λ(8 kn) − λ(kn)` within 1 % of the limit.
///
/// Tolerance: each estimate is within half the bracket (0.1 % of the limit) of the force-
/// controlled capacity at the ratio 1e-5, itself within 0.1 % of the converged one, so the
/// extrapolation carries up to 3 × 0.2 % = 0.6 %; the law's next term (measured: the deficit
/// times kn^{1/3} falls by 3.2 % from 4e10 to 3.2e11 Pa/m and by 1.6 % from 4e11 to 3.2e12 on the
/// semicircle) adds about 0.1 %. 1 % is the criterion and covers both.
fn check_convergence(what: &str, soft: &Capacity, stiff: &Capacity, limit: Real) {
    let (l1, l8) = (soft.estimate(), stiff.estimate());
    let extrapolated = 2.0 * l8 - l1;
    let (d1, d8) = (1.0 - l1 / limit, 1.0 - l8 / limit);
    println!(
        "{what}: limit analysis {limit:.5}; DEM {l1:.5} ({:.4}) at kn, {l8:.5} ({:.4}) at 8 kn; deficits {:.4} / {:.4} \
         (ratio {:.3}, kn^(-1/3) law: 2); extrapolated {extrapolated:.5} ({:+.2} %)",
        l1 / limit,
        l8 / limit,
        d1,
        d8,
        d1 / d8,
        100.0 * (extrapolated / limit - 1.0)
    );
    assert!(
        soft.bracket.end < limit && stiff.bracket.end < limit,
        "{what}: a DEM capacity above the limit load"
    );
    assert!(l1 < l8, "{what}: the stiffer joints carry less");
    // The law itself: the deficit halves when kn grows eightfold. Each deficit carries half a
    // bracket (0.1 % of the limit): 3.6 % on the ratio for the semicircle, 9 % for the tilted
    // arch (its deficits are 3.3 % and 1.7 %), and the law's next term about 3 %: 15 %.
    assert!((d1 / d8 / 2.0 - 1.0).abs() < 0.15, "{what}: deficits {d1} and {d8}");
    assert!(
        (extrapolated / limit - 1.0).abs() < 0.01,
        "{what}: extrapolated {extrapolated} against the limit load {limit}"
    );
}

/// **Deliverable 1 on the thin semicircle**: a point load at the extrados over the quarter span
/// (the newcomer's case). The library's limit analysis of the arch as built: 1098.8 N
/// (hinges 3i 8e 15i 20e; the 1086 N is that of the arch settled with the paper's soft
/// joints). Measured (2026-11-28): 1007.4 N (0.917) at 4e11 Pa/m, 1053.8 N (0.959) at 3.2e12,
/// deficits 0.0832 and 0.0409 (ratio 2.03), extrapolated 1100.2 N (+0.13 %). About 10 s
/// (the stiffer run; both run in parallel).
#[test]
fn thin_semicircle_hinges_converge_to_the_rigid_limit() {
    let kn = 100.0 * PAPER_KN;
    let ((soft, limit, _), (stiff, _, _)) = rayon::join(|| semicircle_capacity(kn), || semicircle_capacity(8.0 * kn));
    check_convergence("thin semicircle, point load (N)", &soft, &stiff, limit);
}

/// Sets the gravity tilted by `atan(lambda)` (towards +x), of the same magnitude.
fn tilt(m: &mut Model, lambda: Real) {
    let a = lambda.atan();
    let mut p = *m.parameters();
    p.gravity = 9.81 * Vector::new(a.sin(), -a.cos(), 0.0);
    m.set_parameters(p).unwrap();
}

/// The critical tilt `tan α` of the thick semicircle, and its limit (the library's limit
/// analysis of the arch as built, the live load the voussoirs' weights along +x: a rigid
/// no-tension joint without cohesion carries tilted gravity `α` exactly as it carries vertical
/// gravity with horizontal forces `tan α` times the weights).
fn tilt_capacity(kn: Real) -> (Capacity, Real) {
    let arch = Arch::new(&semicircle(0.25, 12)).unwrap();
    let mut built = arch_model(&arch, kn);
    built.step().unwrap();
    let live: Vec<LiveLoad> = (1..=arch.spec.voussoirs)
        .map(|k| {
            let b = built.block(arch.voussoir_id(k)).unwrap();
            LiveLoad {
                block: arch.voussoir_id(k),
                point: b.state().pose.translation,
                force: Vector::X * (b.mass_properties().mass * 9.81),
            }
        })
        .collect();
    let limit = LimitProblem::from_model(&built)
        .unwrap()
        .solve(&live, &LimitOptions::default())
        .unwrap()
        .multiplier;
    let mut model = arch_model(&arch, kn);
    model.run_to_equilibrium(SETTLED, 1_000_000).unwrap();
    let k = arch.spec.voussoirs / 2;
    let crown = (arch.voussoir_id(k), arch.extrados_midpoint(k));
    let cap = capacity(&model, tilt, crown, 1.03 * limit, RESOLUTION * limit);
    (cap, limit)
}

/// **Deliverable 1 on an arch under tilted gravity**: a semicircle with a ring of 0.25 m
/// (intrados radius 1 m, 12 voussoirs), gravity tilted step by step, each tilt settled from the
/// last standing state (local damping 0.8), against the library's limit analysis of the same
/// blocks under the tilted gravity: `tan α` = 0.34518 (19.04°, hinges 1i 5e 9i 12e).
/// Measured (2026-11-28): 0.9671 of it at 4e11 Pa/m, 0.9832 at 3.2e12 (deficits 0.0329 and
/// 0.0168, ratio 1.96), extrapolated 0.9993 (−0.07 %); 0.848 at the paper's 4e9. About 5 s.
#[test]
fn tilted_arch_hinges_converge_to_the_rigid_limit() {
    let kn = 100.0 * PAPER_KN;
    let ((soft, limit), (stiff, _)) = rayon::join(|| tilt_capacity(kn), || tilt_capacity(8.0 * kn));
    check_convergence("semicircle t/R 0.25, tilted gravity (tan α)", &soft, &stiff, limit);
}

/// One joint of a ring at a settled state: its force, the distance of its resultant from the
/// nearer edge and which edge, and the Winkler offset `c/3` from its force and rotation.
#[derive(Debug)]
struct JointReading {
    normal_force: Real,
    /// Distance of the compression resultant from the nearer edge (m).
    inside: Real,
    /// The nearer edge is the intrados.
    intrados: bool,
    /// `c/3` with `c = √(2N/(kn d φ))`.
    winkler: Real,
    /// The edges' current positions (intrados, extrados).
    edges: (Vector, Vector),
}

fn read_joints(m: &Model, arch: &Arch, kn: Real) -> Vec<JointReading> {
    (0..=arch.spec.voussoirs)
        .map(|j| {
            let (a, b) = (BlockId(j as u32), BlockId(j as u32 + 1));
            let c = m.contact_between(a, b).expect("every joint of the ring in contact");
            let left = m.block(a).unwrap();
            let joint = arch.joints[j];
            let edges = (
                joint.intrados + left.displacement_of(joint.intrados),
                joint.extrados + left.displacement_of(joint.extrados),
            );
            let along = (edges.1 - edges.0).normalize();
            let s = (c.application_point().expect("a compressed joint") - edges.0).dot(along);
            let t = arch.spec.thickness;
            let phi = (turn(m, b) - turn(m, a)).abs();
            JointReading {
                normal_force: c.normal_force(),
                inside: s.min(t - s),
                intrados: s < 0.5 * t,
                winkler: (2.0 * c.normal_force() / (kn * arch.spec.width * phi)).sqrt() / 3.0,
                edges,
            }
        })
        .collect()
}

/// The hinges of a planar mechanism: the joints of the ring whose two ends open at rates that
/// differ (by more than 1e-3 of the largest), each with the end that opens less (true: the
/// intrados).
fn mechanism_hinges(
    m: &Model,
    pl: &PlanarLimit,
    answer: &planar_limit::PlanarAnswer,
    readings: &[JointReading],
) -> Vec<(usize, bool)> {
    let velocity = |k: usize, p: Vector| {
        let [vx, vy, w] = answer.velocities[k];
        let c = m.blocks()[k].state().pose.translation;
        Vector::new(vx - w * (p.y - c.y), vy + w * (p.x - c.x), 0.0)
    };
    let openings: Vec<(usize, [Vector; 2], [Real; 2])> = (0..readings.len())
        .map(|j| {
            let s = pl
                .segments
                .iter()
                .find(|s| s.blocks == (BlockId(j as u32), BlockId(j as u32 + 1)))
                .expect("a segment per joint");
            let open = |e: Vector| s.normal.dot(velocity(j + 1, e) - velocity(j, e));
            (j, s.ends, [open(s.ends[0]), open(s.ends[1])])
        })
        .collect();
    let scale = openings.iter().flat_map(|o| o.2).fold(0.0, |a: Real, b| a.max(b.abs()));
    openings
        .into_iter()
        .filter(|o| (o.2[0] - o.2[1]).abs() > 1e-3 * scale)
        .map(|(j, ends, open)| {
            let end = if open[0] < open[1] { ends[0] } else { ends[1] };
            let flat = |v: Vector| Vector::new(v.x, v.y, 0.0);
            let (i, e) = readings[j].edges;
            (j, (end - flat(i)).length() < (end - flat(e)).length())
        })
        .collect()
}

/// The planar limit analysis of `pl` with the joints at the hinges of its mechanism shrunk by
/// their Winkler offsets, repeated while the mechanism moves to joints not yet shrunk: the
/// multiplier and the shrunk hinges.
fn shrunk_at_hinges(
    m: &Model,
    mut pl: PlanarLimit,
    seed: Vec<(usize, bool)>,
    readings: &[JointReading],
    live: &[(BlockId, Vector, Vector)],
) -> (Real, Vec<(usize, bool)>) {
    let mut shrunk: Vec<(usize, bool)> = Vec::new();
    let mut hinges = seed;
    let mut multiplier = Real::NAN;
    for _ in 0..6 {
        let new: Vec<(usize, bool)> = hinges.iter().filter(|h| !shrunk.contains(h)).copied().collect();
        if new.is_empty() {
            break;
        }
        for (j, intrados) in new {
            let r = &readings[j];
            let edge = if intrados { r.edges.0 } else { r.edges.1 };
            pl.segment_mut(BlockId(j as u32), BlockId(j as u32 + 1))
                .expect("a segment per joint")
                .shrink_at(edge, r.winkler);
            shrunk.push((j, intrados));
        }
        let answer = pl.solve(live);
        multiplier = answer.multiplier;
        hinges = mechanism_hinges(m, &pl, &answer, readings);
    }
    (multiplier, shrunk)
}

/// **Deliverable 2 on the thin semicircle**: at the paper's kn (4 GPa/m) the point load's
/// capacity is 0.545 of the rigid limit load, and that loss is the Winkler joint with P-Δ:
///
/// 1. at the last state that stood, every joint whose resultant lies outside the middle third
///    (partly open) has it `c/3` inside its edge, `c = √(2N/(kn d φ))` from its force and its
///    relative rotation, to 1 % (measured: within 0.07 % at all 16 such joints; the relation
///    is exact for rigid faces on no-tension springs, the residual is the settling's);
/// 2. the planar limit analysis of the blocks as they stand there (deformed), with the load
///    where the DEM's acts and the joints at its mechanism's hinges shrunk by those `c/3`,
///    gives the DEM's capacity within 1 % (measured: 595.6 N against 598.5 N, −0.48 %; hinges
///    3i 8e 16i 20e shrunk by 11.6, 10.1, 5.1 and 6.3 mm);
/// 3. neither alone does: the deformed blocks with rigid hinges carry 966 N (P-Δ alone) and
///    the blocks as built with the offsets 708 N (the offsets alone); both are asserted more
///    than 2 % (twice the tolerance of the combined) above the capacity.
///
/// The planar programme is checked against the library's on the same model (to 1e-6).
/// About 1 s.
#[test]
fn thin_semicircle_soft_joint_loss_is_winkler_with_p_delta() {
    let spec = thin_semicircle();
    let arch = Arch::new(&spec).unwrap();
    let (block, point) = quarter_span_point(&arch);
    let kn = PAPER_KN;
    let (cap, rigid, built) = semicircle_capacity(kn);
    let dem = cap.estimate();
    let mut m: Model = Model::from_checkpoint_str(&cap.stood).unwrap();
    // The DEM's load: a force and a constant moment about the centroid, a vertical line at
    // x = c − M/P (it moves with the centroid, not with the block's turn).
    let load = m.block(block).unwrap().load();
    let centroid = m.block(block).unwrap().state().pose.translation;
    let line = Vector::new(centroid.x - load.moment.z / (-load.force.y), centroid.y, centroid.z);
    m.set_load(block, Wrench::default()).unwrap();

    // 1. The Winkler joint.
    let readings = read_joints(&m, &arch, kn);
    let mut partly_open = 0;
    for (j, r) in readings.iter().enumerate() {
        if r.inside < spec.thickness / 3.0 {
            partly_open += 1;
            println!(
                "joint {j:2}: N {:7.1} N, resultant {:6.3} mm inside the {}, Winkler c/3 {:6.3} mm",
                r.normal_force,
                r.inside * 1e3,
                if r.intrados { "intrados" } else { "extrados" },
                r.winkler * 1e3
            );
            assert!((r.inside / r.winkler - 1.0).abs() < 0.01, "joint {j}: {r:?}");
        }
    }
    assert!(
        partly_open >= 4,
        "a mechanism needs four hinges; {partly_open} joints are partly open"
    );

    // 2. The limit analysis of the deformed blocks with the Winkler offsets at the hinges.
    let deformed = PlanarLimit::from_model(&m, &[]);
    let material_point = point + m.block(block).unwrap().displacement_of(point);
    let library = limit_load(&m, block, material_point);
    let planar = deformed.solve(&[(block, material_point, -Vector::Y)]).multiplier;
    assert!(
        (planar / library - 1.0).abs() < 1e-6,
        "planar {planar} vs library {library}"
    );
    let live = [(block, line, -Vector::Y)];
    let rigid_hinges = deformed.solve(&live);
    let seed = mechanism_hinges(&m, &deformed, &rigid_hinges, &readings);
    let (winkler_p_delta, hinges) = shrunk_at_hinges(&m, deformed, seed, &readings, &live);

    // 3. Each effect alone.
    let as_built = PlanarLimit::from_model(&built, &[]);
    let seed = mechanism_hinges(&built, &as_built, &as_built.solve(&live), &readings);
    let (winkler_alone, _) = shrunk_at_hinges(&built, as_built, seed, &readings, &live);
    println!(
        "thin semicircle at kn {kn:e}: DEM {dem:.1} N ({:.4} of the rigid {rigid:.1} N); limit analysis of the deformed \
         blocks {:.1} N, with the Winkler offsets at hinges {:?} {winkler_p_delta:.1} N ({:+.2} %); offsets on the \
         blocks as built {winkler_alone:.1} N",
        dem / rigid,
        rigid_hinges.multiplier,
        hinges
            .iter()
            .map(|&(j, i)| format!("{j}{}:{:.1}mm", if i { "i" } else { "e" }, readings[j].winkler * 1e3))
            .collect::<Vec<_>>(),
        100.0 * (winkler_p_delta / dem - 1.0)
    );
    assert!((winkler_p_delta / dem - 1.0).abs() < 0.01);
    assert!(rigid_hinges.multiplier > 1.02 * dem && winkler_alone > 1.02 * dem);
}
