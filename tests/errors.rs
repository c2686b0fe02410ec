//! Every `voussoir::Error` variant, provoked from user input through the public API: the right
//! variant comes back (never a panic), its fields name what is wrong, where, and the bad value,
//! and so does its message.

use crate::common;

use voussoir::block::Dof;
use voussoir::geometry::{ContactParameters, SubContactDensity};
use voussoir::prelude::*;

/// The eight corners of the unit cube, index = x + 2y + 4z.
fn unit_cube() -> Vec<Vector> {
    (0..8)
        .map(|i| Vector::new((i & 1) as f64, (i >> 1 & 1) as f64, (i >> 2) as f64))
        .collect()
}

/// The six faces of [`unit_cube`], counter-clockwise seen from outside.
fn unit_cube_faces() -> Vec<Vec<usize>> {
    vec![
        vec![0, 2, 3, 1], // z = 0
        vec![4, 5, 7, 6], // z = 1
        vec![0, 1, 5, 4], // y = 0
        vec![2, 6, 7, 3], // y = 1
        vec![0, 4, 6, 2], // x = 0
        vec![1, 3, 7, 5], // x = 1
    ]
}

/// Asserts that `message` contains every one of `parts`.
#[track_caller]
fn assert_names(message: &str, parts: &[&str]) {
    for p in parts {
        assert!(message.contains(p), "message {message:?} does not mention {p:?}");
    }
}

/// A model with a fixed 2 m slab (block #0) and a 0.2 m cube resting on it (block #1).
fn slab_and_cube(params: ModelParameters) -> Model {
    let mut model = common::model_with(params, CoulombSlip::dry(1e9, 4e8, 30.0).unwrap());
    model.add_block(common::fixed_slab("slab")).unwrap();
    model
        .add_block(common::cube("cube", Vector::new(0.1, 0.1, 0.0)))
        .unwrap();
    model
}

/// Too few points, a flat (coplanar) set and a collinear set are degenerate: the error names the
/// block and says why.
#[test]
fn degenerate_vertex_sets() {
    let three = [Vector::ZERO, Vector::X, Vector::Y];
    let e = RigidBlock::from_vertices("sliver", &three, 2000.0).unwrap_err();
    assert!(
        matches!(&e, Error::DegenerateGeometry { block, .. } if block == "sliver"),
        "{e:?}"
    );
    assert_names(&e.to_string(), &["sliver", "3 vertices"]);

    // Eight points on the plane z = 0.
    let flat: Vec<Vector> = unit_cube().iter().map(|p| Vector::new(p.x, p.y, 0.0)).collect();
    let e = RigidBlock::from_vertices("flat slab", &flat, 2000.0).unwrap_err();
    assert!(
        matches!(&e, Error::DegenerateGeometry { block, .. } | Error::NonPositiveVolume { block, .. } if block == "flat slab"),
        "{e:?}"
    );
    assert_names(&e.to_string(), &["flat slab"]);

    let line: Vec<Vector> = (0..5).map(|i| Vector::X * i as f64).collect();
    let e = RigidBlock::from_vertices("needle", &line, 2000.0).unwrap_err();
    assert!(
        matches!(&e, Error::DegenerateGeometry { block, .. } | Error::NonPositiveVolume { block, .. } if block == "needle"),
        "{e:?}"
    );

    // Explicit faces: a face with two vertices, and too few faces.
    let mut faces = unit_cube_faces();
    faces[3] = vec![2, 6];
    let e = RigidBlock::from_faces("two-vertex face", &unit_cube(), &faces, 2000.0).unwrap_err();
    assert!(matches!(&e, Error::DegenerateGeometry { .. }), "{e:?}");
    assert_names(&e.to_string(), &["two-vertex face", "face 3"]);
    let e = RigidBlock::from_faces("open box", &unit_cube(), &unit_cube_faces()[..3], 2000.0).unwrap_err();
    assert!(matches!(&e, Error::DegenerateGeometry { .. }), "{e:?}");
    assert_names(&e.to_string(), &["open box", "3 faces"]);
}

/// A (nearly) zero-volume solid: a tetrahedron 1e-15 m thick on a 1 m base is either rejected as
/// degenerate by the hull or as having a non-positive volume, naming the block.
#[test]
fn zero_volume_solid() {
    let pts = [Vector::ZERO, Vector::X, Vector::Y, Vector::new(0.3, 0.3, 1e-15)];
    let e = RigidBlock::from_vertices("wafer", &pts, 2000.0).unwrap_err();
    match &e {
        Error::NonPositiveVolume { block, volume, .. } => {
            assert_eq!(block, "wafer");
            assert!(*volume < 1e-12, "{volume}");
            assert_names(&e.to_string(), &["wafer", "volume"]);
        }
        Error::DegenerateGeometry { block, .. } => assert_eq!(block, "wafer"),
        other => panic!("unexpected {other:?}"),
    }
}

/// The volume threshold is relative to the bounding box, and its message says so: a long slender
/// slab (600 km × 1 m × 0.23 m, 137,869.8 m³) is a block — it used to be refused with "volume
/// 137869.8 m^3 is not positive", the threshold being 1e-12 of the diagonal cubed — while a
/// tetrahedron 1e-13 m thick, tilted so that its bounding box is a unit cube, is refused with a
/// message naming the bounding box's volume and the factor.
#[test]
fn volume_threshold_is_relative_to_the_bounding_box() {
    let slab = RigidBlock::cuboid("slab", Vector::ZERO, Vector::new(600_000.0, 1.0, 0.229_783), 2000.0).unwrap();
    assert!(
        (slab.shape().volume() - 137_869.8).abs() < 1e-6,
        "{}",
        slab.shape().volume()
    );
    let corners: Vec<Vector> = (0..8)
        .map(|i| {
            Vector::new(
                (i & 1) as f64 * 600_000.0,
                (i >> 1 & 1) as f64,
                (i >> 2) as f64 * 0.229_783,
            )
        })
        .collect();
    let hull = RigidBlock::from_vertices("slab", &corners, 2000.0).unwrap();
    assert!((hull.shape().volume() - 137_869.8).abs() < 1e-6);

    // Three unit points on the axes and an apex 1e-13 m above their plane x + y + z = 1.
    let apex = Vector::new(0.3, 0.3, 0.4) + Vector::splat(1e-13 / 3f64.sqrt());
    let pts = [Vector::X, Vector::Y, Vector::Z, apex];
    let mut faces = Vec::new();
    for (i, j, k, opposite) in [(0, 1, 2, 3), (0, 1, 3, 2), (0, 2, 3, 1), (1, 2, 3, 0)] {
        let n = (pts[j] - pts[i]).cross(pts[k] - pts[i]);
        faces.push(if n.dot(pts[opposite] - pts[i]) < 0.0 {
            vec![i, j, k]
        } else {
            vec![i, k, j]
        });
    }
    let e = RigidBlock::from_faces("tilted wafer", &pts, &faces, 2000.0).unwrap_err();
    let Error::NonPositiveVolume {
        block,
        volume,
        bounding_box,
    } = &e
    else {
        panic!("expected NonPositiveVolume, got {e:?}")
    };
    assert_eq!(block, "tilted wafer");
    assert!(*volume < 1e-12, "{volume}");
    assert!((bounding_box - 1.0).abs() < 1e-12, "{bounding_box}");
    assert_names(&e.to_string(), &["tilted wafer", "1e-12", "bounding box", "flat"]);
    assert!(!e.to_string().contains("not positive"), "{e}");
}

/// Explicit faces that do not make a convex solid: a cube whose top is a pyramid pushed *into*
/// the cube (a dimple), a non-planar face, inward-facing faces and a face index out of range.
/// Each error names the block and the offending face or vertex.
#[test]
fn non_convex_explicit_faces() {
    // Dimple: the top is four triangles meeting at vertex 8, pushed down to z = 0.5.
    let mut pts = unit_cube();
    pts.push(Vector::new(0.5, 0.5, 0.5));
    let mut faces = unit_cube_faces();
    faces[1] = vec![4, 5, 8];
    faces.push(vec![5, 7, 8]);
    faces.push(vec![7, 6, 8]);
    faces.push(vec![6, 4, 8]);
    let e = RigidBlock::from_faces("dimpled", &pts, &faces, 2000.0).unwrap_err();
    let Error::NonConvex { block, reason } = &e else {
        panic!("expected NonConvex, got {e:?}")
    };
    assert_eq!(block, "dimpled");
    assert!(reason.contains("vertex") && reason.contains("face"), "{reason}");
    assert_names(&e.to_string(), &["dimpled", "not convex"]);

    // A warped face: vertex 7 lifted, so the top and two sides are not planar.
    let mut warped = unit_cube();
    warped[7].z = 1.2;
    let e = RigidBlock::from_faces("warped", &warped, &unit_cube_faces(), 2000.0).unwrap_err();
    assert!(
        matches!(&e, Error::NonConvex { block, .. } if block == "warped"),
        "{e:?}"
    );
    assert_names(&e.to_string(), &["warped", "face"]);

    // Inward faces (every loop reversed).
    let inward: Vec<Vec<usize>> = unit_cube_faces()
        .into_iter()
        .map(|f| f.into_iter().rev().collect())
        .collect();
    let e = RigidBlock::from_faces("inside out", &unit_cube(), &inward, 2000.0).unwrap_err();
    assert!(
        matches!(&e, Error::NonConvex { block, .. } | Error::NonPositiveVolume { block, .. } if block == "inside out"),
        "{e:?}"
    );

    // A face that refers to a vertex that does not exist.
    let mut faces = unit_cube_faces();
    faces[0] = vec![0, 2, 3, 12];
    let e = RigidBlock::from_faces("dangling", &unit_cube(), &faces, 2000.0).unwrap_err();
    assert!(
        matches!(&e, Error::NonConvex { .. } | Error::DegenerateGeometry { .. }),
        "{e:?}"
    );
    assert_names(&e.to_string(), &["dangling", "12"]);
}

/// A NaN or infinite vertex is rejected before any geometry is built; the message names the
/// vertex index and the block.
#[test]
fn non_finite_vertices() {
    for (bad, label) in [(f64::NAN, "NaN"), (f64::INFINITY, "inf"), (f64::NEG_INFINITY, "-inf")] {
        let mut pts = unit_cube();
        pts[5].y = bad;
        let e = RigidBlock::from_vertices("voussoir 5", &pts, 2000.0).unwrap_err();
        let Error::NonFinite { what } = &e else {
            panic!("{label}: expected NonFinite, got {e:?}")
        };
        assert_names(what, &["vertex 5", "voussoir 5"]);
        let e = RigidBlock::from_faces("voussoir 5", &pts, &unit_cube_faces(), 2000.0).unwrap_err();
        assert!(
            matches!(&e, Error::NonFinite { what } if what.contains("vertex 5")),
            "{e:?}"
        );
    }
    let e = RigidBlock::cuboid("box", Vector::ZERO, Vector::new(1.0, f64::NAN, 1.0), 2000.0).unwrap_err();
    assert!(matches!(&e, Error::NonFinite { what } if what.contains("box")), "{e:?}");
}

/// Density must be positive and finite: zero, negative, NaN and infinity are each rejected with
/// the block's name and the value.
#[test]
fn bad_density() {
    for density in [0.0, -2400.0, f64::NAN, f64::INFINITY] {
        let e = RigidBlock::cuboid("keystone", Vector::ZERO, Vector::ONE, density).unwrap_err();
        let Error::InvalidParameter { name, value, .. } = &e else {
            panic!("density {density}: expected InvalidParameter, got {e:?}")
        };
        assert!(name.contains("density") && name.contains("keystone"), "{name}");
        assert!(value.to_bits() == density.to_bits(), "{value} vs {density}");
        assert_names(&e.to_string(), &["density", "keystone", &format!("{density}")]);
    }
}

/// Joint stiffness must be positive and finite, for the shipped laws and through
/// `Model::set_joint_law` (which validates the law).
#[test]
fn non_positive_stiffness() {
    let e = CoulombSlip::dry(0.0, 4e8, 30.0).unwrap_err();
    assert!(
        matches!(&e, Error::InvalidParameter { name, value, .. } if name == "normal_stiffness" && *value == 0.0),
        "{e:?}"
    );
    assert_names(&e.to_string(), &["normal_stiffness", "= 0"]);
    let e = CoulombSlip::dry(1e9, -4e8, 30.0).unwrap_err();
    assert!(
        matches!(&e, Error::InvalidParameter { name, value, .. } if name == "shear_stiffness" && *value == -4e8),
        "{e:?}"
    );
    assert_names(&e.to_string(), &["shear_stiffness", "-400000000"]);
    let e = CoulombSlip::dry(f64::NAN, 4e8, 30.0).unwrap_err();
    assert!(
        matches!(&e, Error::InvalidParameter { name, .. } if name == "normal_stiffness"),
        "{e:?}"
    );

    let mut model: Model<LinearElastic> = Model::new(ModelParameters::default()).unwrap();
    let law = LinearElastic {
        normal_stiffness: -1e9,
        shear_stiffness: 1e9,
    };
    let e = model.set_joint_law(MaterialId(0), MaterialId(1), law).unwrap_err();
    assert!(
        matches!(&e, Error::InvalidParameter { name, value, .. } if name == "normal_stiffness" && *value == -1e9),
        "{e:?}"
    );
    assert!(
        model.law_table().get(MaterialId(0), MaterialId(1)).is_none(),
        "a rejected law must not be stored"
    );
}

/// Friction angles outside [0°, 90°) are rejected, naming the parameter.
///
/// Note: the constructors take degrees but the rejected value is reported in radians (the
/// stored unit), with the hint "(given in rad)"; the check below accepts that.
#[test]
fn friction_outside_range() {
    for phi in [90.0, 95.0, -1.0, f64::NAN] {
        let e = CoulombSlip::dry(1e9, 4e8, phi).unwrap_err();
        let Error::InvalidParameter { name, value, expected } = &e else {
            panic!("{phi}°: expected InvalidParameter, got {e:?}")
        };
        assert_eq!(name, "friction_angle");
        assert!(
            value.to_bits() == phi.to_radians().to_bits() || value.to_bits() == phi.to_bits(),
            "{phi}° reported as {value}"
        );
        assert!(expected.contains("90"), "{expected}");
        assert_names(&e.to_string(), &["friction_angle", &format!("{value}")]);
    }
    // The residual angle too.
    let e = CoulombSlip::new(1e9, 4e8, 30.0, 90.0, 0.0, 0.0).unwrap_err();
    assert!(
        matches!(&e, Error::InvalidParameter { name, .. } if name == "residual_friction_angle"),
        "{e:?}"
    );
    // Negative cohesion and tensile strength.
    let e = CoulombSlip::new(1e9, 4e8, 30.0, 30.0, -1.0, 0.0).unwrap_err();
    assert!(
        matches!(&e, Error::InvalidParameter { name, value, .. } if name == "cohesion" && *value == -1.0),
        "{e:?}"
    );
    let e = CoulombSlip::new(1e9, 4e8, 30.0, 30.0, 0.0, -5.0).unwrap_err();
    assert!(
        matches!(&e, Error::InvalidParameter { name, .. } if name == "tensile_strength"),
        "{e:?}"
    );
    // 0° is admissible (frictionless).
    assert!(CoulombSlip::dry(1e9, 4e8, 0.0).is_ok());
}

/// NaN or infinite gravity is rejected by `Model::new` and `Model::set_parameters`, which then
/// leaves the model's parameters unchanged.
#[test]
fn non_finite_gravity() {
    for g in [Vector::new(0.0, 0.0, f64::NAN), Vector::new(f64::INFINITY, 0.0, -9.81)] {
        let params = ModelParameters {
            gravity: g,
            ..ModelParameters::default()
        };
        let e = Model::<CoulombSlip>::new(params).unwrap_err();
        assert!(matches!(&e, Error::NonFinite { what } if what == "gravity"), "{e:?}");
        assert_names(&e.to_string(), &["gravity"]);
        let mut model = slab_and_cube(ModelParameters::default());
        let e = model.set_parameters(params).unwrap_err();
        assert!(matches!(&e, Error::NonFinite { .. }), "{e:?}");
        assert_eq!(model.parameters().gravity, Vector::new(0.0, 0.0, -9.81));
    }
}

/// Bad contact-detection parameters and time-step settings name the field and value.
#[test]
fn bad_contact_and_run_parameters() {
    let cases: Vec<(ContactParameters, &str, f64)> = vec![
        (
            ContactParameters {
                tolerance: -1e-3,
                ..ContactParameters::default()
            },
            "contact.tolerance",
            -1e-3,
        ),
        (
            ContactParameters {
                tolerance: 0.0,
                ..ContactParameters::default()
            },
            "contact.tolerance",
            0.0,
        ),
        (
            ContactParameters {
                redetect_fraction: 0.0,
                ..ContactParameters::default()
            },
            "contact.redetect_fraction",
            0.0,
        ),
        (
            ContactParameters {
                redetect_fraction: 1.5,
                ..ContactParameters::default()
            },
            "contact.redetect_fraction",
            1.5,
        ),
        (
            ContactParameters {
                face_angle_tolerance: 1.4,
                ..ContactParameters::default()
            },
            "contact.face_angle_tolerance",
            1.4,
        ),
        (
            ContactParameters {
                density: SubContactDensity::PerEdge(0),
                ..ContactParameters::default()
            },
            "contact.density.per_edge",
            0.0,
        ),
        (
            ContactParameters {
                density: SubContactDensity::Spacing(-0.01),
                ..ContactParameters::default()
            },
            "contact.density.spacing",
            -0.01,
        ),
    ];
    for (contact, field, bad) in cases {
        let params = ModelParameters {
            contact,
            ..ModelParameters::default()
        };
        let e = Model::<CoulombSlip>::new(params).unwrap_err();
        let Error::InvalidParameter { name, value, .. } = &e else {
            panic!("{field}: expected InvalidParameter, got {e:?}")
        };
        assert_eq!(name, field);
        assert_eq!(*value, bad, "{field}");
        assert_names(&e.to_string(), &[field, &format!("{bad}")]);
    }
    let e = Model::<CoulombSlip>::new(ModelParameters {
        contact: ContactParameters {
            tolerance: f64::NAN,
            ..ContactParameters::default()
        },
        ..ModelParameters::default()
    })
    .unwrap_err();
    assert!(
        matches!(&e, Error::InvalidParameter { name, .. } if name == "contact.tolerance"),
        "{e:?}"
    );

    for (time_step, field) in [
        (TimeStep::Fixed(0.0), "time_step"),
        (TimeStep::Fixed(f64::NAN), "time_step"),
        (TimeStep::Auto { safety: 1.5 }, "time_step.safety"),
        (TimeStep::Auto { safety: 0.0 }, "time_step.safety"),
    ] {
        let e = Model::<CoulombSlip>::new(ModelParameters {
            time_step,
            ..ModelParameters::default()
        })
        .unwrap_err();
        assert!(
            matches!(&e, Error::InvalidParameter { name, .. } if name == field),
            "{time_step:?}: {e:?}"
        );
    }
    let e = Model::<CoulombSlip>::new(ModelParameters {
        max_speed: 0.0,
        ..ModelParameters::default()
    })
    .unwrap_err();
    assert!(
        matches!(&e, Error::InvalidParameter { name, .. } if name == "max_speed"),
        "{e:?}"
    );

    // Damping coefficients.
    let mut model = slab_and_cube(ModelParameters::default());
    let e = model.set_damping(Damping::Local { alpha: 1.0 }).unwrap_err();
    assert!(
        matches!(&e, Error::InvalidParameter { name, value, .. } if name == "damping.alpha" && *value == 1.0),
        "{e:?}"
    );
    let e = model
        .set_damping(Damping::Rayleigh {
            mass: -1.0,
            stiffness: 0.0,
        })
        .unwrap_err();
    assert!(
        matches!(&e, Error::InvalidParameter { name, .. } if name == "damping.mass"),
        "{e:?}"
    );
    let e = Damping::rayleigh_stiffness(0.05, 0.0).unwrap_err();
    assert!(
        matches!(&e, Error::InvalidParameter { name, .. } if name == "damping frequency"),
        "{e:?}"
    );
    let e = Damping::rayleigh(-0.05, 10.0).unwrap_err();
    assert!(
        matches!(&e, Error::InvalidParameter { name, .. } if name == "damping ratio"),
        "{e:?}"
    );
    // The model still runs with its previous (default local) damping.
    model.run_steps(10).unwrap();
}

/// A block id the model does not hold: every accessor and setter that takes an id says which id
/// and how many blocks there are.
#[test]
fn unknown_block_id() {
    let mut model = slab_and_cube(ModelParameters::default());
    let check = |e: Error| {
        assert!(
            matches!(e, Error::UnknownBlock { id, count } if id == BlockId(99) && count == 2),
            "{e:?}"
        );
        assert_names(&e.to_string(), &["99", "2 blocks"]);
    };
    check(model.block(BlockId(99)).unwrap_err());
    check(model.set_load(BlockId(99), Wrench::default()).unwrap_err());
    check(model.set_fixity(BlockId(99), Fixity::FIXED).unwrap_err());
    check(model.set_velocity(BlockId(99), Vector::X, Vector::ZERO).unwrap_err());
    check(model.reaction(BlockId(99)).unwrap_err());
    check(model.contact_wrench(BlockId(99)).unwrap_err());
    let monitor = Monitor::Reaction {
        block: BlockId(99),
        component: Component::Z,
    };
    check(
        voussoir::monitor::Recorder::new(1)
            .add_monitor(&model, "ghost", monitor)
            .unwrap_err(),
    );
    // The model is intact and runs.
    model.run_steps(5).unwrap();
    assert_eq!(model.blocks().len(), 2);
}

/// NaN loads, velocities and prescribed velocities are rejected naming the block.
#[test]
fn non_finite_loads_and_velocities() {
    let mut model = slab_and_cube(ModelParameters::default());
    let cube = BlockId(1);
    let e = model
        .set_load(
            cube,
            Wrench {
                force: Vector::new(f64::NAN, 0.0, 0.0),
                moment: Vector::ZERO,
            },
        )
        .unwrap_err();
    assert!(
        matches!(&e, Error::NonFinite { what } if what.contains("load") && what.contains("#1")),
        "{e:?}"
    );
    let e = model
        .set_velocity(cube, Vector::ZERO, Vector::new(0.0, f64::INFINITY, 0.0))
        .unwrap_err();
    assert!(
        matches!(&e, Error::NonFinite { what } if what.contains("velocity") && what.contains("#1")),
        "{e:?}"
    );
    let e = model
        .set_fixity(
            cube,
            Fixity {
                translation: [Dof::Velocity(f64::NAN), Dof::Free, Dof::Free],
                rotation: [Dof::Free; 3],
            },
        )
        .unwrap_err();
    assert!(
        matches!(&e, Error::NonFinite { what } if what.contains("cube")),
        "{e:?}"
    );
    assert_eq!(
        model.block(cube).unwrap().fixity(),
        &Fixity::FREE,
        "a rejected fixity must not stick"
    );
    let moving = RigidBlock::cuboid("thrown", Vector::new(0.5, 0.5, 0.0), Vector::new(0.7, 0.7, 0.2), 2500.0)
        .unwrap()
        .with_velocity(Vector::new(f64::NAN, 0.0, 0.0), Vector::ZERO);
    let e = model.add_block(moving).unwrap_err();
    assert!(
        matches!(&e, Error::NonFinite { what } if what.contains("thrown")),
        "{e:?}"
    );
    assert_eq!(model.blocks().len(), 2, "a rejected block must not be added");
    model.run_steps(5).unwrap();
}

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
