use super::*;
use crate::block::BlockState;
use crate::contact::{ContactPair, ContactStore, SubContact};
use crate::geometry::SubKey;
use crate::law::CoulombSlip;
use crate::math::Vector;
use crate::model::{Energies, Model};
use crate::scenes::{shaking_wall, BENCHMARK_SPACING};

/// The sub-contact ranges increase with the contacts, do not overlap, and lie in the lists,
/// which stay within the room the last fresh layout allowed.
fn check_layout<L: ConstitutiveLaw>(state: &ModelState<L>, room_limit: usize) {
    let mut end = 0;
    for (k, p) in state.contacts.pairs.iter().enumerate() {
        assert!(p.first >= end, "contact {k} starts at {} before {end}", p.first);
        end = p.first + p.count;
    }
    assert!(end as usize <= state.contacts.subs.len(), "sub-contacts past the lists");
    assert!(
        state.contacts.subs.len() <= room_limit,
        "{} sub-contacts' room past {room_limit}",
        state.contacts.subs.len()
    );
}

/// Eight bricks (0.2 × 0.1 × 0.05 m, 30 mm apart) sliding at 2 m/s, undamped, on 5° friction,
/// over a row of twelve fixed ones: their contacts with the row grow, shrink, appear
/// and vanish as they pass, while two bricks resting aside keep theirs.
fn conveyor() -> Model<CoulombSlip> {
    use crate::block::Fixity;
    use crate::ids::MaterialId;
    use crate::integrate::Damping;
    let mut model = Model::new(crate::model::ModelParameters::default()).expect("model");
    model
        .set_joint_law(
            MaterialId(0),
            MaterialId(0),
            CoulombSlip::dry(1e9, 4e8, 5.0).expect("law"),
        )
        .expect("law");
    model.set_damping(Damping::None).expect("undamped");
    let brick = |x: Real, z: Real| {
        RigidBlock::cuboid(
            "brick",
            Vector::new(x, 0.0, z),
            Vector::new(x + 0.2, 0.1, z + 0.05),
            2000.0,
        )
        .expect("brick")
    };
    // Bricks resting on fixed ones aside, first and last: contacts kept through every
    // detection, before and after the others.
    let aside = |model: &mut Model<CoulombSlip>, y: Real| {
        let aside = |b: RigidBlock| b.transformed(Pose::from_translation(Vector::new(0.0, y, 0.0)));
        model
            .add_block(aside(brick(0.0, -0.05)).with_fixity(Fixity::FIXED))
            .expect("aside");
        model.add_block(aside(brick(0.0, 0.0))).expect("aside");
    };
    aside(&mut model, 0.5);
    for k in 0..12 {
        model
            .add_block(brick(0.2 * k as Real, -0.05).with_fixity(Fixity::FIXED))
            .expect("row");
    }
    for k in 0..8 {
        let moving = brick(0.1 + 0.23 * k as Real, 0.0).with_velocity(Vector::new(2.0, 0.0, 0.0), Vector::ZERO);
        model.add_block(moving).expect("brick");
    }
    aside(&mut model, -0.5);
    model
}

/// Every contact with its sub-contacts and their keys (its `first` left out).
type Contacts<S> = Vec<(ContactPair, Vec<SubContact<S>>, Vec<SubKey>)>;

/// The keys of contact `k`'s sub-contacts.
fn keys<S>(contacts: &ContactStore<S>, k: usize) -> Vec<SubKey> {
    let (p, reference) = (&contacts.pairs[k], &contacts.references[k]);
    let subs = &contacts.subs[p.range()];
    subs.iter().enumerate().map(|(i, s)| p.key(reference, i, s)).collect()
}

/// `model` run for `steps` steps with the splices `mode` allows: the blocks' states, the
/// energies, the splice counts and the contacts at the end.
fn run<L: ConstitutiveLaw>(
    mut model: Model<L>,
    mode: SpliceMode,
    steps: usize,
) -> (Vec<BlockState>, Energies, SpliceCounts, Contacts<L::State>) {
    model.pipeline.detection.splice_mode = mode;
    for _ in 0..steps {
        model.step().expect("step");
        check_layout(&model.state, model.pipeline.detection.room_limit);
    }
    let states = model.blocks().iter().map(|b| *b.state()).collect();
    let s = &model.state;
    let contacts = s
        .contacts
        .pairs
        .iter()
        .enumerate()
        .map(|(k, p)| {
            let pair = ContactPair { first: 0, ..p.clone() };
            (pair, s.contacts.subs[p.range()].to_vec(), keys(&s.contacts, k))
        })
        .collect();
    (states, model.energies(), model.pipeline.detection.splices, contacts)
}

/// The in-place splice (re-tested contacts written over the old ones, pushing their
/// neighbours back when they outgrow their room), the full splice into the gapped layout,
/// and the full splice into a fresh layout every time give the same bits, through bricks
/// sliding over a row (contacts growing, shrinking, appearing and vanishing) and a shaking
/// wall's rocking: the sub-contact layout never shows in the results. Each path is taken.
#[test]
fn in_place_full_and_fresh_splices_give_the_same_bits() {
    type Scene = fn() -> Model<CoulombSlip>;
    let scenes: [(&str, Scene, usize); 2] = [
        ("conveyor", conveyor, 4000),
        (
            "shaking wall",
            || shaking_wall(300, BENCHMARK_SPACING).expect("wall"),
            1500,
        ),
    ];
    let mut counts = Vec::new();
    for (name, scene, steps) in scenes {
        let any = run(scene(), SpliceMode::Any, steps);
        let full = run(scene(), SpliceMode::Full, steps);
        let fresh = run(scene(), SpliceMode::Fresh, steps);
        for other in [&full, &fresh] {
            assert!(any.0 == other.0, "{name}: block states differ");
            assert_eq!(any.1, other.1, "{name}: energies differ");
            assert!(any.3 == other.3, "{name}: contacts differ");
        }
        let (f, r) = (full.2, fresh.2);
        assert_eq!(f.in_place, 0, "{name}");
        assert!(
            r.fresh == r.full && r.full > 100,
            "{name}: fresh layouts not exercised: {r:?}"
        );
        counts.push((any.2, f));
    }
    let ((conveyor, conveyor_full), (wall, _)) = (counts[0], counts[1]);
    assert!(
        conveyor.in_place > 100 && conveyor.pushed > 10 && conveyor.full > 5,
        "in-place splices with pushes, and full ones, not exercised: {conveyor:?}"
    );
    assert!(
        conveyor_full.fresh < conveyor_full.full,
        "gapped full splices not exercised: {conveyor_full:?}"
    );
    assert!(wall.in_place > 100, "the shaking wall's splices are in place: {wall:?}");
}

/// Spreading packed lists into segments moves every contact's sub-contacts (and with them
/// their keys) with it, and leaves the slack between segments.
#[test]
fn spreading_segments_keeps_every_contacts_subcontacts() {
    let mut model = shaking_wall(300, BENCHMARK_SPACING).expect("wall");
    model.step().expect("first detection");
    let state = &mut model.state;
    let contacts = state.contacts.pairs.len();
    assert!(contacts > 4 * SEGMENT, "{contacts} contacts");
    let each: Vec<_> = state
        .contacts
        .pairs
        .iter()
        .enumerate()
        .map(|(k, p)| (state.contacts.subs[p.range()].to_vec(), keys(&state.contacts, k)))
        .collect();
    // Packed again, as a full detection stages them.
    let mut subs = Vec::new();
    for (p, (s, _)) in state.contacts.pairs.iter_mut().zip(&each) {
        p.first = subs.len() as u32;
        subs.extend_from_slice(s);
    }
    let live = subs.len();
    state.contacts.subs = subs;
    state.spread_segments();
    check_layout(state, room_limit(live));
    for (k, (p, (s, r))) in state.contacts.pairs.iter().zip(&each).enumerate() {
        assert!(state.contacts.subs[p.range()] == s[..], "contact {k}'s sub-contacts");
        assert!(keys(&state.contacts, k) == r[..], "contact {k}'s keys");
    }
    let gaps = contacts.div_ceil(SEGMENT) - 1;
    assert!(
        state.contacts.subs.len() >= live + 4 * gaps,
        "{} for {live} live",
        state.contacts.subs.len()
    );
    for k in 1..=gaps {
        let (before, after) = (
            &state.contacts.pairs[k * SEGMENT - 1],
            &state.contacts.pairs[k * SEGMENT],
        );
        assert!(
            after.first >= before.first + before.count + 4,
            "no slack before segment {k}"
        );
    }
}

/// Galloping finds the partition point from any start.
#[test]
fn gallop_finds_the_partition_point() {
    let list: Vec<u32> = (0..200).map(|k| k / 3).collect();
    for start in [0, 1, 17, 100, 199, 200] {
        for x in [0, 1, 5, 33, 50, 66, 67, 80] {
            let expected = start + list[start..].partition_point(|&v| v < x);
            assert_eq!(gallop(&list, start, |&v| v < x), expected, "start {start}, x {x}");
        }
    }
}
