//! Every `voussoir::Error` variant, provoked from user input through the public API: the right
//! variant comes back (never a panic), its fields name what is wrong, where, and the bad value,
//! and so does its message.

use crate::common;

use voussoir::block::Dof;
use voussoir::geometry::{ContactParameters, SubContactDensity};
use voussoir::prelude::*;

/// The eight corners of the unit cube, index = x + 2y + 4z.
pub(crate) fn unit_cube() -> Vec<Vector> {
    (0..8)
        .map(|i| Vector::new((i & 1) as f64, (i >> 1 & 1) as f64, (i >> 2) as f64))
        .collect()
}

/// The six faces of [`unit_cube`], counter-clockwise seen from outside.
pub(crate) fn unit_cube_faces() -> Vec<Vec<usize>> {
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
pub(crate) fn assert_names(message: &str, parts: &[&str]) {
    for p in parts {
        assert!(message.contains(p), "message {message:?} does not mention {p:?}");
    }
}

/// A model with a fixed 2 m slab (block #0) and a 0.2 m cube resting on it (block #1).
pub(crate) fn slab_and_cube(params: ModelParameters) -> Model {
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
