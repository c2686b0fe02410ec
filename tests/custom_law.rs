//! A joint law written outside voussoir, through the public API only: Coulomb friction with a
//! cohesion that softens linearly with the accumulated plastic slip. This file is the worked
//! example of `docs/custom-law.md`.
//!
//! Per sub-contact of area `A`, with `κ` the plastic slip accumulated so far:
//!
//! * normal: `F_n = −kn·A·u_n` in compression, no tension (an open joint carries nothing);
//! * shear (incremental): `F_s ← F_s − ks·A·Δu_s`, capped at `c(κ)·A + F_n·tan φ`, with
//!   `c(κ) = c₀·max(0, 1 − κ/u_soft)`;
//! * whatever part of the increment the cap removes is plastic: `κ ← κ + (|F_s,trial| − cap)/(ks·A)`.
//!
//! A block bonded to a slab with this law and pushed sideways resists up to `c₀·A + N·tan φ`,
//! then softens to `N·tan φ` once it has slipped `u_soft`.

use serde::{Deserialize, Serialize};
use voussoir::law::{conformance, AnyLaw, ElasticRegime};
use voussoir::law::{ConstitutiveLaw, JointAxes, JointForce, JointStatus, JointStep, JointStiffness};
use voussoir::math::Vector2;
use voussoir::prelude::*;

/// Coulomb slip with linearly softening cohesion. (serde only for checkpoints.)
#[derive(Debug, Clone, Copy, PartialEq, Serialize, Deserialize)]
pub struct SofteningCoulomb {
    /// Normal stiffness `kn` (Pa/m).
    pub normal_stiffness: f64,
    /// Shear stiffness `ks` (Pa/m).
    pub shear_stiffness: f64,
    /// `tan φ` of the friction angle (-).
    pub tan_friction: f64,
    /// Initial cohesion `c₀` (Pa).
    pub cohesion: f64,
    /// Plastic slip over which the cohesion decays to zero, `u_soft` (m).
    pub softening_slip: f64,
}

/// What each sub-contact remembers besides its forces. `Default` is the virgin joint.
#[derive(Debug, Clone, Copy, Default, PartialEq, Serialize, Deserialize)]
pub struct SofteningState {
    /// Accumulated plastic slip `κ` (m).
    pub plastic_slip: f64,
}

impl SofteningCoulomb {
    /// The law from stiffnesses (Pa/m), friction angle (degrees), cohesion (Pa) and softening
    /// slip (m), validated.
    pub fn new(kn: f64, ks: f64, friction_deg: f64, cohesion: f64, softening_slip: f64) -> Result<Self> {
        if !(0.0..90.0).contains(&friction_deg) {
            return Err(Error::InvalidParameter {
                name: "friction_angle_deg".into(),
                value: friction_deg,
                expected: "must lie in [0, 90) degrees",
            });
        }
        let law = Self {
            normal_stiffness: kn,
            shear_stiffness: ks,
            tan_friction: friction_deg.to_radians().tan(),
            cohesion,
            softening_slip,
        };
        law.validate()?;
        Ok(law)
    }

    /// Cohesion left after a plastic slip `kappa` (Pa).
    pub fn cohesion_at(&self, kappa: f64) -> f64 {
        self.cohesion * (1.0 - kappa / self.softening_slip).max(0.0)
    }
}

impl ConstitutiveLaw for SofteningCoulomb {
    type State = SofteningState;

    fn stiffness(&self) -> JointStiffness {
        JointStiffness {
            normal: self.normal_stiffness,
            shear: self.shear_stiffness,
        }
    }

    fn update(&self, step: &JointStep, force: &mut JointForce, state: &mut SofteningState) -> JointStatus {
        let area = step.area;
        // Normal: total displacement, positive = opening; force positive in compression.
        force.normal = -self.normal_stiffness * step.normal_displacement * area;
        if force.normal <= 0.0 {
            force.normal = 0.0;
            force.shear = Vector2::ZERO;
            return JointStatus::Open;
        }
        // Shear: incremental. `force.shear` arrives holding last step's force as components
        // along the joint's tangents (which turn with the plane); `shear_increment` is the slip
        // of block b relative to a, along the same tangents.
        force.shear -= step.shear_increment * (self.shear_stiffness * area);
        let cap = self.cohesion_at(state.plastic_slip) * area + force.normal * self.tan_friction;
        let trial = force.shear.length();
        if trial > cap {
            // Return to the cap; the excess is plastic slip.
            state.plastic_slip += (trial - cap) / (self.shear_stiffness * area);
            force.shear *= cap / trial;
            return JointStatus::Sliding;
        }
        JointStatus::Elastic
    }

    fn is_failed(&self, state: &SofteningState) -> bool {
        state.plastic_slip >= self.softening_slip
    }

    fn validate(&self) -> Result<()> {
        let positive = |name: &str, value: f64| {
            if value.is_finite() && value > 0.0 {
                Ok(())
            } else {
                Err(Error::InvalidParameter {
                    name: name.into(),
                    value,
                    expected: "must be positive and finite",
                })
            }
        };
        positive("normal_stiffness", self.normal_stiffness)?;
        positive("shear_stiffness", self.shear_stiffness)?;
        positive("softening_slip", self.softening_slip)?;
        for (name, value) in [("tan_friction", self.tan_friction), ("cohesion", self.cohesion)] {
            if !(value.is_finite() && value >= 0.0) {
                return Err(Error::InvalidParameter {
                    name: name.into(),
                    value,
                    expected: "must be finite and not negative",
                });
            }
        }
        Ok(())
    }
}

// ---------------------------------------------------------------------------------------------
// The law on its own.

/// The law alone, driven by hand through a monotonic slip at constant compression, traces the
/// closed-form curve: elastic up to `c₀A + N tan φ`, then on the cap `c(κ)·A + N tan φ` with the
/// plastic slip `κ = u − F_s/(ks·A)`, falling linearly to `N tan φ` at `κ = u_soft`, and staying
/// there. The return mapping is explicit — each step caps the force with the cohesion left at the
/// start of the step — so the cap is compared with the plastic slip before the step; agreement
/// is then to round-off (1e-9 relative).
#[test]
fn law_alone_traces_the_softening_curve() {
    let law = SofteningCoulomb::new(1e9, 1e8, 30.0, 2e3, 1e-3).unwrap();
    let area = 0.01;
    let n = 1e3; // compression (N): u_n = −n/(kn·A)
    let step = |du: f64| JointStep {
        area,
        normal_displacement: -n / (law.normal_stiffness * area),
        normal_increment: 0.0,
        shear_increment: Vector2::new(du, 0.0),
        axes: JointAxes::from_normal(Vector::Z),
        dt: 1e-4,
    };
    let mut force = JointForce::default();
    let mut state = SofteningState::default();
    let du = 1e-7;
    let peak = law.cohesion * area + n * law.tan_friction;
    let residual = n * law.tan_friction;
    let mut max_shear: f64 = 0.0;
    for k in 1..=30_000 {
        let kappa_before = state.plastic_slip;
        let status = law.update(&step(du), &mut force, &mut state);
        let u = k as f64 * du;
        let shear = force.shear.length();
        max_shear = max_shear.max(shear);
        // The shear force opposes the slip of b: negative x.
        assert!(force.shear.x <= 0.0 && force.shear.y == 0.0);
        assert!((force.normal - n).abs() < 1e-9 * n);
        let elastic_limit = peak / (law.shear_stiffness * area);
        if u < elastic_limit * (1.0 - 1e-9) {
            assert_eq!(status, JointStatus::Elastic, "at u = {u}");
            assert!(state.plastic_slip == 0.0);
        } else if u > elastic_limit * (1.0 + 1e-6) {
            assert_eq!(status, JointStatus::Sliding, "at u = {u}");
            // On the cap, and the plastic slip is the slip less the elastic part.
            let expected = law.cohesion_at(kappa_before) * area + residual;
            assert!((shear - expected).abs() < 1e-9 * peak, "u = {u}: {shear} vs {expected}");
            let kappa = u - shear / (law.shear_stiffness * area);
            assert!((state.plastic_slip - kappa).abs() < 1e-9 * u, "u = {u}");
        }
    }
    assert!((max_shear - peak).abs() < 1e-9 * peak, "{max_shear} vs {peak}");
    assert!(law.is_failed(&state));
    assert!((force.shear.length() - residual).abs() < 1e-9 * residual);
    // An open joint carries nothing and keeps its history.
    let opened = JointStep {
        normal_displacement: 1e-6,
        ..step(du)
    };
    assert_eq!(law.update(&opened, &mut force, &mut state), JointStatus::Open);
    assert_eq!(force, JointForce::default());
    assert!(state.plastic_slip > law.softening_slip);
    // Validation names the parameter.
    let e = SofteningCoulomb::new(1e9, 1e8, 30.0, 2e3, 0.0).unwrap_err();
    assert!(e.to_string().contains("softening_slip"), "{e}");
    let e = SofteningCoulomb::new(1e9, 1e8, 95.0, 2e3, 1e-3).unwrap_err();
    assert!(
        e.to_string().contains("friction") && e.to_string().contains("95"),
        "{e}"
    );
}

// ---------------------------------------------------------------------------------------------
// The law in a model.

const STONE: MaterialId = MaterialId(0);
const STEEL: MaterialId = MaterialId(1);

/// Bonded joint: friction 30°, cohesion 2 kPa softening over 1 mm of plastic slip.
const PHI_DEG: f64 = 30.0;
const COHESION: f64 = 2e3;
const U_SOFT: f64 = 1e-3;
/// The bonded block: 0.4 × 0.4 × 0.05 m of stone, 2500 kg/m³.
const SIDE: f64 = 0.4;
const HEIGHT: f64 = 0.05;
const DENSITY: f64 = 2500.0;
/// The pusher advances at 2 mm/s. Up to the peak the tile only deforms its joint elastically
/// (27 µm), so its inertia barely matters there (its kinetic energy stays below 1e-4 J), and the
/// resistance changes by at most ~12 N (3 % of the peak) in a step.
const PUSH_SPEED: f64 = 0.002;

struct ShearTest {
    model: Model<SofteningCoulomb>,
    slab: BlockId,
    block: BlockId,
    pusher: BlockId,
}

/// A stone tile bonded to a fixed slab, and a steel pusher, initially at rest 0.5 mm behind the
/// tile's −x face and 3 mm above the slab (so that it never touches the slab). The
/// pusher–tile joint is frictionless and cohesionless: it transmits a horizontal push only.
fn shear_test() -> ShearTest {
    let mut model: Model<SofteningCoulomb> = Model::new(ModelParameters::default()).unwrap();
    let bond = SofteningCoulomb::new(1e9, 1e8, PHI_DEG, COHESION, U_SOFT).unwrap();
    let smooth = SofteningCoulomb::new(1e9, 1e8, 0.0, 0.0, U_SOFT).unwrap();
    model.set_joint_law(STONE, STONE, bond).unwrap();
    model.set_joint_law(STONE, STEEL, smooth).unwrap();
    let slab = model
        .add_block(
            RigidBlock::cuboid(
                "slab",
                Vector::new(-1.0, -1.0, -0.2),
                Vector::new(1.0, 1.0, 0.0),
                DENSITY,
            )
            .unwrap()
            .with_fixity(Fixity::FIXED),
        )
        .unwrap();
    let h = 0.5 * SIDE;
    let block = model
        .add_block(RigidBlock::cuboid("tile", Vector::new(-h, -h, 0.0), Vector::new(h, h, HEIGHT), DENSITY).unwrap())
        .unwrap();
    let pusher = model
        .add_block(
            RigidBlock::cuboid(
                "pusher",
                Vector::new(-h - 0.1 - 5e-4, -h, 0.003),
                Vector::new(-h - 5e-4, h, HEIGHT),
                7850.0,
            )
            .unwrap()
            .with_material(STEEL)
            .with_fixity(Fixity::FIXED),
        )
        .unwrap();
    ShearTest {
        model,
        slab,
        block,
        pusher,
    }
}

/// What one step of the shear test shows.
#[derive(Debug, Clone, Copy)]
struct Sample {
    /// Pusher travel since it started (m).
    travel: f64,
    /// Tile displacement along x (m).
    slide: f64,
    /// Shear resistance of the bonded joint: the x force of the slab on the tile (N).
    resistance: f64,
    /// Normal force on the bonded joint (N).
    normal: f64,
    /// Mean plastic slip of the joint's sub-contacts (m).
    mean_kappa: f64,
    /// Smallest plastic slip of a sub-contact (m).
    min_kappa: f64,
}

/// A bonded tile pushed sideways at constant speed (displacement control).
///
/// Closed form, with `W = m·g` the tile's weight (the frictionless pusher adds no vertical force,
/// so the joint carries `N = W`) and `A` the joint area:
///
/// * the shear resistance peaks at `c₀·A + W·tan φ` (320 N + 113.3 N): within 2 %. The push
///   acts 2.6 cm above the joint, so the normal stress is trapezoidal (e = M/N ≈ 0.058 m <
///   L/6 ≈ 0.067 m: the whole joint stays closed) and the lightly loaded sub-contacts reach the
///   cap ~1e-5 m earlier than the heavily loaded ones; the cohesion they lose meanwhile
///   (c₀·A·1e-5/u_soft ≈ 0.3 % of c₀·A) plus dynamic oscillation of the normal force set the
///   tolerance;
/// * once every sub-contact has slipped more than `u_soft` the resistance is `W·tan φ`: within
///   2 % (steady sliding at constant speed; the tolerance covers the small rocking of the tile);
/// * the law's state (`plastic_slip`) is visible through `SubContact::law_state` and survives
///   the many re-detections that the sliding triggers (the tile moves 3 mm, re-detection every
///   0.25 mm): the plastic slip of each sub-contact, identified by its key, never decreases from
///   one step to the next, and at the end the mean plastic slip equals the tile's slide less the
///   elastic shear displacement `R/(ks·A)` within 1 % — a history reset at re-detection would
///   lose up to 0.25 mm of it.
/// * the energy dissipated by the joints equals the closed form `W·tan φ·κ̄ + c₀·A·u_soft/2`
///   within 3 % (the frictional work plus the cohesion work under the softening line), and the
///   model's energy balance closes within 1 % at the end of the run.
#[test]
fn bonded_tile_pushed_sideways_softens_to_friction() {
    let ShearTest {
        mut model,
        slab,
        block,
        pusher,
    } = shear_test();
    let area = SIDE * SIDE;
    let weight = DENSITY * area * HEIGHT * 9.81;
    let tan_phi = PHI_DEG.to_radians().tan();
    let peak_closed = COHESION * area + weight * tan_phi;
    let residual_closed = weight * tan_phi;

    // Let the tile settle on its joint, then start pushing.
    model.run_to_equilibrium(1e-5, 20_000).unwrap();
    let normal_at_rest = model.contact_between(slab, block).unwrap().normal_force();
    assert!(
        (normal_at_rest - weight).abs() < 1e-3 * weight,
        "{normal_at_rest} vs {weight}"
    );
    model
        .set_fixity(pusher, Fixity::velocity(Vector::new(PUSH_SPEED, 0.0, 0.0)))
        .unwrap();
    let x0 = model.block(block).unwrap().state().pose.translation.x;
    let p0 = model.block(pusher).unwrap().state().pose.translation.x;
    let detections0 = model.detection_count();

    let mut samples: Vec<Sample> = Vec::new();
    let mut kappa_by_key: std::collections::BTreeMap<u64, f64> = Default::default();
    let mut max_kinetic: f64 = 0.0;
    let mut max_load_step: f64 = 0.0;
    while model.block(pusher).unwrap().state().pose.translation.x - p0 < 3.5e-3 {
        model.step().unwrap();
        let joint = model.contact_between(slab, block).expect("the tile stays on the slab");
        let mut sum = 0.0;
        let mut min_kappa = f64::INFINITY;
        for s in joint.subcontacts() {
            let kappa = s.law_state().plastic_slip;
            // History is never lost: per sub-contact (by key), plastic slip only grows.
            let previous = kappa_by_key.insert(s.key().0, kappa).unwrap_or(0.0);
            assert!(
                kappa >= previous,
                "sub-contact {:?} lost plastic slip at step {}: {previous} -> {kappa}",
                s.key(),
                model.step_count()
            );
            sum += kappa;
            min_kappa = min_kappa.min(kappa);
        }
        let state = model.block(block).unwrap().state();
        samples.push(Sample {
            travel: model.block(pusher).unwrap().state().pose.translation.x - p0,
            slide: state.pose.translation.x - x0,
            resistance: -joint.resultant().x,
            normal: joint.normal_force(),
            mean_kappa: sum / joint.subcontact_count() as f64,
            min_kappa,
        });
        max_kinetic = max_kinetic.max(model.energies().kinetic);
        if let [.., a, b] = samples.as_slice() {
            max_load_step = max_load_step.max((b.resistance - a.resistance).abs());
        }
    }

    let peak = samples.iter().map(|s| s.resistance).fold(0.0, f64::max);
    let last = *samples.last().unwrap();
    let steady: Vec<&Sample> = samples.iter().filter(|s| s.min_kappa > 1.2 * U_SOFT).collect();
    let residual = steady.iter().map(|s| s.resistance).sum::<f64>() / steady.len() as f64;
    let elastic_slip = last.resistance / (1e8 * area);
    let e = model.energies();
    let dissipated_closed = weight * tan_phi * last.mean_kappa + COHESION * area * U_SOFT / 2.0;
    println!(
        "peak {peak:.2} N (closed form {peak_closed:.2}), residual {residual:.2} N over {} steps \
         (closed form {residual_closed:.2}); slide {:.4e} m, mean κ {:.4e} m (slide − R/(ks·A) = {:.4e}); \
         detections {}; dt {:.3e} s, {} steps, largest change of resistance in a step {max_load_step:.2} N; \
         max kinetic {max_kinetic:.2e} J; dissipated {:.3} J (closed form {dissipated_closed:.3}); \
         balance error {:.2e} J; {e:?}",
        steady.len(),
        last.slide,
        last.mean_kappa,
        last.slide - elastic_slip,
        model.detection_count() - detections0,
        model.dt(),
        samples.len(),
        e.friction,
        e.balance_error(),
    );
    assert!(
        (peak - peak_closed).abs() < 0.02 * peak_closed,
        "peak {peak} vs {peak_closed}"
    );
    assert!(steady.len() > 100, "too little fully softened sliding");
    assert!(
        (residual - residual_closed).abs() < 0.02 * residual_closed,
        "residual {residual} vs {residual_closed}"
    );
    assert!(
        steady.iter().all(|s| (s.normal - weight).abs() < 0.02 * weight),
        "the joint's normal force should stay at the tile's weight"
    );
    // The pusher drove the tile: it slid most of the travel.
    assert!(last.slide > 2.5e-3 && last.slide <= last.travel, "{last:?}");
    // Re-detection happened repeatedly while the state was carried over.
    assert!(
        model.detection_count() - detections0 >= 8,
        "only {} detections",
        model.detection_count() - detections0
    );
    // State visible and consistent with the kinematics.
    assert!(
        (last.mean_kappa - (last.slide - elastic_slip)).abs() < 0.01 * last.slide,
        "mean plastic slip {} vs slide {} − elastic {}",
        last.mean_kappa,
        last.slide,
        elastic_slip
    );
    let joint = model.contact_between(slab, block).unwrap();
    assert!(joint
        .subcontacts()
        .all(|s| model.law_table().laws()[joint.law_index()].is_failed(s.law_state())));
    // Energy: dissipation as in closed form, and the balance closes.
    assert!(
        (e.friction - dissipated_closed).abs() < 0.03 * dissipated_closed,
        "dissipated {} J vs closed form {dissipated_closed} J",
        e.friction
    );
    assert!(
        e.balance_error().abs() < 0.01 * e.input(),
        "energy balance error {} J of {} J put in",
        e.balance_error(),
        e.input()
    );
}

/// The law's state is part of a checkpoint: a run stopped half-way through the softening and
/// restored from `Model::to_checkpoint_string` continues bit-identically, plastic slip included.
#[test]
fn law_state_survives_a_checkpoint() {
    let ShearTest {
        mut model,
        slab,
        block,
        pusher,
    } = shear_test();
    model.run_to_equilibrium(1e-5, 20_000).unwrap();
    model
        .set_fixity(pusher, Fixity::velocity(Vector::new(PUSH_SPEED, 0.0, 0.0)))
        .unwrap();
    // Push until the joint is half softened.
    let half = |m: &Model<SofteningCoulomb>| {
        let joint = m.contact_between(slab, block).unwrap();
        let mean =
            joint.subcontacts().map(|s| s.law_state().plastic_slip).sum::<f64>() / joint.subcontact_count() as f64;
        mean > 0.5 * U_SOFT
    };
    assert!(model.run_until(100_000, half).unwrap());
    let text = model.to_checkpoint_string().unwrap();
    let mut restored: Model<SofteningCoulomb> = Model::from_checkpoint_str(&text).unwrap();
    let kappas = |m: &Model<SofteningCoulomb>| -> Vec<(u64, u64)> {
        let joint = m.contact_between(slab, block).unwrap();
        joint
            .subcontacts()
            .map(|s| (s.key().0, s.law_state().plastic_slip.to_bits()))
            .collect()
    };
    assert_eq!(kappas(&model), kappas(&restored), "state restored exactly");
    model.run_steps(2000).unwrap();
    restored.run_steps(2000).unwrap();
    assert_eq!(kappas(&model), kappas(&restored), "and continues bit-identically");
    assert_eq!(
        model.block(block).unwrap().state(),
        restored.block(block).unwrap().state()
    );
}

// ---------------------------------------------------------------------------------------------
// The law contract, checked by `voussoir::law::conformance`.

/// The softening law keeps the contract: its updates are deterministic, finite, force-free when
/// open, no stiffer than `stiffness()`, with non-negative energies and dissipation on monotonic
/// loading — also from states far along the softening that the checker's own histories do not
/// reach. It offers neither shortcut (`elastic_regime`, `stays_open`), so the report shows none.
#[test]
fn softening_law_conforms() {
    let law = SofteningCoulomb::new(1e9, 1e8, PHI_DEG, COHESION, U_SOFT).unwrap();
    let report = conformance::check(&law).unwrap_or_else(|e| panic!("{e}"));
    assert!(report.updates > 1000 && report.states > 100, "{report:?}");
    assert_eq!((report.regime_stood, report.open_promised), (0, 0), "{report:?}");
    let softened = [0.5, 1.0, 3.0].map(|k| SofteningState {
        plastic_slip: k * U_SOFT,
    });
    conformance::check_with_states(&law, &softened).unwrap_or_else(|e| panic!("{e}"));
}

/// The shipped laws keep the contract and offer their shortcuts, and `AnyLaw` forwards them:
/// wrapped, each law gives the same report as alone (the same regime trials standing, the same
/// open promises), and `elastic_regime` returns the inner law's.
#[test]
fn shipped_laws_and_any_law_conform() {
    let laws: [AnyLaw; 4] = [
        CoulombSlip::dry(4e9, 1.6e9, 30.0).unwrap().into(),
        CoulombSlip::new(1e9, 4e8, 35.0, 25.0, 2e5, 0.0).unwrap().into(),
        CoulombSlip::new(1e9, 1e9, 30.0, 20.0, 1e5, 5e4).unwrap().into(),
        LinearElastic {
            normal_stiffness: 3e9,
            shear_stiffness: 1.2e9,
        }
        .into(),
    ];
    for law in laws {
        let any = conformance::check(&law).unwrap_or_else(|e| panic!("{law:?}: {e}"));
        let (alone, regime) = match law {
            AnyLaw::Coulomb(inner) => (conformance::check(&inner), inner.elastic_regime()),
            AnyLaw::Elastic(inner) => (conformance::check(&inner), inner.elastic_regime()),
            _ => unreachable!(),
        };
        assert_eq!(Ok(any), alone, "{law:?}");
        assert!(regime.is_some() && law.elastic_regime() == regime, "{law:?}");
        assert!(any.regime_stood > 1000, "{law:?}: {any:?}");
        if let AnyLaw::Coulomb(_) = law {
            assert!(any.open_promised > 100, "{law:?}: {any:?}");
        }
    }
}

/// What a user's forwarding `enum` forwards: a shipped law and the softening law, each with its
/// state, side by side.
#[derive(Debug, Clone, Copy, Default, PartialEq)]
struct MixedState {
    coulomb: voussoir::law::CoulombState,
    softening: SofteningState,
}

/// A forwarding `enum` written with care: every method forwarded, the shortcuts included.
#[derive(Debug, Clone, Copy)]
enum Mixed {
    Coulomb(CoulombSlip),
    Softening(SofteningCoulomb),
}

impl ConstitutiveLaw for Mixed {
    type State = MixedState;
    fn stiffness(&self) -> JointStiffness {
        match self {
            Mixed::Coulomb(l) => l.stiffness(),
            Mixed::Softening(l) => l.stiffness(),
        }
    }
    fn update(&self, step: &JointStep, force: &mut JointForce, state: &mut MixedState) -> JointStatus {
        match self {
            Mixed::Coulomb(l) => l.update(step, force, &mut state.coulomb),
            Mixed::Softening(l) => l.update(step, force, &mut state.softening),
        }
    }
    fn stays_open(&self, area: f64, gap: f64, state: &MixedState) -> bool {
        match self {
            Mixed::Coulomb(l) => l.stays_open(area, gap, &state.coulomb),
            Mixed::Softening(l) => l.stays_open(area, gap, &state.softening),
        }
    }
    fn elastic_regime(&self) -> Option<ElasticRegime> {
        match self {
            Mixed::Coulomb(l) => l.elastic_regime(),
            Mixed::Softening(l) => l.elastic_regime(),
        }
    }
    fn elastic_energy(&self, area: f64, force: &JointForce, state: &MixedState) -> f64 {
        match self {
            Mixed::Coulomb(l) => l.elastic_energy(area, force, &state.coulomb),
            Mixed::Softening(l) => l.elastic_energy(area, force, &state.softening),
        }
    }
    fn is_failed(&self, state: &MixedState) -> bool {
        match self {
            Mixed::Coulomb(l) => l.is_failed(&state.coulomb),
            Mixed::Softening(l) => l.is_failed(&state.softening),
        }
    }
    fn validate(&self) -> Result<()> {
        match self {
            Mixed::Coulomb(l) => l.validate(),
            Mixed::Softening(l) => l.validate(),
        }
    }
}

/// The same `enum` written in a hurry: `update` and the rest forwarded, the two shortcuts
/// forgotten. Correct, but the contact kernel never takes its fast paths.
#[derive(Debug, Clone, Copy)]
enum Forgetful {
    Coulomb(CoulombSlip),
    Softening(SofteningCoulomb),
}

impl ConstitutiveLaw for Forgetful {
    type State = MixedState;
    fn stiffness(&self) -> JointStiffness {
        match self {
            Forgetful::Coulomb(l) => l.stiffness(),
            Forgetful::Softening(l) => l.stiffness(),
        }
    }
    fn update(&self, step: &JointStep, force: &mut JointForce, state: &mut MixedState) -> JointStatus {
        match self {
            Forgetful::Coulomb(l) => l.update(step, force, &mut state.coulomb),
            Forgetful::Softening(l) => l.update(step, force, &mut state.softening),
        }
    }
    fn is_failed(&self, state: &MixedState) -> bool {
        match self {
            Forgetful::Coulomb(l) => l.is_failed(&state.coulomb),
            Forgetful::Softening(l) => l.is_failed(&state.softening),
        }
    }
}

/// A forwarding `enum` that answers `stays_open` with "open whenever the joint opens" for
/// every arm: true of the softening law and of a dry joint, a lie for a bonded joint, which
/// carries tension and fails when it opens.
#[derive(Debug, Clone, Copy)]
struct OpensWhenOpen(Mixed);

impl ConstitutiveLaw for OpensWhenOpen {
    type State = MixedState;
    fn stiffness(&self) -> JointStiffness {
        self.0.stiffness()
    }
    fn update(&self, step: &JointStep, force: &mut JointForce, state: &mut MixedState) -> JointStatus {
        self.0.update(step, force, state)
    }
    fn stays_open(&self, _area: f64, gap: f64, _state: &MixedState) -> bool {
        gap > 0.0
    }
    fn elastic_regime(&self) -> Option<ElasticRegime> {
        self.0.elastic_regime()
    }
}

/// The checker shows what a forwarding `enum` forwards.
///
/// * Careful: it conforms, and each arm's report equals the inner law's.
/// * Forgetful: it conforms (skipping the shortcuts is always allowed), but its Coulomb arm's
///   report differs from `CoulombSlip`'s: no elastic regime stood, no open promise. The report
///   is how a user sees the lost fast path. (The softening law has no shortcut to lose.)
#[test]
fn conformance_shows_a_forgetful_forwarding_enum() {
    let dry = CoulombSlip::dry(4e9, 1.6e9, 30.0).unwrap();
    let bonded = CoulombSlip::new(1e9, 1e9, 30.0, 20.0, 1e5, 5e4).unwrap();
    let softening = SofteningCoulomb::new(1e9, 1e8, PHI_DEG, COHESION, U_SOFT).unwrap();
    for coulomb in [dry, bonded] {
        let alone = conformance::check(&coulomb).unwrap();
        assert!(alone.regime_stood > 0 && alone.open_promised > 0, "{alone:?}");
        assert_eq!(conformance::check(&Mixed::Coulomb(coulomb)), Ok(alone));
        let forgetful = conformance::check(&Forgetful::Coulomb(coulomb)).expect("correct, if slow");
        assert_ne!(forgetful, alone, "the lost fast paths show in the report");
        assert_eq!((forgetful.regime_stood, forgetful.open_promised), (0, 0));
        assert_eq!(forgetful.states, alone.states);
    }
    let alone = conformance::check(&softening).unwrap();
    assert_eq!(conformance::check(&Mixed::Softening(softening)), Ok(alone));
    assert_eq!(conformance::check(&Forgetful::Softening(softening)), Ok(alone));
}

/// The checker catches a `stays_open` that lies: "open whenever the joint opens" for an intact
/// bonded joint, which carries tension and fails when it opens; it names the clause and gives
/// the step that shows it. The same rule is the truth for a dry joint and for the softening
/// law, and passes there.
#[test]
fn conformance_catches_a_lying_stays_open() {
    let bonded = CoulombSlip::new(1e9, 1e9, 30.0, 20.0, 1e5, 5e4).unwrap();
    let error = conformance::check(&OpensWhenOpen(Mixed::Coulomb(bonded))).expect_err("a lie");
    assert_eq!(error.clause, conformance::Clause::StaysOpen, "{error}");
    assert!(
        error.to_string().contains("stays_open") && error.detail.contains("Elastic"),
        "{error}"
    );
    let dry = CoulombSlip::dry(4e9, 1.6e9, 30.0).unwrap();
    let softening = SofteningCoulomb::new(1e9, 1e8, PHI_DEG, COHESION, U_SOFT).unwrap();
    for honest in [Mixed::Coulomb(dry), Mixed::Softening(softening)] {
        let report = conformance::check(&OpensWhenOpen(honest)).unwrap_or_else(|e| panic!("{honest:?}: {e}"));
        assert!(report.open_promised > 0, "{report:?}");
    }
}
