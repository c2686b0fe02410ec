//! Quasi-static loading: displacement control whose answer does not depend on the loading
//! speed.
//!
//! A block driven at a prescribed velocity (a loading plate) loads a structure dynamically: the
//! structure lags behind the plate, and what the plate measures includes inertia. The faster
//! the plate, the more inertia; a peak load read at a fast rate overestimates the capacity, and
//! the collapse mechanism may change (`docs/benchmarks/arch-static.md`).
//!
//! [`Servo`] removes the rate from the answer: the plate advances by a fixed increment per
//! step ([`Servo::increment`]) only while the model is close to equilibrium — the
//! unbalanced-force ratio ([`crate::Model::unbalanced_force_ratio`]) at or below
//! [`Servo::max_unbalanced_ratio`] — and stands still otherwise, until the structure has
//! settled under the load it carries. The plate's path is thus followed through a sequence of
//! equilibria; there is no loading speed at all, and the answer is read at the settled states
//! ([`Servo::settled`]). Use it (with local damping, which settles the structure between
//! advances) for capacities, pushover curves and softening branches. Use a plain prescribed
//! velocity ([`crate::block::Fixity::velocity`]) when the rate is part of the problem (impact,
//! a test run at a known speed). Check the answer of any quasi-static run by halving the
//! increment and the threshold ([`Servo::refined`], [`Servo::check_convergence`]): a converged
//! answer does not move.
//!
//! Choosing the parameters:
//! - **`max_unbalanced_ratio`** sets how close to equilibrium each state is: it is the
//!   parameter the answer depends on most. Where joints slide or hinges form, the path between
//!   equilibria matters (friction is path-dependent), and a loose threshold loads the structure
//!   a little dynamically; 1e-3 is a sensible start, and [`Servo::check_convergence`] says
//!   whether it is tight enough.
//! - **`increment`** sets how far apart the equilibria are: small against the displacements
//!   of interest (the answer is read every many increments), not so small that the run is
//!   made of increments. The cost of settling after an increment grows only with its
//!   logarithm, so a larger increment is cheaper per metre of travel.
//! - **The time step.** Inertia plays no part in a quasi-static answer, so the step's margin
//!   below the stability limit, which impacts and changing contacts need, is not needed
//!   either: [`crate::integrate::TimeStep::Auto`] with `safety` 0.8–0.9 (the limit is an
//!   upper bound of the frequencies, `docs/theory.md`) halves the steps of a servo run against
//!   the default 0.5. Check that the answer does not change.
//! - **Mass scaling** (3DEC's static mode) is not offered: in an assembly of similar blocks,
//!   such as an arch, it barely changes the ratio of the highest to the lowest frequency, which
//!   is what settling costs.
//!
//! ```
//! use std::ops::ControlFlow;
//! use voussoir::loading::Servo;
//! use voussoir::prelude::*;
//!
//! // A cube between a fixed base and a plate pushed down: two joints in series, each `kn·A`,
//! // so once the plate touches, its force grows by `kn·A·Δδ/2` for a travel `Δδ`.
//! let (kn, a) = (1e9, 0.04);
//! let mut model: Model = Model::new(ModelParameters::default())?;
//! model.set_joint_law(MaterialId(0), MaterialId(0), CoulombSlip::dry(kn, kn, 30.0)?)?;
//! model.set_damping(Damping::Local { alpha: 0.8 })?;
//! model.add_block(
//!     RigidBlock::cuboid("base", Vector::new(-0.5, -0.5, -0.1), Vector::new(0.5, 0.5, 0.0), 2500.0)?
//!         .with_fixity(Fixity::FIXED),
//! )?;
//! let cube = model.add_block(RigidBlock::cuboid("cube", Vector::new(-0.1, -0.1, 0.0), Vector::new(0.1, 0.1, 0.2), 2500.0)?)?;
//! let plate = model.add_block(
//!     RigidBlock::cuboid("plate", Vector::new(-0.3, -0.3, 0.2), Vector::new(0.3, 0.3, 0.25), 7800.0)?
//!         .with_fixity(Fixity::velocity(Vector::ZERO)),
//! )?;
//! let servo = Servo::new(plate, Vector::new(0.0, 0.0, -1.0), 1e-7, 1e-3)?; // 0.1 µm a step
//! # let _ = servo.refined();
//! let z0 = model.block(plate)?.state().pose.translation.z;
//! let mut samples = Vec::new(); // (travel, plate force) at 20 and 40 µm
//! servo.run(&mut model, 1_000_000, &mut |m: &Model| {
//!     let travel = z0 - m.blocks()[plate.index()].state().pose.translation.z;
//!     if servo.settled(m) && travel >= 2e-5 * (samples.len() + 1) as f64 {
//!         samples.push((travel, m.contact_between(cube, plate).map_or(0.0, |c| c.normal_force())));
//!     }
//!     Ok(if samples.len() == 2 { ControlFlow::Break(()) } else { ControlFlow::Continue(()) })
//! })?;
//! let [(t1, f1), (t2, f2)] = [samples[0], samples[1]];
//! let expected = kn * a * (t2 - t1) / 2.0;
//! assert!(((f2 - f1) - expected).abs() < 0.01 * expected, "{} N vs {expected} N", f2 - f1);
//! # Ok::<(), voussoir::Error>(())
//! ```

mod pushover;
mod servo;

pub use crate::math::Convergence;
pub use crate::signal::{BaseMotion, LoadHistory, MotionKind, TimeHistory};
pub use pushover::{PushOver, PushOverResult, PushOverSample, PushOverStop};
pub use servo::Servo;
