//! Blocks turned away from the world axes get their inertia tensor right at every scale and for
//! every shape (oblate, prolate, isotropic, generic): each block's world tensor `R·diag(I)·Rᵀ`
//! against one computed here independently (the closed form of a turned box, or a quadrature
//! over the hull's tetrahedra), and a free block spun up by a moment `M` for a time `t` turns
//! at `I⁻¹·M·t`. parry3d-f64 0.31.1's eigen solver got these wrong by up to 69 % of the largest
//! moment (`docs/parry-issue-inertia.md`).

use crate::common::Lcg;
use voussoir::build::arch::{Arch, ArchSpec};
use voussoir::build::{multi_leaf_wall, rubble_wall, running_bond_wall, MultiLeafSpec, RubbleWallSpec, WallSpec};
use voussoir::math::Matrix;
use voussoir::prelude::*;

fn outer(u: Vector) -> Matrix {
    Matrix::from_cols(u * u.x, u * u.y, u * u.z)
}

fn max_abs(m: Matrix) -> Real {
    m.to_cols_array().iter().fold(0.0, |s: Real, x| s.max(x.abs()))
}

/// The block's world inertia tensor per unit density from its own principal moments and pose.
fn tensor_of(block: &RigidBlock) -> Matrix {
    let r = Matrix::from_quat(block.state().pose.rotation);
    r * Matrix::from_diagonal(block.mass_properties().principal_inertia / block.density()) * r.transpose()
}

/// The world inertia tensor per unit density of the block's hull about its centroid, by
/// quadrature: the hull split into tetrahedra (each face fanned, each triangle joined to the
/// mean of the vertices, inside a convex hull), `∫(|x|²·𝟙 − x·xᵀ)dV` on each by the 4-point
/// rule exact for quadratics (points at 0.5854 / 0.1382 barycentric weights), with `x` taken
/// from the centroid the same rule gives. Nothing here is shared with the library's formula.
fn quadrature_tensor(block: &RigidBlock) -> (Real, Vector, Matrix) {
    let shape = block.shape();
    let pose = block.state().pose;
    let world: Vec<Vector> = shape.vertices().iter().map(|v| pose.transform_point(*v)).collect();
    let apex = world.iter().copied().sum::<Vector>() / world.len() as Real;
    let mut tets = Vec::new();
    for f in 0..shape.faces().len() {
        let ids = shape.face_loop(f);
        for k in 1..ids.len() - 1 {
            let [a, b, c] = [ids[0], ids[k], ids[k + 1]].map(|i| world[i as usize]);
            tets.push([apex, a, b, c]);
        }
    }
    let (alpha, beta) = (0.585_410_196_624_968_5, 0.138_196_601_125_010_5);
    let points = |t: &[Vector; 4]| -> [Vector; 4] {
        std::array::from_fn(|i| (0..4).fold(Vector::ZERO, |s, j| s + t[j] * if i == j { alpha } else { beta }))
    };
    let volume_of = |t: &[Vector; 4]| ((t[1] - t[0]).dot((t[2] - t[0]).cross(t[3] - t[0])) / 6.0).abs();
    let (mut volume, mut first) = (0.0, Vector::ZERO);
    for t in &tets {
        let v = volume_of(t);
        volume += v;
        first += points(t).iter().fold(Vector::ZERO, |s, p| s + *p) * (v / 4.0);
    }
    let centroid = first / volume;
    let mut tensor = Matrix::ZERO;
    for t in &tets {
        let v = volume_of(t);
        for p in points(t) {
            let x = p - centroid;
            tensor += (Matrix::from_diagonal(Vector::splat(x.length_squared())) - outer(x)) * (v / 4.0);
        }
    }
    (volume, centroid, tensor)
}

/// The box `a × b × c` about its centre, turned by `r` and moved to `at`: its corners and its
/// world tensor per unit density, `R·(V/12)·diag(b²+c², a²+c², a²+b²)·Rᵀ`.
fn turned_box(size: Vector, r: Rotation, at: Vector) -> (Vec<Vector>, Matrix) {
    let corners = (0..8)
        .map(|i| {
            let s = Vector::new((i & 1) as Real, (i >> 1 & 1) as Real, (i >> 2) as Real) - Vector::splat(0.5);
            r * (s * size) + at
        })
        .collect();
    let sq = size * size;
    let volume = size.x * size.y * size.z;
    let rm = Matrix::from_quat(r);
    let principal = Vector::new(sq.y + sq.z, sq.x + sq.z, sq.x + sq.y) * (volume / 12.0);
    (corners, rm * Matrix::from_diagonal(principal) * rm.transpose())
}

/// Spins `block` up from rest by a constant world moment, with no gravity, no contact and no
/// damping, for a few steps (rotating it by under 1e-7 rad), and returns the world moment `M`,
/// the time `t` and the angular velocity reached.
fn spin_up(block: RigidBlock, moment_scale: Real, direction: Vector) -> Result<(Vector, Real, Vector)> {
    let mut model: Model = Model::new(ModelParameters {
        gravity: Vector::ZERO,
        ..ModelParameters::default()
    })?;
    model.set_joint_law(MaterialId(0), MaterialId(0), CoulombSlip::dry(1e9, 4e8, 30.0)?)?;
    model.set_damping(Damping::None)?;
    let id = model.add_block(block)?;
    let moment = direction * moment_scale;
    model.set_load(
        id,
        Wrench {
            force: Vector::ZERO,
            moment,
        },
    )?;
    model.run_steps(4)?;
    Ok((moment, model.time(), model.block(id)?.state().angular_velocity))
}

/// Turned boxes of every aspect, at every scale from 1 mm to 10 m, and random hulls (stretched
/// into oblate, prolate and isotropic clouds): the tensor and the spin-up.
#[test]
fn turned_blocks_have_their_hulls_tensor_and_spin_up_by_it() -> Result<()> {
    let mut rng = Lcg(2026);
    let aspects = [
        ("oblate 1:4:4 (the probe's slab)", Vector::new(0.25, 1.0, 1.0)),
        ("prolate 1:1:4", Vector::new(0.25, 0.25, 1.0)),
        ("cube", Vector::new(1.0, 1.0, 1.0)),
        (
            "generic 1:2:3 (the probe's box)",
            Vector::new(1.0 / 3.0, 2.0 / 3.0, 1.0),
        ),
        ("brick", Vector::new(1.0, 0.5, 0.3)),
    ];
    let mut worst: Real = 0.0;
    let mut cases = 0;
    for scale in [1e-3, 1e-2, 0.1, 1.0, 10.0] {
        for (name, aspect) in aspects {
            for _ in 0..6 {
                let r = rng.rotation();
                let at = rng.unit() * (100.0 * scale * rng.next());
                let (corners, expected) = turned_box(aspect * scale, r, at);
                let block = RigidBlock::from_vertices("box", &corners, 2000.0)?;
                check_block(&block, expected, &format!("{name} × {scale} m"), 1e-9, &mut worst)?;
                cases += 1;
            }
        }
        for (name, stretch) in [
            ("oblate cloud", Vector::new(1.0, 1.0, 0.3)),
            ("prolate cloud", Vector::new(0.3, 0.3, 1.0)),
            ("isotropic cloud", Vector::ONE),
        ] {
            for _ in 0..6 {
                let r = rng.rotation();
                let points: Vec<Vector> = (0..24).map(|_| r * (rng.unit() * stretch * scale)).collect();
                let block = RigidBlock::from_vertices("hull", &points, 2000.0)?;
                let (volume, centroid, expected) = quadrature_tensor(&block);
                let v = block.shape().volume();
                assert!((volume - v).abs() <= 1e-12 * v, "{name}: volume {volume} against {v}");
                assert!((centroid - block.state().pose.translation).length() <= 1e-12 * scale);
                check_block(&block, expected, &format!("{name} × {scale} m"), 1e-9, &mut worst)?;
                cases += 1;
            }
        }
    }
    eprintln!("{cases} turned blocks: worst tensor error {worst:.2e} of the largest moment");
    Ok(())
}

/// The block's tensor against `expected` (per unit density, relative to its largest moment),
/// then the spin-up about a random axis against `I⁻¹·M·t`.
fn check_block(block: &RigidBlock, expected: Matrix, what: &str, tolerance: Real, worst: &mut Real) -> Result<()> {
    let largest = max_abs(expected);
    let error = max_abs(tensor_of(block) - expected) / largest;
    *worst = worst.max(error);
    assert!(
        error <= tolerance,
        "{what}: tensor {:?} against {:?} ({error:.2e} of the largest moment)",
        tensor_of(block),
        expected
    );
    let direction = Vector::new(0.8, -0.36, 0.48);
    let inertia = expected * block.density();
    // A moment that turns the block by under 1e-8 rad in its four steps (up to 3 ms each for
    // the 10 m blocks), so that the tensor's turn during the spin-up stays below the tolerance.
    let (moment, t, omega) = spin_up(block.clone(), 1e-3 * largest * block.density(), direction)?;
    let predicted = inertia.inverse() * (moment * t);
    let spin_error = (omega - predicted).length() / predicted.length();
    assert!(
        spin_error <= 1e-6,
        "{what}: ω {omega:?} after {t} s, I⁻¹·M·t = {predicted:?} ({spin_error:.2e})"
    );
    Ok(())
}

/// The generators' blocks: the reference arch (extruded along z, its in-plane moment right
/// before the fix, the others not), a multi-leaf wall, a rubble wall and a running-bond wall,
/// each block's tensor against the quadrature of its hull.
#[test]
fn the_generators_blocks_have_their_hulls_tensor() -> Result<()> {
    let mut worst: Real = 0.0;
    let sets = [
        ("reference arch", Arch::new(&ArchSpec::reference(0.15))?.blocks),
        ("multi-leaf wall", multi_leaf_wall(&MultiLeafSpec::default())?),
        ("rubble wall", rubble_wall(&RubbleWallSpec::default())?),
        ("running-bond wall", running_bond_wall(&WallSpec::default())?),
    ];
    for (name, blocks) in sets {
        for (i, block) in blocks.iter().enumerate() {
            let (_, _, expected) = quadrature_tensor(block);
            let error = max_abs(tensor_of(block) - expected) / max_abs(expected);
            worst = worst.max(error);
            assert!(error <= 1e-9, "{name}, block {i}: {error:.2e} of the largest moment");
        }
    }
    eprintln!("generators: worst tensor error {worst:.2e}");
    Ok(())
}

/// Turned blocks of every aspect save checkpoints that load and continue bit for bit: the load
/// check recomputes the tensor from the stored vertices, so it refused a 1 × 2 × 2 m slab whose
/// principal axes the old solver got wrong.
#[test]
fn turned_blocks_checkpoint_and_reload() -> Result<()> {
    let mut rng = Lcg(47);
    for size in [
        Vector::new(1.0, 2.0, 2.0),
        Vector::new(0.05, 0.2, 0.2),
        Vector::new(0.05, 0.1, 0.15),
        Vector::new(0.003, 0.001, 0.001),
    ] {
        let mut model: Model = Model::new(ModelParameters {
            gravity: Vector::ZERO,
            ..ModelParameters::default()
        })?;
        model.set_joint_law(MaterialId(0), MaterialId(0), CoulombSlip::dry(1e9, 4e8, 30.0)?)?;
        for k in 0..3 {
            let (corners, _) = turned_box(size, rng.rotation(), Vector::new(3.0 * k as Real, 0.0, 0.0));
            let block = RigidBlock::from_vertices("slab", &corners, 2000.0)?.with_velocity(rng.unit(), rng.unit());
            model.add_block(block)?;
        }
        model.run_steps(20)?;
        let text = model.to_checkpoint_string()?;
        let mut restarted = Model::<CoulombSlip>::from_checkpoint_str(&text)
            .unwrap_or_else(|e| panic!("{size:?}: the checkpoint does not load: {e}"));
        model.run_steps(20)?;
        restarted.run_steps(20)?;
        assert_eq!(
            model.to_checkpoint_string()?,
            restarted.to_checkpoint_string()?,
            "{size:?}"
        );
    }
    Ok(())
}
