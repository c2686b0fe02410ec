//! Golden fingerprints: the bits of a few fixed scenes (every block state, contact and energy
//! term after a fixed number of steps, [`common::fingerprint`]), hashed and kept here, on one and
//! on two threads.
//!
//! A change that should not change the physics (a faster loop, a new layout, a split file) must
//! leave every hash as it is. A change that does change it (a new contact formulation) updates
//! the hashes of the scenes it changes, and only those, in the same commit, saying why: the
//! failure message prints the new value. The scenes cover face contacts (a wall settling, a
//! shaking wall, a cube landing flat), node contacts (a cube landing on an edge and on a
//! corner, a tetrahedron landing on a vertex) and the changes between them. The node-contact
//! hashes changed with issue 29 (node contacts replaced point contacts; tilted faces that first
//! meet are node contacts); the face-contact ones did not. The face-contact ones changed with
//! the cells' closed-form integration (round-off only: the all-closed cells' moments summed
//! once per contact, `−k_n s Σ J`, and the straddling cells integrated in closed form instead of
//! by triangles, which agree to 1e-15 of the cell's force). The settling wall's changed when a
//! dry joint touching at exactly zero gap became open (it was elastic or sliding with zero
//! force: the same forces, other statuses and slips), and the face-contact ones when joints
//! closed everywhere were taken four cells at a time (`contact/closed_lanes.rs`; round-off
//! only: each cell's forces keep their bits, the contact's sums are taken per lane). The walls'
//! changed again when `running_bond_wall` placed copies of one brick at their centres (the
//! bricks share one shape; their corners moved by round-off), and when joints closed all over
//! and sticking were stepped as a whole (issue 45, `contact/joint_level.rs`; round-off only:
//! their sums come from the cells' area moments, and their shear history is kept as
//! `F⁰ − k_s A U`; the drops' frictionless joints never stick and kept their bits). The
//! face-contact ones changed again when the critical time step took a face joint's area
//! moments from those its cells keep on the anchor plane (issue 45; round-off only: the same
//! moments, summed otherwise, so the time step's last bits moved); the node-contact drops
//! kept theirs. The walls' changed again when a joint stopped entering joint-level stepping
//! while its corners already fail the test it would meet at its next step (issue 45; round-off
//! only: a joint closed by round-off with next to no load had entered and left again at every
//! step, its cells written from the joint's record each time; it now stays with its cells).
//! The shaking wall's changed again when joints open in part (hinges) were stepped as a whole
//! but for the cells the line `g = 0` crosses and the open ones (issue 45; round-off only: the
//! closed cells' forces summed from the joint's moments, as for a joint closed all over); the
//! settling wall's too when such a joint may enter with an eighth of its cells closed rather
//! than half (round-off only, for the same reason). The shaking wall's changed again when a
//! hinge's open cells at one end were stepped as a whole too (issue 45; round-off only: such
//! a hinge leaves when an open cell starts to close, where that cell closed within the range
//! before, and the step after sums its closed cells one by one).
//!
//! The values are those of x86_64 (with or without AVX2: both kernels give the same bits); the
//! test does not run elsewhere.
#![cfg(target_arch = "x86_64")]

use crate::common;

use common::{fingerprint, fixed_slab};
use voussoir::prelude::*;

/// FNV-1a over the words of a fingerprint.
fn hash(words: &[u64]) -> u64 {
    let mut h: u64 = 0xcbf2_9ce4_8422_2325;
    for w in words {
        for byte in w.to_le_bytes() {
            h ^= u64::from(byte);
            h = h.wrapping_mul(0x0100_0000_01b3);
        }
    }
    h
}

/// An undamped, frictionless model (the drops) or the default one.
fn drop_model() -> Model {
    let mut model = common::model(CoulombSlip::dry(1e9, 1e9, 0.0).expect("law"));
    model.set_damping(Damping::None).expect("damping");
    model
}

/// A cube released 20 mm above the slab, turned by `tilt` (rad) about x then about y.
fn cube_drop(tilt: (Real, Real)) -> Model {
    let mut model = drop_model();
    model.add_block(fixed_slab("slab")).expect("slab");
    model.add_block(common::tilted_cube("cube", tilt, 0.02)).expect("cube");
    model
}

/// A regular tetrahedron (0.2 m edges) released vertex down 20 mm above the slab.
fn tetrahedron_drop() -> Model {
    let mut model = drop_model();
    model.add_block(fixed_slab("slab")).expect("slab");
    let a = 0.2 / 2f64.sqrt();
    let up = [
        Vector::new(a, a, a),
        Vector::new(a, -a, -a),
        Vector::new(-a, a, -a),
        Vector::new(-a, -a, a),
    ]
    .map(|v| 0.5 * v);
    // Turned so that the vertex (a, a, a) points down, slightly off the vertical.
    let turn = Rotation::from_rotation_arc(Vector::new(1.0, 1.0, 1.0).normalize(), -Vector::Z)
        * Rotation::from_rotation_x(0.05);
    let vertices = up.map(|v| turn * v);
    let lowest = vertices.iter().map(|v| v.z).fold(Real::INFINITY, Real::min);
    let placed = vertices.map(|v| v + Vector::new(0.0, 0.0, 0.02 - lowest));
    model
        .add_block(RigidBlock::from_vertices("tetrahedron", &placed, common::STONE_DENSITY).expect("tetrahedron"))
        .expect("tetrahedron");
    model
}

/// A scene: its name, how it is built, its steps and its golden hash.
///
/// History of the hashes: set at 30dbef7 (equal to those of cc8f339, before issue 34's
/// changes); the edge, corner and tetrahedron drops changed with issue 33's travel cap on the
/// automatic step (a block moves at most half the contact tolerance per step: their point
/// contacts' larger critical step let them fall 0.6 mm per step).
type Scene = (&'static str, fn() -> Model, u64, u64);

/// The scenes.
fn scenes() -> Vec<Scene> {
    vec![
        ("cube flat", || cube_drop((0.0, 0.0)), 1500, 0xfd3a_a393_3d2b_7b52),
        ("cube on an edge", || cube_drop((0.5, 0.0)), 1500, 0x38a1_94b9_f345_5b52),
        (
            "cube on a corner",
            || cube_drop((0.6, 0.7)),
            1500,
            0x0dc6_da58_60d3_6d96,
        ),
        ("tetrahedron on a vertex", tetrahedron_drop, 1500, 0x83ad_c639_e483_dd7e),
        (
            "settling wall",
            || voussoir::scenes::benchmark_wall(300).expect("wall"),
            200,
            0x3fd4_e64d_e29e_497b,
        ),
        (
            "shaking wall",
            || voussoir::scenes::shaking_wall(300, voussoir::scenes::BENCHMARK_SPACING).expect("wall"),
            400,
            0x91f5_d8f8_1c0b_2006,
        ),
    ]
}

#[test]
fn fixed_scenes_keep_their_bits_on_one_and_two_threads() {
    let pool = |n| rayon::ThreadPoolBuilder::new().num_threads(n).build().expect("pool");
    let mut changed = Vec::new();
    for (name, build, steps, golden) in scenes() {
        let run = || {
            let mut model = build();
            model.run_steps(steps).expect("run");
            hash(&fingerprint(&model))
        };
        let (one, two) = (pool(1).install(run), pool(2).install(run));
        assert_eq!(one, two, "{name}: 1 and 2 threads differ");
        if one != golden {
            changed.push(format!("{name}: {one:#018x} (kept: {golden:#018x})"));
        }
    }
    assert!(
        changed.is_empty(),
        "the bits of these scenes changed; if the physics changed on purpose, update their hashes \
         in tests/golden_fingerprints.rs and say why in the commit:\n{}",
        changed.join("\n")
    );
}
