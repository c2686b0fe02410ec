//! Tests of the model as a whole: AVX2 and portable builds bit for bit, the sub-contact loops
//! against each other, re-detection carrying shear forces, custom integrators kept.

use super::*;
use crate::block::{Block, Wrench};
use crate::contact::{update_contact, ContactWrench, DisplacementMode, KernelContext};
use crate::error::Error;
use crate::integrate::{CentralDifference, Damping};
use crate::law::{JointStatus, MaterialId};
use crate::math::{Vector, Vector2};

/// The AVX2 builds of the contact pass and the integrator and the portable ones give
/// bit-identical results (no
/// fused multiply-add, same operations in the same order). Meaningful on a processor with
/// AVX2; elsewhere both runs take the portable path.
#[test]
fn avx2_and_portable_builds_are_bit_identical() {
    // With `VOUSSOIR_PORTABLE` set, both runs would take the portable path and prove nothing.
    assert!(
        !crate::dispatch::portable_requested(),
        "VOUSSOIR_PORTABLE is set: this test compares the AVX2 build with the portable one; unset it"
    );
    let run = |portable: bool| {
        crate::dispatch::set_portable_only(portable);
        let mut model = crate::scenes::benchmark_wall(300).expect("wall");
        model.run_steps(300).expect("run");
        crate::dispatch::set_portable_only(false);
        let states: Vec<_> = model.blocks().iter().map(|b| *b.state()).collect();
        (states, model.energies())
    };
    let (fast, fast_energy) = run(false);
    let (portable, portable_energy) = run(true);
    assert!(fast
        .iter()
        .zip(&portable)
        .any(|(a, b)| a.velocity != Vector::ZERO && a == b));
    assert_eq!(fast, portable);
    assert_eq!(fast_energy, portable_energy);
}

/// A column of four cubes on a fixed base, each overhanging the one below by 40 mm: it
/// leans and topples, so blocks move beyond the re-detection trigger, joints open onto
/// edges (node contacts) and contacts change.
pub(crate) fn toppling_column(params: ModelParameters) -> Model {
    let mut column: Model = Model::new(params).expect("model");
    column
        .set_joint_law(
            MaterialId(0),
            MaterialId(0),
            CoulombSlip::dry(1e8, 4e7, 30.0).expect("law"),
        )
        .expect("law");
    let base = RigidBlock::cuboid(
        "base",
        Vector::new(-1.0, -1.0, -0.2),
        Vector::new(1.0, 1.0, 0.0),
        2500.0,
    )
    .expect("base")
    .with_fixity(crate::block::Fixity::FIXED);
    column.add_block(base).expect("base");
    for level in 0..4 {
        let (x, z) = (0.04 * level as Real, 0.1 * level as Real);
        let cube = RigidBlock::cuboid(
            "cube",
            Vector::new(x - 0.05, -0.05, z),
            Vector::new(x + 0.05, 0.05, z + 0.1),
            2500.0,
        )
        .expect("cube");
        column.add_block(cube).expect("cube");
    }
    column
}

/// Runs both sub-contact loops on every contact of `model` from its current state and
/// checks that each sub-contact gets bit for bit the same forces, gap, status, law state and
/// slip, and each contact the same sums to round-off. Returns the numbers of sub-contacts
/// compared, sliding, open, and of nodes of node contacts (not compared: one loop).
fn compare_loops<L: ConstitutiveLaw<State = crate::law::CoulombState>>(model: &Model, law: &L) -> [usize; 4] {
    let ctx = KernelContext {
        dt: model.state.clock.dt,
        impact_speed: Real::INFINITY,
        impact_horizon: 0.0,
        stiffness_damping: 0.0,
        mode: model.state.params.mode,
        lanes: crate::contact::LaneBuild::Portable,
        joint_level: false,
        node_density: model.state.params.contact.density,
        node_rule: model.state.params.contact.node_rule,
        step: 0,
    };
    let (mut grouped_subs, mut single_subs) = (model.state.contacts.subs.clone(), model.state.contacts.subs.clone());
    let dashpots = vec![Vector::ZERO; model.state.contacts.subs.len()];
    let (mut grouped_dashpots, mut single_dashpots) = (dashpots.clone(), dashpots);
    let (mut grouped_pairs, mut single_pairs) =
        (model.state.contacts.pairs.clone(), model.state.contacts.pairs.clone());
    let mut counts = [0; 4];
    for k in 0..model.state.contacts.pairs.len() {
        let r = model.state.contacts.pairs[k].range();
        let (a, b) = (
            model.state.contacts.pairs[k].a as usize,
            model.state.contacts.pairs[k].b as usize,
        );
        let (ma, mb) = (
            crate::block::BlockMotion::of(&model.state.blocks[a]),
            crate::block::BlockMotion::of(&model.state.blocks[b]),
        );
        let (sa, sb) = (&ma, &mb);
        if matches!(model.state.contacts.pairs[k].kind, crate::geometry::ContactKind::Nodes) {
            // Node contacts have one loop (`contact/node_step.rs`).
            counts[3] += r.len();
            continue;
        }
        // The grouped loop runs without dashpot forces; the single loop when the contact may
        // hold some (none are held here, so it books zero dashpot forces).
        let (mut grouped_wrench, mut single_wrench) = (ContactWrench::default(), ContactWrench::default());
        for (dashpots, pairs, subs, dashpot_forces, wrench) in [
            (
                false,
                &mut grouped_pairs,
                &mut grouped_subs,
                &mut grouped_dashpots,
                &mut grouped_wrench,
            ),
            (
                true,
                &mut single_pairs,
                &mut single_subs,
                &mut single_dashpots,
                &mut single_wrench,
            ),
        ] {
            pairs[k].dashpots = dashpots;
            *wrench = update_contact(
                &mut pairs[k],
                &mut model.state.contacts.references[k].clone(),
                crate::contact::SmallReference::of(&model.state.contacts.small_refs, k, ctx.mode),
                &mut subs[r.clone()],
                &mut dashpot_forces[r.clone()],
                sa,
                sb,
                law,
                ctx,
                0.0,
                false,
            )
            .wrench;
        }
        for i in r {
            assert_eq!(grouped_subs[i], single_subs[i], "contact {k}, sub-contact {i}");
            assert_eq!(grouped_dashpots[i], single_dashpots[i], "contact {k}, sub-contact {i}");
            counts[0] += 1;
            counts[1] += usize::from(single_subs[i].status == JointStatus::Sliding);
            counts[2] += usize::from(single_subs[i].status == JointStatus::Open);
        }
        let (g, s) = (&grouped_pairs[k], &single_pairs[k]);
        let scale = s.normal_force.abs().max(1e-9);
        let (gw, sw) = (grouped_wrench, single_wrench);
        assert!((gw.force - sw.force).length() <= 1e-12 * scale, "contact {k}");
        assert!((g.normal_force - s.normal_force).abs() <= 1e-12 * scale, "contact {k}");
        let arm = (gw.moment_a - sw.moment_a).length() + (gw.moment_b - sw.moment_b).length();
        assert!(arm <= 1e-12 * scale, "contact {k}: {arm}");
    }
    counts
}

/// [`CoulombSlip`] with its law but without its elastic regime, so that the kernel takes
/// the four-at-a-time loop.
#[derive(Debug, Clone)]
struct WithoutRegime(CoulombSlip);

impl ConstitutiveLaw for WithoutRegime {
    type State = crate::law::CoulombState;
    fn stiffness(&self) -> crate::law::JointStiffness {
        self.0.stiffness()
    }
    fn update(
        &self,
        step: &crate::law::JointStep,
        force: &mut crate::law::JointForce,
        state: &mut Self::State,
    ) -> JointStatus {
        self.0.update(step, force, state)
    }
    fn stays_open(&self, area: Real, gap: Real, state: &Self::State) -> bool {
        self.0.stays_open(area, gap, state)
    }
}

/// Both loops for contacts without dashpot forces — sub-contacts in their elastic regime
/// first (a law with an [`crate::law::ElasticRegime`]), four at a time (a law
/// without) — give each sub-contact bit for bit the forces, gap, status, law state and slip
/// of the one-at-a-time loop (which runs when the contact has dashpot forces); only the
/// contact sums of the four-at-a-time loop, taken in another order, differ by round-off.
/// On a settling wall, and on a toppling column (incremental gaps) in large-
/// and small-displacement mode.
#[test]
fn grouped_and_single_sub_contact_loops_agree() {
    let mut wall = crate::scenes::benchmark_wall(300).expect("wall");
    // Settling: by step 100 some cells slide (the comparison must cover sliding cells).
    wall.run_steps(100).expect("run");
    let coulomb = wall.state.laws.laws()[0];
    for counts in [
        compare_loops(&wall, &coulomb),
        compare_loops(&wall, &WithoutRegime(coulomb)),
    ] {
        let [compared, sliding, open, _] = counts;
        assert!(
            compared > 10_000 && sliding > 100 && open > 100,
            "{compared} {sliding} {open}"
        );
    }

    for mode in [DisplacementMode::Large, DisplacementMode::Small] {
        let mut params = ModelParameters {
            mode,
            ..ModelParameters::default()
        };
        // Faces more than 15° apart make node contacts too (counted, not compared).
        params.contact.face_angle_tolerance = 15f64.to_radians();
        let mut column = toppling_column(params);
        let mut totals = [0; 4];
        let coulomb = column.state.laws.laws()[0];
        for _ in 0..8 {
            column.run_steps(150).expect("run");
            for counts in [
                compare_loops(&column, &coulomb),
                compare_loops(&column, &WithoutRegime(coulomb)),
            ] {
                totals.iter_mut().zip(counts).for_each(|(t, c)| *t += c);
            }
        }
        assert!(totals[0] > 1_000 && totals[2] > 10, "{mode:?}: {totals:?}");
    }
}

/// Re-detection carries each sub-contact's shear force as the same world vector, also where
/// the joint's tangents are not the ones a new contact with that normal would get (they have
/// turned with the plane): the carried components are read in the old contact's axes. A
/// tilted, near-vertical joint whose first tangent is turned 40° about the normal from the
/// fresh one; reading the components in fresh axes would turn every shear force by 40°.
#[test]
fn redetection_carries_shear_forces_in_turned_axes() {
    use crate::geometry::SubKey;
    use crate::law::JointAxes;
    use crate::math::Pose;
    let mut model: Model = Model::new(ModelParameters::default()).expect("model");
    model
        .set_joint_law(
            MaterialId(0),
            MaterialId(0),
            CoulombSlip::dry(1e9, 4e8, 30.0).expect("law"),
        )
        .expect("law");
    // Two cubes side by side (joint normal along x), the pair tilted generically.
    let tilt = Pose {
        translation: Vector::new(0.3, -0.2, 1.0),
        rotation: crate::math::Rotation::from_scaled_axis(Vector::new(0.15, -0.25, 0.6)),
    };
    let cube = |name: &str, x: Real| {
        RigidBlock::cuboid(name, Vector::new(x, 0.0, 0.0), Vector::new(x + 0.2, 0.2, 0.2), 2500.0)
            .expect("cube")
            .transformed(tilt)
            .with_fixity(crate::block::Fixity::FIXED)
    };
    model.add_block(cube("a", 0.0)).expect("a");
    // Held still too, but not `FIXED` (two fixed blocks get no contact).
    let b = cube("b", 0.2).with_fixity(crate::block::Fixity::velocity(Vector::ZERO));
    model.add_block(b).expect("b");
    model.run_steps(1).expect("detection");
    assert_eq!(model.state.contacts.pairs.len(), 1, "one joint");
    let (normal, range) = (
        model.state.contacts.pairs[0].normal,
        model.state.contacts.pairs[0].range(),
    );
    assert!(normal.z.abs() < 0.6, "a steep joint: {normal}");
    // Turn the tangents 40° about the normal and load the springs elastically.
    let fresh = JointAxes::from_normal(normal);
    let turned = crate::math::Rotation::from_axis_angle(normal, 40f64.to_radians()) * fresh.tangent;
    model.state.contacts.pairs[0].tangent = turned;
    for (i, sub) in model.state.contacts.subs[range].iter_mut().enumerate() {
        sub.force.normal = 100.0 + i as Real;
        sub.force.shear = crate::math::Vector2::new(30.0 - i as Real, 5.0 + 2.0 * i as Real);
        sub.status = JointStatus::Elastic;
    }
    let mut subs = model.state.contacts.subs[model.state.contacts.pairs[0].range()].to_vec();
    let law = model.state.laws.laws()[0];
    let poses = (model.state.blocks[0].state.pose, model.state.blocks[1].state.pose);
    model.state.contacts.pairs[0].refresh_springs(&mut subs, &law, Some((&poses.0, &poses.1)));
    let world_shears = |m: &Model| -> Vec<(SubKey, Vector)> {
        let view = m.contacts().next().expect("the joint");
        view.subcontacts().map(|s| (s.key(), s.shear_force())).collect()
    };
    let before = world_shears(&model);
    model.state.changes.insert(Changes::DETECTION);
    model.state.detect(&mut model.pipeline).expect("re-detection");
    let after = world_shears(&model);
    assert_eq!(before.len(), after.len());
    let mut worst: Real = 0.0;
    for ((k0, f0), (k1, f1)) in before.iter().zip(&after) {
        assert_eq!(k0, k1);
        worst = worst.max((*f1 - *f0).length() / f0.length());
    }
    assert!(worst < 1e-14, "shear forces changed by {worst} (relative)");
    // What fresh axes would have given: the test can tell.
    let misread = before[0].1.length() * 2.0 * (20f64.to_radians()).sin();
    let first = model.state.contacts.subs[model.state.contacts.pairs[0].range()][0]
        .force
        .shear;
    assert!((fresh.shear(first) - before[0].1).length() > 0.5 * misread);
}

/// A custom integrator is neither saved as another nor silently replaced by `set_damping`.
#[test]
fn custom_integrators_are_not_swapped_behind_the_users_back() {
    use crate::block::{BlockState, Fixity};
    use crate::geometry::MassProperties;
    use crate::integrate::{StepDurations, StepRecord};

    #[derive(Debug, Clone, Copy)]
    struct Mine(CentralDifference);
    impl Integrator for Mine {
        fn advance_block(
            &self,
            state: &mut BlockState,
            mass: &MassProperties,
            fixity: &Fixity,
            wrench: &Wrench,
            step: StepDurations,
        ) -> StepRecord {
            self.0.advance_block(state, mass, fixity, wrench, step)
        }
        fn damping(&self) -> Damping {
            self.0.damping()
        }
        fn boxed_clone(&self) -> Box<dyn Integrator> {
            Box::new(*self)
        }
    }
    let mut model: Model = Model::new(ModelParameters::default()).unwrap();
    model
        .add_block(RigidBlock::cuboid("b", Vector::ZERO, Vector::splat(0.1), 2000.0).unwrap())
        .unwrap();
    model
        .set_integrator(Mine(CentralDifference::new(Damping::None)))
        .unwrap();
    model.run_steps(3).unwrap();
    assert!(matches!(
        model.set_damping(Damping::None),
        Err(Error::Unsupported { .. })
    ));
    #[cfg(feature = "serde")]
    assert!(matches!(model.to_checkpoint_string(), Err(Error::Unsupported { .. })));
    // Central difference is restored by a checkpoint, and set_damping replaces it.
    model.set_integrator(CentralDifference::new(Damping::None)).unwrap();
    model.set_damping(Damping::Local { alpha: 0.8 }).unwrap();
    #[cfg(feature = "serde")]
    assert!(model.to_checkpoint_string().is_ok());
}

/// A model keeps its sub-contacts' dashpot forces only once Rayleigh damping puts some on them:
/// the toppling column without it keeps none (24 bytes per sub-contact saved) through its
/// re-detections; with Rayleigh damping switched on halfway it keeps one per sub-contact from
/// the next step on, through the re-detections that follow, and some are not zero.
#[test]
fn dashpot_forces_are_kept_only_with_rayleigh_damping() {
    let mut model = toppling_column(ModelParameters::default());
    model.run_steps(400).expect("run");
    let c = &model.state.contacts;
    assert!(!c.dashpots_kept && c.sub_dashpots.is_empty() && !c.subs.is_empty());
    let detections = model.state.found.detections;
    model
        .set_damping(Damping::rayleigh_stiffness(0.05, 50.0).expect("damping"))
        .expect("damped");
    model.run_steps(1200).expect("run");
    let c = &model.state.contacts;
    assert!(c.dashpots_kept && c.sub_dashpots.len() == c.subs.len() && c.in_step());
    assert!(
        model.state.found.detections > detections + 2,
        "re-detections with dashpots kept"
    );
    assert!(c.sub_dashpots.iter().any(|d| *d != Vector::ZERO));
    let e = model.energies();
    assert!(e.damping > 0.0);
}

/// What the contact pass asks the cache for ahead (`ContactPair::cells_read_by_step`) is what
/// the step reads: over steps without a detection of a wall after its first sag, a joint
/// stepped as a whole before and after a step leaves every cell untouched, and a hinge every
/// cell outside its span. Joints of both kinds are there, so that the test has something to
/// check.
#[test]
fn a_step_touches_only_the_cells_it_is_said_to_read() {
    let mut model = crate::scenes::benchmark_wall(400).unwrap();
    model.run_steps(400).unwrap();
    let (mut whole, mut hinges) = (0, 0);
    for _ in 0..60 {
        let detections = model.detection_count();
        let pairs = model.state.contacts.pairs.clone();
        let subs = model.state.contacts.subs.clone();
        model.step().unwrap();
        if model.detection_count() != detections {
            continue;
        }
        for (before, after) in pairs.iter().zip(&model.state.contacts.pairs) {
            // A joint that left during the step wrote its cells, and one that entered read
            // them (its field since the cells were written starts at zero): the hint cannot
            // know, and these are left out. Open joints keep no field.
            let entered = after.joint.field == [Vector2::ZERO; 3] && !after.joint.open;
            if !(before.joint.active && after.joint.active) || before.joint.span != after.joint.span || entered {
                continue;
            }
            let read = before.cells_read_by_step();
            if read.is_empty() {
                whole += 1;
            } else {
                hinges += 1;
            }
            for (i, (old, new)) in subs[before.range()]
                .iter()
                .zip(&model.state.contacts.subs[after.range()])
                .enumerate()
            {
                if !read.contains(&i) {
                    assert_eq!(old, new, "cell {i} of contact ({}, {}) changed", before.a, before.b);
                }
            }
        }
    }
    assert!(
        whole > 1000 && hinges > 0,
        "{whole} whole joints and {hinges} hinges checked"
    );
}
