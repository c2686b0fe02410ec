//! Limit analysis (`voussoir::analysis::limit`) against closed forms: a block pushed up an
//! incline, a pier pushed at its top (overturning or sliding), a symmetric wedge in a V, the
//! minimum thickness of a semicircular arch, and the dead-load question alone (a block on an
//! incline stands while the slope is below the friction angle). Derivations in
//! `docs/theory.md` §9.
//!
//! Tolerances: the programme is solved by an interior-point method to Clarabel's default
//! tolerances (gap and feasibility 1e-8, relative to the programme scaled by the blocks' weight),
//! so a multiplier is good to ~1e-7 of the weight; the geometry is exact (coincident faces). The
//! tests allow 1e-6 of the weight, except the arch (see there).
#![cfg(feature = "limit")]

use voussoir::analysis::limit::{
    DeadLoadResult, FrictionModel, JointStrength, LimitAnswer, LimitContact, LimitOptions, LimitProblem, LiveLoad,
};
use voussoir::analysis::{HingeSide, JointRef};
use voussoir::build::arch::{AbutmentShape, Arch, ArchSpec};
use voussoir::prelude::*;

const RHO: Real = 2500.0;
const G: Real = 9.81;

/// A model with `gravity` and a dry Coulomb law of angle `phi_deg`, with `blocks` added, stepped
/// once so that its contacts are detected.
fn detected(gravity: Vector, phi_deg: Real, blocks: Vec<RigidBlock>) -> Model {
    let params = ModelParameters {
        gravity,
        ..ModelParameters::default()
    };
    let mut model: Model = Model::new(params).unwrap();
    model
        .set_joint_law(
            MaterialId(0),
            MaterialId(0),
            CoulombSlip::dry(1e9, 4e8, phi_deg).unwrap(),
        )
        .unwrap();
    for b in blocks {
        model.add_block(b).unwrap();
    }
    model.step().unwrap();
    model
}

/// Where the material point of block `k` that was at `p` at construction is now.
fn moved(model: &Model, k: usize, p: Vector) -> Vector {
    p + model.blocks()[k].displacement_of(p)
}

fn fixed_box(name: &str, min: Vector, max: Vector) -> RigidBlock {
    RigidBlock::cuboid(name, min, max, RHO)
        .unwrap()
        .with_fixity(Fixity::FIXED)
}

/// A block of weight W on a slope ψ (as a tilted gravity), pushed horizontally (in the true
/// frame) up the slope: sliding up at `λ = W tan(ψ + φ)`; pushed down the slope (ψ < φ) at
/// `λ = W tan(φ − ψ)`.
#[test]
fn block_pushed_along_an_incline() {
    let (psi, phi) = (20f64.to_radians(), 30.0f64);
    // Model frame: the slope is the plane z = 0, down-slope is +x.
    let gravity = G * Vector::new(psi.sin(), 0.0, -psi.cos());
    let (lo, hi) = (Vector::new(0.0, 0.0, 0.0), Vector::new(0.4, 0.4, 0.1));
    let model = detected(
        gravity,
        phi,
        vec![
            fixed_box("ramp", Vector::new(-1.0, -1.0, -0.2), Vector::new(1.4, 1.4, 0.0)),
            RigidBlock::cuboid("block", lo, hi, RHO).unwrap(),
        ],
    );
    let weight = RHO * 0.016 * G;
    let centre = 0.5 * (lo + hi);
    // The true horizontal towards up-slope, and its opposite.
    let up = Vector::new(-psi.cos(), 0.0, -psi.sin());
    let problem = LimitProblem::from_model(&model).unwrap();
    assert_eq!(problem.contact_count(), 1);
    let options = LimitOptions::default();
    let solve = |force: Vector, options: &LimitOptions| {
        problem
            .solve(
                &[LiveLoad {
                    block: BlockId(1),
                    point: centre,
                    force,
                }],
                options,
            )
            .unwrap()
    };
    let phi = phi.to_radians();
    let up_result = solve(up, &options);
    let expected = weight * (psi + phi).tan();
    let error = (up_result.multiplier - expected).abs() / weight;
    println!(
        "incline, up:   λ = {:.9} N, closed form {expected:.9} N, error {error:.2e} W",
        up_result.multiplier
    );
    assert!(error < 1e-6);
    // The mechanism: the block slides up (−x) and lifts off at tan φ of its slip (associative).
    let (v, w) = up_result.block_velocity(BlockId(1)).unwrap();
    assert!(v.x < 0.0 && w.length() < 1e-6 * v.length(), "{v} {w}");
    assert!((v.z / -v.x - phi.tan()).abs() < 1e-5, "dilatancy {}", v.z / -v.x);
    // The live load's power is one per newton: its point moves at unit speed along it.
    assert!((up_result.point_velocity(BlockId(1), centre).unwrap().dot(up) - 1.0).abs() < 1e-6);
    let down = solve(-up, &options);
    let expected = weight * (phi - psi).tan();
    let error = (down.multiplier - expected).abs() / weight;
    println!(
        "incline, down: λ = {:.9} N, closed form {expected:.9} N, error {error:.2e} W",
        down.multiplier
    );
    assert!(error < 1e-6);
    // The forces at collapse carry the weight and the push.
    let resultant: Vector = up_result.contacts.iter().map(|c| c.resultant()).sum();
    let applied = gravity * RHO * 0.016 + up * up_result.multiplier;
    assert!(
        (resultant + applied).length() < 1e-6 * weight,
        "{resultant} vs {applied}"
    );
    // The inscribed pyramid lies between the cone of μ cos(π/m) and the cone of μ.
    let facets = 16;
    let pyramid = solve(
        up,
        &LimitOptions {
            friction: FrictionModel::Pyramid { facets },
            ..options
        },
    );
    let inner = weight * (psi + (phi.tan() * (std::f64::consts::PI / facets as Real).cos()).atan()).tan();
    println!(
        "incline, pyramid of {facets}: λ = {:.6} N in [{inner:.6}, {:.6}]",
        pyramid.multiplier, up_result.multiplier
    );
    assert!(pyramid.multiplier >= inner * (1.0 - 1e-6) && pyramid.multiplier <= up_result.multiplier * (1.0 + 1e-6));
    assert!(matches!(
        problem.solve(&[], &options),
        Err(Error::InvalidParameter { .. })
    ));
}

/// A pier of width b and height h on a fixed base pushed sideways at its top: it overturns about
/// its toe at `λ = W b / (2h)`, or slides at `λ = μ W` if that is less.
#[test]
fn pier_pushed_at_its_top_overturns_or_slides() {
    let (b, d, h) = (0.2, 0.2, 0.6);
    let weight = RHO * b * d * h * G;
    let joint = JointRef {
        index: 0,
        blocks: (BlockId(0), BlockId(1)),
        intrados: Vector::new(0.0, 0.5 * d, 0.0),
        extrados: Vector::new(b, 0.5 * d, 0.0),
    };
    for (phi_deg, overturns) in [(40.0, true), (5.0, false)] {
        let model = detected(
            Vector::new(0.0, 0.0, -G),
            phi_deg,
            vec![
                fixed_box("base", Vector::new(-1.0, -1.0, -0.2), Vector::new(1.0, 1.0, 0.0)),
                RigidBlock::cuboid("pier", Vector::ZERO, Vector::new(b, d, h), RHO).unwrap(),
            ],
        );
        let problem = LimitProblem::from_model(&model).unwrap();
        // The first step (which detected the contact) let the pier sink by a few µm into its
        // joint: the lever arm is that of the current geometry.
        let point = moved(&model, 1, Vector::new(0.0, 0.5 * d, h));
        let base = problem
            .polygons()
            .flat_map(|(_, p)| p.iter().map(|q| q.z))
            .fold(Real::INFINITY, Real::min);
        let lever = point.z - base;
        assert!((lever - h).abs() < 1e-4 * h);
        let push = LiveLoad {
            block: BlockId(1),
            point,
            force: Vector::X,
        };
        let result = problem.solve(&[push], &LimitOptions::default()).unwrap();
        let mu = phi_deg.to_radians().tan();
        let expected = (weight * b / (2.0 * lever)).min(mu * weight);
        let error = (result.multiplier - expected).abs() / weight;
        let (_, mechanism) = result.classify(&model, &[joint], 1e-3);
        println!(
            "pier, φ = {phi_deg}°: λ = {:.9} N, closed form {expected:.9} N (overturning {:.6}, sliding {:.6}), error {error:.2e} W; {}",
            result.multiplier,
            weight * b / (2.0 * lever),
            mu * weight,
            mechanism.describe()
        );
        assert!(error < 1e-6);
        let (v, w) = result.block_velocity(BlockId(1)).unwrap();
        if overturns {
            // A rotation about the toe (x = b, z = 0): clockwise seen from −y, i.e. ω along +y.
            assert!(w.y > 0.0);
            let toe = result
                .point_velocity(BlockId(1), moved(&model, 1, Vector::new(b, 0.5 * d, 0.0)))
                .unwrap();
            assert!(toe.length() < 1e-5 * v.length(), "toe moves at {toe}");
            assert_eq!(mechanism.hinges.len(), 1);
            assert_eq!(mechanism.hinges[0].side, HingeSide::Extrados);
            assert!(mechanism.sliding_joints.is_empty());
        } else {
            // Sliding, with the associative lift-off: v_z = μ v_x, no rotation.
            assert!(v.x > 0.0 && w.length() * h < 1e-5 * v.length(), "{v} {w}");
            assert!((v.z / v.x - mu).abs() < 1e-4, "dilatancy {}", v.z / v.x);
            assert!(mechanism.hinges.is_empty());
            assert_eq!(mechanism.sliding_joints, [0]);
        }
    }
}

/// A symmetric wedge of weight W in a V of two planes at the included angle ξ, whose line of
/// intersection plunges at ψ, pushed down that line. With the associative cone at every corner,
/// `λ = μ W cos ψ / √(sin²(ξ/2) − μ² cos²(ξ/2)) − W sin ψ` (`docs/theory.md` §9); Hoek & Bray's
/// wedge, with normal reactions only in the cross-section, has `μ W cos ψ / sin(ξ/2) − W sin ψ`,
/// less by the factor `√(1 − μ²/tan²(ξ/2))`. At `tan(ξ/2) ≤ μ` the wedge locks: unbounded.
#[test]
fn symmetric_wedge_in_a_v() {
    let (xi, psi, phi_deg) = (90f64.to_radians(), 10f64.to_radians(), 30.0);
    let (s, c) = ((0.5 * xi).sin(), (0.5 * xi).cos());
    let (len, side) = (0.6, 0.3);
    let extrude = |pts: &[(Real, Real)], x0: Real, x1: Real| -> Vec<Vector> {
        pts.iter()
            .flat_map(|&(y, z)| [Vector::new(x0, y, z), Vector::new(x1, y, z)])
            .collect()
    };
    // Cross-section in (y, z): the V's apex at the origin, its sides at ±ξ/2 from the vertical.
    let (left, right) = ((-s * side, c * side), (s * side, c * side));
    let wedge = RigidBlock::from_vertices("wedge", &extrude(&[(0.0, 0.0), left, right], 0.0, len), RHO).unwrap();
    let support = |name: &str, top: (Real, Real)| {
        RigidBlock::from_vertices(
            name,
            &extrude(&[(0.0, 0.0), top, (top.0, -0.2), (0.0, -0.2)], -0.2, len + 0.2),
            RHO,
        )
        .unwrap()
        .with_fixity(Fixity::FIXED)
    };
    let weight = RHO * 0.5 * (2.0 * s * side) * (c * side) * len * G;
    // The line of intersection plunges at ψ towards +x.
    let gravity = G * Vector::new(psi.sin(), 0.0, -psi.cos());
    let model = detected(
        gravity,
        phi_deg,
        vec![support("left", left), support("right", right), wedge],
    );
    let problem = LimitProblem::from_model(&model).unwrap();
    assert_eq!(problem.contact_count(), 2, "the wedge on its two planes");
    let centroid = model.blocks()[2].state().pose.translation;
    let push = LiveLoad {
        block: BlockId(2),
        point: centroid,
        force: Vector::X,
    };
    let result = problem.solve(&[push], &LimitOptions::default()).unwrap();
    let mu = phi_deg.to_radians().tan();
    let expected = mu * weight * psi.cos() / (s * s - mu * mu * c * c).sqrt() - weight * psi.sin();
    let hoek_bray = mu * weight * psi.cos() / s - weight * psi.sin();
    let error = (result.multiplier - expected).abs() / weight;
    println!(
        "wedge ξ = 90°, ψ = 10°, φ = 30°: λ = {:.9} N, closed form {expected:.9} N, error {error:.2e} W; \
         Hoek & Bray (non-associative) {hoek_bray:.6} N; factors of safety {:.6} (associative), {:.6} (Hoek & Bray)",
        result.multiplier,
        1.0 + expected / (weight * psi.sin()),
        1.0 + hoek_bray / (weight * psi.sin()),
    );
    assert!(error < 1e-6);
    // The mechanism: the wedge slides down the line and lifts out of the V.
    let (v, _) = result.block_velocity(BlockId(2)).unwrap();
    assert!(v.x > 0.0 && v.z > 0.0 && v.y.abs() < 1e-6 * v.x, "{v}");
    // A V narrower than twice the friction angle locks the wedge: λ is unbounded.
    let narrow = detected(gravity, 50.0, model.blocks().to_vec());
    let problem = LimitProblem::from_model(&narrow).unwrap();
    let error = problem.solve(&[push], &LimitOptions::default()).unwrap_err();
    println!("locked wedge: {error}");
    assert!(matches!(error, Error::LimitUnbounded { .. }), "{error}");
}

/// A semicircular arch of `n` voussoirs, intrados radius `ri` and ring thickness `t`, 0.2 m
/// deep on 0.3 m abutments, under gravity along −y, its contacts detected.
fn semicircle_under_gravity(ri: Real, t: Real, n: usize) -> Model {
    let spec = ArchSpec {
        span: 2.0 * ri,
        rise: ri,
        thickness: t,
        width: 0.2,
        voussoirs: n,
        density: RHO,
        abutment: AbutmentShape {
            outer_width: 0.3,
            depth: 0.3,
        },
        voussoir_material: MaterialId(0),
        abutment_material: MaterialId(0),
    };
    detected(Vector::new(0.0, -G, 0.0), 45.0, Arch::new(&spec).unwrap().blocks)
}

/// Whether a semicircular arch of `n` radial-jointed voussoirs, centre-line radius `r` and ring
/// thickness `t` carries its own weight (no sliding: μ = 2).
fn arch_stands(r: Real, t: Real, n: usize) -> bool {
    let model = semicircle_under_gravity(r - 0.5 * t, t, n);
    let problem = LimitProblem::from_model_with(&model, |_| Some(JointStrength::new(2.0, 0.0).unwrap())).unwrap();
    assert_eq!(problem.contact_count(), n + 1, "every joint of the ring");
    problem.carries_dead_load(&LimitOptions::default()).unwrap()
}

/// The minimum thickness of a semicircular arch under its own weight (Heyman 1969; Milankovitch
/// 1907): `t/R = 0.1075` for a continuous ring (R the centre-line radius), hinges at the crown,
/// at 54.5° from it and at the springings. With 40 voussoirs the haunch hinge can only sit at a
/// joint (54°, 0.5° off), and the critical thickness is stationary in the hinge's position, so
/// the discrete ring needs at most a few 1e-4 less: the test allows 0.5 %.
#[test]
fn minimum_thickness_of_a_semicircular_arch() {
    let (r, n) = (1.0, 40);
    let (mut lo, mut hi) = (0.09, 0.13);
    assert!(!arch_stands(r, lo, n), "t/R = {lo} should be too thin");
    assert!(arch_stands(r, hi, n), "t/R = {hi} should stand");
    while hi - lo > 2e-5 {
        let mid = 0.5 * (lo + hi);
        if arch_stands(r, mid, n) {
            hi = mid;
        } else {
            lo = mid;
        }
    }
    let t = 0.5 * (lo + hi);
    let error = (t / r - 0.1075) / 0.1075;
    println!(
        "semicircular arch, {n} voussoirs: t/R = {:.5} (continuous ring 0.1075; {:+.3} %)",
        t / r,
        100.0 * error
    );
    assert!(error.abs() < 5e-3);
}

/// Errors: a structure that cannot carry its own weight, a live load on a support (unbounded),
/// a joint law with no strength, bad inputs.
#[test]
fn typed_errors() {
    // A block overhanging its support by more than half: it cannot stand.
    let model = detected(
        Vector::new(0.0, 0.0, -G),
        30.0,
        vec![
            fixed_box("base", Vector::new(-1.0, -1.0, -0.2), Vector::new(0.0, 1.0, 0.0)),
            RigidBlock::cuboid("slab", Vector::new(-0.1, 0.0, 0.0), Vector::new(0.3, 0.2, 0.1), RHO).unwrap(),
        ],
    );
    let problem = LimitProblem::from_model(&model).unwrap();
    assert!(!problem.carries_dead_load(&LimitOptions::default()).unwrap());
    // Pushed sideways it cannot be held either: the push would need 2W of friction.
    let push = LiveLoad {
        block: BlockId(1),
        point: Vector::new(0.1, 0.1, 0.05),
        force: -Vector::X,
    };
    let error = problem.solve(&[push], &LimitOptions::default()).unwrap_err();
    println!("overhang, pushed: {error}");
    assert!(matches!(error, Error::LimitInfeasible { .. }), "{error}");
    // Lifted at its tip it stands for W/3 ≤ λ ≤ W/2: only with the live load's help.
    let lift = LiveLoad {
        block: BlockId(1),
        point: Vector::new(0.3, 0.1, 0.1),
        force: Vector::Z,
    };
    let error = problem.solve(&[lift], &LimitOptions::default()).unwrap_err();
    println!("overhang, lifted: {error}");
    assert!(matches!(error, Error::LimitInfeasible { .. }), "{error}");
    let unchecked = LimitOptions {
        check_dead_load: false,
        ..LimitOptions::default()
    };
    let weight = RHO * 0.4 * 0.2 * 0.1 * G;
    let lifted = problem.solve(&[lift], &unchecked).unwrap().multiplier;
    assert!(
        (lifted - 0.5 * weight).abs() < 1e-6 * weight,
        "{lifted} vs {}",
        0.5 * weight
    );
    // A live load on the support only: unbounded.
    let on_base = LiveLoad {
        block: BlockId(0),
        point: Vector::ZERO,
        force: Vector::X,
    };
    let stable = detected(
        Vector::new(0.0, 0.0, -G),
        30.0,
        vec![
            fixed_box("base", Vector::new(-1.0, -1.0, -0.2), Vector::new(1.0, 1.0, 0.0)),
            RigidBlock::cuboid("cube", Vector::ZERO, Vector::splat(0.2), RHO).unwrap(),
        ],
    );
    let problem = LimitProblem::from_model(&stable).unwrap();
    assert!(problem.carries_dead_load(&LimitOptions::default()).unwrap());
    let error = problem.solve(&[on_base], &LimitOptions::default()).unwrap_err();
    println!("load on a support: {error}");
    assert!(matches!(error, Error::LimitUnbounded { .. }), "{error}");
    // Bad live loads and options.
    let bad = |l: LiveLoad| problem.solve(&[l], &LimitOptions::default()).unwrap_err();
    assert!(matches!(
        bad(LiveLoad {
            block: BlockId(7),
            ..on_base
        }),
        Error::UnknownBlock { .. }
    ));
    assert!(matches!(
        bad(LiveLoad {
            force: Vector::new(Real::NAN, 0.0, 0.0),
            ..on_base
        }),
        Error::NonFinite { .. }
    ));
    assert!(matches!(
        bad(LiveLoad {
            force: Vector::ZERO,
            ..on_base
        }),
        Error::InvalidParameter { .. }
    ));
    let pyramid = LimitOptions {
        friction: FrictionModel::Pyramid { facets: 2 },
        ..LimitOptions::default()
    };
    assert!(matches!(
        problem.carries_dead_load(&pyramid),
        Err(Error::InvalidParameter { .. })
    ));
    let tiny = LimitOptions {
        max_iterations: 1,
        ..LimitOptions::default()
    };
    let cube_push = LiveLoad {
        block: BlockId(1),
        point: Vector::new(0.0, 0.1, 0.2),
        force: Vector::X,
    };
    assert!(matches!(
        problem.solve(&[cube_push], &tiny),
        Err(Error::LimitSolver { .. })
    ));
    // A law without strength.
    let mut elastic: Model<LinearElastic> = Model::new(ModelParameters::default()).unwrap();
    elastic
        .set_joint_law(
            MaterialId(0),
            MaterialId(0),
            LinearElastic {
                normal_stiffness: 1e9,
                shear_stiffness: 4e8,
            },
        )
        .unwrap();
    for b in stable.blocks() {
        elastic.add_block(b.clone()).unwrap();
    }
    elastic.step().unwrap();
    assert!(matches!(
        LimitProblem::from_model(&elastic),
        Err(Error::Unsupported { .. })
    ));
    let with = LimitProblem::from_model_with(&elastic, |_| JointStrength::from_degrees(30.0, 0.0).ok()).unwrap();
    assert_eq!(with.contact_count(), 1);
    assert!(JointStrength::from_degrees(90.0, 0.0).is_err());
    assert!(JointStrength::new(0.5, -1.0).is_err());
}

/// The largest imbalance of the free blocks `free` of `model` under gravity and the corner
/// forces of `contacts`: force (N) and moment about the block's centroid (N·m).
fn imbalance(model: &Model, contacts: &[LimitContact], free: &[usize]) -> (Real, Real) {
    let gravity = model.parameters().gravity;
    let (mut force, mut moment): (Real, Real) = (0.0, 0.0);
    for &k in free {
        let block = &model.blocks()[k];
        let centre = block.state().pose.translation;
        let mut f = gravity * block.mass_properties().mass;
        let mut m = Vector::ZERO;
        for c in contacts {
            let sign = if c.blocks.1 .0 as usize == k {
                1.0
            } else if c.blocks.0 .0 as usize == k {
                -1.0
            } else {
                continue;
            };
            for v in &c.vertices {
                let on = sign * (c.normal * v.normal_force + v.shear_force);
                f += on;
                m += (v.point - centre).cross(on);
            }
        }
        force = force.max(f.length());
        moment = moment.max(m.length());
    }
    (force, moment)
}

/// The corner forces of an admissible state: compression only, shear within `μ n` (to `tol`).
fn admissible(contacts: &[LimitContact], mu: Real, tol: Real) -> bool {
    contacts
        .iter()
        .flat_map(|c| &c.vertices)
        .all(|v| v.normal_force >= -tol && v.shear_force.length() <= mu * v.normal_force + tol)
}

/// Whether the certificate of a dead load not carried moves the blocks admissibly: every
/// corner opens by at least `μ` times its slip (to `tol` of the largest corner rate).
fn admissible_motion(dead: &DeadLoadResult, mu: Real, tol: Real) -> bool {
    let corners = || dead.contacts.iter().flat_map(|c| &c.vertices);
    let scale = corners().map(|v| v.opening.hypot(v.sliding)).fold(0.0, Real::max);
    scale > 0.0 && corners().all(|v| v.opening >= mu * v.sliding - tol * scale)
}

/// The dead-load question alone on a block on a slope ψ (gravity tilted) with friction angle φ:
/// carried while `tan ψ ≤ tan φ` (sliding governs: the 0.4 m × 0.1 m block tips at
/// `tan ψ = 4`), with the contact forces of an admissible state that balance the weight;
/// beyond, not carried, with the solver's certificate: the block moving down the slope, its
/// joint opening by at least `tan φ` of the slip (associative flow). The friction pyramid of m facets, inscribed, carries it while
/// `tan ψ ≤ μ cos(π/m)`. `analyse` with no live load, or a zero one, asks the same question;
/// `solve` still wants a live load.
#[test]
fn dead_load_of_a_block_on_an_incline() {
    let phi_deg: Real = 30.0;
    let (lo, hi) = (Vector::new(0.0, 0.0, 0.0), Vector::new(0.4, 0.4, 0.1));
    let weight = RHO * 0.016 * G;
    let on_slope = |psi_deg: Real| {
        let psi = psi_deg.to_radians();
        detected(
            G * Vector::new(psi.sin(), 0.0, -psi.cos()),
            phi_deg,
            vec![
                fixed_box("ramp", Vector::new(-1.0, -1.0, -0.2), Vector::new(1.4, 1.4, 0.0)),
                RigidBlock::cuboid("block", lo, hi, RHO).unwrap(),
            ],
        )
    };
    let options = LimitOptions::default();
    let mu = phi_deg.to_radians().tan();
    for (psi_deg, carried) in [(0.0, true), (20.0, true), (29.0, true), (31.0, false), (45.0, false)] {
        let model = on_slope(psi_deg);
        let problem = LimitProblem::from_model(&model).unwrap();
        let dead = problem.dead_load(&options).unwrap();
        assert_eq!(dead.carried, carried, "ψ = {psi_deg}°: {dead:?}");
        assert_eq!(problem.carries_dead_load(&options).unwrap(), carried);
        if carried {
            assert!(
                dead.reason.is_none() && dead.status.contains("Solved"),
                "{}",
                dead.status
            );
            // The forces balance the weight: the one contact's resultant is −W, to round-off
            // of the interior point's 1e-8.
            let (force, moment) = imbalance(&model, &dead.contacts, &[1]);
            println!(
                "incline ψ = {psi_deg}°: carried ({}), imbalance {:.1e} W, {:.1e} W·m",
                dead.status,
                force / weight,
                moment / weight
            );
            assert!(force < 1e-8 * weight && moment < 1e-8 * weight * 0.1);
            assert!(admissible(&dead.contacts, mu, 1e-8 * weight));
            // No mechanism.
            assert!(dead
                .blocks
                .iter()
                .all(|b| b.velocity == Vector::ZERO && b.angular_velocity == Vector::ZERO));
        } else {
            let reason = dead.reason.as_deref().unwrap();
            println!("incline ψ = {psi_deg}°: not carried ({}): {reason}", dead.status);
            assert!(dead.status.contains("PrimalInfeasible"), "{}", dead.status);
            assert!(reason.contains("#1 (\"block\")"), "{reason}");
            // No forces; the certificate: the block moves down the slope (+x), its joint
            // opening by at least tan φ of its slip at every corner (kinematically admissible),
            // the dead load's power the weight.
            assert!(dead
                .contacts
                .iter()
                .flat_map(|c| &c.vertices)
                .all(|v| v.normal_force == 0.0 && v.shear_force == Vector::ZERO));
            let (v, w) = dead.block_velocity(BlockId(1)).unwrap();
            println!("  certificate: v = {v}, ω = {w}");
            assert!(v.x > 0.0 && v.y.abs() < 1e-6 * v.x, "{v} {w}");
            assert!(admissible_motion(&dead, mu, 1e-6));
            assert!(dead.contacts[0].vertices.iter().any(|c| c.sliding > 1e-3 * v.x));
            let power = model.parameters().gravity.dot(v) * RHO * 0.016;
            assert!((power - weight).abs() < 1e-6 * weight, "{power} vs {weight}");
        }
        // The same through `analyse`, with no live load or a zero one.
        let zero = LiveLoad {
            block: BlockId(1),
            point: 0.5 * (lo + hi),
            force: Vector::ZERO,
        };
        for live in [&[][..], &[zero][..]] {
            let answer = problem.analyse(live, &options).unwrap();
            assert_eq!(answer.multiplier(), None);
            let LimitAnswer::DeadLoad(again) = answer else {
                panic!("a dead-load answer expected")
            };
            assert_eq!(again.carried, carried);
        }
        // `solve` wants a live load and says where the dead-load question is.
        let error = problem.solve(&[zero], &options).unwrap_err();
        assert!(
            matches!(error, Error::InvalidParameter { .. }) && error.to_string().contains("dead_load"),
            "{error}"
        );
    }
    // The inscribed pyramid: carried while tan ψ ≤ μ cos(π/16) (ψ ≤ 29.52°).
    let pyramid = LimitOptions {
        friction: FrictionModel::Pyramid { facets: 16 },
        ..options
    };
    let limit = (mu * (std::f64::consts::PI / 16.0).cos()).atan().to_degrees();
    for (psi_deg, carried) in [(limit - 0.05, true), (limit + 0.05, false)] {
        let model = on_slope(psi_deg);
        let problem = LimitProblem::from_model(&model).unwrap();
        let dead = problem.dead_load(&pyramid).unwrap();
        assert_eq!(dead.carried, carried, "pyramid, ψ = {psi_deg}°");
        assert!(
            problem.carries_dead_load(&options).unwrap(),
            "the cone carries it at ψ = {psi_deg}°"
        );
        if carried {
            let (force, _) = imbalance(&model, &dead.contacts, &[1]);
            assert!(force < 1e-8 * weight, "{force}");
        }
    }
    // With a live load, `analyse` is `solve`: pushed up the slope of 20° at W tan(ψ + φ).
    let model = on_slope(20.0);
    let problem = LimitProblem::from_model(&model).unwrap();
    let psi = 20f64.to_radians();
    let push = LiveLoad {
        block: BlockId(1),
        point: 0.5 * (lo + hi),
        force: Vector::new(-psi.cos(), 0.0, -psi.sin()),
    };
    let answer = problem.analyse(&[push], &options).unwrap();
    let expected = weight * (psi + phi_deg.to_radians()).tan();
    assert!((answer.multiplier().unwrap() - expected).abs() < 1e-6 * weight);
    assert!(matches!(answer, LimitAnswer::Collapse(_)));
    // A bad block is still refused, live load or not.
    let stray = LiveLoad {
        block: BlockId(9),
        force: Vector::ZERO,
        ..push
    };
    assert!(matches!(
        problem.analyse(&[stray], &options),
        Err(Error::UnknownBlock { .. })
    ));
}

/// The dead-load question on a semicircular arch: at 0.2 m the contact forces of the admissible
/// state hold every voussoir in equilibrium (force and moment, to the solver's round-off); at
/// 0.05 m (below Heyman's minimum thickness, `t/R = 0.1075`) it is not carried, and the
/// solver's certificate is a mechanism in which the crown falls.
#[test]
fn dead_load_of_a_semicircular_arch() {
    let (ri, n) = (1.0, 16);
    let arch_of = |t: Real| semicircle_under_gravity(ri, t, n);
    let strength = |_: &CoulombSlip| Some(JointStrength::new(2.0, 0.0).unwrap());
    let options = LimitOptions::default();
    let model = arch_of(0.2);
    let problem = LimitProblem::from_model_with(&model, strength).unwrap();
    let dead: DeadLoadResult = problem.dead_load(&options).unwrap();
    assert!(dead.carried);
    let free: Vec<usize> = (1..=n).collect();
    let weight: Real = free.iter().map(|&k| model.blocks()[k].mass_properties().mass * G).sum();
    let (force, moment) = imbalance(&model, &dead.contacts, &free);
    println!(
        "semicircle t = 0.2 m: carried ({}, {} iterations), imbalance {:.1e} W, {:.1e} W·m",
        dead.status,
        dead.iterations,
        force / weight,
        moment / weight
    );
    assert!(force < 1e-8 * weight && moment < 1e-8 * weight * ri);
    assert!(admissible(&dead.contacts, 2.0, 1e-8 * weight));
    // The abutments carry the weight between them.
    let on_abutments: Vector = dead
        .contacts
        .iter()
        .filter(|c| c.blocks.0 == BlockId(0) || c.blocks.1 == BlockId(n as u32 + 1))
        .map(|c| {
            if c.blocks.0 == BlockId(0) {
                c.resultant()
            } else {
                -c.resultant()
            }
        })
        .sum();
    assert!((on_abutments.y - weight).abs() < 1e-8 * weight, "{on_abutments}");

    let model = arch_of(0.05);
    let problem = LimitProblem::from_model_with(&model, strength).unwrap();
    let dead = problem.dead_load(&options).unwrap();
    assert!(!dead.carried);
    println!(
        "semicircle t = 0.05 m: not carried ({}): {}",
        dead.status,
        dead.reason.as_deref().unwrap_or("")
    );
    assert!(dead.status.contains("PrimalInfeasible"), "{}", dead.status);
    assert!(admissible_motion(&dead, 2.0, 1e-6));
    let power: Real = free
        .iter()
        .map(|&k| {
            let block = &model.blocks()[k];
            model.parameters().gravity.dot(dead.blocks[k].velocity) * block.mass_properties().mass
        })
        .sum();
    let weight: Real = free.iter().map(|&k| model.blocks()[k].mass_properties().mass * G).sum();
    assert!((power - weight).abs() < 1e-6 * weight, "{power} vs {weight}");
    // The crown sinks.
    let crown = model.blocks()[n / 2].state().pose.translation;
    let v = dead.point_velocity(BlockId(n as u32 / 2), crown).unwrap();
    assert!(v.y < 0.0, "{v}");
}
