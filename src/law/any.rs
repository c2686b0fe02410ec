//! [`AnyLaw`]: the shipped laws as one type, to mix them in one model.

#[cfg(feature = "serde")]
use serde::{Deserialize, Serialize};

use super::{
    ConstitutiveLaw, CoulombSlip, CoulombState, ElasticRegime, JointForce, JointStatus, JointStep, JointStiffness,
    LinearElastic, MortarJoint, MortarState,
};
use crate::error::Result;
use crate::math::Real;

/// Any of the laws voussoir ships, so that one model can give different kinds of law to
/// different pairs of materials: `Model<AnyLaw>`, with [`CoulombSlip`] between stones,
/// [`MortarJoint`] for the mortared joints and [`LinearElastic`] for an elastic pad, say.
///
/// Every method of [`ConstitutiveLaw`] is forwarded to the inner law, the two shortcuts of the
/// contact kernel included: [`ConstitutiveLaw::elastic_regime`] and
/// [`ConstitutiveLaw::stays_open`] return what the inner law returns, so a sub-contact under
/// `AnyLaw` takes the same fast path, with the same forces bit for bit, as under the inner law
/// alone. (A hand-written forwarding `enum` that forgets one of them stays correct but silently
/// loses the fast path; [`super::conformance`] shows it: compare its report with the inner law's.)
///
/// The state is [`AnyState`], which holds each law's state side by side.
///
/// In JSON (scenes, checkpoints) a law is written with its variant's name,
/// `{"Coulomb": {...}}`, `{"Mortar": {...}}` or `{"Elastic": {...}}`, and the inner law as on
/// its own; a [`CoulombSlip`] or a [`MortarJoint`] is validated as it is read.
///
/// ```
/// use voussoir::law::{conformance, AnyLaw};
/// use voussoir::prelude::*;
///
/// const STONE: MaterialId = MaterialId(0);
/// const PAD: MaterialId = MaterialId(1);
/// let mut model: Model<AnyLaw> = Model::new(ModelParameters::default())?;
/// model.set_joint_law(STONE, STONE, CoulombSlip::dry(1e9, 4e8, 30.0)?.into())?;
/// let pad = LinearElastic { normal_stiffness: 2e8, shear_stiffness: 8e7 };
/// model.set_joint_law(STONE, PAD, pad.into())?;
/// model.add_block(
///     RigidBlock::cuboid("base", Vector::new(-1.0, -1.0, -0.2), Vector::new(1.0, 1.0, 0.0), 2500.0)?
///         .with_fixity(Fixity::FIXED),
/// )?;
/// // A stone cube on the base (Coulomb), an elastic pad beside it (linear elastic).
/// model.add_block(RigidBlock::cuboid("cube", Vector::ZERO, Vector::splat(0.2), 2500.0)?)?;
/// model.add_block(
///     RigidBlock::cuboid("pad", Vector::new(0.5, 0.0, 0.0), Vector::new(0.7, 0.2, 0.05), 1200.0)?
///         .with_material(PAD),
/// )?;
/// model.run_to_equilibrium(1e-4, 20_000)?;
/// let weight = (2500.0 * 0.008 + 1200.0 * 0.002) * 9.81;
/// let support: f64 = model.contacts().map(|c| c.normal_force()).sum();
/// assert!((support - weight).abs() < 1e-3 * weight);
///
/// // The fast paths are the inner law's.
/// let law = AnyLaw::from(pad);
/// assert_eq!(law.elastic_regime(), pad.elastic_regime());
/// assert_eq!(conformance::check(&law)?, conformance::check(&pad)?);
/// # Ok::<(), Box<dyn std::error::Error>>(())
/// ```
#[derive(Debug, Clone, Copy, PartialEq)]
#[cfg_attr(feature = "serde", derive(Serialize, Deserialize))]
#[cfg_attr(feature = "serde", serde(deny_unknown_fields))]
#[non_exhaustive]
pub enum AnyLaw {
    /// Coulomb slip with tension cut-off, cohesion and residual friction.
    Coulomb(CoulombSlip),
    /// A mortared joint whose tension and cohesion soften by their fracture energies.
    Mortar(MortarJoint),
    /// Linear springs with no strength limit.
    Elastic(LinearElastic),
}

/// The per-sub-contact state of [`AnyLaw`]: the state of each kind of law, side by side. Each
/// law reads and writes its own field and leaves the others at their default.
///
/// A struct rather than an `enum` of the states, so that `AnyState::default()` is the virgin
/// state of *every* law at once. The contact kernel takes the elastic fast path only for a
/// sub-contact whose state equals `State::default()`; with an `enum`, the default would be one
/// law's variant, and a sub-contact of another law would either never be virgin (no fast path) or
/// have to read a foreign variant as its own. Here there is nothing to map: a sub-contact that
/// changes law (its pair of materials given another law) keeps a state the new law reads as
/// it would its own. The struct is `Copy` and as small as the states it holds side by side
/// (32 bytes: [`MortarState`]'s three lengths, and [`CoulombState`]'s flag).
///
/// ```
/// use voussoir::law::{AnyLaw, AnyState, ConstitutiveLaw, CoulombSlip};
/// let law = AnyLaw::from(CoulombSlip::new(1e9, 4e8, 30.0, 25.0, 1e5, 5e4)?);
/// let mut state = AnyState::default();
/// assert!(!law.is_failed(&state));
/// state.coulomb.failed = true;
/// assert!(law.is_failed(&state));
/// # Ok::<(), voussoir::Error>(())
/// ```
#[derive(Debug, Clone, Copy, PartialEq, Default)]
#[cfg_attr(feature = "serde", derive(Serialize, Deserialize))]
#[cfg_attr(feature = "serde", serde(default))]
#[non_exhaustive]
pub struct AnyState {
    /// The state of [`AnyLaw::Coulomb`].
    pub coulomb: CoulombState,
    /// The state of [`AnyLaw::Mortar`].
    pub mortar: MortarState,
}

impl From<CoulombSlip> for AnyLaw {
    fn from(law: CoulombSlip) -> Self {
        AnyLaw::Coulomb(law)
    }
}

impl From<MortarJoint> for AnyLaw {
    fn from(law: MortarJoint) -> Self {
        AnyLaw::Mortar(law)
    }
}

impl From<LinearElastic> for AnyLaw {
    fn from(law: LinearElastic) -> Self {
        AnyLaw::Elastic(law)
    }
}

impl ConstitutiveLaw for AnyLaw {
    type State = AnyState;

    #[inline]
    fn stiffness(&self) -> JointStiffness {
        match self {
            AnyLaw::Coulomb(law) => law.stiffness(),
            AnyLaw::Mortar(law) => law.stiffness(),
            AnyLaw::Elastic(law) => law.stiffness(),
        }
    }

    #[inline]
    fn update(&self, step: &JointStep, force: &mut JointForce, state: &mut AnyState) -> JointStatus {
        match self {
            AnyLaw::Coulomb(law) => law.update(step, force, &mut state.coulomb),
            AnyLaw::Mortar(law) => law.update(step, force, &mut state.mortar),
            AnyLaw::Elastic(law) => law.update(step, force, &mut ()),
        }
    }

    #[inline]
    fn stays_open(&self, area: Real, normal_displacement: Real, state: &AnyState) -> bool {
        match self {
            AnyLaw::Coulomb(law) => law.stays_open(area, normal_displacement, &state.coulomb),
            AnyLaw::Mortar(law) => law.stays_open(area, normal_displacement, &state.mortar),
            AnyLaw::Elastic(law) => law.stays_open(area, normal_displacement, &()),
        }
    }

    #[inline]
    fn elastic_regime(&self) -> Option<ElasticRegime> {
        match self {
            AnyLaw::Coulomb(law) => law.elastic_regime(),
            AnyLaw::Mortar(law) => law.elastic_regime(),
            AnyLaw::Elastic(law) => law.elastic_regime(),
        }
    }

    fn elastic_energy(&self, area: Real, force: &JointForce, state: &AnyState) -> Real {
        match self {
            AnyLaw::Coulomb(law) => law.elastic_energy(area, force, &state.coulomb),
            AnyLaw::Mortar(law) => law.elastic_energy(area, force, &state.mortar),
            AnyLaw::Elastic(law) => law.elastic_energy(area, force, &()),
        }
    }

    #[inline]
    fn fracture_work(&self, area: Real, before: &AnyState, after: &AnyState) -> Real {
        match self {
            AnyLaw::Coulomb(law) => law.fracture_work(area, &before.coulomb, &after.coulomb),
            AnyLaw::Mortar(law) => law.fracture_work(area, &before.mortar, &after.mortar),
            AnyLaw::Elastic(law) => law.fracture_work(area, &(), &()),
        }
    }

    fn unbonded_state(&self) -> AnyState {
        match self {
            AnyLaw::Coulomb(law) => AnyState {
                coulomb: law.unbonded_state(),
                ..AnyState::default()
            },
            AnyLaw::Mortar(law) => AnyState {
                mortar: law.unbonded_state(),
                ..AnyState::default()
            },
            AnyLaw::Elastic(_) => AnyState::default(),
        }
    }

    fn is_failed(&self, state: &AnyState) -> bool {
        match self {
            AnyLaw::Coulomb(law) => law.is_failed(&state.coulomb),
            AnyLaw::Mortar(law) => law.is_failed(&state.mortar),
            AnyLaw::Elastic(law) => law.is_failed(&()),
        }
    }

    fn validate(&self) -> Result<()> {
        match self {
            AnyLaw::Coulomb(law) => law.validate(),
            AnyLaw::Mortar(law) => law.validate(),
            AnyLaw::Elastic(law) => law.validate(),
        }
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::law::JointAxes;
    use crate::math::{Vector, Vector2};

    fn coulomb_laws() -> [CoulombSlip; 3] {
        [
            CoulombSlip::dry(4e9, 1.6e9, 30.0).unwrap(),
            CoulombSlip::new(4e9, 1.6e9, 35.0, 25.0, 2e5, 0.0).unwrap(),
            CoulombSlip::new(1e9, 1e9, 30.0, 20.0, 1e5, 5e4).unwrap(),
        ]
    }

    fn elastic_law() -> LinearElastic {
        LinearElastic {
            normal_stiffness: 3e9,
            shear_stiffness: 1.2e9,
        }
    }

    /// Every method gives what the inner law gives, bit for bit, over a grid of steps and
    /// states: the shortcuts (`elastic_regime`, `stays_open`), the update (forces, state,
    /// status), the energy, `is_failed`, `unbonded_state`, `stiffness` and `validate`.
    #[test]
    fn every_method_is_forwarded() {
        let gaps = [-1e-3, -2.5e-5, -1e-9, -0.0, 0.0, 1e-12, 4e-5, 6e-5, 1.0];
        let increments = [0.0, 3e-6, -2e-5, 1e-3];
        let bits = |f: &JointForce| [f.normal.to_bits(), f.shear.x.to_bits(), f.shear.y.to_bits()];
        let mut compared = 0;
        for inner in coulomb_laws() {
            let any = AnyLaw::from(inner);
            assert_eq!(any.stiffness(), inner.stiffness());
            assert_eq!(any.elastic_regime(), inner.elastic_regime());
            assert!(any.elastic_regime().is_some());
            assert_eq!(any.unbonded_state().coulomb, inner.unbonded_state());
            assert!(any.validate().is_ok());
            for failed in [false, true] {
                let state = CoulombState { failed };
                let any_state = AnyState {
                    coulomb: state,
                    ..AnyState::default()
                };
                assert_eq!(any.is_failed(&any_state), inner.is_failed(&state));
                for &gap in &gaps {
                    assert_eq!(any.stays_open(0.3, gap, &any_state), inner.stays_open(0.3, gap, &state));
                    for &du in &increments {
                        let step = JointStep {
                            area: 0.3,
                            normal_displacement: gap,
                            normal_increment: du,
                            shear_increment: Vector2::new(du, -0.4 * du),
                            axes: JointAxes::from_normal(Vector::new(0.0, 0.6, 0.8)),
                            dt: 1e-5,
                        };
                        let start = JointForce {
                            normal: 2.0,
                            shear: Vector2::new(3e4, -1e3),
                        };
                        let (mut f, mut s) = (start, state);
                        let (mut g, mut t) = (start, any_state);
                        assert_eq!(any.update(&step, &mut g, &mut t), inner.update(&step, &mut f, &mut s));
                        assert_eq!(bits(&g), bits(&f));
                        assert_eq!(
                            t,
                            AnyState {
                                coulomb: s,
                                ..AnyState::default()
                            }
                        );
                        assert_eq!(
                            any.elastic_energy(0.3, &g, &t).to_bits(),
                            inner.elastic_energy(0.3, &f, &s).to_bits()
                        );
                        compared += 1;
                    }
                }
            }
        }
        let inner = elastic_law();
        let any = AnyLaw::from(inner);
        assert_eq!(any.stiffness(), inner.stiffness());
        assert_eq!(any.elastic_regime(), inner.elastic_regime());
        assert!(any.elastic_regime().is_some());
        assert!(any.validate().is_ok());
        assert!(!any.is_failed(&AnyState::default()));
        for &gap in &gaps {
            assert_eq!(
                any.stays_open(0.3, gap, &AnyState::default()),
                inner.stays_open(0.3, gap, &())
            );
            for &du in &increments {
                let step = JointStep {
                    area: 0.3,
                    normal_displacement: gap,
                    normal_increment: du,
                    shear_increment: Vector2::new(du, -0.4 * du),
                    axes: JointAxes::from_normal(Vector::Z),
                    dt: 1e-5,
                };
                let (mut f, mut g, mut t) = (JointForce::default(), JointForce::default(), AnyState::default());
                assert_eq!(any.update(&step, &mut g, &mut t), inner.update(&step, &mut f, &mut ()));
                assert_eq!(bits(&g), bits(&f));
                assert_eq!(t, AnyState::default());
                assert_eq!(
                    any.elastic_energy(0.3, &g, &t).to_bits(),
                    inner.elastic_energy(0.3, &f, &()).to_bits()
                );
                compared += 1;
            }
        }
        assert_eq!(compared, 3 * 2 * 9 * 4 + 9 * 4);
        // Validation errors come from the inner law.
        let bad = AnyLaw::Elastic(LinearElastic {
            normal_stiffness: -1.0,
            shear_stiffness: 1.0,
        });
        assert!(bad.validate().unwrap_err().to_string().contains("normal_stiffness"));
    }

    /// `AnyLaw` and its state round-trip through JSON, variant and bits included, and a
    /// `CoulombSlip` is validated as it is read.
    #[test]
    #[cfg(feature = "io")]
    fn serde_round_trip() {
        let laws = [AnyLaw::from(coulomb_laws()[2]), AnyLaw::from(elastic_law())];
        let text = serde_json::to_string(&laws).unwrap();
        assert!(text.contains("\"Coulomb\"") && text.contains("\"Elastic\""), "{text}");
        let back: Vec<AnyLaw> = serde_json::from_str(&text).unwrap();
        assert_eq!(back, laws);
        let state = AnyState {
            coulomb: CoulombState { failed: true },
            mortar: MortarState {
                crack_opening: 1.25e-4,
                plastic_slip: 3e-5,
                crushing: 2e-5,
            },
        };
        let back: AnyState = serde_json::from_str(&serde_json::to_string(&state).unwrap()).unwrap();
        assert_eq!(back, state);
        // Fields added later default on load.
        assert_eq!(serde_json::from_str::<AnyState>("{}").unwrap(), AnyState::default());
        let bad = text.replace("30.0", "95.0");
        assert!(serde_json::from_str::<Vec<AnyLaw>>(&bad).is_err(), "{bad}");
        // In a scene, as `docs/scene-format.md` writes it.
        let scene = r#"{"joints": [
            {"materials": [0, 0], "law": {"Coulomb": {"normal_stiffness": 1e9, "shear_stiffness": 4e8,
                "friction_deg": 30, "residual_friction_deg": 30}}},
            {"materials": [0, 1], "law": {"Elastic": {"normal_stiffness": 2e8, "shear_stiffness": 8e7}}}
        ], "blocks": []}"#;
        let scene = crate::io::scene::Scene::<AnyLaw>::from_json(scene).unwrap();
        assert_eq!(
            scene.joints[0].law,
            AnyLaw::from(CoulombSlip::dry(1e9, 4e8, 30.0).unwrap())
        );
        assert_eq!(
            scene.joints[1].law,
            AnyLaw::from(LinearElastic {
                normal_stiffness: 2e8,
                shear_stiffness: 8e7
            })
        );
    }

    /// The state is the laws' states side by side and no larger: `MortarState` (three lengths,
    /// 24 bytes) and `CoulombState`'s flag, 32 bytes with the alignment.
    #[test]
    fn state_is_the_laws_states_side_by_side() {
        assert_eq!(std::mem::size_of::<MortarState>(), 24);
        assert_eq!(std::mem::size_of::<CoulombState>(), 1);
        assert_eq!(std::mem::size_of::<AnyState>(), 32);
        // A sub-contact of a `Model<AnyLaw>`: 112 bytes (80 with `CoulombSlip`'s state alone).
        assert_eq!(std::mem::size_of::<crate::contact::SubContact<AnyState>>(), 112);
    }

    fn mortar_laws() -> [MortarJoint; 2] {
        [
            MortarJoint::builder(1e10, 4e9, 35.0)
                .residual_friction(28.0)
                .tension(1e5, 8.0)
                .cohesion(1.5e5, 40.0)
                .build()
                .unwrap(),
            MortarJoint::builder(1e10, 4e9, 30.0)
                .tension(1e5, 0.0)
                .cohesion(2e5, 0.0)
                .softening(crate::law::Softening::Linear)
                .build()
                .unwrap(),
        ]
    }

    /// `AnyLaw::Mortar` forwards every method to the `MortarJoint` it holds, on its field of
    /// the state, bit for bit, `fracture_work` included, over opening, closing and sliding
    /// histories; the other laws' fields stay at their default.
    #[test]
    fn mortar_is_forwarded() {
        let bits = |f: &JointForce| [f.normal.to_bits(), f.shear.x.to_bits(), f.shear.y.to_bits()];
        let mut fracture = 0.0;
        for inner in mortar_laws() {
            let any = AnyLaw::from(inner);
            assert_eq!(any.stiffness(), inner.stiffness());
            assert_eq!(any.unbonded_state().mortar, inner.unbonded_state());
            assert_eq!(any.elastic_regime(), inner.elastic_regime());
            assert!(any.validate().is_ok());
            let (mut f, mut s) = (JointForce::default(), MortarState::default());
            let (mut g, mut t) = (JointForce::default(), AnyState::default());
            for k in 0..400 {
                let x = k as Real;
                let step = JointStep {
                    area: 0.3,
                    normal_displacement: 2e-5 * (0.05 * x).sin() - 2e-6,
                    normal_increment: 0.0,
                    shear_increment: Vector2::new(1e-6 * (0.03 * x).cos(), 2e-7),
                    axes: JointAxes::from_normal(Vector::Z),
                    dt: 1e-5,
                };
                let (s0, t0) = (s, t);
                assert_eq!(any.update(&step, &mut g, &mut t), inner.update(&step, &mut f, &mut s));
                assert_eq!(bits(&g), bits(&f));
                assert_eq!(
                    t,
                    AnyState {
                        mortar: s,
                        ..AnyState::default()
                    }
                );
                let (a, b) = (any.fracture_work(0.3, &t0, &t), inner.fracture_work(0.3, &s0, &s));
                assert_eq!(a.to_bits(), b.to_bits());
                fracture += a;
                assert_eq!(
                    any.elastic_energy(0.3, &g, &t).to_bits(),
                    inner.elastic_energy(0.3, &f, &s).to_bits()
                );
                assert_eq!(any.is_failed(&t), inner.is_failed(&s));
                for gap in [-1e-6, 0.0, 1e-6, 1e-3] {
                    assert_eq!(any.stays_open(0.3, gap, &t), inner.stays_open(0.3, gap, &s));
                }
            }
            assert!(inner.is_failed(&s));
        }
        // The softening joint cracked and consumed fracture energy; the brittle one none.
        assert!(fracture > 0.0);
        // The other laws book none.
        let coulomb = AnyLaw::from(coulomb_laws()[2]);
        let failed = AnyState {
            coulomb: CoulombState { failed: true },
            ..AnyState::default()
        };
        assert_eq!(coulomb.fracture_work(1.0, &AnyState::default(), &failed), 0.0);
    }

    /// A `MortarJoint` in JSON as `{"Mortar": {...}}`, round-tripping bit for bit, validated as
    /// it is read, and a strength given without its fracture energy refused by name.
    #[test]
    #[cfg(feature = "io")]
    fn mortar_serde_round_trip() {
        let laws = mortar_laws().map(AnyLaw::from);
        let text = serde_json::to_string(&laws).unwrap();
        assert!(text.contains("\"Mortar\""), "{text}");
        let back: Vec<AnyLaw> = serde_json::from_str(&text).unwrap();
        assert_eq!(back, laws);
        let bad = text.replacen("\"cohesion\":150000.0", "\"cohesion\":-1.0", 1);
        assert_ne!(bad, text);
        let e = serde_json::from_str::<Vec<AnyLaw>>(&bad).unwrap_err();
        assert!(e.to_string().contains("cohesion"), "{e}");
        let missing = r#"{"Mortar": {"normal_stiffness": 1e10, "shear_stiffness": 4e9, "friction_deg": 30,
            "tensile_strength": 1e5}}"#;
        let e = serde_json::from_str::<AnyLaw>(missing).unwrap_err();
        assert!(e.to_string().contains("mode_i_fracture_energy"), "{e}");
        // A dry mortar joint needs nothing but its stiffnesses and friction.
        let dry = r#"{"Mortar": {"normal_stiffness": 1e10, "shear_stiffness": 4e9, "friction_deg": 30}}"#;
        assert_eq!(
            serde_json::from_str::<AnyLaw>(dry).unwrap(),
            AnyLaw::from(MortarJoint::builder(1e10, 4e9, 30.0).build().unwrap())
        );
    }
}
