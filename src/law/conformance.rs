//! Checks that a joint law keeps the contract of [`ConstitutiveLaw`]: for authors of custom laws,
//! and for anyone wrapping laws in a forwarding `enum`.
//!
//! [`check`] drives the law through a fixed, deterministic set of kinematic histories and grids
//! of steps, and checks every promise the contact kernel relies on:
//!
//! * **`elastic_regime`** ([`Clause::ElasticRegime`]): on a grid of areas, total normal
//!   displacements (both zeros, and `1e-300`, 1, 2 and 5 per decade from `1e-12` to `5e-2`,
//!   and `0.1` m, of both signs), shear increments, carried shear forces (from zero to several
//!   times the normal force and the cohesion), carried normal forces, axes and time steps,
//!   wherever [`ElasticRegime::step`](super::ElasticRegime::step) gives forces for a virgin
//!   sub-contact (the trial standing, or for a regime that
//!   [`slides`](super::ElasticRegime::slides), the slide), `update` returns its status
//!   ([`JointStatus::Elastic`] or [`JointStatus::Sliding`]), exactly its forces (the same bits)
//!   and the virgin state; and `step` stands exactly where
//!   [`ElasticRegime::trial`](super::ElasticRegime::trial) does.
//! * **`stays_open`** ([`Clause::StaysOpen`]): for every state the histories reach (and any you
//!   give to [`check_with_states`]), every area and normal displacement of the grid, wherever
//!   `stays_open` promises, `update` from zero forces returns [`JointStatus::Open`], zero forces
//!   and the same state, with several normal and shear increments, axes and time steps.
//! * **Determinism** ([`Clause::Determinism`]): every call of `update` is made twice from the
//!   same inputs and must give the same bits; `stiffness` and `elastic_regime` the same values.
//! * **Forces** ([`Clause::NonFinite`], [`Clause::OpenWithForce`]): finite after every update,
//!   and zero whenever the status is `Open` (an open joint carries nothing, see
//!   [`JointStatus::Open`]).
//! * **Stiffness** ([`Clause::Stiffness`]): `stiffness()` finite and not negative, and no
//!   elastic step (from `Elastic` to `Elastic`, state unchanged) changes the normal or the shear
//!   force faster than it says: it is the largest stiffness, which the critical time step uses.
//! * **Energies** ([`Clause::ElasticEnergy`], [`Clause::Dissipation`]): `elastic_energy` finite
//!   and not negative after every update; and the energy voussoir books as dissipated for a step
//!   (see `docs/custom-law.md`, "Dissipation"; the same expression as the contact kernel) not
//!   negative, beyond round-off, on monotonic loading: closing, opening, and sliding one way at
//!   constant normal displacement. (Reversals are not checked: an explicit return mapping of a
//!   softening law books a little negative work on the step after a reversal, made up by the
//!   steps before.)
//! * **Fracture work** ([`Clause::FractureWork`]): [`ConstitutiveLaw::fracture_work`] finite
//!   and not negative for every update, and zero for one that leaves the state as it was.
//!
//! The histories, from the virgin state, for each of four areas (`1e-4` to 4 m²) and two sets
//! of axes and time steps: closing from 0.1 m open to 0.1 m of interpenetration and opening
//! back through the displacement grid; at four compressions, sliding one way by growing
//! increments (to about 1 cm), reversing twice as far, opening, closing again and sliding
//! across; and under three small tensions, sliding, then opening fully.
//!
//! A law that passes is not proven right (only its own tests, against closed forms, do that),
//! and a grid can miss a disagreement confined between its points; but a law that fails is
//! wrong, and the error gives the step that shows it.
//! The [`ConformanceReport`] says how much of the fast paths the law offered: a law without
//! `elastic_regime` or `stays_open` passes, with `regime_stood` or `open_promised` zero. Two
//! laws that behave alike give equal reports, so comparing the report of a wrapper with the
//! inner law's shows whether it forwards the shortcuts.
//!
//! ```
//! use voussoir::law::conformance::{self, Clause};
//! use voussoir::law::{ConstitutiveLaw, JointForce, JointStatus, JointStep, JointStiffness};
//! use voussoir::math::Vector2;
//!
//! /// Frictionless, no tension; open when not compressed.
//! #[derive(Debug, Clone)]
//! struct Frictionless { kn: f64, lie: bool }
//!
//! impl ConstitutiveLaw for Frictionless {
//!     type State = ();
//!     fn stiffness(&self) -> JointStiffness { JointStiffness { normal: self.kn, shear: 0.0 } }
//!     fn update(&self, s: &JointStep, f: &mut JointForce, _: &mut ()) -> JointStatus {
//!         f.shear = Vector2::ZERO;
//!         f.normal = (-self.kn * s.normal_displacement * s.area).max(0.0);
//!         if f.normal > 0.0 { JointStatus::Sliding } else { JointStatus::Open }
//!     }
//!     fn stays_open(&self, area: f64, normal_displacement: f64, _: &()) -> bool {
//!         // The honest answer is `update`'s own test; the lie: always open.
//!         self.lie || -self.kn * normal_displacement * area <= 0.0
//!     }
//! }
//!
//! let report = conformance::check(&Frictionless { kn: 1e9, lie: false })?;
//! assert!(report.open_promised > 0 && report.regime_stood == 0);
//! let error = conformance::check(&Frictionless { kn: 1e9, lie: true }).unwrap_err();
//! assert_eq!(error.clause, Clause::StaysOpen);
//! # Ok::<(), conformance::ConformanceError>(())
//! ```

use super::{ConstitutiveLaw, JointAxes, JointForce, JointStatus, JointStep};
use crate::math::{Real, Vector, Vector2};

/// The promise of [`ConstitutiveLaw`] that a law broke (see the [module](self) documentation).
#[derive(Debug, Clone, Copy, PartialEq, Eq, Hash, thiserror::Error)]
#[non_exhaustive]
pub enum Clause {
    /// The law's own [`ConstitutiveLaw::validate`] rejects it; nothing else was checked.
    #[error("the law's own `validate` rejects it")]
    Validate,
    /// `stiffness()` is not finite and non-negative, or an elastic step stiffens beyond it.
    #[error("`stiffness` is not finite and non-negative, or an elastic step is stiffer")]
    Stiffness,
    /// The same inputs gave different results.
    #[error("not deterministic")]
    Determinism,
    /// `update` returned a force that is not finite.
    #[error("`update` returned a force that is not finite")]
    NonFinite,
    /// `update` returned [`JointStatus::Open`] with a force.
    #[error("`update` returned `Open` with a force")]
    OpenWithForce,
    /// `elastic_energy` is negative or not finite.
    #[error("`elastic_energy` is negative or not finite")]
    ElasticEnergy,
    /// A step of monotonic loading dissipated a negative energy.
    #[error("negative dissipation on monotonic loading")]
    Dissipation,
    /// `fracture_work` is negative or not finite, or not zero for an unchanged state.
    #[error("`fracture_work` is negative, not finite, or not zero for an unchanged state")]
    FractureWork,
    /// `update` does not do what [`ConstitutiveLaw::elastic_regime`] promises.
    #[error("`elastic_regime` promises what `update` does not do")]
    ElasticRegime,
    /// `update` does not do what [`ConstitutiveLaw::stays_open`] promises.
    #[error("`stays_open` promises what `update` does not do")]
    StaysOpen,
}

/// A broken promise: which, and the first inputs that show it.
#[derive(Debug, Clone, PartialEq, thiserror::Error)]
#[error("{clause}: {detail}")]
pub struct ConformanceError {
    /// The promise broken.
    pub clause: Clause,
    /// The step, forces and state that show it, and what happened.
    pub detail: String,
}

/// What [`check`] exercised. Laws that behave alike give equal reports.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Default)]
#[non_exhaustive]
pub struct ConformanceReport {
    /// Calls of `update` checked (each made twice).
    pub updates: usize,
    /// Distinct states the histories reached, with the virgin and any given state.
    pub states: usize,
    /// Grid points where the elastic regime's trial stood and `update` matched it bit for bit
    /// (zero without [`ConstitutiveLaw::elastic_regime`]).
    pub regime_stood: usize,
    /// Grid points where the trial declined, left to `update`.
    pub regime_declined: usize,
    /// Cases where `stays_open` promised and `update` kept the promise, each over four steps
    /// (zero without [`ConstitutiveLaw::stays_open`]).
    pub open_promised: usize,
    /// Cases where `stays_open` declined.
    pub open_declined: usize,
}

/// Checks `law` against the contract of [`ConstitutiveLaw`] (see the [module](self)
/// documentation for what is checked and how).
///
/// # Errors
/// The first broken promise found, with the inputs that show it.
pub fn check<L: ConstitutiveLaw>(law: &L) -> Result<ConformanceReport, ConformanceError> {
    check_with_states(law, &[])
}

/// As [`check`], with `states` checked (by `stays_open`, `elastic_energy`) besides those the
/// histories reach: for a law whose interesting states lie beyond those histories.
///
/// # Errors
/// The first broken promise found, with the inputs that show it.
pub fn check_with_states<L: ConstitutiveLaw>(
    law: &L,
    states: &[L::State],
) -> Result<ConformanceReport, ConformanceError> {
    if let Err(e) = law.validate() {
        return fail(Clause::Validate, format!("{e}"));
    }
    let k = law.stiffness();
    if !(k.normal.is_finite() && k.shear.is_finite() && k.normal >= 0.0 && k.shear >= 0.0) {
        return fail(Clause::Stiffness, format!("stiffness() = {k:?}"));
    }
    let regime = law.elastic_regime();
    if law.stiffness() != k || law.elastic_regime() != regime {
        return fail(
            Clause::Determinism,
            "`stiffness` or `elastic_regime` changed between calls".into(),
        );
    }
    let mut checker = Checker {
        law,
        report: ConformanceReport::default(),
        states: vec![L::State::default()],
    };
    for state in states {
        checker.remember(state);
    }
    checker.elastic_regime()?;
    checker.histories()?;
    checker.stays_open()?;
    checker.report.states = checker.states.len();
    Ok(checker.report)
}

fn fail<T>(clause: Clause, detail: String) -> Result<T, ConformanceError> {
    Err(ConformanceError { clause, detail })
}

/// Sub-contact areas (m²).
const AREAS: [Real; 4] = [1e-4, 0.01, 0.37, 4.0];

/// At most this many of the states reached are checked by `stays_open` (evenly picked).
const MAX_STATES: usize = 256;

/// Total normal displacements (m), ascending: `0.1`, 1, 2 and 5 per decade from `1e-12` to
/// `5e-2` and `1e-300`, both signs, and both zeros.
fn gaps() -> Vec<Real> {
    let mut magnitudes = vec![1e-300];
    for decade in -12..=-2 {
        for m in [1.0, 2.0, 5.0] {
            magnitudes.push(m * Real::powi(10.0, decade));
        }
    }
    magnitudes.push(0.1);
    let mut gaps: Vec<Real> = magnitudes.iter().rev().map(|m| -m).collect();
    gaps.extend([-0.0, 0.0]);
    gaps.extend(magnitudes);
    gaps
}

/// Sizes of the shear increments along a slide (m): 1, 2 and 5 per decade from `1e-12` to
/// `5e-3` (about 1 cm in all).
fn slide_increments() -> Vec<Real> {
    (-12..=-3)
        .flat_map(|decade| [1.0, 2.0, 5.0].map(|m| m * Real::powi(10.0, decade)))
        .collect()
}

/// Two sets of joint axes and time steps: the world's `z` and a tilted normal.
fn frames() -> [(JointAxes, Real); 2] {
    [
        (JointAxes::from_normal(Vector::Z), 1e-5),
        (JointAxes::from_normal(Vector::new(0.36, -0.48, 0.8)), 3e-3),
    ]
}

fn bits(f: &JointForce) -> [u64; 3] {
    [f.normal.to_bits(), f.shear.x.to_bits(), f.shear.y.to_bits()]
}

fn is_finite(f: &JointForce) -> bool {
    f.normal.is_finite() && f.shear.x.is_finite() && f.shear.y.is_finite()
}

struct Checker<'a, L: ConstitutiveLaw> {
    law: &'a L,
    report: ConformanceReport,
    /// Distinct states met so far, the virgin one first.
    states: Vec<L::State>,
}

/// Where a history stands between steps.
struct Point<S> {
    area: Real,
    axes: JointAxes,
    dt: Real,
    gap: Real,
    force: JointForce,
    state: S,
    status: JointStatus,
}

impl<L: ConstitutiveLaw> Checker<'_, L> {
    fn remember(&mut self, state: &L::State) {
        if !self.states.contains(state) {
            self.states.push(state.clone());
        }
    }

    /// `update` twice from the same inputs; the result if both agree bit for bit, with the
    /// checks that hold for every update (finite forces, none when open, energy).
    fn update(
        &mut self,
        step: &JointStep,
        force: JointForce,
        state: &L::State,
    ) -> Result<(JointStatus, JointForce, L::State), ConformanceError> {
        self.report.updates += 1;
        let (mut f, mut s) = (force, state.clone());
        let status = self.law.update(step, &mut f, &mut s);
        let (mut g, mut t) = (force, state.clone());
        let again = self.law.update(step, &mut g, &mut t);
        let context = || format!("{step:?}, force before {force:?}, state before {state:?}");
        if status != again || bits(&f) != bits(&g) || s != t {
            return fail(
                Clause::Determinism,
                format!(
                    "{}: once {status:?} {f:?} {s:?}, again {again:?} {g:?} {t:?}",
                    context()
                ),
            );
        }
        if !is_finite(&f) {
            return fail(Clause::NonFinite, format!("{}: {status:?} {f:?}", context()));
        }
        if status == JointStatus::Open && (f.normal != 0.0 || f.shear != Vector2::ZERO) {
            return fail(Clause::OpenWithForce, format!("{}: {f:?}", context()));
        }
        let energy = self.law.elastic_energy(step.area, &f, &s);
        if !(energy >= 0.0 && energy.is_finite()) {
            return fail(
                Clause::ElasticEnergy,
                format!("{}: {status:?} {f:?} {s:?}, elastic energy {energy}", context()),
            );
        }
        let fracture = self.law.fracture_work(step.area, state, &s);
        if !(fracture >= 0.0 && fracture.is_finite()) || (s == *state && fracture != 0.0) {
            return fail(
                Clause::FractureWork,
                format!("{}: {status:?} {f:?} {s:?}, fracture work {fracture}", context()),
            );
        }
        Ok((status, f, s))
    }

    /// The elastic regime's promise for a virgin sub-contact, over the grid.
    fn elastic_regime(&mut self) -> Result<(), ConformanceError> {
        let Some(regime) = self.law.elastic_regime() else {
            return Ok(());
        };
        let virgin = L::State::default();
        let mut increments = vec![Vector2::ZERO];
        for m in [1e-12, 1e-9, 1e-7, 3e-6, 1e-5, 1e-4, 1e-3] {
            increments.push(Vector2::new(m, 0.6 * m));
            increments.push(Vector2::new(-0.3 * m, m));
        }
        let direction = Vector2::new(1.0, -0.3).normalize();
        for &area in &AREAS {
            for gap in gaps() {
                let normal = -regime.normal_stiffness * gap * area;
                let mut carried = vec![Vector2::ZERO];
                for scale in [normal.abs(), regime.cohesion * area] {
                    if scale > 0.0 && scale.is_finite() {
                        for factor in [0.01, 0.5, 0.99, 1.0, 1.01, 3.0] {
                            carried.push(direction * (factor * scale));
                        }
                    }
                }
                for &du in &increments {
                    for &shear in &carried {
                        let stepped = regime.step(area, gap, du, shear);
                        let elastic = stepped.filter(|(_, status)| *status == JointStatus::Elastic);
                        if elastic.map(|(force, _)| bits(&force))
                            != regime.trial(area, gap, du, shear).map(|f| bits(&f))
                        {
                            return fail(
                                Clause::ElasticRegime,
                                format!("{regime:?}: `step` and `trial` disagree at area {area}, gap {gap}, du {du:?}"),
                            );
                        }
                        let Some((trial, expected)) = stepped else {
                            self.report.regime_declined += 1;
                            continue;
                        };
                        self.report.regime_stood += 1;
                        for (axes, dt) in frames() {
                            for (previous, normal_increment) in [(0.0, 0.0), (trial.normal, 0.0), (1.0, -1e-7)] {
                                let step = JointStep {
                                    area,
                                    normal_displacement: gap,
                                    normal_increment,
                                    shear_increment: du,
                                    axes,
                                    dt,
                                };
                                let before = JointForce {
                                    normal: previous,
                                    shear,
                                };
                                let (status, force, state) = self.update(&step, before, &virgin)?;
                                if status != expected || bits(&force) != bits(&trial) || state != virgin {
                                    return fail(
                                        Clause::ElasticRegime,
                                        format!(
                                            "{step:?} from {before:?} in the virgin state: the step \
                                             of {regime:?} gives {expected:?} with {trial:?}, but `update` \
                                             returned {status:?}, {force:?}, state {state:?}"
                                        ),
                                    );
                                }
                            }
                        }
                    }
                }
            }
        }
        Ok(())
    }

    /// The histories, from the virgin state.
    fn histories(&mut self) -> Result<(), ConformanceError> {
        let gaps = gaps();
        let slides = slide_increments();
        let (d1, d2) = (Vector2::new(0.8, 0.6), Vector2::new(-0.6, 0.8));
        for &area in &AREAS {
            for (axes, dt) in frames() {
                let start = |gap: Real| Point {
                    area,
                    axes,
                    dt,
                    gap,
                    force: JointForce::default(),
                    state: L::State::default(),
                    status: JointStatus::Open,
                };
                // Closing from wide open to deep interpenetration, and opening back.
                let mut p = start(0.1);
                self.walk(&mut p, &gaps, -0.1)?;
                self.walk(&mut p, &gaps, 0.1)?;
                // Sliding at four compressions: one way, back twice as far, opening, closing
                // and sliding across.
                for compression in [-1e-9, -1e-6, -1e-4, -1e-2] {
                    let mut p = start(0.0);
                    self.walk(&mut p, &gaps, compression)?;
                    self.slide(&mut p, &slides, d1, true)?;
                    self.slide(&mut p, &slides, -d1, false)?;
                    self.slide(&mut p, &slides, -d1, false)?;
                    self.walk(&mut p, &gaps, 1e-2)?;
                    self.walk(&mut p, &gaps, compression)?;
                    self.slide(&mut p, &slides, d2, false)?;
                }
                // Sliding under a small tension (a bonded joint carries some), then opening.
                for tension in [1e-9, 1e-6, 2e-5] {
                    let mut p = start(0.0);
                    self.walk(&mut p, &gaps, tension)?;
                    self.slide(&mut p, &slides, d2, true)?;
                    self.walk(&mut p, &gaps, 0.1)?;
                }
            }
        }
        Ok(())
    }

    /// Moves the normal displacement to `to` through the grid values between, without shear.
    fn walk(&mut self, p: &mut Point<L::State>, gaps: &[Real], to: Real) -> Result<(), ConformanceError> {
        let from = p.gap;
        let path: Vec<Real> = if to < from {
            gaps.iter().rev().copied().filter(|&g| g < from && g >= to).collect()
        } else {
            gaps.iter().copied().filter(|&g| g > from && g <= to).collect()
        };
        for gap in path {
            self.advance(p, gap, Vector2::ZERO, true)?;
        }
        Ok(())
    }

    /// Slides by `increments` along `direction` at constant normal displacement.
    fn slide(
        &mut self,
        p: &mut Point<L::State>,
        increments: &[Real],
        direction: Vector2,
        monotonic: bool,
    ) -> Result<(), ConformanceError> {
        for &du in increments {
            self.advance(p, p.gap, direction * du, monotonic)?;
        }
        Ok(())
    }

    /// One step of a history: the update, the stiffness bound, and on monotonic loading the
    /// dissipation.
    fn advance(
        &mut self,
        p: &mut Point<L::State>,
        gap: Real,
        du_s: Vector2,
        monotonic: bool,
    ) -> Result<(), ConformanceError> {
        let step = JointStep {
            area: p.area,
            normal_displacement: gap,
            normal_increment: gap - p.gap,
            shear_increment: du_s,
            axes: p.axes,
            dt: p.dt,
        };
        let (status, force, state) = self.update(&step, p.force, &p.state)?;
        let before = p.force;
        let context = || {
            format!(
                "{step:?}, force before {before:?}, state before {:?}, status before {:?}: {status:?}, \
                 {force:?}, {state:?}",
                p.state, p.status
            )
        };
        if p.status == JointStatus::Elastic && status == JointStatus::Elastic && state == p.state {
            let k = self.law.stiffness();
            let exceeds = |change: Real, stiffness: Real, displacement: Real, scale: Real| {
                change > stiffness * p.area * displacement * (1.0 + 1e-9) + 1e-12 * scale
            };
            let normal = exceeds(
                (force.normal - before.normal).abs(),
                k.normal,
                step.normal_increment.abs(),
                force.normal.abs() + before.normal.abs(),
            );
            let shear = exceeds(
                (force.shear - before.shear).length(),
                k.shear,
                du_s.length(),
                force.shear.length() + before.shear.length(),
            );
            if normal || shear {
                return fail(
                    Clause::Stiffness,
                    format!("{}: stiffer than stiffness() = {k:?}", context()),
                );
            }
        }
        if monotonic {
            let dissipated = booked_dissipation(self.law, p, &step, &force, &state, status);
            let e = |f: &JointForce, s: &L::State| self.law.elastic_energy(p.area, f, s);
            let scale = e(&before, &p.state)
                + e(&force, &state)
                + (before.normal.abs() + force.normal.abs()) * step.normal_increment.abs()
                + (before.shear.length() + force.shear.length()) * du_s.length();
            if dissipated < -1e-9 * scale {
                return fail(Clause::Dissipation, format!("{}: dissipated {dissipated} J", context()));
            }
        }
        self.remember(&state);
        *p = Point {
            gap,
            force,
            state,
            status,
            ..*p
        };
        Ok(())
    }

    /// The promise of `stays_open` at every state met, area and normal displacement.
    fn stays_open(&mut self) -> Result<(), ConformanceError> {
        let states: Vec<L::State> = if self.states.len() > MAX_STATES {
            (0..MAX_STATES)
                .map(|i| self.states[i * self.states.len() / MAX_STATES].clone())
                .collect()
        } else {
            self.states.clone()
        };
        let [(z, slow), (tilted, fast)] = frames();
        for state in &states {
            for &area in &AREAS {
                for gap in gaps() {
                    let promised = self.law.stays_open(area, gap, state);
                    if promised != self.law.stays_open(area, gap, state) {
                        return fail(
                            Clause::Determinism,
                            format!("`stays_open({area}, {gap}, {state:?})` changed between calls"),
                        );
                    }
                    if !promised {
                        self.report.open_declined += 1;
                        continue;
                    }
                    self.report.open_promised += 1;
                    let rests = [
                        (0.0, Vector2::ZERO, z, slow),
                        (1e-6, Vector2::new(1e-3, -2e-4), tilted, fast),
                        (-1e-6, Vector2::new(-1e-7, 0.0), z, fast),
                        (gap, Vector2::new(0.0, 5e-5), tilted, slow),
                    ];
                    for (normal_increment, shear_increment, axes, dt) in rests {
                        let step = JointStep {
                            area,
                            normal_displacement: gap,
                            normal_increment,
                            shear_increment,
                            axes,
                            dt,
                        };
                        let (status, force, after) = self.update(&step, JointForce::default(), state)?;
                        if status != JointStatus::Open || force != JointForce::default() || after != *state {
                            return fail(
                                Clause::StaysOpen,
                                format!(
                                    "`stays_open` promised at {step:?} in state {state:?}, but `update` \
                                     from zero forces returned {status:?}, {force:?}, state {after:?}"
                                ),
                            );
                        }
                    }
                }
            }
        }
        Ok(())
    }
}

/// The energy the contact kernel books as dissipated by the law over a step from `p` (see
/// `docs/custom-law.md`, "Dissipation"; the same expression as the kernel's `update_with_law`,
/// keep them in step).
fn booked_dissipation<L: ConstitutiveLaw>(
    law: &L,
    p: &Point<L::State>,
    step: &JointStep,
    force: &JointForce,
    state: &L::State,
    status: JointStatus,
) -> Real {
    let before = &p.force;
    let du_s = step.shear_increment;
    if *state != p.state {
        let work = -0.5
            * ((before.normal + force.normal) * (step.normal_displacement - p.gap)
                + (before.shear + force.shear).dot(du_s));
        work - (law.elastic_energy(p.area, force, state) - law.elastic_energy(p.area, before, &p.state))
    } else if status == JointStatus::Sliding || (status == JointStatus::Open && before.shear != Vector2::ZERO) {
        let work = -0.5 * (before.shear + force.shear).dot(du_s);
        let ks_area = law.stiffness().shear * p.area;
        if ks_area > 0.0 {
            work - 0.5 * (force.shear.length_squared() - before.shear.length_squared()) / ks_area
        } else {
            work
        }
    } else {
        0.0
    }
}

#[cfg(test)]
#[path = "conformance_tests.rs"]
mod tests;
