//! Two kinds of law in one model through `AnyLaw`: each part of the scene moves, bit for bit, as
//! it does in a model of its own law alone.

use crate::common;

use voussoir::integrate::TimeStep;
use voussoir::law::AnyLaw;
use voussoir::prelude::*;

use common::part_fingerprint;

const STONE: MaterialId = MaterialId(0);
const PAD: MaterialId = MaterialId(1);

fn coulomb() -> CoulombSlip {
    CoulombSlip::new(1e9, 4e8, 30.0, 25.0, 2e4, 1e4).unwrap()
}

fn elastic() -> LinearElastic {
    LinearElastic {
        normal_stiffness: 5e8,
        shear_stiffness: 2e8,
    }
}

/// The same fixed step in every model, so that the critical step of the other part does not
/// change a part's step.
fn parameters() -> ModelParameters {
    ModelParameters {
        time_step: TimeStep::Fixed(2e-5),
        ..ModelParameters::default()
    }
}

/// A stack of material `material` at `x0`: a fixed slab and three staggered cubes, the top one
/// thrown sideways so that its joint slides (or, elastic, swings), the middle one dropped from
/// half a millimetre. Returns the block ids.
fn stack<L: ConstitutiveLaw>(model: &mut Model<L>, x0: f64, material: MaterialId) -> Vec<BlockId> {
    let at = |x: f64, y: f64, z: f64| Vector::new(x0 + x, y, z);
    let mut ids = vec![model
        .add_block(
            RigidBlock::cuboid("slab", at(-0.5, -0.5, -0.2), at(0.5, 0.5, 0.0), 2500.0)
                .unwrap()
                .with_material(material)
                .with_fixity(Fixity::FIXED),
        )
        .unwrap()];
    for (k, (dx, dz)) in [(0.0, 0.0), (0.03, 5e-4), (0.05, 5e-4)].into_iter().enumerate() {
        let z = 0.2 * k as f64 + dz;
        let mut cube = RigidBlock::cuboid(
            &format!("cube {k}"),
            at(dx - 0.1, -0.1, z),
            at(dx + 0.1, 0.1, z + 0.2),
            2500.0,
        )
        .unwrap()
        .with_material(material);
        if k == 2 {
            cube = cube.with_velocity(Vector::new(0.4, 0.15, 0.0), Vector::new(0.0, 0.0, 1.0));
        }
        ids.push(model.add_block(cube).unwrap());
    }
    ids
}

/// A Coulomb stack and an elastic stack 10 m apart in one `Model<AnyLaw>`, against each stack
/// alone in a `Model<CoulombSlip>` and a `Model<LinearElastic>`: the block states (poses,
/// velocities, angular momenta) and the joints between them (resultants, moments, and the
/// sub-contacts' forces, slips and gaps) agree bit for bit at every checkpoint of the run. The run
/// exercises the laws' fast paths and their full updates: the top Coulomb joint slides (and
/// fails: it is cohesive), the dropped cubes bounce.
#[test]
fn any_law_model_matches_each_law_alone_bit_for_bit() {
    let mut mixed: Model<AnyLaw> = Model::new(parameters()).unwrap();
    mixed.set_joint_law(STONE, STONE, coulomb().into()).unwrap();
    mixed.set_joint_law(PAD, PAD, elastic().into()).unwrap();
    let stone_ids = stack(&mut mixed, 0.0, STONE);
    let pad_ids = stack(&mut mixed, 10.0, PAD);

    let mut stone: Model<CoulombSlip> = Model::new(parameters()).unwrap();
    stone.set_joint_law(STONE, STONE, coulomb()).unwrap();
    let alone_stone_ids = stack(&mut stone, 0.0, STONE);
    let mut pad: Model<LinearElastic> = Model::new(parameters()).unwrap();
    pad.set_joint_law(PAD, PAD, elastic()).unwrap();
    let alone_pad_ids = stack(&mut pad, 10.0, PAD);

    let start = (
        part_fingerprint(&stone, &alone_stone_ids),
        part_fingerprint(&pad, &alone_pad_ids),
    );
    for checkpoint in 1..=6 {
        for model in [&mut mixed as &mut dyn Run, &mut stone, &mut pad] {
            model.run(500);
        }
        assert_eq!(mixed.dt().to_bits(), stone.dt().to_bits());
        assert_eq!(
            part_fingerprint(&mixed, &stone_ids),
            part_fingerprint(&stone, &alone_stone_ids),
            "Coulomb stack, checkpoint {checkpoint}"
        );
        assert_eq!(
            part_fingerprint(&mixed, &pad_ids),
            part_fingerprint(&pad, &alone_pad_ids),
            "elastic stack, checkpoint {checkpoint}"
        );
    }
    // Both stacks moved, and the two laws did what only they do.
    assert_ne!(part_fingerprint(&stone, &alone_stone_ids), start.0);
    assert_ne!(part_fingerprint(&pad, &alone_pad_ids), start.1);
    let top = mixed
        .contact_between(stone_ids[2], stone_ids[3])
        .expect("the top cube stays on its stack");
    let law = mixed.law_table().laws()[top.law_index()];
    assert!(matches!(law, AnyLaw::Coulomb(_)));
    assert!(
        top.subcontacts().any(|s| law.is_failed(s.law_state())),
        "the thrown cube's joint should have slid and failed"
    );
    let slip = |c: &voussoir::contact::ContactView<'_, _>| c.subcontacts().map(|s| s.slip()).fold(0.0, f64::max);
    assert!(slip(&top) > 1e-4, "slip {}", slip(&top));
    // The linear elastic joint has no strength: it never slides.
    let held = mixed
        .contact_between(pad_ids[2], pad_ids[3])
        .expect("the top pad stays on");
    assert_eq!(slip(&held), 0.0);
}

/// A model of any law type, for running the three models in one loop.
trait Run {
    fn run(&mut self, steps: u64);
}

impl<L: ConstitutiveLaw> Run for Model<L> {
    fn run(&mut self, steps: u64) {
        self.run_steps(steps).unwrap();
    }
}

/// Two equal blocks side by side on one slab (φ = 30°), settled, then each pushed sideways by
/// 0.5 W: below tan 30° W = 0.577 W both stand. Then the interface of the second with the
/// slab gets its own law, φ = 20° (tan 20° W = 0.364 W).
fn two_blocks_on_a_slab(weak_material: MaterialId) -> (Model, [BlockId; 3]) {
    let phi30 = CoulombSlip::dry(1e9, 4e8, 30.0).unwrap();
    let mut model: Model = Model::new(ModelParameters::default()).unwrap();
    model.set_joint_law(STONE, STONE, phi30).unwrap();
    model.set_joint_law(STONE, PAD, phi30).unwrap();
    let slab = model
        .add_block(
            RigidBlock::cuboid(
                "slab",
                Vector::new(-1.0, -0.5, -0.2),
                Vector::new(1.0, 0.5, 0.0),
                2500.0,
            )
            .unwrap()
            .with_fixity(Fixity::FIXED),
        )
        .unwrap();
    let cube = |name: &str, x: f64| {
        RigidBlock::cuboid(name, Vector::new(x, -0.1, 0.0), Vector::new(x + 0.2, 0.1, 0.2), 2500.0).unwrap()
    };
    let held = model.add_block(cube("held", -0.6)).unwrap();
    let weak = model.add_block(cube("weak", 0.4).with_material(weak_material)).unwrap();
    // Settled under gravity (damped: undamped, the blocks would bounce on their joints for
    // ever): both contacts exist with the materials' law.
    model.run_to_equilibrium(1e-6, 200_000).unwrap();
    model.set_damping(Damping::None).unwrap();
    let weight = 2500.0 * 0.008 * 9.81;
    for b in [held, weak] {
        let force = Vector::new(0.5 * weight, 0.0, 0.0);
        model
            .set_load(
                b,
                Wrench {
                    force,
                    moment: Vector::ZERO,
                },
            )
            .unwrap();
    }
    (model, [slab, held, weak])
}

/// The weakened block slides as the same block does with φ = 20° as its material's law, bit
/// for bit, and about as a block on a Coulomb joint does, `x = ½ (0.5 − tan 20°) g t²`
/// (within 10 %: the sudden load first stretches the joint's shear springs, the block
/// accelerating faster than it slides until they reach the friction limit, and sets it rocking
/// on its normal springs; measured +6.6 % over 0.1 s, +3.9 % with the load at the joint's
/// plane, while the shear force stays at tan 20° of the normal force). The other block stands. A
/// law set on the interface of blocks already in contact takes effect at the next step; a
/// scene and a checkpoint keep it.
#[test]
fn an_interface_law_overrides_its_materials() {
    let phi20 = CoulombSlip::dry(1e9, 4e8, 20.0).unwrap();
    let (mut model, [slab, held, weak]) = two_blocks_on_a_slab(STONE);
    let law_of = |m: &Model, b: BlockId| m.contact_between(slab, b).unwrap().law_index();
    assert_eq!(law_of(&model, held), law_of(&model, weak));
    model.set_interface_law(weak, slab, phi20).unwrap();
    assert!(model.set_interface_law(weak, weak, phi20).is_err());
    assert!(model.set_interface_law(weak, BlockId(9), phi20).is_err());
    // The reference: the weak block of its own material, whose law with the slab's is φ 20°.
    let (mut reference, _) = two_blocks_on_a_slab(PAD);
    reference.set_joint_law(STONE, PAD, phi20).unwrap();

    // A scene and a checkpoint keep the interface's law.
    let scene = voussoir::io::scene::Scene::from_model(&model);
    assert_eq!(scene.interfaces.len(), 1);
    let rebuilt: Model = voussoir::io::scene::Scene::from_json(&scene.to_json().unwrap())
        .unwrap()
        .build()
        .unwrap();
    assert_eq!(rebuilt.law_table().get_interface(slab, weak), Some(&phi20));
    let restored: Model = Model::from_checkpoint_str(&model.to_checkpoint_string().unwrap()).unwrap();
    assert_eq!(restored.law_table().get_interface(weak, slab), Some(&phi20));

    let x = |m: &Model, b: BlockId| m.block(b).unwrap().state().pose.translation.x;
    let (held0, weak0) = (x(&model, held), x(&model, weak));
    let t0 = model.time();
    model.run_until_time(t0 + 0.1).unwrap();
    reference.run_until_time(t0 + 0.1).unwrap();
    assert_ne!(law_of(&model, held), law_of(&model, weak));
    assert_eq!(
        model.block(weak).unwrap().state(),
        reference.block(weak).unwrap().state()
    );
    let t = model.time() - t0;
    let expected = 0.5 * (0.5 - 20f64.to_radians().tan()) * 9.81 * t * t;
    let slid = x(&model, weak) - weak0;
    assert!(
        (slid - expected).abs() < 0.1 * expected,
        "slid {slid} m, expected {expected} m"
    );
    assert!((x(&model, held) - held0).abs() < 1e-4, "the held block moved");
}
