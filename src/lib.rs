//! # voussoir
//!
//! Discrete element modelling of masonry built from rigid convex polyhedral blocks: arches,
//! walls, vaults and bridges under static and impact loads.
//!
//! Blocks interact through **soft contacts**: each joint carries sub-contacts (points with a
//! tributary area) where normal and shear springs, capped by a [`ConstitutiveLaw`] such as
//! Coulomb slip with tension cut-off, give the joint forces. Blocks move by explicit central
//! difference with local (Cundall) or Rayleigh damping. f64 and SI units throughout.
//!
//! ## Getting started
//!
//! A block on an incline steeper than its friction angle slides with
//! `a = g (sin ψ − tan φ cos ψ)`:
//!
//! ```
//! use voussoir::prelude::*;
//!
//! let slope = 35f64.to_radians();
//! let params = ModelParameters {
//!     gravity: 9.81 * Vector::new(slope.sin(), 0.0, -slope.cos()), // incline as a tilted gravity
//!     ..ModelParameters::default()
//! };
//! let mut model: Model = Model::new(params)?;
//! model.set_joint_law(MaterialId(0), MaterialId(0), CoulombSlip::dry(1e9, 1e9, 30.0)?)?;
//! model.set_damping(Damping::None)?;
//! model.add_block(
//!     RigidBlock::cuboid("ramp", Vector::new(-1.0, -0.5, -0.1), Vector::new(2.0, 0.5, 0.0), 2500.0)?
//!         .with_fixity(Fixity::FIXED),
//! )?;
//! let brick = model.add_block(RigidBlock::cuboid("brick", Vector::ZERO, Vector::new(0.2, 0.2, 0.1), 2500.0)?)?;
//! model.run_until_time(0.3)?;
//! let v = model.block(brick)?.state().velocity.x;
//! let a = 9.81 * (slope.sin() - 30f64.to_radians().tan() * slope.cos());
//! assert!((v / 0.3 - a).abs() < 0.03 * a, "{} vs {}", v / 0.3, a);
//! # Ok::<(), voussoir::Error>(())
//! ```
//!
//! ## Map of the crate
//!
//! `docs/architecture.md` draws the house: the step as a list of stages, who owns which data.
//!
//! | module | stage |
//! |---|---|
//! | [`geometry`] | polyhedra, mass properties, broad phase, contact polygon and sub-contacts |
//! | [`block`] | the [`Block`] trait, fixity, rigid blocks |
//! | [`ids`] | typed ids |
//! | [`contact`] | the read API of contacts (views, the [`Contact`] trait) and the contact kernel |
//! | [`law`] | the [`ConstitutiveLaw`] trait and the shipped laws |
//! | [`loading`] | quasi-static loading: servo-controlled displacement |
//! | [`integrate`] | the [`Integrator`] trait, central difference, damping, critical step |
//! | [`model`] | the [`Model`]: state, the step's stages, runs and observers, energies, checkpoints |
//! | [`monitor`] | observation: the [`monitor::Probe`] trait, built-in monitors, the recorder and histories |
//! | [`build`] | generators (walls, arches, vaults): they return blocks |
//! | [`scenes`] | ready-made models (the benchmarks' wall) |
//! | [`io`] | ParaView series, CSV histories, scenes (feature `io`) |
//! | [`analysis`] | joint states and collapse mechanisms; limit analysis (feature `limit`) |
//!
//! The reproduction of the reference arch's tests (Pulatsu, Gonen & Lourenço 2021), with its
//! command line, plots and progress bars, is the repository's unpublished `voussoir-arch` crate
//! (`arch/`), built on this crate's public API.
//!
//! ## Features
//!
//! All three are on by default; `default-features = false` builds the solver alone (parry, glam,
//! rayon, thiserror, approx).
//!
//! | feature | gives | brings in |
//! |---|---|---|
//! | `serde` | `Serialize`/`Deserialize` on the public types (parameters, laws and their states, blocks, monitors, histories, joint states); checkpoints: [`Model::to_checkpoint_string`], [`Model::from_checkpoint_str`], [`Model::save_checkpoint`], [`Model::load_checkpoint`] | serde, serde_json, serde_path_to_error, glam's and parry's serde support |
//! | `io` | the `io` module: ParaView series, CSV histories, scene files, `write_json` | `serde` |
//! | `limit` | [`analysis::limit`]: limit analysis of the blocks as they stand (collapse load multiplier, contact forces, mechanism) | clarabel (pure-Rust conic interior point) |
#![cfg_attr(docsrs, feature(doc_cfg))]
#![warn(missing_docs)]

pub mod analysis;
pub mod block;
pub mod build;
pub mod contact;
mod dispatch;
pub mod error;
#[cfg_attr(not(feature = "serde"), allow(dead_code))]
mod file;
pub mod geometry;
pub mod ids;
pub mod integrate;
#[cfg(feature = "io")]
#[cfg_attr(docsrs, doc(cfg(feature = "io")))]
pub mod io;
#[cfg(feature = "serde")]
mod json_keys;
pub mod law;
pub mod loading;
pub mod math;
pub mod model;
pub mod monitor;
pub mod scenes;
pub mod signal;

pub use block::{Block, BlockId, RigidBlock};
pub use contact::Contact;
pub use error::{Error, Result};
pub use integrate::Integrator;
pub use law::ConstitutiveLaw;
pub use model::{Model, ModelParameters};

// Fails to compile if our glam and parry's glam ever diverge.
const _: fn(glam::DVec3) -> parry3d_f64::math::Vector = |v| v;
const _: fn(glam::DQuat) -> parry3d_f64::math::Rotation = |q| q;
const _: fn(parry3d_f64::glamx::DPose3) -> parry3d_f64::math::Pose = |p| p;

/// The names most programs need.
pub mod prelude {
    pub use crate::block::{Block, BlockId, Dof, Fixity, RigidBlock, Wrench};
    pub use crate::contact::{Contact, DisplacementMode};
    pub use crate::error::{Error, Result};
    #[allow(deprecated)]
    pub use crate::geometry::SubcontactDensity;
    pub use crate::geometry::{ContactParameters, NodeRule, SubContactDensity};
    pub use crate::integrate::{CentralDifference, Damping, Integrator, TimeStep};
    pub use crate::law::{
        AnyLaw, ConstitutiveLaw, CoulombSlip, JointStatus, LawTable, LinearElastic, MaterialId, MortarJoint,
    };
    pub use crate::math::{Pose, Real, Rotation, Vector};
    pub use crate::model::{Energies, Model, ModelParameters, Observer};
    pub use crate::monitor::{Component, EnergyTerm, Monitor, MonitorId, Probe, Recorder};
}

/// The README's usage example, compiled and run as a doc-test.
#[cfg(doctest)]
#[doc = include_str!("../README.md")]
pub struct ReadmeDoctests;
