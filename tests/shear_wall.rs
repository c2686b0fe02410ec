//! The shear wall of `examples/shear_wall/` (J4D, `docs/benchmarks/shear-wall.md`) before it
//! cracks: its initial horizontal stiffness against the closed form of a stack of rigid courses
//! on joint springs.
//!
//! With each course one rigid block (990 × 62.5 × 100 mm), the wall between the fixed base and a
//! top beam kept horizontal is `n + 1` bed joints in series, each a shear spring `k_s A` and a
//! rotational spring `k_r` (the normal springs summed over the joint's cells). A
//! horizontal force `V` at the top slips every joint by `V/(k_s A)` and, with both ends held
//! horizontal (the joints' rotations sum to zero), bends joint `j` (at height `z_j`) by the
//! moment `V (H/2 − z_j)`, so
//!
//! `δ/V = (n + 1)/(k_s A) + Σ_j (z_j − H/2)² / k_r`.
//!
//! The pre-compression (0.30 MPa) keeps every joint closed (the bending stress at 20 µm is under
//! a third of it), and its second-order effect, `P/H` against the stiffness, is 2e-4 of it.

use std::ops::ControlFlow;

use voussoir::law::MortarJoint;
use voussoir::loading::{PushOver, Servo};
use voussoir::prelude::*;

const LENGTH: Real = 0.99;
const THICKNESS: Real = 0.1;
const COURSES: usize = 16;
const COURSE: Real = 1.0 / COURSES as Real;
const KN: Real = 82e9;
const KS: Real = 36e9;

fn slab(name: &str, z: (Real, Real), density: Real) -> RigidBlock {
    RigidBlock::cuboid(
        name,
        Vector::new(0.0, 0.0, z.0),
        Vector::new(LENGTH, THICKNESS, z.1),
        density,
    )
    .expect("block")
}

/// Lourenço's J4D joints: the initial stiffness measured within 0.5 % of the closed form (the
/// servo scatters by its threshold, 1e-4 of the load; second-order effects are 2e-4).
#[test]
fn initial_stiffness_matches_joint_springs_in_series() {
    let n: usize = 3;
    let law = MortarJoint::builder(KN, KS, 0.75f64.atan().to_degrees())
        .tension(0.25e6, 18.0)
        .cohesion(0.35e6, 125.0)
        .build()
        .expect("law");
    let params = ModelParameters {
        contact: ContactParameters {
            density: SubContactDensity::PerEdge(n as u16),
            ..ContactParameters::default()
        },
        time_step: TimeStep::Auto { safety: 0.8 },
        ..ModelParameters::default()
    };
    let mut model: Model<MortarJoint> = Model::new(params).expect("model");
    model.set_joint_law(MaterialId(0), MaterialId(0), law).expect("law");
    model.set_damping(Damping::Local { alpha: 0.8 }).expect("damping");
    model
        .add_block(slab("base", (-0.2, 0.0), 7850.0).with_fixity(Fixity::FIXED))
        .expect("base");
    for c in 0..COURSES {
        model
            .add_block(slab(
                &format!("course {c}"),
                (c as Real * COURSE, (c + 1) as Real * COURSE),
                2000.0,
            ))
            .expect("course");
    }
    let beam = model
        .add_block(slab("beam", (1.0, 1.2), 7850.0).with_fixity(Fixity {
            translation: [Dof::Velocity(0.0), Dof::Fixed, Dof::Free],
            rotation: [Dof::Fixed; 3],
        }))
        .expect("beam");
    model
        .set_load(
            beam,
            Wrench {
                force: Vector::new(0.0, 0.0, -0.30e6 * LENGTH * THICKNESS),
                moment: Vector::ZERO,
            },
        )
        .expect("load");
    model.run_to_equilibrium(1e-6, 1_000_000).expect("settled");
    let push = PushOver {
        max_travel: 2e-5,
        stop_fraction: 0.0,
        ..PushOver::new(Servo::new(beam, Vector::X, 2e-7, 1e-4).expect("servo"))
    };
    let r = push
        .run(&mut model, 5_000_000, |_, _| ControlFlow::Continue(()))
        .expect("push-over");
    // The least-squares slope of the load over the travel from 5 µm to the end (past the first
    // increments' transient). Not a secant: a sample's load lags its travel by up to one
    // advance while the servo waits for the wall to settle, so two samples' secant moves by
    // one advance's load (26 N of 2.6 kN, 1 %) with the phase at which they fall.
    let samples: Vec<(Real, Real)> = r
        .curve
        .iter()
        .filter(|s| s.travel >= 5e-6)
        .map(|s| (s.travel, s.load))
        .collect();
    assert!(samples.len() > 20, "{} samples", samples.len());
    let count = samples.len() as Real;
    let (mean_x, mean_y) = samples
        .iter()
        .fold((0.0, 0.0), |(x, y), &(t, l)| (x + t / count, y + l / count));
    let (sxy, sxx) = samples.iter().fold((0.0, 0.0), |(sxy, sxx), &(t, l)| {
        (sxy + (t - mean_x) * (l - mean_y), sxx + (t - mean_x) * (t - mean_x))
    });
    let measured = sxy / sxx;
    let area = LENGTH * THICKNESS;
    // A bonded joint's normal springs act at its cells' anchors (`docs/theory.md` §2.3): the
    // rotational spring is the sum over the cells along the length, not the integral. The cells
    // are the tributary strips of `n` nodes spaced `L/(n − 1)` from end to end (trapezoidal: the
    // end strips half as wide), each anchored at its centroid.
    let spacing = LENGTH / (n - 1) as Real;
    let k_r: Real = (0..n)
        .map(|i| {
            let node = i as Real * spacing;
            let (lo, hi) = ((node - 0.5 * spacing).max(0.0), (node + 0.5 * spacing).min(LENGTH));
            let lever = 0.5 * (lo + hi) - 0.5 * LENGTH;
            KN * THICKNESS * (hi - lo) * lever * lever
        })
        .sum();
    let bending: Real = (0..=COURSES).map(|j| (j as Real * COURSE - 0.5).powi(2)).sum::<Real>() / k_r;
    let expected = 1.0 / ((COURSES + 1) as Real / (KS * area) + bending);
    println!(
        "initial stiffness {:.4e} N/m, closed form {expected:.4e} N/m ({:+.2} %)",
        measured,
        100.0 * (measured / expected - 1.0)
    );
    assert!(
        (measured / expected - 1.0).abs() < 0.005,
        "{measured} N/m vs {expected} N/m"
    );
}
