//! The impact tests' setups and the analysis of one of them ([`ImpactCase`]): the six tests
//! with what was observed, how the impactor is guided, its base and its release, the model
//! parameters, and the names of the choices (one set, read by the command line and by Python).
//! The run itself is in [`super::arch_impact`].

use serde::{Deserialize, Serialize};

use super::arch_impact::GRAVITY;
use super::{in_range, non_negative, positive};
use voussoir::error::{Error, Result};
use voussoir::math::Real;

/// One of the six tests, with what was observed.
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
pub struct ImpactSetup {
    /// Name, e.g. `"M60H20"`.
    pub name: String,
    /// Drop mass (kg).
    pub mass: Real,
    /// Drop height (m).
    pub height: Real,
    /// Observed: the arch collapsed.
    pub collapsed: bool,
    /// Observed maximum quarter-span vertical displacement (m), when it stood.
    pub max_disp: Option<Real>,
    /// Observed peak quarter-span velocity (m/s).
    pub max_velocity: Real,
    /// Observed peak quarter-span acceleration (m/s²).
    pub max_accel: Real,
}

/// The six tests of the paper (the paper's Table 3; `docs/benchmarks/arch-impact.md`).
pub fn setups() -> Vec<ImpactSetup> {
    let s = |name: &str, mass, height, collapsed, max_disp, max_velocity, max_accel| ImpactSetup {
        name: name.into(),
        mass,
        height,
        collapsed,
        max_disp,
        max_velocity,
        max_accel,
    };
    vec![
        s("M80H45", 81.00, 0.450, true, None, 3.19, 5115.0),
        s("M75H45", 74.35, 0.455, true, None, 2.99, 2139.0),
        s("M75H20", 74.35, 0.205, true, None, 1.91, 1416.0),
        s("M60H20", 60.93, 0.205, false, Some(0.034), 1.99, 1417.0),
        s("M60H25", 60.93, 0.255, false, Some(0.040), 2.13, 1589.0),
        s("M60H30", 60.93, 0.305, false, Some(0.053), 2.08, 1440.0),
    ]
}

/// How the impactor is guided.
/// On the command line (`--guide`): `frame`, `seat`.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Default, Serialize, Deserialize)]
pub enum ImpactorGuide {
    /// A free block between fixed frame blocks, guided only through contacts, striking the
    /// extrados of voussoir 5 directly (the paper's model; default).
    #[default]
    Frame,
    /// Only the vertical translation is free (constrained degrees of freedom); it strikes a
    /// steel seat with a horizontal top resting on voussoir 5.
    SeatConstrained,
}

/// The shape of the impactor's bottom face ([`ImpactorGuide::Frame`] only).
/// On the command line (`--base`): `sloped`, `flat`.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Default, Serialize, Deserialize)]
pub enum ImpactorBase {
    /// Parallel to the extrados of voussoir 5 (20.7° to the horizontal): the whole footprint
    /// strikes at once (default).
    #[default]
    Sloped,
    /// Horizontal: the impactor strikes with the edge of its footprint on the higher side.
    Flat,
}

/// Where the impactor starts.
/// On the command line (`--release`): `above`, `full`.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Default, Serialize, Deserialize)]
pub enum Release {
    /// [`ImpactCase::release_gap`] above the point of contact, moving down at the speed of the
    /// fall there, `√(2g(H − gap))` (default).
    #[default]
    JustAbove,
    /// At rest, the drop height `H` above the point of contact.
    FullHeight,
}

/// The names of a setting's choices, in one place: the command line (`clap::ValueEnum`, feature
/// `cli`) and the Python bindings (`FromStr`) read them from here.
macro_rules! named_choices {
    ($ty:ident, $what:literal, [$($variant:ident => $name:literal),+ $(,)?]) => {
        impl $ty {
            /// Every choice, in order.
            pub const ALL: &'static [$ty] = &[$($ty::$variant),+];

            /// The choice's name on the command line and in Python.
            pub fn name(self) -> &'static str {
                match self {
                    $($ty::$variant => $name),+
                }
            }
        }

        impl std::str::FromStr for $ty {
            type Err = String;

            /// A choice from its name (any case); the error lists the names.
            fn from_str(s: &str) -> std::result::Result<Self, String> {
                let lower = s.to_ascii_lowercase();
                Self::ALL.iter().copied().find(|c| c.name() == lower).ok_or_else(|| {
                    let names: Vec<String> = Self::ALL.iter().map(|c| format!("{:?}", c.name())).collect();
                    format!("{} {s:?}: expected {}", $what, names.join(" or "))
                })
            }
        }

        #[cfg(feature = "cli")]
        impl clap::ValueEnum for $ty {
            fn value_variants<'a>() -> &'a [Self] {
                Self::ALL
            }

            fn to_possible_value(&self) -> Option<clap::builder::PossibleValue> {
                Some(clap::builder::PossibleValue::new(self.name()))
            }
        }
    };
}

named_choices!(ImpactorGuide, "guide", [Frame => "frame", SeatConstrained => "seat"]);
named_choices!(ImpactorBase, "base", [Sloped => "sloped", Flat => "flat"]);
named_choices!(Release, "release", [JustAbove => "above", FullHeight => "full"]);

/// One analysis: a setup and the model parameters.
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
pub struct ImpactCase {
    /// The test.
    pub setup: ImpactSetup,
    /// Label (setup plus what differs from the baseline).
    pub label: String,
    /// Normal joint stiffness (Pa/m), every stone and stone–steel joint.
    pub kn: Real,
    /// Shear joint stiffness (Pa/m).
    pub ks: Real,
    /// Friction angle (degrees).
    pub friction_deg: Real,
    /// Rayleigh damping ratio (stiffness-proportional).
    pub damping_ratio: Real,
    /// Frequency at which the ratio is set (Hz).
    pub damping_frequency: Real,
    /// Out-of-plane width (m).
    pub width: Real,
    /// Simulated time after release (s).
    pub duration: Real,
    /// Sub-contacts per joint edge.
    pub per_edge: u16,
    /// How node contacts' normal springs act: `integrated` (the baseline's: the books of a
    /// collapse close) or `point` (the library's default, and this benchmark's before the
    /// session of 2026-11-30, eighth); see [`voussoir::geometry::NodeRule`] and
    /// `docs/benchmarks/arch-impact.md`, item 6. Absent from a case written before the field
    /// existed, it is `point`, the rule such a case ran with.
    #[serde(default)]
    pub node_rule: voussoir::geometry::NodeRule,
    /// How the impactor is guided.
    pub guide: ImpactorGuide,
    /// Shape of the impactor's bottom face (frame guide only).
    pub base: ImpactorBase,
    /// Where the impactor starts.
    pub release: Release,
    /// Change of the drop height from the test's (m): the perturbation of the robustness runs.
    pub height_offset: Real,
    /// Relative change of gravity while the arch settles, restored before the release (0 for
    /// the test): a settled state that differs from the test's at round-off level, for the
    /// ensembles that say how far a result moves with round-off (`k·1e-12`, issue 43, item 5).
    pub settle_perturbation: Real,
    /// Impactor footprint along the span (m).
    pub impactor_length: Real,
    /// Impactor height (m, at mid-footprint); its density is set to give the test's mass.
    pub impactor_height: Real,
    /// Gap between the impactor and each frame block (m).
    pub guide_clearance: Real,
    /// Thickness of the frame blocks (m).
    pub guide_thickness: Real,
    /// Friction angle of the impactor–frame joint (degrees); 0 = frictionless.
    pub guide_friction_deg: Real,
    /// Vertical distance kept between the frame blocks along the span and the arch's extrados
    /// below them (m).
    pub guide_standoff: Real,
    /// Seat thickness above the highest extrados corner of voussoir 5 (m), seat variant.
    pub seat_thickness: Real,
    /// Vertical gap between the impactor and what it strikes at release (m),
    /// [`Release::JustAbove`].
    pub release_gap: Real,
    /// Interval of the recorded histories (s).
    pub sample_interval: Real,
}

impl ImpactCase {
    /// The paper's values for a setup: kn = 4 GPa/m, ks = 1.6 GPa/m, φ = 30.5°, 1 % stiffness-
    /// proportional damping at 25 Hz, width 0.15 m, 1 s; the frame-guided free impactor with a
    /// sloped base, frictionless guides 0.5 mm away, released 0.5 mm above the extrados.
    pub fn baseline(setup: ImpactSetup) -> Self {
        Self {
            label: setup.name.clone(),
            setup,
            kn: 4e9,
            ks: 1.6e9,
            friction_deg: 30.5,
            damping_ratio: 0.01,
            damping_frequency: 25.0,
            width: 0.15,
            duration: 1.0,
            per_edge: 15,
            node_rule: voussoir::geometry::NodeRule::Integrated,
            guide: ImpactorGuide::Frame,
            base: ImpactorBase::Sloped,
            release: Release::JustAbove,
            height_offset: 0.0,
            settle_perturbation: 0.0,
            impactor_length: 0.10,
            impactor_height: 0.20,
            guide_clearance: 5e-4,
            guide_thickness: 0.05,
            guide_friction_deg: 0.0,
            guide_standoff: 0.02,
            seat_thickness: 0.01,
            release_gap: 5e-4,
            sample_interval: 5e-4,
        }
    }

    /// The previous default: steel seat on voussoir 5, impactor guided by constrained degrees of
    /// freedom.
    pub fn seat_constrained(setup: ImpactSetup) -> Self {
        Self {
            guide: ImpactorGuide::SeatConstrained,
            ..Self::baseline(setup)
        }
    }

    /// Drop height `H` of this case: the test's plus [`ImpactCase::height_offset`] (m).
    pub fn drop_height(&self) -> Real {
        self.setup.height + self.height_offset
    }

    /// Impact velocity `√(2gH)` (m/s).
    pub fn impact_velocity(&self) -> Real {
        (2.0 * GRAVITY * self.drop_height()).sqrt()
    }

    /// Checks the parameters the scenario itself uses (the joint laws and the model check the
    /// rest).
    ///
    /// # Errors
    /// [`Error::InvalidParameter`] naming the first bad value.
    pub fn validate(&self) -> Result<()> {
        positive("impact.mass", self.setup.mass)?;
        positive("impact.drop_height", self.drop_height())?;
        positive("impact.width", self.width)?;
        positive("impact.duration", self.duration)?;
        positive("impact.impactor_length", self.impactor_length)?;
        positive("impact.impactor_height", self.impactor_height)?;
        non_negative("impact.guide_clearance", self.guide_clearance)?;
        positive("impact.guide_thickness", self.guide_thickness)?;
        positive("impact.guide_standoff", self.guide_standoff)?;
        positive("impact.seat_thickness", self.seat_thickness)?;
        positive("impact.sample_interval", self.sample_interval)?;
        in_range(
            "impact.guide_friction_deg",
            self.guide_friction_deg,
            0.0,
            89.999,
            "must lie in [0°, 90°)",
        )?;
        non_negative("impact.release_gap", self.release_gap)?;
        in_range(
            "impact.settle_perturbation",
            self.settle_perturbation,
            -1e-6,
            1e-6,
            "a round-off perturbation, within ±1e-6",
        )?;
        if self.release == Release::JustAbove && self.release_gap >= self.drop_height() {
            return Err(Error::InvalidParameter {
                name: "impact.release_gap".into(),
                value: self.release_gap,
                expected: "smaller than the drop height",
            });
        }
        // The footprint must lie on the extrados of voussoir 5 (0.1436 m along the span).
        in_range(
            "impact.impactor_length",
            self.impactor_length,
            0.0,
            0.14,
            "at most 0.14 m (the extrados of voussoir 5)",
        )?;
        Ok(())
    }
}
