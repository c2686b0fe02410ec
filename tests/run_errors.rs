//! `voussoir::Error` variants of running, files and outputs, provoked through the public API
//! (the building errors are in `errors.rs`): the right variant comes back (never a panic), its
//! fields name what is wrong, where, and the bad value, and so does its message.

use crate::common;
use crate::errors::{assert_names, slab_and_cube, unit_cube, unit_cube_faces};

use voussoir::geometry::{ContactParameters, SubContactDensity};
use voussoir::prelude::*;

/// Two blocks of materials with no joint law between them touch: the first step fails, naming
/// both materials and both blocks.
#[test]
fn missing_joint_law() {
    let mut model = common::model(CoulombSlip::dry(1e9, 4e8, 30.0).unwrap());
    model.add_block(common::fixed_slab("slab")).unwrap();
    model
        .add_block(
            RigidBlock::cuboid("steel plate", Vector::ZERO, Vector::new(0.2, 0.2, 0.02), 7850.0)
                .unwrap()
                .with_material(MaterialId(3)),
        )
        .unwrap();
    let e = model.step().unwrap_err();
    let Error::MissingJointLaw { a, b, block_a, block_b } = e.clone() else {
        panic!("expected MissingJointLaw, got {e:?}")
    };
    assert_eq!((a, b), (MaterialId(0), MaterialId(3)));
    assert_eq!((block_a, block_b), (BlockId(0), BlockId(1)));
    assert_names(&e.to_string(), &["material 0", "material 3", "#0", "#1"]);
    // Supplying the law fixes it.
    model
        .set_joint_law(MaterialId(3), MaterialId(0), CoulombSlip::dry(1e9, 4e8, 20.0).unwrap())
        .unwrap();
    model.run_steps(10).unwrap();
}

/// A user-fixed time step of 1 s is far above the critical step of a 0.2 m stone cube on 1 GPa/m
/// springs (~1e-4 s): the first step fails naming the step, the limit and the block that sets it
/// (the cube, #1; the slab is fixed).
#[test]
fn fixed_time_step_above_the_stable_limit() {
    let params = ModelParameters {
        time_step: TimeStep::Fixed(1.0),
        ..ModelParameters::default()
    };
    let mut model = slab_and_cube(params);
    let e = model.step().unwrap_err();
    let Error::TimeStepTooLarge { dt, limit, block } = e.clone() else {
        panic!("expected TimeStepTooLarge, got {e:?}")
    };
    assert_eq!(dt, 1.0);
    assert!((1e-6..1e-2).contains(&limit), "limit {limit}");
    assert_eq!(block, BlockId(1));
    assert_names(&e.to_string(), &["time step 1 s", &format!("{limit}"), "#1"]);
    // Half the reported limit is accepted.
    let mut model = slab_and_cube(ModelParameters {
        time_step: TimeStep::Fixed(0.5 * limit),
        ..ModelParameters::default()
    });
    model.run_steps(10).unwrap();
    assert_eq!(model.dt(), 0.5 * limit);
    // Stiffness-proportional damping lowers the limit: a step just below the undamped limit
    // becomes unstable once heavy Rayleigh damping is switched on.
    let mut model = slab_and_cube(ModelParameters {
        time_step: TimeStep::Fixed(0.95 * limit),
        ..ModelParameters::default()
    });
    model.run_steps(1).unwrap();
    let heavy = Damping::Rayleigh {
        mass: 0.0,
        stiffness: 10.0 * limit,
    };
    let e = model.set_damping(heavy).unwrap_err();
    assert!(matches!(e, Error::TimeStepTooLarge { block: BlockId(1), .. }), "{e:?}");
}

/// Runs that blow up stop with `Diverged`, naming the step and the block: a 1e12 N push on a
/// 16 kg cube (speed past the 1000 m/s default limit within a few steps), and a falling block
/// with a tiny `max_speed`.
#[test]
fn diverging_runs() {
    let mut model = slab_and_cube(ModelParameters::default());
    model
        .set_load(
            BlockId(1),
            Wrench {
                force: Vector::new(1e12, 0.0, 0.0),
                moment: Vector::ZERO,
            },
        )
        .unwrap();
    let e = model.run_steps(1000).unwrap_err();
    let Error::Diverged {
        step,
        time,
        block,
        reason,
    } = e.clone()
    else {
        panic!("expected Diverged, got {e:?}")
    };
    assert_eq!(block, BlockId(1));
    assert!((1..1000).contains(&step), "step {step}");
    assert_eq!(
        step,
        model.step_count(),
        "the error names the step the model stopped at"
    );
    assert!(time > 0.0);
    assert!(reason.contains("max_speed"), "{reason}");
    assert_names(&e.to_string(), &[&format!("step {step}"), "#1"]);

    // A block in free fall above the slab with max_speed = 1 mm/s: exceeded after ~0.1 ms.
    let params = ModelParameters {
        max_speed: 1e-3,
        ..ModelParameters::default()
    };
    let mut model = common::model_with(params, CoulombSlip::dry(1e9, 4e8, 30.0).unwrap());
    model.add_block(common::fixed_slab("slab")).unwrap();
    model
        .add_block(
            RigidBlock::cuboid(
                "dropped",
                Vector::new(0.0, 0.0, 0.5),
                Vector::new(0.2, 0.2, 0.7),
                2500.0,
            )
            .unwrap(),
        )
        .unwrap();
    let e = model.run_until_time(1.0).unwrap_err();
    assert!(matches!(&e, Error::Diverged { block: BlockId(1), .. }), "{e:?}");
}

/// `run_to_equilibrium` with a budget too small for its target returns `NotConverged` with the
/// number of steps and the last unbalanced-force ratio; a non-positive target is an
/// `InvalidParameter`.
#[test]
fn equilibrium_not_reached() {
    let mut model = slab_and_cube(ModelParameters::default());
    let e = model.run_to_equilibrium(1e-12, 5).unwrap_err();
    let Error::NotConverged { what, steps, last } = e.clone() else {
        panic!("expected NotConverged, got {e:?}")
    };
    assert_eq!(steps, 5);
    assert_eq!(model.step_count(), 5);
    assert!(what.contains("unbalanced"), "{what}");
    assert!(last > 1e-12, "{last}");
    assert_names(&e.to_string(), &["5 steps", &format!("{last}")]);
    let e = model.run_to_equilibrium(0.0, 5).unwrap_err();
    assert!(
        matches!(&e, Error::InvalidParameter { value, .. } if *value == 0.0),
        "{e:?}"
    );
}

/// A model with nothing fixed falls: `run_to_equilibrium` ends with an infinite ratio (no
/// contact carries a force) and says what that means (it said only "last value inf").
#[test]
fn equilibrium_without_a_support_says_so() {
    let mut model: Model = Model::new(ModelParameters::default()).unwrap();
    model
        .set_joint_law(MaterialId(0), MaterialId(0), CoulombSlip::dry(1e9, 4e8, 30.0).unwrap())
        .unwrap();
    model
        .add_block(RigidBlock::cuboid("stone", Vector::ZERO, Vector::splat(0.2), 2500.0).unwrap())
        .unwrap();
    let e = model.run_to_equilibrium(1e-5, 200).unwrap_err();
    assert!(
        matches!(e, Error::NotConverged { last, .. } if last.is_infinite()),
        "{e:?}"
    );
    assert_names(&e.to_string(), &["200 steps", "no contact carries a force", "fixed"]);
    // A finite last value keeps the plain message.
    let mut model = slab_and_cube(ModelParameters::default());
    let e = model.run_to_equilibrium(1e-12, 5).unwrap_err();
    assert!(!e.to_string().contains("no contact"), "{e}");
}

/// File and checkpoint errors: writing a checkpoint below a regular file fails with `Io` naming
/// the path; corrupt checkpoint text fails with `Checkpoint` naming where.
#[test]
fn io_and_checkpoint_errors() {
    let mut model = slab_and_cube(ModelParameters::default());
    model.run_steps(3).unwrap();
    let dir = std::env::temp_dir().join(format!("voussoir-errors-{}", std::process::id()));
    std::fs::create_dir_all(&dir).unwrap();
    let file = dir.join("not-a-directory");
    std::fs::write(&file, "x").unwrap();
    let target = file.join("model.json");
    let e = model.save_checkpoint(&target).unwrap_err();
    assert!(matches!(&e, Error::Io { .. }), "{e:?}");
    assert_names(&e.to_string(), &["not-a-directory"]);
    std::fs::remove_dir_all(&dir).unwrap();

    for text in ["", "{", "{\"format\": 3}", "[1, 2, 3]"] {
        let e = Model::<CoulombSlip>::from_checkpoint_str(text).unwrap_err();
        assert!(matches!(&e, Error::Checkpoint { .. }), "{text:?}: {e:?}");
    }
    // A valid checkpoint with one block's coordinates corrupted to a string.
    let good = model.to_checkpoint_string().unwrap();
    assert!(Model::<CoulombSlip>::from_checkpoint_str(&good).is_ok());
    let bad = good.replacen("\"step\":3", "\"step\":\"three\"", 1);
    assert_ne!(bad, good, "the checkpoint layout changed: update the corruption");
    // Resealed (the checksum would refuse it first), so that the typed reading is reached.
    let bad = voussoir::model::reseal_checkpoint(&bad).unwrap();
    let e = Model::<CoulombSlip>::from_checkpoint_str(&bad).unwrap_err();
    let Error::Checkpoint { path, .. } = &e else {
        panic!("expected Checkpoint, got {e:?}")
    };
    assert!(path.contains("step"), "{path}");
}

/// A fixed step just below the stable limit while a cube slides onto another: as the joint
/// grows, a re-detection finds it stiffer and fails with `TimeStepTooLarge`, and so does every
/// later step (the run does not go on with the unstable step) until the step is changed.
#[test]
fn fixed_time_step_too_large_once_a_joint_grows_stays_an_error() {
    let stack = |time_step| {
        let mut model = slab_and_cube(ModelParameters {
            time_step,
            ..ModelParameters::default()
        });
        // Overlapping the lower cube by 120 mm and sliding back over it at 0.8 m/s.
        let sliding = RigidBlock::cuboid(
            "sliding",
            Vector::new(0.08, 0.0, 0.2),
            Vector::new(0.28, 0.2, 0.4),
            2500.0,
        )
        .unwrap()
        .with_velocity(Vector::new(-0.8, 0.0, 0.0), Vector::ZERO);
        model.add_block(sliding).unwrap();
        model
    };
    // The limit at the start, from a step far too large.
    let Err(Error::TimeStepTooLarge { limit, .. }) = stack(TimeStep::Fixed(1.0)).step() else {
        panic!("a 1 s step must be refused")
    };
    let dt = 0.995 * limit;
    let mut model = stack(TimeStep::Fixed(dt));
    let mut steps = 0;
    let e = loop {
        match model.step() {
            Ok(()) => steps += 1,
            Err(e) => break e,
        }
        assert!(steps < 2000, "no error within {steps} steps");
    };
    assert!(steps > 1, "failed at step {steps}: {e:?}");
    let Error::TimeStepTooLarge { limit: grown, .. } = e else {
        panic!("expected TimeStepTooLarge, got {e:?}")
    };
    assert!(grown < dt, "{grown} {limit}");
    for _ in 0..3 {
        assert!(matches!(model.step(), Err(Error::TimeStepTooLarge { .. })));
    }
    let mut params = *model.parameters();
    params.time_step = TimeStep::Fixed(0.5 * grown);
    model.set_parameters(params).unwrap();
    model.run_steps(10).unwrap();
}

/// A block's state edited through `RigidBlock::state_mut` is checked when it is added: a
/// rotation that is not a unit quaternion or a non-finite angular momentum is refused naming
/// the block.
#[test]
fn edited_block_states_are_checked_on_add() {
    let cube = || RigidBlock::cuboid("edited", Vector::ZERO, Vector::splat(0.2), 2500.0).unwrap();
    let mut model: Model = Model::new(ModelParameters::default()).unwrap();

    let mut stretched = cube();
    stretched.state_mut().pose.rotation = Rotation::from_xyzw(0.0, 0.0, 0.0, 1.01);
    let e = model.add_block(stretched).unwrap_err();
    assert!(
        matches!(&e, Error::InvalidParameter { value, .. } if (*value - 1.01).abs() < 1e-12),
        "{e:?}"
    );
    assert_names(&e.to_string(), &["edited", "rotation", "unit quaternion"]);

    let mut spinning = cube();
    spinning.state_mut().angular_momentum = Vector::new(Real::NAN, 0.0, 0.0);
    let e = model.add_block(spinning).unwrap_err();
    assert!(matches!(&e, Error::NonFinite { .. }), "{e:?}");
    assert_names(&e.to_string(), &["angular momentum", "edited"]);
}

/// A model with no blocks cannot advance time: stepping it is an error, not a run that never
/// ends (it used to loop forever with `dt` 0).
#[test]
fn an_empty_model_does_not_hang() {
    let mut model: Model = Model::new(ModelParameters::default()).unwrap();
    assert!(matches!(model.step(), Err(Error::EmptyModel)));
    assert!(matches!(model.run_until_time(1.0), Err(Error::EmptyModel)));
    assert!(matches!(model.run_steps(3), Err(Error::EmptyModel)));
}

/// A run to a NaN or infinite time is refused (a NaN end time used to return at once with
/// `Ok`, an infinite one to run for ever).
#[test]
fn non_finite_end_times_are_errors() {
    let mut model = common::model(CoulombSlip::dry(1e9, 4e8, 30.0).unwrap());
    model.add_block(common::fixed_slab("base")).unwrap();
    for t in [f64::NAN, f64::INFINITY] {
        let e = model.run_until_time(t).unwrap_err();
        assert!(matches!(&e, Error::NonFinite { .. }), "{e:?}");
        assert_names(&e.to_string(), &["end time"]);
        let mut never = |_: &Model| Ok(std::ops::ControlFlow::Continue(()));
        let e = model.run_until_time_observed(t, &mut never).unwrap_err();
        assert!(matches!(&e, Error::NonFinite { .. }), "{e:?}");
    }
    assert_eq!(model.step_count(), 0);
}

/// Two laws for one pair of materials in a scene file: an error naming both entries, not the
/// last one silently winning.
#[test]
fn duplicate_joint_laws_in_a_scene_are_errors() {
    use voussoir::io::scene::Scene;
    let path = std::path::Path::new(env!("CARGO_MANIFEST_DIR")).join("docs/examples/block-on-base.json");
    let text = std::fs::read_to_string(path).expect("example file");
    let mut json: serde_json::Value = serde_json::from_str(&text).expect("json");
    let mut second = json["joints"][0].clone();
    second["law"]["friction_deg"] = serde_json::json!(40.0);
    json["joints"].as_array_mut().expect("joints").push(second);
    let scene = Scene::<CoulombSlip>::from_json(&json.to_string()).expect("parses");
    let e = scene.build().unwrap_err();
    assert_names(&e.to_string(), &["joints[1]", "joints[0]"]);
}

/// Sub-contact grids too dense to allocate are refused with the parameter (and the block)
/// named, instead of aborting on a failed allocation of 65535² sub-contacts per face or
/// running for minutes.
#[test]
fn sub_contact_grids_too_dense_are_errors() {
    let dense = |density| ModelParameters {
        contact: ContactParameters {
            density,
            ..ContactParameters::default()
        },
        ..ModelParameters::default()
    };
    let e = Model::<CoulombSlip>::new(dense(SubContactDensity::PerEdge(65535))).unwrap_err();
    assert_names(&e.to_string(), &["contact.density.per_edge", "65535"]);
    assert!(Model::<CoulombSlip>::new(dense(SubContactDensity::PerEdge(1000))).is_ok());
    // A spacing is checked against each block as it comes.
    let mut model: Model = Model::new(dense(SubContactDensity::Spacing(1e-9))).unwrap();
    let e = model.add_block(common::cube("stone", Vector::ZERO)).unwrap_err();
    assert_names(&e.to_string(), &["contact.density.spacing", "stone"]);
    assert!(model.blocks().is_empty());
    // ... and against the blocks already there when the parameters change.
    let mut model = common::model(CoulombSlip::dry(1e9, 4e8, 30.0).unwrap());
    model.add_block(common::cube("stone", Vector::ZERO)).unwrap();
    let e = model
        .set_parameters(dense(SubContactDensity::Spacing(1e-7)))
        .unwrap_err();
    assert_names(&e.to_string(), &["contact.density.spacing", "stone"]);
    assert_eq!(*model.parameters(), ModelParameters::default());
}

/// Laws are validated wherever they come from: a stiffness the critical step cannot rest on
/// (NaN, negative) is refused by `set_joint_law`, and a checkpoint's laws are validated as they
/// load (a negative stiffness used to load, and a NaN one made the step fall back to 1e-4 s).
#[test]
fn laws_are_validated_on_every_path() {
    use voussoir::law::{JointForce, JointStatus, JointStep, JointStiffness};
    #[derive(Debug, Clone, PartialEq, serde::Serialize, serde::Deserialize)]
    struct Broken(f64);
    impl ConstitutiveLaw for Broken {
        type State = ();
        fn stiffness(&self) -> JointStiffness {
            JointStiffness {
                normal: self.0,
                shear: 1e8,
            }
        }
        fn update(&self, s: &JointStep, f: &mut JointForce, _: &mut ()) -> JointStatus {
            f.normal = -1e9 * s.normal_displacement * s.area;
            JointStatus::Elastic
        }
        fn elastic_energy(&self, _: f64, _: &JointForce, _: &()) -> f64 {
            0.0
        }
    }
    for k in [f64::NAN, -1e9, f64::INFINITY] {
        let mut model: Model<Broken> = Model::new(ModelParameters::default()).unwrap();
        let e = model
            .set_joint_law(MaterialId(0), MaterialId(0), Broken(k))
            .unwrap_err();
        assert_names(&e.to_string(), &["stiffness().normal"]);
    }
    // A linear elastic law edited to a negative stiffness in a checkpoint.
    let mut model: Model<LinearElastic> = Model::new(ModelParameters::default()).unwrap();
    let law = LinearElastic {
        normal_stiffness: 1e9,
        shear_stiffness: 4e8,
    };
    model.set_joint_law(MaterialId(0), MaterialId(0), law).unwrap();
    model.add_block(common::fixed_slab("base")).unwrap();
    let text = model.to_checkpoint_string().unwrap();
    let bad = text.replacen(
        "\"normal_stiffness\":1000000000.0",
        "\"normal_stiffness\":-1000000000.0",
        1,
    );
    assert_ne!(bad, text);
    let bad = voussoir::model::reseal_checkpoint(&bad).unwrap();
    let e = Model::<LinearElastic>::from_checkpoint_str(&bad).unwrap_err();
    assert_names(&e.to_string(), &["joints.laws[0]", "normal_stiffness"]);
}

/// A monitor at a NaN point is refused when added (it used to record NaN).
#[test]
fn monitors_at_non_finite_points_are_errors() {
    let mut model = common::model(CoulombSlip::dry(1e9, 4e8, 30.0).unwrap());
    let base = model.add_block(common::fixed_slab("base")).unwrap();
    let monitor = Monitor::Displacement {
        block: base,
        point: Vector::new(f64::NAN, 0.0, 0.0),
        component: Component::X,
    };
    let e = voussoir::monitor::Recorder::new(1)
        .add_monitor(&model, "nan point", monitor)
        .unwrap_err();
    assert!(matches!(&e, Error::NonFinite { .. }), "{e:?}");
    assert_names(&e.to_string(), &["nan point"]);
}

/// Blocks that start overlapping deeper than the contact tolerance are an error naming both
/// (two free cubes overlapping by half used to fly apart at 107 m/s each, 2.3e5 J from
/// nothing); an overlap within the tolerance is a contact, as always.
#[test]
fn initial_overlap_beyond_the_tolerance_is_an_error() {
    for (lift, overlapping) in [(-0.1, true), (-0.002, true), (-0.0005, false), (0.0, false)] {
        let mut model = common::model(CoulombSlip::dry(1e9, 4e8, 30.0).unwrap());
        model.add_block(common::fixed_slab("base")).unwrap();
        let cube = model
            .add_block(common::cube("cube", Vector::new(0.0, 0.0, lift)))
            .unwrap();
        match model.step() {
            Err(Error::InitialOverlap { a, b, depth, .. }) => {
                assert!(overlapping, "lift {lift}");
                assert_eq!((a, b), (BlockId(0), cube));
                assert!((depth + lift).abs() < 1e-9, "{depth} vs {lift}");
            }
            Ok(()) => assert!(!overlapping, "lift {lift} should be refused"),
            Err(e) => panic!("{e}"),
        }
    }
}

/// A series name that is not a portable file name (here one that would write outside the
/// series folder) is `InvalidName`, naming the name and the separator, before anything is
/// written (tests/vtk_output.rs checks the other characters and the folder).
#[test]
fn series_names_that_are_not_file_names_are_errors() {
    let model = slab_and_cube(ModelParameters::default());
    let dir = std::env::temp_dir().join(format!("voussoir-errors-series-{}", std::process::id()));
    let e = voussoir::io::vtk::Series::new(&dir, "../up")
        .write_frame(&model)
        .unwrap_err();
    let Error::InvalidName { what, name, reason } = &e else {
        panic!("expected InvalidName, got {e:?}")
    };
    assert_eq!((*what, name.as_str()), ("series name", "../up"));
    assert!(reason.contains("separator"), "{reason}");
    assert_names(&e.to_string(), &["series name", "\"../up\"", "'/'"]);
    assert!(!dir.exists(), "{} was created", dir.display());
}

/// A block whose convex hull has more than `MAX_HULL_VERTICES` vertices is refused at
/// construction, naming the block, the count and the limit: a 20,000-point sphere used to be
/// accepted and its first step on a slab took 10–14 s (two touching 1,000-vertex blocks: 13 s).
/// Interior points do not count, and a shape at the limit is accepted.
#[test]
fn hulls_with_too_many_vertices_are_errors() {
    use voussoir::geometry::MAX_HULL_VERTICES;
    // Points on a sphere (Fibonacci lattice): every one is a hull vertex.
    let sphere = |n: usize| -> Vec<Vector> {
        let g = std::f64::consts::PI * (3.0 - 5f64.sqrt());
        (0..n)
            .map(|i| {
                let z = 1.0 - 2.0 * (i as f64 + 0.5) / n as f64;
                let r = (1.0 - z * z).sqrt();
                let t = g * i as f64;
                Vector::new(0.1 * r * t.cos(), 0.1 * r * t.sin(), 0.1 * z)
            })
            .collect()
    };
    for n in [MAX_HULL_VERTICES + 1, 20_000] {
        let e = RigidBlock::from_vertices("boulder", &sphere(n), 2500.0).unwrap_err();
        let Error::TooManyVertices { block, vertices, limit } = &e else {
            panic!("expected TooManyVertices, got {e:?}")
        };
        assert_eq!((block.as_str(), *vertices, *limit), ("boulder", n, MAX_HULL_VERTICES));
        assert_names(
            &e.to_string(),
            &["boulder", &n.to_string(), &MAX_HULL_VERTICES.to_string()],
        );
    }
    let at_limit = RigidBlock::from_vertices("boulder", &sphere(MAX_HULL_VERTICES), 2500.0).unwrap();
    assert_eq!(at_limit.shape().vertices().len(), MAX_HULL_VERTICES);
    // A cube given with 20,000 interior points has 8 hull vertices.
    let mut cloud = unit_cube();
    cloud.extend(
        (0..20_000).map(|i| Vector::new(0.5, 0.25 + (i % 100) as f64 * 0.005, 0.25 + (i / 100) as f64 * 0.0025)),
    );
    assert_eq!(
        RigidBlock::from_vertices("cloud", &cloud, 2500.0)
            .unwrap()
            .shape()
            .vertices()
            .len(),
        8
    );
    // Explicit faces: refused before the convexity check.
    let many = sphere(MAX_HULL_VERTICES + 1);
    let e = RigidBlock::from_faces("faceted", &many, &unit_cube_faces(), 2500.0).unwrap_err();
    assert!(
        matches!(&e, Error::TooManyVertices { block, .. } if block == "faceted"),
        "{e:?}"
    );
}
