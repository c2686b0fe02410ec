//! The J4D wall as a model: the joints' stiffnesses and laws, the blocks, the pre-compression,
//! the push-over, and the joints' damage read back.

use super::*;

/// The joints' stiffnesses: (bed, head) joints, and the potential cracks in the units.
pub(super) struct Stiffnesses {
    pub(super) bed: (Real, Real),
    pub(super) head: (Real, Real),
    pub(super) unit: (Real, Real),
}

impl Stiffnesses {
    pub(super) fn of(stiffness: StiffnessArg, unit_cracks: bool) -> Self {
        let head_length = if unit_cracks { 0.5 * UNIT_LENGTH } else { UNIT_LENGTH };
        let unit = match stiffness {
            StiffnessArg::Joints => (UNIT_STIFFNESS_FACTOR * KN, UNIT_STIFFNESS_FACTOR * KS),
            StiffnessArg::Lumped => (UNIT_E / (0.5 * UNIT_LENGTH), UNIT_G / (0.5 * UNIT_LENGTH)),
        };
        Self {
            bed: stiffness.of(COURSE_HEIGHT),
            head: stiffness.of(head_length),
            unit,
        }
    }
}

/// The potential crack in the units, of stiffnesses `(kn, ks)`.
pub(super) fn unit_law((kn, ks): (Real, Real)) -> Result<MortarJoint> {
    let phi = UNIT_TAN_PHI.atan().to_degrees();
    MortarJoint::builder(kn, ks, phi)
        .tension(UNIT_FT, UNIT_GF_I)
        .cohesion(UNIT_C, GF_II * (UNIT_C / COHESION))
        .build()
}

/// The bricks of even courses and the top beam are of one material, those of odd courses and the
/// base of the other: a bed joint is between the two, a head joint within one.
pub(super) const EVEN: MaterialId = MaterialId(1);
pub(super) const ODD: MaterialId = MaterialId(2);

/// A wall ready to push: the model, the top beam and the pairs of brick halves (unit cracks).
pub(super) struct Wall {
    pub(super) model: Model<MortarJoint>,
    pub(super) beam: BlockId,
    pub(super) unit_pairs: HashSet<(BlockId, BlockId)>,
}

pub(super) fn cuboid(name: &str, x: (Real, Real), z: (Real, Real), density: Real) -> Result<RigidBlock> {
    RigidBlock::cuboid(
        name,
        Vector::new(x.0, 0.0, z.0),
        Vector::new(x.1, THICKNESS, z.1),
        density,
    )
}

/// The x-edges of the units of course `c`: 4 whole bricks and a half brick, the half at the
/// right end on even courses and at the left on odd ones (990 = 4.5 × 220 mm).
pub(super) fn course_edges(c: usize) -> Vec<Real> {
    let half = 0.5 * UNIT_LENGTH;
    if c.is_multiple_of(2) {
        let mut e: Vec<Real> = (0..=4).map(|k| k as Real * UNIT_LENGTH).collect();
        e.push(LENGTH);
        e
    } else {
        let mut e = vec![0.0];
        e.extend((0..=4).map(|k| half + k as Real * UNIT_LENGTH));
        e
    }
}

pub(super) fn build(joints: Joints, options: &Options) -> Result<Wall> {
    let (per_edge, unit_cracks, top) = (options.per_edge, options.unit_cracks, options.top);
    let stiffnesses = Stiffnesses::of(options.stiffness, unit_cracks);
    let params = ModelParameters {
        contact: ContactParameters {
            density: SubContactDensity::PerEdge(per_edge),
            ..ContactParameters::default()
        },
        // A quasi-static run: no margin for impacts needed (`loading` module docs).
        time_step: TimeStep::Auto { safety: 0.8 },
        ..ModelParameters::default()
    };
    let mut model: Model<MortarJoint> = Model::new(params)?;
    let cap = options.cap.cap();
    model.set_joint_law(EVEN, ODD, joints.law(stiffnesses.bed, cap)?)?;
    model.set_joint_law(EVEN, EVEN, joints.law(stiffnesses.head, cap)?)?;
    model.set_joint_law(ODD, ODD, joints.law(stiffnesses.head, cap)?)?;
    model.set_damping(Damping::Local { alpha: 0.8 })?;
    // The fixed base: the bottom steel beam with the clamped bottom course.
    model.add_block(
        cuboid("base", (0.0, LENGTH), (-BEAM_DEPTH, 0.0), STEEL_DENSITY)?
            .with_fixity(Fixity::FIXED)
            .with_material(ODD),
    )?;
    let mut unit_pairs = HashSet::new();
    let law = unit_law(stiffnesses.unit)?;
    for c in 0..COURSES {
        let z = (c as Real * COURSE_HEIGHT, (c + 1) as Real * COURSE_HEIGHT);
        let material = if c.is_multiple_of(2) { EVEN } else { ODD };
        let brick = |name: String, x: (Real, Real)| -> Result<RigidBlock> {
            Ok(cuboid(&name, x, z, BRICK_DENSITY)?.with_material(material))
        };
        for (k, x) in course_edges(c).windows(2).enumerate() {
            let whole = x[1] - x[0] > 0.75 * UNIT_LENGTH;
            if unit_cracks && whole {
                let mid = 0.5 * (x[0] + x[1]);
                let a = model.add_block(brick(format!("brick c{c} k{k} a"), (x[0], mid))?)?;
                let b = model.add_block(brick(format!("brick c{c} k{k} b"), (mid, x[1]))?)?;
                model.set_interface_law(a, b, law)?;
                unit_pairs.insert((a, b));
            } else {
                model.add_block(brick(format!("brick c{c} k{k}"), (x[0], x[1]))?)?;
            }
        }
    }
    // The top beam with the clamped top course: pushed along x by the servo, held in y, free
    // to rise or sink under its load, kept horizontal.
    // Its material is the even courses' (the top course, 15, is odd).
    let beam = cuboid("top beam", (0.0, LENGTH), (HEIGHT, HEIGHT + BEAM_DEPTH), STEEL_DENSITY)?
        .with_fixity(Fixity {
            translation: [Dof::Velocity(0.0), Dof::Fixed, Dof::Free],
            rotation: [Dof::Fixed; 3],
        })
        .with_material(EVEN);
    let beam_weight = STEEL_DENSITY * LENGTH * THICKNESS * BEAM_DEPTH * 9.81;
    let beam = model.add_block(beam)?;
    let total = PRECOMPRESSION * LENGTH * THICKNESS * (1.0 + options.perturbation);
    model.set_load(
        beam,
        Wrench {
            force: Vector::new(0.0, 0.0, -(total - beam_weight)),
            moment: Vector::ZERO,
        },
    )?;
    model.run_to_equilibrium(1e-5, 2_000_000)?;
    if top == TopArg::Confined {
        model.set_fixity(
            beam,
            Fixity {
                translation: [Dof::Velocity(0.0), Dof::Fixed, Dof::Fixed],
                rotation: [Dof::Fixed; 3],
            },
        )?;
    }
    Ok(Wall {
        model,
        beam,
        unit_pairs,
    })
}

/// A push-over of the top beam to `travel` (m), sampling every 10 µm; `on_sample` sees each
/// settled sample.
pub(super) fn push(
    wall: &mut Wall,
    servo: Servo,
    travel: Real,
    mut on_sample: impl FnMut(&Model<MortarJoint>, Real, Real, Real),
) -> Result<PushOverResult> {
    let pushover = PushOver {
        max_travel: travel,
        stop_fraction: 0.0,
        sample_travel: 1e-5,
        smoothing_window: 5e-5,
        ..PushOver::new(servo)
    };
    let beam = wall.beam;
    pushover.run(&mut wall.model, 200_000_000, |m, s| {
        // The vertical force the beam puts on the wall (N, downwards positive).
        let vertical = m.contact_wrench(beam).map_or(Real::NAN, |w| w.force.z);
        on_sample(m, s.travel, s.load, vertical);
        ControlFlow::Continue(())
    })
}

/// The damage of each joint at the end: (kind, x, z, mean fraction of strength lost, blocks).
pub(super) struct JointDamage {
    pub(super) kind: &'static str,
    pub(super) x: (Real, Real),
    pub(super) z: (Real, Real),
    pub(super) lost: Real,
}

pub(super) fn joint_damage(wall: &Wall) -> Result<Vec<JointDamage>> {
    let model = &wall.model;
    let table = model.law_table();
    let law_of = |a: BlockId, b: BlockId| -> Result<MortarJoint> {
        let (ma, mb) = (model.block(a)?.material(), model.block(b)?.material());
        let index = table.index_for((a, ma), (b, mb)).expect("every pair has a law");
        Ok(table.laws()[index as usize])
    };
    let mut out = Vec::new();
    for contact in wall.model.contacts() {
        // Node contacts (where blocks meet at an edge) are no joints, and start unbonded.
        if matches!(contact.kind(), ContactKind::Nodes) {
            continue;
        }
        let (a, b) = contact.blocks();
        let n = contact.normal();
        let law = law_of(a, b)?;
        let kind = if wall.unit_pairs.contains(&(a, b)) || wall.unit_pairs.contains(&(b, a)) {
            "unit"
        } else if n.z.abs() > 0.9 {
            "bed"
        } else if n.x.abs() > 0.9 {
            "head"
        } else {
            continue;
        };
        let (mut lost, mut count) = (0.0, 0usize);
        let (mut x, mut z) = (
            (Real::INFINITY, Real::NEG_INFINITY),
            (Real::INFINITY, Real::NEG_INFINITY),
        );
        for s in contact.subcontacts() {
            lost += 1.0 - law.strengths(s.law_state()).remaining;
            count += 1;
            let p = s.point();
            x = (x.0.min(p.x), x.1.max(p.x));
            z = (z.0.min(p.z), z.1.max(p.z));
        }
        if count > 0 {
            out.push(JointDamage {
                kind,
                x,
                z,
                lost: lost / count as Real,
            });
        }
    }
    Ok(out)
}
