//! The limit analysis of the reference arch (`scenarios::arch_limit`): the mechanism is a
//! kinematically admissible one whose work equation gives the same load (duality), for a
//! sliding case and a hinge case; the ParaView frames are written; bad options are refused.

use voussoir::block::{Block, BlockId};
use voussoir::math::Vector;
use voussoir_arch::scenarios::arch_limit::{run, write_mechanism, LimitCase};
use voussoir_arch::scenarios::arch_static::StaticCase;

fn case(friction_deg: f64) -> LimitCase {
    LimitCase {
        case: StaticCase {
            friction_deg,
            ..StaticCase::baseline()
        },
        settle: false,
    }
}

#[test]
fn the_mechanism_does_the_work_of_the_collapse_load() {
    for (phi, hinges) in [(30.5, false), (40.0, true)] {
        let r = run(&case(phi)).unwrap();
        let mu = phi.to_radians().tan();
        // Work equation of the mechanism (no cohesion: friction dissipates nothing under
        // normality): λ = −Σ W_k·v_k, the live load's power being one.
        let gravity = r.model.parameters().gravity;
        let dead_power: f64 = r
            .model
            .blocks()
            .iter()
            .enumerate()
            .map(|(k, b)| {
                let (v, _) = r.result.block_velocity(BlockId(k as u32)).unwrap();
                b.mass_properties().mass * gravity.dot(v)
            })
            .sum();
        let error = (r.summary.multiplier + dead_power).abs() / r.summary.multiplier;
        println!(
            "φ = {phi}°: limit load {:.4} kN, work of the dead loads {:.4} kN, {:.1e}; {}",
            r.summary.load / 1e3,
            -dead_power / 1e3,
            error,
            r.summary.mechanism.describe()
        );
        assert!(error < 1e-6);
        // Admissible: every corner opens at least μ times its slip (normality).
        let scale = r
            .result
            .contacts
            .iter()
            .flat_map(|c| c.vertices.iter().map(|v| v.opening.hypot(v.sliding)))
            .fold(0.0, f64::max);
        for c in &r.result.contacts {
            for v in &c.vertices {
                assert!(v.opening >= mu * v.sliding - 1e-6 * scale, "{c:?}");
            }
        }
        // The plate moves down at unit speed.
        let plate = BlockId(15);
        let (v, _) = r.result.block_velocity(plate).unwrap();
        assert!((v.dot(-Vector::Y) - 1.0).abs() < 1e-6, "{v}");
        assert_eq!(!r.summary.mechanism.hinges.is_empty(), hinges);
        assert!(r.model.blocks()[plate.index()].name().contains("plate"));
    }
}

#[test]
fn mechanism_frames_are_written() {
    let r = run(&case(30.5)).unwrap();
    let dir = std::env::temp_dir().join(format!("voussoir_limit_frames_{}", std::process::id()));
    let pvd = write_mechanism(&dir, "mechanism", &r.model, &r.result, 3, 0.01).unwrap();
    let collection = std::fs::read_to_string(&pvd).unwrap();
    assert_eq!(collection.matches("<DataSet").count(), 3);
    assert!(dir.join("mechanism_blocks_00002.vtu").exists());
    assert!(write_mechanism(&dir, "m", &r.model, &r.result, 1, 0.01).is_err());
    assert!(write_mechanism(&dir, "m", &r.model, &r.result, 3, f64::NAN).is_err());
    std::fs::remove_dir_all(&dir).unwrap();
}
