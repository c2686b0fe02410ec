//! The TU Eindhoven shear wall J4D (Raijmakers & Vermeltfoort 1992; Lourenço 1996) with mortared
//! joints that crack and soften (`MortarJoint`), and the same wall with dry joints beside it.
//!
//! ```text
//! cargo run --release --example shear_wall [-- --joints both|mortar|dry] [--per-edge 3]
//!     [--top confined|loaded] [--stiffness lumped|joints] [--cap lourenco|none]
//!     [--max-travel-mm 3] [--unit-cracks] [--masonry-strength-mpa F] [--check]
//!     [--check-travel-mm 1.5] [--ensemble N] [--out DIR]
//! ```
//!
//! The wall, 990 × 1000 × 100 mm, is built of units expanded by half a joint (220 × 62.5 ×
//! 100 mm, zero-thickness interfaces), 16 active courses in running bond; the two clamped
//! courses of the test are part of the steel beams: the bottom one of the fixed base, the top one
//! of the top beam. The top beam is loaded by the pre-compression (0.30 MPa × 990 × 100 mm =
//! 29.7 kN, its own weight included), kept horizontal (its rotations fixed) and pushed
//! horizontally by a servo (`loading::Servo`, `PushOver`) through settled states; while it is
//! pushed its height is held (`--top confined`, Lourenço's model) or its load (`--top loaded`). Every interface has Lourenço's calibrated parameters (kn 82 N/mm³, ks 36 N/mm³,
//! f_t 0.25 MPa, G_f^I 18 N/m, c 0.35 MPa, tan φ 0.75, G_f^II 125 N/m, no dilatancy). His
//! bricks are elastic (E 16 700 MPa, ν 0.15) and his interface stiffnesses do not include them;
//! ours are rigid, so by default (`--stiffness lumped`) each joint carries in series the
//! elasticity of the unit it stands for (a course's height for a bed joint, a unit's length for a
//! head joint); `--stiffness joints` takes his kn, ks unchanged. The joints crush on Lourenço's
//! compression cap (f_m 10.5 MPa, G_c 5 N/mm, C_ss 9, κ_p 0.09 mm; `--cap none` leaves it out).
//! `--unit-cracks` adds a potential crack in each whole brick's middle. The model, the adopted values and where they
//! differ from the test are in `docs/benchmarks/shear-wall.md`.
//!
//! Writes into `--out` (default `out/shear_wall`): `summary.json` (`peak_kN` and the rest),
//! `force_displacement.svg` (the curves against the test's peak), `cracks_mortar.svg` /
//! `cracks_dry.svg` (the joints coloured by their damage at the end), `shear_wall_mortar.html` /
//! `shear_wall_dry.html` (viewers, open in a browser) and `curve_mortar.csv` / `curve_dry.csv`.
//! `--check` runs the sub-contact density check (`SubContactDensity::check_convergence`) and the
//! servo's (`Servo::check_convergence`) on the mortared wall, each up to `--check-travel-mm`.

#[path = "../common/args.rs"]
mod args;
mod drawing;
mod wall;

use std::collections::HashSet;
use std::fmt::Write as _;
use std::ops::Bound::Included;
use std::ops::ControlFlow;
use std::path::PathBuf;
use std::time::Instant;

use clap::{Parser, ValueEnum};
use serde_json::json;
use voussoir::geometry::ContactKind;
use voussoir::io::viewer::Viewer;
use voussoir::law::{CompressionCap, MortarJoint};
use voussoir::loading::{PushOver, PushOverResult, Servo};
use voussoir::prelude::*;

use drawing::*;
use wall::*;

// ---- The wall (m, kg/m³) -------------------------------------------------------------------

/// Length, height of the active part and thickness of the wall (m).
const LENGTH: Real = 0.99;
const HEIGHT: Real = 1.0;
const THICKNESS: Real = 0.1;
/// Active courses (18 in the test, the top and bottom ones clamped in the steel beams).
const COURSES: usize = 16;
/// Expanded unit: 210 mm + 10 mm joint long; the course height is the wall's 1000 mm over its
/// 16 active courses (52 mm + 10 mm joint would be 62 mm: 992 mm).
const UNIT_LENGTH: Real = 0.22;
const COURSE_HEIGHT: Real = HEIGHT / COURSES as Real;
/// Density of the bricks (assumed: solid clay brick; the wall's weight is 6 % of the load).
const BRICK_DENSITY: Real = 2000.0;
/// Steel beams.
const STEEL_DENSITY: Real = 7850.0;
const BEAM_DEPTH: Real = 0.2;

// ---- Loads and the test --------------------------------------------------------------------

/// Vertical pre-compression (Pa).
const PRECOMPRESSION: Real = 0.30e6;
/// The test's peak horizontal load (kN): J4D, as read from Lourenço (1996), where J4D and J5D
/// (both at 0.30 MPa) peaked at about 50 kN. Sources quote 50–57 kN for these walls; the higher
/// figures are numerical models', and we compare with the test.
const TEST_PEAK_KN: Real = 50.0;
/// The target band: ±15 % of the test's peak.
const TOLERANCE: Real = 0.15;

// ---- Lourenço's interface parameters (SI) --------------------------------------------------

const KN: Real = 82e9; // 82 N/mm³
const KS: Real = 36e9; // 36 N/mm³
const FT: Real = 0.25e6;
const GF_I: Real = 18.0; // 0.018 N/mm
const COHESION: Real = 0.35e6;
const TAN_PHI: Real = 0.75;
const GF_II: Real = 125.0; // 0.125 N/mm

/// Lourenço's compression cap for these walls (1996; Lourenço & Rots 1997): compressive strength
/// f_m 10.5 MPa, compressive fracture energy G_c 5 N/mm, shear factor C_ss 9, plastic closure at
/// the peak κ_p 0.09 mm (as we have them from his thesis; to be checked against it).
const CAP_STRENGTH: Real = 10.5e6;
const CAP_FRACTURE_ENERGY: Real = 5000.0; // 5 N/mm
const CAP_SHEAR_FACTOR: Real = 9.0;
const CAP_PEAK_CLOSURE: Real = 0.09e-3;

/// Lourenço's elastic bricks (E 16 700 MPa, ν 0.15): his interfaces' kn, ks were derived as
/// `kn = E_u E_m / (h_m (E_u − E_m))` (and the same for shear), the mortar's compliance less that
/// of the unit material its thickness replaces, so they leave the units' elasticity to the
/// units. Rigid blocks need it in the joints.
const UNIT_E: Real = 16.7e9;
const UNIT_NU: Real = 0.15;
/// The bricks' shear modulus, `E / 2(1 + ν)`.
const UNIT_G: Real = UNIT_E / (2.0 * (1.0 + UNIT_NU));

/// The potential crack in the units (`--unit-cracks`): the brick's tensile strength and
/// mode-I fracture energy (Lourenço 1996: 2.0 MPa, 0.08 N/mm), a cohesion of 1.4 f_t and
/// friction tan φ = 1 (his assumptions for the unit interface); the mode-II fracture energy is
/// taken in the same ratio to the cohesion as the joints' (assumed, see the write-up). Its
/// stiffness is that of half a unit's length on either side (with `--stiffness lumped`; the head
/// joints then carry only the other half of their units), or a penalty of 10 × the joints' with
/// `--stiffness joints`.
const UNIT_FT: Real = 2.0e6;
const UNIT_GF_I: Real = 80.0;
const UNIT_C: Real = 2.8e6;
const UNIT_TAN_PHI: Real = 1.0;
const UNIT_STIFFNESS_FACTOR: Real = 10.0;

const TRAVEL: args::Interval = args::Interval {
    lo: Included(0.05),
    hi: Included(10.0),
};
const INCREMENT: args::Interval = args::Interval {
    lo: Included(0.05),
    hi: Included(50.0),
};
const STRENGTH: args::Interval = args::Interval {
    lo: Included(0.1),
    hi: Included(1000.0),
};
const RATIO: args::Interval = args::Interval {
    lo: Included(1e-5),
    hi: Included(1e-1),
};

#[derive(Debug, Clone, Copy, PartialEq, Eq, ValueEnum)]
enum TopArg {
    /// After the pre-compression the top beam's height is held (Lourenço's model: "precluding
    /// any vertical movement"); the vertical force then follows the wall.
    Confined,
    /// The vertical load is held at 29.7 kN and the beam rises or sinks freely.
    Loaded,
}

/// How the joints' stiffnesses account for the units' elasticity.
#[derive(Debug, Clone, Copy, PartialEq, Eq, ValueEnum)]
enum StiffnessArg {
    /// Each joint in series with the unit it stands for (`1/k = 1/k_n + l/E_u`, `l/G_u` in
    /// shear; `l` a course's height for a bed joint, a unit's length for a head joint)
    Lumped,
    /// Lourenço's kn, ks unchanged (the rigid units then stiffer than his elastic ones)
    Joints,
}

impl StiffnessArg {
    /// (kn, ks) of a joint standing for a length `l` (m) of unit.
    fn of(self, l: Real) -> (Real, Real) {
        match self {
            StiffnessArg::Joints => (KN, KS),
            StiffnessArg::Lumped => (1.0 / (1.0 / KN + l / UNIT_E), 1.0 / (1.0 / KS + l / UNIT_G)),
        }
    }
}

#[derive(Debug, Clone, Copy, PartialEq, Eq, ValueEnum)]
enum JointsArg {
    /// Mortared and dry walls, one after the other.
    Both,
    /// The mortared wall only.
    Mortar,
    /// The dry wall only.
    Dry,
}

/// The shear wall J4D under servo-controlled push-over.
#[derive(Debug, Clone, Parser)]
#[command(name = "shear_wall", args_override_self = true)]
struct Options {
    /// Which walls to push
    #[arg(long, value_enum, default_value = "both")]
    joints: JointsArg,
    /// How the top beam is held vertically while it is pushed
    #[arg(long, value_enum, default_value = "confined")]
    top: TopArg,
    /// How the joints' stiffnesses account for the units' elasticity
    #[arg(long, value_enum, default_value = "lumped")]
    stiffness: StiffnessArg,
    /// Sub-contacts per joint edge
    #[arg(long, value_name = "N", value_parser = args::whole::<u16>(2), default_value = "3")]
    per_edge: u16,
    /// Horizontal travel of the top beam (mm), in [0.05, 10]
    #[arg(long, value_name = "MM", value_parser = TRAVEL.parser(), default_value = "3")]
    max_travel_mm: f64,
    /// The servo's advance (µm per advancing step), in [0.05, 50]
    #[arg(long, value_name = "UM", value_parser = INCREMENT.parser(), default_value = "1")]
    increment_um: f64,
    /// The servo's unbalanced-force ratio threshold, in [1e-5, 0.1]
    #[arg(long, value_name = "RATIO", value_parser = RATIO.parser(), default_value = "5e-4")]
    threshold: f64,
    /// A potential crack in the middle of each whole brick, with the brick's strength
    #[arg(long)]
    unit_cracks: bool,
    /// The joints' compression cap: Lourenço's (f_m 10.5 MPa, G_c 5 N/mm, C_ss 9, κ_p 0.09 mm),
    /// or none (the joints do not crush)
    #[arg(long, value_enum, default_value = "lourenco")]
    cap: CapArg,
    /// Flag the joints' cells whose compressive stress passes this masonry strength (MPa;
    /// Lourenço's cap: 10.5; useful with `--cap none`): the summary says from when and how many
    #[arg(long, value_name = "MPA", value_parser = STRENGTH.parser())]
    masonry_strength_mpa: Option<f64>,
    /// Run the density and servo convergence checks on the mortared wall
    #[arg(long)]
    check: bool,
    /// Push N copies of the mortared wall whose pre-compression differs by k·1e-12 of itself
    /// (k = 0..N): the peak's median and range over states that differ at round-off
    #[arg(long, value_name = "N", value_parser = args::whole::<usize>(2))]
    ensemble: Option<usize>,
    /// Relative change of the pre-compression (the ensemble's perturbation; 0 for the wall)
    #[arg(skip = 0.0)]
    perturbation: f64,
    /// Travel of the convergence checks' runs (mm), in [0.05, 10]
    #[arg(long, value_name = "MM", value_parser = TRAVEL.parser(), default_value = "1.5")]
    check_travel_mm: f64,
    /// Output folder
    #[arg(long, value_name = "DIR", default_value = "out/shear_wall")]
    out: PathBuf,
}

/// The joints' compression cap.
#[derive(Debug, Clone, Copy, PartialEq, Eq, ValueEnum)]
enum CapArg {
    /// Lourenço's cap for these walls.
    Lourenco,
    /// No cap: the joints do not crush.
    None,
}

impl CapArg {
    fn cap(self) -> Option<CompressionCap> {
        match self {
            CapArg::Lourenco => Some(
                CompressionCap::new(CAP_STRENGTH, CAP_FRACTURE_ENERGY)
                    .with_shear_factor(CAP_SHEAR_FACTOR)
                    .with_peak_closure(CAP_PEAK_CLOSURE),
            ),
            CapArg::None => None,
        }
    }
}

#[derive(Debug, Clone, Copy, PartialEq, Eq)]
enum Joints {
    Mortar,
    Dry,
}

impl Joints {
    fn name(self) -> &'static str {
        match self {
            Joints::Mortar => "mortar",
            Joints::Dry => "dry",
        }
    }

    /// The law of the mortar joints (and of the wall's faces against the beams) of stiffnesses
    /// `(kn, ks)`, crushing on `cap` if given (dry joints too: the bricks crush whether the
    /// joints are mortared or not).
    fn law(self, (kn, ks): (Real, Real), cap: Option<CompressionCap>) -> Result<MortarJoint> {
        let phi = TAN_PHI.atan().to_degrees();
        let builder = match self {
            Joints::Mortar => MortarJoint::builder(kn, ks, phi)
                .residual_friction(phi)
                .tension(FT, GF_I)
                .cohesion(COHESION, GF_II)
                .dilatancy(0.0),
            // Same stiffness and friction, no tension, no cohesion.
            Joints::Dry => MortarJoint::builder(kn, ks, phi),
        };
        match cap {
            Some(cap) => builder.compression_cap(cap).build(),
            None => builder.build(),
        }
    }
}

/// What one push-over gave.
struct Outcome {
    joints: Joints,
    /// The vertical force on the wall at each sample of the curve (kN).
    vertical_kn: Vec<Real>,
    result: PushOverResult,
    energies: Energies,
    damage: Vec<JointDamage>,
    /// Travel (m) and load (N) at which a cell first passed `--masonry-strength-mpa`, and the
    /// number of cells past it at the end.
    first_overstress: Option<(Real, Real)>,
    overstressed_cells: usize,
    /// With the cap: travel (m) and load (N) at which a cell first yielded on it, and first
    /// passed its peak (softening); the cells crushed (yielded) and softening at the end.
    first_crush: Option<(Real, Real)>,
    first_softening: Option<(Real, Real)>,
    crushed_cells: usize,
    softening_cells: usize,
    /// The largest plastic closure of a cell at the end (m).
    max_crushing: Real,
    seconds: f64,
    steps: u64,
    blocks: usize,
}

fn run_wall(options: &Options, joints: Joints) -> Result<Outcome> {
    let started = Instant::now();
    let mut wall = build(joints, options)?;
    let settled = wall.model.step_count();
    let before = wall.model.energies();
    let servo = Servo::new(wall.beam, Vector::X, options.increment_um * 1e-6, options.threshold)?;
    let name = joints.name();
    let mut viewer = Viewer::new(&format!("shear wall J4D, {name} joints"));
    viewer.record(&wall.model)?;
    let mut next_frame = 0.25e-3;
    let mut frame_error = None;
    let mut next_print = 0.25e-3;
    let mut vertical_kn = Vec::new();
    // The travel (m) and load (N) at which a cell first passed the masonry strength, first
    // crushed, and first passed the cap's peak.
    let mut first_overstress: Option<(Real, Real)> = None;
    let mut first_crush: Option<(Real, Real)> = None;
    let mut first_softening: Option<(Real, Real)> = None;
    let peak_closure = options.cap.cap().map(|c| c.peak_closure);
    let f_m = options.masonry_strength_mpa.map(|f| f * 1e6);
    let result = push(
        &mut wall,
        servo,
        options.max_travel_mm * 1e-3,
        |m, travel, load, vertical| {
            vertical_kn.push(vertical * 1e-3);
            if let Some(f_m) = f_m {
                if first_overstress.is_none() && m.contacts().any(|c| c.subcontacts().any(|s| s.normal_stress() > f_m))
                {
                    first_overstress = Some((travel, load));
                }
            }
            if let Some(kp) = peak_closure {
                if first_softening.is_none() {
                    let most = m
                        .contacts()
                        .flat_map(|c| c.subcontacts().map(|s| s.law_state().crushing))
                        .fold(0.0, Real::max);
                    if most > 0.0 && first_crush.is_none() {
                        first_crush = Some((travel, load));
                    }
                    if most > kp {
                        first_softening = Some((travel, load));
                    }
                }
            }
            if travel >= next_frame {
                next_frame += 0.25e-3;
                if let Err(e) = viewer.record(m) {
                    frame_error.get_or_insert(e);
                }
            }
            if travel >= next_print {
                next_print += 0.25e-3;
                println!(
                    "  {name}: {:.2} mm  {:6.2} kN  vertical {:6.2} kN  fracture {:.2} J  ({} steps, {:.0} s)",
                    travel * 1e3,
                    load * 1e-3,
                    vertical * 1e-3,
                    m.energies().fracture,
                    m.step_count(),
                    started.elapsed().as_secs_f64()
                );
            }
        },
    )?;
    if let Some(e) = frame_error {
        return Err(e);
    }
    let travel_mm: Vec<f64> = result.curve.iter().map(|s| s.travel * 1e3).collect();
    let load_kn: Vec<f64> = result.curve.iter().map(|s| s.load * 1e-3).collect();
    viewer.add_curve(
        "horizontal load",
        ("top displacement (mm)", "load (kN)"),
        &travel_mm,
        &load_kn,
        false,
    )?;
    viewer.write(&options.out.join(format!("shear_wall_{name}.html")))?;
    let mut csv = String::from("travel_mm,load_kN,smoothed_load_kN\n");
    for s in &result.curve {
        let _ = writeln!(
            csv,
            "{:.6},{:.6},{:.6}",
            s.travel * 1e3,
            s.load * 1e-3,
            s.smoothed_load * 1e-3
        );
    }
    args::write_text(&options.out.join(format!("curve_{name}.csv")), &csv)?;
    let damage = joint_damage(&wall)?;
    args::write_text(
        &options.out.join(format!("cracks_{name}.svg")),
        &crack_svg(
            &damage,
            &format!("J4D, {name} joints: damage at {:.1} mm", options.max_travel_mm),
        ),
    )?;
    let e = wall.model.energies();
    let energies = Energies {
        fracture: e.fracture - before.fracture,
        friction: e.friction - before.friction,
        damping: e.damping - before.damping,
        ..e
    };
    let overstressed_cells = f_m.map_or(0, |f_m| {
        wall.model
            .contacts()
            .map(|c| c.subcontacts().filter(|s| s.normal_stress() > f_m).count())
            .sum()
    });
    let crushing = |past: Real| -> usize {
        wall.model
            .contacts()
            .map(|c| c.subcontacts().filter(|s| s.law_state().crushing > past).count())
            .sum()
    };
    let (crushed_cells, softening_cells) = (crushing(0.0), peak_closure.map_or(0, crushing));
    let max_crushing = wall
        .model
        .contacts()
        .flat_map(|c| c.subcontacts().map(|s| s.law_state().crushing))
        .fold(0.0, Real::max);
    Ok(Outcome {
        joints,
        vertical_kn,
        result,
        energies,
        damage,
        first_overstress,
        overstressed_cells,
        first_crush,
        first_softening,
        crushed_cells,
        softening_cells,
        max_crushing,
        seconds: started.elapsed().as_secs_f64(),
        steps: wall.model.step_count() - settled,
        blocks: wall.model.blocks().len(),
    })
}

/// The peaks (N) of `count` mortared walls whose pre-compression differs by k·1e-12 of itself,
/// pushed to the travel of the run, as many at a time as there are threads.
fn ensemble_peaks(options: &Options, count: usize) -> Result<Vec<Real>> {
    use rayon::prelude::*;
    (0..count)
        .into_par_iter()
        .map(|k| {
            let copy = Options {
                perturbation: k as Real * 1e-12,
                ..options.clone()
            };
            let mut wall = build(Joints::Mortar, &copy)?;
            let servo = Servo::new(wall.beam, Vector::X, options.increment_um * 1e-6, options.threshold)?;
            Ok(push(&mut wall, servo, options.max_travel_mm * 1e-3, |_, _, _, _| {})?.peak_load)
        })
        .collect()
}

fn main() {
    if let Err(e) = run() {
        eprintln!("shear_wall: {e}");
        std::process::exit(1);
    }
}

fn summary_of(o: &Outcome) -> serde_json::Value {
    let r = &o.result;
    let last = r.curve.last().map_or(0.0, |s| s.smoothed_load);
    let count = |kind: &str, above: Real| o.damage.iter().filter(|d| d.kind == kind && d.lost > above).count();
    let total = |kind: &str| o.damage.iter().filter(|d| d.kind == kind).count();
    json!({
        "peak_kN": r.peak_load * 1e-3,
        "raw_peak_kN": r.raw_peak_load * 1e-3,
        "travel_at_peak_mm": r.travel_at_peak * 1e3,
        "final_travel_mm": r.curve.last().map_or(0.0, |s| s.travel) * 1e3,
        "final_load_kN": last * 1e-3,
        "final_over_peak": last / r.peak_load,
        // Whether the load fell past its maximum within the travel (a peak), or was still at
        // its maximum at the end of it.
        "peaked": r.travel_at_peak < r.curve.last().map_or(0.0, |s| s.travel) - 0.1e-3,
        "stop": format!("{:?}", r.stop),
        "first_overstress": o.first_overstress.map(|(t, l)| json!({"travel_mm": t * 1e3, "load_kN": l * 1e-3})),
        "overstressed_cells": o.overstressed_cells,
        "first_crush": o.first_crush.map(|(t, l)| json!({"travel_mm": t * 1e3, "load_kN": l * 1e-3})),
        "first_cap_softening": o.first_softening.map(|(t, l)| json!({"travel_mm": t * 1e3, "load_kN": l * 1e-3})),
        "crushed_cells": o.crushed_cells,
        "cap_softening_cells": o.softening_cells,
        "max_crushing_mm": o.max_crushing * 1e3,
        "fracture_J": o.energies.fracture,
        "friction_J": o.energies.friction,
        "damping_J": o.energies.damping,
        "joints_cracked": {
            "bed": [count("bed", 0.5), total("bed")],
            "head": [count("head", 0.5), total("head")],
            "unit": [count("unit", 0.5), total("unit")],
        },
        "joints_damaged": {
            "bed": count("bed", 0.01),
            "head": count("head", 0.01),
            "unit": count("unit", 0.01),
        },
        "blocks": o.blocks,
        "steps": o.steps,
        "seconds": o.seconds,
        "curve": {
            "travel_mm": r.curve.iter().map(|s| s.travel * 1e3).collect::<Vec<_>>(),
            "load_kN": r.curve.iter().map(|s| s.load * 1e-3).collect::<Vec<_>>(),
            "vertical_kN": o.vertical_kn,
        },
        "vertical_at_peak_kN": r.curve.iter().zip(&o.vertical_kn)
            .min_by(|a, b| (a.0.travel - r.travel_at_peak).abs().total_cmp(&(b.0.travel - r.travel_at_peak).abs()))
            .map_or(Real::NAN, |p| *p.1),
    })
}

fn run() -> Result<()> {
    let options = Options::parse();

    let walls: &[Joints] = match options.joints {
        JointsArg::Both => &[Joints::Mortar, Joints::Dry],
        JointsArg::Mortar => &[Joints::Mortar],
        JointsArg::Dry => &[Joints::Dry],
    };
    let mut files = vec!["summary.json".to_owned(), "force_displacement.svg".to_owned()];
    for j in walls {
        for f in ["shear_wall_{}.html", "curve_{}.csv", "cracks_{}.svg"] {
            files.push(f.replace("{}", j.name()));
        }
    }
    args::prepare_output_dir(&options.out, &[], &files)?;
    println!(
        "shear wall J4D: {LENGTH} × {HEIGHT} × {THICKNESS} m, {COURSES} courses of {:.1} mm units, {} per edge, \
         servo {} µm / {:.0e}, top {:?}, stiffness {:?}, cap {:?}{}",
        COURSE_HEIGHT * 1e3,
        options.per_edge,
        options.increment_um,
        options.threshold,
        options.top,
        options.stiffness,
        options.cap,
        if options.unit_cracks { ", unit cracks" } else { "" }
    );
    let mut outcomes = Vec::new();
    for &joints in walls {
        let o = run_wall(&options, joints)?;
        println!(
            "{} joints: peak {:.1} kN at {:.2} mm ({:+.1} % of the test's {TEST_PEAK_KN} kN); {:.1} kN at {:.2} mm; \
             fracture {:.2} J, friction {:.2} J; {} steps in {:.0} s",
            joints.name(),
            o.result.peak_load * 1e-3,
            o.result.travel_at_peak * 1e3,
            100.0 * (o.result.peak_load * 1e-3 / TEST_PEAK_KN - 1.0),
            o.result.curve.last().map_or(0.0, |s| s.smoothed_load) * 1e-3,
            o.result.curve.last().map_or(0.0, |s| s.travel) * 1e3,
            o.energies.fracture,
            o.energies.friction,
            o.steps,
            o.seconds
        );
        if let Some(f_m) = options.masonry_strength_mpa {
            match o.first_overstress {
                Some((t, l)) => println!(
                    "  compressive stress past {f_m} MPa from {:.2} mm ({:.1} kN) on; {} cells at the end",
                    t * 1e3,
                    l * 1e-3,
                    o.overstressed_cells
                ),
                None => println!("  no cell's compressive stress passed {f_m} MPa"),
            }
        }
        if options.cap != CapArg::None {
            let at = |x: Option<(Real, Real)>| match x {
                Some((t, l)) => format!("from {:.2} mm ({:.1} kN)", t * 1e3, l * 1e-3),
                None => "never".to_owned(),
            };
            println!(
                "  cap: cells yield {}, pass the peak {}; {} crushed, {} softening at the end, the deepest by {:.3} mm",
                at(o.first_crush),
                at(o.first_softening),
                o.crushed_cells,
                o.softening_cells,
                o.max_crushing * 1e3
            );
        }
        print!("{}", crack_map(&o.damage));
        outcomes.push(o);
    }
    let points: Vec<Vec<(Real, Real)>> = outcomes
        .iter()
        .map(|o| o.result.curve.iter().map(|s| (s.travel * 1e3, s.load * 1e-3)).collect())
        .collect();
    let named: Vec<NamedCurve<'_>> = outcomes
        .iter()
        .zip(&points)
        .map(|(o, p)| match o.joints {
            Joints::Mortar => ("mortar joints (model)", "#c00000", p.as_slice()),
            Joints::Dry => ("dry joints (model)", "#404040", p.as_slice()),
        })
        .collect();
    args::write_text(&options.out.join("force_displacement.svg"), &curve_svg(&named))?;

    let stiffnesses = Stiffnesses::of(options.stiffness, options.unit_cracks);
    let mut summary = json!({
        "test": {
            "wall": "J4D (Raijmakers & Vermeltfoort 1992; Lourenço 1996)",
            "peak_kN": TEST_PEAK_KN,
            "tolerance": TOLERANCE,
        },
        "model": {
            "courses": COURSES,
            "unit_mm": [UNIT_LENGTH * 1e3, THICKNESS * 1e3, COURSE_HEIGHT * 1e3],
            "precompression_MPa": PRECOMPRESSION * 1e-6,
            "vertical_load_kN": PRECOMPRESSION * LENGTH * THICKNESS * 1e-3,
            "kn_N_per_mm3": KN * 1e-9,
            "ks_N_per_mm3": KS * 1e-9,
            "stiffness": format!("{:?}", options.stiffness),
            "unit_E_MPa": UNIT_E * 1e-6,
            "unit_nu": UNIT_NU,
            "bed_joint_kn_ks_N_per_mm3": [stiffnesses.bed.0 * 1e-9, stiffnesses.bed.1 * 1e-9],
            "head_joint_kn_ks_N_per_mm3": [stiffnesses.head.0 * 1e-9, stiffnesses.head.1 * 1e-9],
            "ft_MPa": FT * 1e-6,
            "GfI_N_per_m": GF_I,
            "c_MPa": COHESION * 1e-6,
            "tan_phi": TAN_PHI,
            "GfII_N_per_m": GF_II,
            "unit_cracks": options.unit_cracks,
            "masonry_strength_MPa": options.masonry_strength_mpa,
            "cap": options.cap.cap().map(|c| json!({
                "fm_MPa": c.strength * 1e-6,
                "Gc_N_per_m": c.fracture_energy,
                "Css": c.shear_factor,
                "kappa_p_mm": c.peak_closure * 1e3,
            })),
            "top": format!("{:?}", options.top),
            "subcontacts_per_edge": options.per_edge,
            "servo_increment_um": options.increment_um,
            "servo_threshold": options.threshold,
            "max_travel_mm": options.max_travel_mm,
        },
    });
    for o in &outcomes {
        summary[o.joints.name()] = summary_of(o);
    }
    if let Some(m) = outcomes.iter().find(|o| o.joints == Joints::Mortar) {
        let peak = m.result.peak_load * 1e-3;
        summary["peak_kN"] = json!(peak);
        summary["peak_over_test"] = json!(peak / TEST_PEAK_KN);
        summary["within_tolerance"] = json!((peak / TEST_PEAK_KN - 1.0).abs() <= TOLERANCE);
    }

    if options.check {
        let travel = options.check_travel_mm * 1e-3;
        let peak_with = |per_edge: u16, increment: Real, threshold: Real| -> Result<Real> {
            let mut wall = build(
                Joints::Mortar,
                &Options {
                    per_edge,
                    ..options.clone()
                },
            )?;
            let servo = Servo::new(wall.beam, Vector::X, increment, threshold)?;
            Ok(push(&mut wall, servo, travel, |_, _, _, _| {})?.peak_load)
        };
        let t = Instant::now();
        let density = SubContactDensity::PerEdge(options.per_edge).check_convergence(|d| match d {
            SubContactDensity::PerEdge(n) => peak_with(n, options.increment_um * 1e-6, options.threshold),
            SubContactDensity::Spacing(_) => unreachable!("the check refines a per-edge density per edge"),
        })?;
        let density_seconds = t.elapsed().as_secs_f64();
        println!(
            "density check to {:.2} mm: {} per edge {:.2} kN, {:?} {:.2} kN: change {:.2} % ({density_seconds:.0} s)",
            options.check_travel_mm,
            options.per_edge,
            density.value * 1e-3,
            SubContactDensity::PerEdge(options.per_edge).refined(),
            density.refined * 1e-3,
            100.0 * density.relative_change()
        );
        let t = Instant::now();
        let servo = Servo::new(BlockId(0), Vector::X, options.increment_um * 1e-6, options.threshold)?;
        let servo_check =
            servo.check_convergence(|s| peak_with(options.per_edge, s.increment, s.max_unbalanced_ratio))?;
        let servo_seconds = t.elapsed().as_secs_f64();
        println!(
            "servo check to {:.2} mm: {:.2} kN, refined (half increment and threshold) {:.2} kN: change {:.2} % ({servo_seconds:.0} s)",
            options.check_travel_mm,
            servo_check.value * 1e-3,
            servo_check.refined * 1e-3,
            100.0 * servo_check.relative_change()
        );
        summary["convergence"] = json!({
            "travel_mm": options.check_travel_mm,
            "density": {
                "per_edge": [options.per_edge, match SubContactDensity::PerEdge(options.per_edge).refined() {
                    SubContactDensity::PerEdge(n) => n,
                    SubContactDensity::Spacing(_) => 0,
                }],
                "peak_kN": [density.value * 1e-3, density.refined * 1e-3],
                "relative_change": density.relative_change(),
                "seconds": density_seconds,
            },
            "servo": {
                "increment_um": [options.increment_um, 0.5 * options.increment_um],
                "threshold": [options.threshold, 0.5 * options.threshold],
                "peak_kN": [servo_check.value * 1e-3, servo_check.refined * 1e-3],
                "relative_change": servo_check.relative_change(),
                "seconds": servo_seconds,
            },
        });
    }
    if let Some(count) = options.ensemble {
        let t = Instant::now();
        let peaks = ensemble_peaks(&options, count)?;
        let mut sorted = peaks.clone();
        sorted.sort_by(Real::total_cmp);
        let n = sorted.len();
        let median = if n % 2 == 1 {
            sorted[n / 2]
        } else {
            0.5 * (sorted[n / 2 - 1] + sorted[n / 2])
        };
        let seconds = t.elapsed().as_secs_f64();
        println!(
            "ensemble of {n} (pre-compression × (1 + k·1e-12)): peak median {:.2} kN, range {:.2}–{:.2} kN \
             ({:+.1} % of the test's; {seconds:.0} s)",
            median * 1e-3,
            sorted[0] * 1e-3,
            sorted[n - 1] * 1e-3,
            100.0 * (median * 1e-3 / TEST_PEAK_KN - 1.0)
        );
        summary["ensemble"] = json!({
            "perturbation": "pre-compression × (1 + k·1e-12), k = 0..n",
            "peaks_kN": peaks.iter().map(|p| p * 1e-3).collect::<Vec<_>>(),
            "median_kN": median * 1e-3,
            "range_kN": [sorted[0] * 1e-3, sorted[n - 1] * 1e-3],
            "median_over_test": median * 1e-3 / TEST_PEAK_KN,
            "seconds": seconds,
        });
    }
    voussoir::io::write_json(&options.out.join("summary.json"), &summary)?;
    println!(
        "wrote {} (summary.json, force_displacement.svg, cracks_*.svg, shear_wall_*.html, curve_*.csv)",
        options.out.display()
    );
    Ok(())
}
