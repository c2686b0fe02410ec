//! Tests of the conformance kit: it passes the shipped laws and catches laws that break each
//! clause.

use super::*;
use crate::law::{AnyLaw, CoulombSlip, CoulombState, ElasticRegime, JointStiffness, LinearElastic};

fn coulomb_laws() -> [CoulombSlip; 4] {
    [
        CoulombSlip::dry(4e9, 1.6e9, 30.0).unwrap(),
        CoulombSlip::new(4e9, 1.6e9, 35.0, 25.0, 2e5, 0.0).unwrap(),
        CoulombSlip::new(1e9, 1e9, 30.0, 20.0, 1e5, 5e4).unwrap(),
        CoulombSlip::new(1e9, 1e9, 0.0, 0.0, 0.0, 1e4).unwrap(),
    ]
}

/// The grid of displacements is sorted, holds both zeros, and is symmetric.
#[test]
fn gap_grid() {
    let g = gaps();
    assert!(g.windows(2).all(|w| w[0] <= w[1]));
    assert_eq!(g.len(), 2 * 35 + 2);
    assert!(g.iter().any(|x| x.to_bits() == (-0.0f64).to_bits()));
    assert!(g.iter().zip(g.iter().rev()).all(|(a, b)| *a == -*b));
}

/// The shipped laws conform, offer both shortcuts where they should, and `AnyLaw` gives the
/// same report as the law it wraps.
#[test]
fn shipped_laws_conform() {
    for law in coulomb_laws() {
        let report = check(&law).unwrap_or_else(|e| panic!("{law:?}: {e}"));
        // Frictionless and cohesionless, the last stands only without shear.
        let stood = if law.friction_angle() > 0.0 { 1000 } else { 100 };
        assert!(
            report.regime_stood > stood && report.regime_declined > 1000,
            "{report:?}"
        );
        assert!(report.updates > 10_000, "{report:?}");
        assert_eq!(check(&AnyLaw::from(law)), Ok(report));
    }
    // Dry with equal residual friction: nothing ever fails, open joints stay open.
    let dry = check(&coulomb_laws()[0]).unwrap();
    assert_eq!(dry.states, 1);
    assert!(dry.open_promised > 0);
    // Bonded: failure reached; open promised only once failed.
    let bonded = check(&coulomb_laws()[2]).unwrap();
    assert_eq!(bonded.states, 2);
    assert!(bonded.open_promised > 0);
    let elastic = LinearElastic {
        normal_stiffness: 3e9,
        shear_stiffness: 1.2e9,
    };
    let report = check(&elastic).unwrap();
    assert!(report.regime_stood > 1000 && report.open_promised == 0, "{report:?}");
    assert_eq!(check(&AnyLaw::from(elastic)), Ok(report));
}

/// A law that breaks one promise at a time, each on an otherwise correct `CoulombSlip`.
#[derive(Debug, Clone)]
struct Broken {
    law: CoulombSlip,
    flaw: Flaw,
}

#[derive(Debug, Clone, Copy, PartialEq)]
enum Flaw {
    /// `stays_open` for any opening, forgetting that an intact bonded joint fails.
    OpenIgnoresState,
    /// Claims the regime of a stiffer spring.
    StifferRegime,
    /// The normal force reassociated: `−kn·(u_n·A)`, off by an ulp at times.
    Reassociated,
    /// `stiffness()` half the spring's.
    SoftStiffness,
    /// An open joint keeps its shear force.
    OpenKeepsShear,
    /// Elastic energy of the wrong sign.
    NegativeEnergy,
    /// Gives energy back while sliding: the shear force pushes along the slip (and does not
    /// claim that its regime slides).
    ActiveSlip,
    /// The same, claiming that its regime slides as Coulomb's does.
    ActiveSlipInRegime,
    /// Returns a different force every other call.
    Flaky,
    /// Reports fracture work of the wrong sign at a failure.
    NegativeFracture,
}

impl ConstitutiveLaw for Broken {
    type State = CoulombState;
    fn stiffness(&self) -> JointStiffness {
        let k = self.law.stiffness();
        match self.flaw {
            Flaw::SoftStiffness => JointStiffness {
                normal: 0.5 * k.normal,
                shear: k.shear,
            },
            _ => k,
        }
    }
    fn update(&self, step: &JointStep, force: &mut JointForce, state: &mut CoulombState) -> JointStatus {
        let before = force.shear;
        let status = self.law.update(step, force, state);
        match self.flaw {
            Flaw::Reassociated if status == JointStatus::Elastic => {
                force.normal = -self.law.normal_stiffness() * (step.normal_displacement * step.area);
            }
            Flaw::OpenKeepsShear if status == JointStatus::Open => force.shear = before,
            Flaw::ActiveSlip | Flaw::ActiveSlipInRegime if status == JointStatus::Sliding => force.shear = -force.shear,
            Flaw::Flaky => {
                use std::sync::atomic::{AtomicU64, Ordering};
                static CALLS: AtomicU64 = AtomicU64::new(0);
                if CALLS.fetch_add(1, Ordering::Relaxed) % 2 == 1 {
                    force.normal *= 1.0 + 1e-15;
                }
            }
            _ => {}
        }
        status
    }
    fn stays_open(&self, area: Real, gap: Real, state: &CoulombState) -> bool {
        match self.flaw {
            Flaw::OpenIgnoresState => gap > 0.0,
            _ => self.law.stays_open(area, gap, state),
        }
    }
    fn elastic_regime(&self) -> Option<ElasticRegime> {
        let regime = self.law.elastic_regime()?;
        Some(match self.flaw {
            Flaw::StifferRegime => ElasticRegime {
                normal_stiffness: regime.normal_stiffness * 1.001,
                ..regime
            },
            Flaw::ActiveSlip => ElasticRegime {
                slides: false,
                ..regime
            },
            _ => regime,
        })
    }
    fn fracture_work(&self, _area: Real, before: &CoulombState, after: &CoulombState) -> Real {
        if self.flaw == Flaw::NegativeFracture && before != after {
            -1.0
        } else {
            0.0
        }
    }
    fn elastic_energy(&self, area: Real, force: &JointForce, state: &CoulombState) -> Real {
        let e = self.law.elastic_energy(area, force, state);
        if self.flaw == Flaw::NegativeEnergy {
            -e
        } else {
            e
        }
    }
}

/// Each broken promise is caught, and named.
#[test]
fn broken_laws_are_caught() {
    let bonded = coulomb_laws()[2];
    let dry = coulomb_laws()[0];
    for (law, flaw, clause) in [
        (bonded, Flaw::OpenIgnoresState, Clause::StaysOpen),
        (dry, Flaw::StifferRegime, Clause::ElasticRegime),
        (dry, Flaw::Reassociated, Clause::ElasticRegime),
        (dry, Flaw::SoftStiffness, Clause::Stiffness),
        (bonded, Flaw::OpenKeepsShear, Clause::OpenWithForce),
        (dry, Flaw::NegativeEnergy, Clause::ElasticEnergy),
        (dry, Flaw::ActiveSlip, Clause::Dissipation),
        (dry, Flaw::ActiveSlipInRegime, Clause::ElasticRegime),
        (dry, Flaw::Flaky, Clause::Determinism),
        (bonded, Flaw::NegativeFracture, Clause::FractureWork),
    ] {
        let error = check(&Broken { law, flaw }).expect_err(&format!("{flaw:?} passed"));
        assert_eq!(error.clause, clause, "{flaw:?}: {error}");
    }
    // An invalid law is refused before anything else.
    let invalid = AnyLaw::Elastic(LinearElastic {
        normal_stiffness: 0.0,
        shear_stiffness: 1.0,
    });
    assert_eq!(check(&invalid).unwrap_err().clause, Clause::Validate);
}

/// Given states are checked too: a law that lies about one state only the caller knows.
#[test]
fn given_states_are_checked() {
    #[derive(Debug, Clone)]
    struct Counter;
    impl ConstitutiveLaw for Counter {
        type State = u32;
        fn stiffness(&self) -> JointStiffness {
            JointStiffness {
                normal: 1e9,
                shear: 0.0,
            }
        }
        fn update(&self, step: &JointStep, force: &mut JointForce, state: &mut u32) -> JointStatus {
            force.shear = Vector2::ZERO;
            force.normal = (-1e9 * step.normal_displacement * step.area).max(0.0);
            if *state == 7 {
                *state = 8;
            }
            if force.normal > 0.0 {
                JointStatus::Sliding
            } else {
                JointStatus::Open
            }
        }
        fn stays_open(&self, area: Real, gap: Real, _: &u32) -> bool {
            -1e9 * gap * area <= 0.0
        }
    }
    assert!(check(&Counter).is_ok());
    let error = check_with_states(&Counter, &[3, 7]).unwrap_err();
    assert_eq!(error.clause, Clause::StaysOpen, "{error}");
    assert!(error.detail.contains("state 7"), "{error}");
}
