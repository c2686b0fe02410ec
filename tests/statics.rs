//! Statics against closed forms: blocks resting on supports, eccentric loads inside and beyond the
//! kern, and a column of stacked blocks.
//!
//! Every run uses the default quasi-static setting (Cundall local damping, α = 0.8) and
//! [`Model::run_to_equilibrium`]. Tolerances are derived from two error sources, each stated where
//! it is used:
//!
//! * the equilibrium residual: `run_to_equilibrium(EQ_RATIO, ..)` stops once the largest
//!   out-of-balance force on a free block is below `EQ_RATIO` × the mean contact force;
//! * the discretisation of a joint into a grid of sub-contacts (trapezoidal quadrature of the joint
//!   stresses), which is exact for uniform stress and has a known error for linear stress.
//!
//! Closed forms are written out from the geometry and the loads; nothing is read back from a
//! previous run.

use crate::common;

use voussoir::law::JointStatus;
use voussoir::prelude::*;

/// Gravity (m/s²), the model default, pointing along −z.
const G: f64 = 9.81;
/// Density of every block (kg/m³).
const RHO: f64 = 2500.0;
/// Friction angle of the dry joints (degrees).
const PHI: f64 = 30.0;
/// Target unbalanced-force ratio of the equilibrium runs.
const EQ_RATIO: f64 = 1e-8;
/// Step budget of an equilibrium run (a few thousand are needed; this is only a safety cap).
const MAX_STEPS: u64 = 200_000;

/// A model with one dry Coulomb joint law (`ks = 0.4 kn`, φ = 30°), default local damping and the
/// given sub-contact density.
fn model(kn: f64, density: SubContactDensity) -> Model {
    let mut params = ModelParameters::default();
    params.contact.density = density;
    common::model_with(params, CoulombSlip::dry(kn, 0.4 * kn, PHI).unwrap())
}

fn cuboid(name: &str, min: [f64; 3], max: [f64; 3]) -> RigidBlock {
    RigidBlock::cuboid(name, Vector::from_array(min), Vector::from_array(max), RHO).unwrap()
}

fn fixed_cuboid(name: &str, min: [f64; 3], max: [f64; 3]) -> RigidBlock {
    cuboid(name, min, max).with_fixity(Fixity::FIXED)
}

/// Weight (N) of a box of the given extents, from its dimensions (not from the engine).
fn weight(min: [f64; 3], max: [f64; 3]) -> f64 {
    RHO * G * (max[0] - min[0]) * (max[1] - min[1]) * (max[2] - min[2])
}

/// Length of the overlap of two intervals.
fn overlap(a: (f64, f64), b: (f64, f64)) -> f64 {
    (a.1.min(b.1) - a.0.max(b.0)).max(0.0)
}

/// Runs to equilibrium and checks that the run really converged.
fn settle(m: &mut Model) -> u64 {
    let steps = m.run_to_equilibrium(EQ_RATIO, MAX_STEPS).unwrap();
    assert!(m.unbalanced_force_ratio() < EQ_RATIO);
    steps
}

/// What the sub-contacts of one joint add up to.
#[derive(Debug)]
struct JointSums {
    area: f64,
    normal_force: f64,
    /// Sum of sub-contact normal forces times their world position (N·m).
    first_moment: Vector,
    count: usize,
}

fn joint_sums(m: &Model, a: BlockId, b: BlockId) -> JointSums {
    let c = m.contact_between(a, b).expect("the blocks should be in contact");
    let mut s = JointSums {
        area: 0.0,
        normal_force: 0.0,
        first_moment: Vector::ZERO,
        count: c.subcontact_count(),
    };
    for sub in c.subcontacts() {
        s.area += sub.area();
        s.normal_force += sub.normal_force();
        s.first_moment += sub.normal_force_point() * sub.normal_force();
    }
    // The pair's own resultant must agree with the sum over its sub-contacts (same additions,
    // possibly a different order: round-off only).
    assert!(
        (c.normal_force() - s.normal_force).abs() <= 1e-12 * s.normal_force.abs(),
        "pair normal force {} vs sum of sub-contacts {}",
        c.normal_force(),
        s.normal_force
    );
    s
}

/// Support of a block resting on a fixed base with an identical footprint (coincident faces, the
/// commonest masonry joint).
///
/// Physics: a free block of weight `W = ρ g V` on a rigid support is in equilibrium when the joint
/// carries `N = W`; with a rigid block on uniform normal springs the closure is uniform, so every
/// sub-contact carries the stress `σ = W / A = ρ g h`, and the tributary areas of the sub-contact
/// grid tile the joint, summing to the face area `L × B`.
///
/// Tolerances:
/// * `N = W` to 1e-6 relative: the run stops at an unbalanced-force ratio of 1e-8, and with a single
///   contact the out-of-balance force of the block is `|W − N|` (plus shear, here zero) over a mean
///   contact force of `N`, so the residual is ≤ 1e-8 W; 1e-6 leaves room only for round-off.
/// * stresses uniform to 1e-6 relative: by symmetry of the load and of the grid nothing tilts the
///   block except round-off, so the spread of stresses is of the order of the equilibrium residual.
/// * areas to 1e-12 relative: the grid cells tile the face exactly; only round-off of the clipping
///   and of 15 × 15 additions remains.
#[test]
fn block_on_coincident_base_carries_its_weight_uniformly() {
    let (lo, hi) = ([-0.2, -0.15, 0.0], [0.2, 0.15, 0.2]);
    let mut m = model(4e9, SubContactDensity::PerEdge(15));
    let base = m
        .add_block(fixed_cuboid("base", [-0.2, -0.15, -0.2], [0.2, 0.15, 0.0]))
        .unwrap();
    let block = m.add_block(cuboid("block", lo, hi)).unwrap();
    let steps = settle(&mut m);
    let w = weight(lo, hi);
    let face = 0.4 * 0.3;
    let sigma = RHO * G * 0.2;
    check_uniform_joint(&m, base, block, w, face, sigma, steps);
}

/// Support of a block smaller than its base and placed off-centre on it.
///
/// Physics as in [`block_on_coincident_base_carries_its_weight_uniformly`]: the overlap of the
/// two faces is the whole (smaller) block face, so `N = W`, `σ = ρ g h` everywhere and the
/// sub-contact areas sum to the block's face area, whatever the block's position on the base.
/// Here the sub-contacts are hosted by the smaller face (the block's), the other case from the
/// coincident test, and the block is 0.25 m high with a softer joint (kn = 1e9 Pa/m).
///
/// Tolerances as in the coincident test, for the same reasons.
#[test]
fn block_smaller_than_base_and_offset_carries_its_weight_uniformly() {
    let (lo, hi) = ([0.13, -0.31, 0.0], [0.53, -0.01, 0.25]);
    let mut m = model(1e9, SubContactDensity::PerEdge(15));
    let base = m
        .add_block(fixed_cuboid("base", [-0.5, -0.4, -0.2], [0.6, 0.5, 0.0]))
        .unwrap();
    let block = m.add_block(cuboid("block", lo, hi)).unwrap();
    let steps = settle(&mut m);
    let w = weight(lo, hi);
    let face = 0.4 * 0.3;
    let sigma = RHO * G * 0.25;
    check_uniform_joint(&m, base, block, w, face, sigma, steps);
}

fn check_uniform_joint(m: &Model, base: BlockId, block: BlockId, w: f64, face: f64, sigma: f64, steps: u64) {
    let s = joint_sums(m, base, block);
    let c = m.contact_between(base, block).unwrap();
    let (mut smin, mut smax) = (f64::INFINITY, f64::NEG_INFINITY);
    for sub in c.subcontacts() {
        smin = smin.min(sub.normal_stress());
        smax = smax.max(sub.normal_stress());
        assert_eq!(sub.status(), JointStatus::Elastic, "{sub:?}");
    }
    let err_n = (s.normal_force - w).abs() / w;
    let err_a = (s.area - face).abs() / face;
    let err_s = (smin - sigma).abs().max((smax - sigma).abs()) / sigma;
    println!(
        "steps {steps}, {} sub-contacts: N = {:.9} N vs W = {w:.9} N (rel {err_n:.2e}); sum A = {:.15} \
         vs {face} (rel {err_a:.2e}); sigma in [{smin:.6}, {smax:.6}] vs {sigma:.6} Pa (rel {err_s:.2e})",
        s.count, s.normal_force, s.area
    );
    assert_eq!(s.count, 15 * 15);
    assert!(err_n < 1e-6, "normal force {} vs weight {w}", s.normal_force);
    assert!(err_a < 1e-12, "areas sum to {} vs face {face}", s.area);
    assert!(err_s < 1e-6, "stress range [{smin}, {smax}] vs rho g h = {sigma}");
}

/// Support of a block that overhangs the edges of its base in both x and y.
///
/// Physics: the joint is the overlap rectangle of the two faces, `Lx × Ly` with
/// `Lx = 0.35 m`, `Ly = 0.28 m` (the block face is 0.4 × 0.3 m): the sub-contact areas must sum to
/// the overlap area, not to either face. The block's centroid lies over the overlap (inside its
/// kern, so the whole joint stays in compression) and the joint carries `N = W`; moment
/// equilibrium puts the resultant of the normal forces on the vertical through the block's
/// centroid. The stresses are not uniform here (the overlap is eccentric), so only the resultants
/// are compared.
///
/// Tolerances: `N = W` to 1e-6 relative and areas to 1e-12 relative as in the coincident test (the
/// cells cut by the overlap boundary are clipped exactly, so they still tile the overlap). The
/// resultant position: its error is the out-of-balance moment divided by `N`; local damping drives
/// the rotations to rest at the same rate as the translations, so we allow 1e-6 of the joint size
/// (0.35 µm) — five orders of magnitude below the 25 mm offset between overlap centre and
/// centroid that a missing or misplaced sub-contact would shift.
#[test]
fn overhanging_block_areas_sum_to_the_overlap() {
    let (lo, hi) = ([-0.05, 0.0, 0.0], [0.35, 0.3, 0.2]);
    let (blo, bhi) = ([-0.3, -0.2, -0.2], [0.3, 0.28, 0.0]);
    let mut m = model(2e9, SubContactDensity::PerEdge(15));
    let base = m.add_block(fixed_cuboid("base", blo, bhi)).unwrap();
    let block = m.add_block(cuboid("block", lo, hi)).unwrap();
    let steps = settle(&mut m);
    let w = weight(lo, hi);
    let lx = overlap((lo[0], hi[0]), (blo[0], bhi[0]));
    let ly = overlap((lo[1], hi[1]), (blo[1], bhi[1]));
    let area = lx * ly;
    let s = joint_sums(&m, base, block);
    let c = m.contact_between(base, block).unwrap();
    assert!(
        c.subcontacts().all(|sub| sub.normal_force() > 0.0),
        "the whole overlap is in compression"
    );
    let centroid = m.block(block).unwrap().state().pose.translation;
    let resultant = s.first_moment / s.normal_force;
    let err_n = (s.normal_force - w).abs() / w;
    let err_a = (s.area - area).abs() / area;
    let err_x = (resultant.x - centroid.x).abs();
    let err_y = (resultant.y - centroid.y).abs();
    println!(
        "steps {steps}, {} sub-contacts: N = {:.9} vs W = {w:.9} (rel {err_n:.2e}); sum A = {:.15} vs overlap {area} \
         (rel {err_a:.2e}); resultant - centroid = ({err_x:.2e}, {err_y:.2e}) m",
        s.count, s.normal_force, s.area
    );
    assert!(err_n < 1e-6, "normal force {} vs weight {w}", s.normal_force);
    assert!(err_a < 1e-12, "areas sum to {} vs overlap {area}", s.area);
    assert!(
        err_x < 1e-6 * lx && err_y < 1e-6 * ly,
        "resultant {resultant} vs centroid {centroid}"
    );
}

/// Geometry of the eccentric-load tests: a 0.4 × 0.3 × 0.2 m block on a larger fixed base, so the
/// joint is the block's face, hosted by it and covered by an `n × n` grid.
const L: f64 = 0.4;
const B: f64 = 0.3;
const H: f64 = 0.2;
/// Sub-contacts per edge in the eccentric-load tests.
const N_GRID: u16 = 40;

/// Outcome of an eccentric-load run.
struct Eccentric {
    /// Resultant normal force (closed form: applied load + weight).
    n_total: f64,
    /// Eccentricity of the resultant about the current centroid (closed form).
    e: f64,
    /// Horizontal offset of the joint centre from the current centroid (rigid rotation of the
    /// block, `≈ θ·H/2`): the closed forms below hold about the joint centre.
    s: f64,
    /// Per sub-contact: x of its material point, measured from the face centre along the face
    /// (m), and its normal stress (Pa) and force (N).
    subs: Vec<(f64, f64, f64)>,
    /// Horizontal position of the resultant of the normal forces relative to the current centroid.
    resultant_x: f64,
}

/// A block with a vertical load `F` applied at eccentricity `e·(F + W)/F` along x from its
/// centroid (as a force and the moment `r × F` about the centroid), so that the resultant of load
/// and weight, `N = F + W`, acts at eccentricity `e`.
fn eccentric(e: f64) -> Eccentric {
    let (lo, hi) = ([-L / 2.0, -B / 2.0, 0.0], [L / 2.0, B / 2.0, H]);
    let mut m = model(4e9, SubContactDensity::PerEdge(N_GRID));
    let base = m
        .add_block(fixed_cuboid("base", [-0.5, -0.5, -0.2], [0.5, 0.5, 0.0]))
        .unwrap();
    let block = m.add_block(cuboid("block", lo, hi)).unwrap();
    let w = weight(lo, hi);
    let f = 10.0 * w;
    let arm = Vector::new(e * (f + w) / f, 0.0, 0.0);
    let force = Vector::new(0.0, 0.0, -f);
    m.set_load(
        block,
        Wrench {
            force,
            moment: arm.cross(force),
        },
    )
    .unwrap();
    let steps = settle(&mut m);
    let b = m.block(block).unwrap();
    let centroid = b.state().pose.translation;
    let face_centre0 = Vector::new(0.0, 0.0, 0.0);
    let face_centre = face_centre0 + b.displacement_of(face_centre0);
    let c = m.contact_between(base, block).unwrap();
    let mut subs = Vec::with_capacity(c.subcontact_count());
    for sub in c.subcontacts() {
        // Back to the material point's initial position: x along the face from its centre.
        let x0 = b.initial_pose().transform_point(b.local_point(sub.point()));
        subs.push((x0.x - face_centre0.x, sub.normal_stress(), sub.normal_force()));
    }
    let sums = joint_sums(&m, base, block);
    // Rigid rotation since the start (the body frame is the principal frame, not the world's).
    let theta = (b.state().pose.rotation * b.initial_pose().rotation.inverse()).to_scaled_axis();
    println!(
        "e = {e:.5} m: steps {steps}, {} sub-contacts, rotation about y {:.3e} rad, joint-centre offset {:.3e} m",
        sums.count,
        theta.y,
        face_centre.x - centroid.x
    );
    Eccentric {
        n_total: f + w,
        e,
        s: face_centre.x - centroid.x,
        subs,
        resultant_x: sums.first_moment.x / sums.normal_force - centroid.x,
    }
}

/// Eccentric vertical load inside the kern (`e < L/6`): linear normal stresses.
///
/// Physics: a rigid block on uniform normal springs closes the joint by a plane, so while the
/// whole joint is compressed the stress is linear, and equilibrium of force and moment gives the
/// Navier formula `σ(x) = N/A·(1 + 12·e·x/L²)` (x from the joint centre, `A = L·B`). The
/// eccentricity about the joint centre is `e − s`, where `s ≈ θ·H/2` (a few µm, checked to be
/// below 1e-4 L) is the horizontal shift of the joint centre under the block's small rigid
/// rotation θ; the load is applied about the current centroid.
///
/// Tolerance: sub-contacts sit on the nodes of an `n × n` grid, the outer ones on the joint edges,
/// each carrying its tributary area (trapezoidal rule), so the discrete second moment of area is
/// `A·L²/12·(1 + 2/(n − 1)²)`. The discrete solution then has the slope of σ smaller by the factor
/// `δ = (2/(n−1)²)/(1 + 2/(n−1)²)`, an error at most `N/A·6·e/L·δ` at the edges (1.3e-3 N/A at
/// n = 40, e near L/6). To that bound we add the equilibrium residual: a resultant off by `δ` tilts the
/// stresses by at most `N/A·6·δ/L`, and the resultant is checked to within `δ = 1e-6 L` (see the
/// beyond-kern test), hence `+ 6e-6 N/A`.
#[test]
fn eccentric_load_inside_the_kern_gives_linear_stresses() {
    let gaps = (f64::from(N_GRID) - 1.0).powi(2);
    let delta = (2.0 / gaps) / (1.0 + 2.0 / gaps);
    for e in [L / 12.0, L / 8.0] {
        let r = eccentric(e);
        assert!(r.s.abs() < 1e-4 * L, "joint-centre shift {} is not small", r.s);
        let ej = r.e - r.s;
        let mean = r.n_total / (L * B);
        let tol = mean * (6.0 * ej / L * delta + 6.0 * 1e-6);
        let mut worst: f64 = 0.0;
        for &(x, sigma, _) in &r.subs {
            let closed = mean * (1.0 + 12.0 * ej * x / (L * L));
            worst = worst.max((sigma - closed).abs());
        }
        let err_res = (r.resultant_x - r.e).abs();
        println!(
            "  inside kern e = L/{:.0}: max |sigma - Navier| = {worst:.4e} Pa = {:.3e} N/A (tolerance {:.3e} N/A); \
             resultant at {:.9} vs e {:.9} (err {err_res:.2e} m)",
            L / e,
            worst / mean,
            tol / mean,
            r.resultant_x,
            r.e
        );
        assert!(worst <= tol, "e = {e}: stress error {worst} Pa above {tol} Pa");
        assert!(
            r.subs.iter().all(|s| s.2 > 0.0),
            "inside the kern the whole joint is compressed"
        );
        // Resultant: equilibrium only (see the beyond-kern test for the tolerance).
        assert!(err_res < 1e-6 * L, "resultant at {} vs e = {}", r.resultant_x, r.e);
    }
}

/// Eccentric vertical load beyond the kern (`e > L/6`): partial contact.
///
/// Physics: a no-tension joint under a resultant `N` at eccentricity `e` (about the joint centre)
/// opens on the side away from the load; the compressed part is the length `c = 3·(L/2 − e)`
/// from the loaded edge, with a triangular stress block whose centroid (a third of `c` from the
/// edge) lies under the load. Here the joint law is a dry Coulomb joint (no tension) and
/// `e = L/4` and `L/3` (c = 0.3 m and 0.2 m).
///
/// Tolerances:
/// * contact length: measured as the extent of the compressed cells, `L/2 − (x_first − w/2)` with
///   `w = L/n` the cell width and `x_first` the centre of the first compressed column. The
///   measured edge lies on a cell boundary, and the neutral axis of the discrete grid may differ
///   from the continuum one by a fraction of a cell: we allow one cell width (1 cm at n = 40).
/// * resultant of the normal stresses at `e` about the current centroid: pure equilibrium, so its
///   error is the out-of-balance moment divided by `N` (the normal of the slightly rotated joint is
///   off vertical by `θ/2 ~ 1e-4`, which changes lever arms only at second order). Local damping
///   brings the rotation to rest with the translations: 1e-6 L (0.4 µm), against the 0.1–0.13 m
///   eccentricity.
#[test]
fn eccentric_load_beyond_the_kern_gives_partial_contact() {
    let w_cell = L / f64::from(N_GRID);
    for e in [L / 4.0, L / 3.0] {
        let r = eccentric(e);
        assert!(r.s.abs() < 1e-4 * L, "joint-centre shift {} is not small", r.s);
        let ej = r.e - r.s;
        let c = 3.0 * (L / 2.0 - ej);
        let compressed: Vec<f64> = r.subs.iter().filter(|s| s.2 > 0.0).map(|s| s.0).collect();
        let x_first = compressed.iter().copied().fold(f64::INFINITY, f64::min);
        let c_meas = L / 2.0 - (x_first - w_cell / 2.0);
        // Every sub-contact on the loaded side of the first compressed column is compressed, and
        // every one beyond it is open with no force.
        for &(x, _, fnorm) in &r.subs {
            if x >= x_first - 1e-9 {
                assert!(
                    fnorm > 0.0,
                    "sub-contact at x = {x} inside the contact length is not compressed"
                );
            } else {
                assert_eq!(
                    fnorm, 0.0,
                    "sub-contact at x = {x} outside the contact length carries force"
                );
            }
        }
        let err_res = (r.resultant_x - r.e).abs();
        println!(
            "  beyond kern e = L/{:.0}: contact length {c_meas:.4} m vs 3(L/2 - e) = {c:.4} m \
             (err {:.2e} m, cell {w_cell} m); resultant at {:.9} vs e {:.9} (err {err_res:.2e} m)",
            L / e,
            (c_meas - c).abs(),
            r.resultant_x,
            r.e
        );
        assert!((c_meas - c).abs() <= w_cell, "contact length {c_meas} vs {c}");
        assert!(err_res < 1e-6 * L, "resultant at {} vs e = {}", r.resultant_x, r.e);
    }
}

/// A column of three blocks of different heights on a fixed base.
///
/// Physics: each joint carries the weight of everything above it, `N_k = Σ_{j ≥ k} W_j`, spread
/// uniformly over the joint (`σ_k = N_k / A`), and the sub-contact areas sum to the face area.
///
/// Tolerance 1e-6 relative: the run stops when every free block's out-of-balance force is below
/// 1e-8 × the mean contact force (which is below the heaviest joint force `N_0`), so a joint's force
/// differs from the weight above it by at most 3 × 1e-8 × N_0 ≤ 1e-7 N_k here (N_0 / N_2 < 4);
/// 1e-6 leaves room only for round-off. Stresses: uniform by symmetry, as in the single-block test.
#[test]
fn column_of_three_blocks_joints_carry_the_weight_above() {
    let heights = [0.25, 0.15, 0.2];
    let (x, y) = ((-0.2, 0.2), (-0.15, 0.15));
    let mut m = model(4e9, SubContactDensity::PerEdge(15));
    let mut ids = vec![m
        .add_block(fixed_cuboid("base", [x.0, y.0, -0.2], [x.1, y.1, 0.0]))
        .unwrap()];
    let mut weights = Vec::new();
    let mut z = 0.0;
    for (k, h) in heights.iter().enumerate() {
        let (lo, hi) = ([x.0, y.0, z], [x.1, y.1, z + h]);
        ids.push(m.add_block(cuboid(&format!("block {k}"), lo, hi)).unwrap());
        weights.push(weight(lo, hi));
        z += h;
    }
    let steps = settle(&mut m);
    let face = (x.1 - x.0) * (y.1 - y.0);
    println!("steps {steps}");
    for k in 0..heights.len() {
        let above: f64 = weights[k..].iter().sum();
        let s = joint_sums(&m, ids[k], ids[k + 1]);
        let c = m.contact_between(ids[k], ids[k + 1]).unwrap();
        let sigma = above / face;
        let err_s = c
            .subcontacts()
            .map(|sub| (sub.normal_stress() - sigma).abs() / sigma)
            .fold(0.0, f64::max);
        let err_n = (s.normal_force - above).abs() / above;
        let err_a = (s.area - face).abs() / face;
        println!(
            "  joint {k}: N = {:.9} N vs weight above {above:.9} N (rel {err_n:.2e}); stresses rel {err_s:.2e}; \
             areas rel {err_a:.2e}",
            s.normal_force
        );
        assert!(err_n < 1e-6, "joint {k}: {} vs {above}", s.normal_force);
        assert!(
            err_s < 1e-6,
            "joint {k}: stresses not uniform at {sigma} Pa (rel {err_s})"
        );
        assert!(err_a < 1e-12, "joint {k}: areas sum to {}", s.area);
    }
    // No other contacts than the three joints (blocks two apart are 0.15 m or more apart).
    assert_eq!(m.contacts().len(), heights.len());
}

/// **A hinge is a Winkler joint** (`docs/theory.md` §4.1): a 0.2 × 0.2 × 0.6 m pier on a fixed
/// base under gravity tilted to 0.97 of its rigid overturning tilt (b/h), stiff joints (kn
/// 4e11 Pa/m, φ 35°), settled: the joint is closed over a strip of width `c` at the toe, its
/// resultant sits `c/3` inside the toe and the pier has turned by `φ = 2N/(kn c² d)`, the
/// closed form of linear no-tension springs, to 1 % (measured: 1.8039e-4 rad both, c 8.8 mm).
/// With springs at points on the edge (43203ac, before the exact cell integration) the
/// resultant sat on the edge, a rigid pivot (6.7e-6 rad at the rigid tilt itself): issue 43's
/// "hinges lost capacity" is this closed form, converging as kn^(-1/3).
#[test]
fn a_hinge_turns_as_a_no_tension_winkler_joint() -> Result<()> {
    let (b, d, h, kn): (Real, Real, Real, Real) = (0.2, 0.2, 0.6, 4e11);
    let mut params = ModelParameters::default();
    params.contact.density = SubContactDensity::PerEdge(5);
    let tilt = (0.97 * b / h).atan();
    params.gravity = 9.81 * Vector::new(tilt.sin(), 0.0, -tilt.cos());
    let mut model: Model = Model::new(params)?;
    model.set_joint_law(MaterialId(0), MaterialId(0), CoulombSlip::dry(kn, 0.4 * kn, 35.0)?)?;
    let base = model.add_block(common::fixed_slab("base"))?;
    let pier = model.add_block(RigidBlock::cuboid(
        "pier",
        Vector::new(-b / 2.0, -d / 2.0, 0.0),
        Vector::new(b / 2.0, d / 2.0, h),
        2500.0,
    )?)?;
    model.run_to_equilibrium(1e-6, 400_000)?;
    let block = model.block(pier)?;
    let turn = (block.state().pose.rotation * block.initial_pose().rotation.inverse())
        .to_scaled_axis()
        .y;
    let toe = Vector::new(b / 2.0, 0.0, 0.0);
    let toe = toe + block.displacement_of(toe);
    let contact = model.contact_between(base, pier).expect("a contact");
    let (mut n, mut moment) = (0.0, 0.0);
    for s in contact.subcontacts() {
        n += s.normal_force();
        moment += s.normal_force() * s.normal_force_point().x;
    }
    let inside = toe.x - moment / n;
    let c = 3.0 * inside;
    let winkler = 2.0 * n / (kn * c * c * d);
    assert!(c > 0.0 && c < 0.1 * b, "compressed strip {c} m");
    assert!(
        (turn / winkler - 1.0).abs() < 0.01,
        "turned {turn} rad, Winkler {winkler} rad (c = {c} m)"
    );
    Ok(())
}
