//! Limit analysis of the reference arch (`voussoir::analysis::limit`): the collapse load of a
//! point load on voussoir 5 through the static test's plate, the collapse mechanism, and the
//! mechanism as a ParaView series — the answer of a rigid-block limit analysis (RING, LiABlock)
//! beside the DEM's ([`super::arch_static`]).

use std::fmt::Write as _;
use std::path::Path;

use serde::{Deserialize, Serialize};
use voussoir::analysis::limit::LimitResult;
use voussoir::block::{Block, BlockId, RigidBlock};
use voussoir::error::{Error, Result};
use voussoir::math::Real;
use voussoir::model::Model;

use super::arch_static::{build, limit_analysis, LimitSummary, StaticCase};

/// A limit analysis of the reference arch.
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
pub struct LimitCase {
    /// The static case whose arch, plate and joint friction are analysed.
    pub case: StaticCase,
    /// Settle the arch under gravity first (as the static test does before loading); otherwise
    /// the arch as built (one step, to detect its contacts).
    pub settle: bool,
}

/// What [`run`] gives.
#[derive(Debug)]
pub struct LimitRun {
    /// The model the analysis was made on.
    pub model: Model,
    /// The summary (load on voussoir 5, mechanism).
    pub summary: LimitSummary,
    /// The full answer: contact forces at collapse, block velocities of the mechanism.
    pub result: LimitResult,
    /// Steps taken before the analysis (settling, or the one detecting step).
    pub steps: u64,
}

/// Builds the case's arch and plate ([`build`]), settles it (or steps once) and runs the limit
/// analysis ([`limit_analysis`]).
///
/// # Errors
/// Bad parameters, a failed settling, or the limit analysis's errors.
pub fn run(c: &LimitCase) -> Result<LimitRun> {
    let mut m = build(&c.case)?;
    if c.settle {
        m.model.run_to_equilibrium(c.case.settle_ratio, 200_000)?;
    } else {
        m.model.step()?;
    }
    let (summary, result) = limit_analysis(&m.model, m.plate, &m.joints)?;
    Ok(LimitRun {
        steps: m.model.step_count(),
        model: m.model,
        summary,
        result,
    })
}

/// Writes the mechanism as a ParaView series `<name>_blocks_<k>.vtu` (k = 0..frames-1) with
/// its collection `<name>_blocks.pvd` into `dir`: the blocks moved along the mechanism, rigidly
/// (a turn about the centroid and a translation), so that the point that moves most has moved
/// `amplitude` (m) in the last frame; each frame's `velocity` array is the mechanism's block
/// velocity, on the same scale, and `displacement`/`rotation` are from the analysed pose.
/// Returns the path of the collection.
///
/// # Errors
/// [`Error::InvalidParameter`] for fewer than 2 frames or a bad amplitude; [`Error::Io`].
pub fn write_mechanism(
    dir: &Path,
    name: &str,
    model: &Model,
    result: &LimitResult,
    frames: usize,
    amplitude: Real,
) -> Result<std::path::PathBuf> {
    voussoir::error::positive("mechanism amplitude (m)", amplitude)?;
    if frames < 2 {
        return Err(Error::InvalidParameter {
            name: "mechanism frames".into(),
            value: frames as Real,
            expected: "at least 2",
        });
    }
    // The largest speed of a block's vertex in the mechanism.
    let fastest = model
        .blocks()
        .iter()
        .enumerate()
        .flat_map(|(k, b)| {
            b.shape()
                .vertices()
                .iter()
                .map(move |v| (k, b.state().pose.transform_point(*v)))
        })
        .map(|(k, p)| result.point_velocity(BlockId(k as u32), p).map_or(0.0, |v| v.length()))
        .fold(0.0, Real::max);
    let scale = if fastest > 0.0 { amplitude / fastest } else { 0.0 };
    std::fs::create_dir_all(dir).map_err(|e| Error::Io {
        path: dir.display().to_string(),
        message: e.to_string(),
    })?;
    let mut pvd = String::from(
        "<?xml version=\"1.0\"?>\n<VTKFile type=\"Collection\" version=\"0.1\" byte_order=\"LittleEndian\">\n<Collection>\n",
    );
    for k in 0..frames {
        let t = scale * k as Real / (frames - 1) as Real;
        let moved: Vec<RigidBlock> = model
            .blocks()
            .iter()
            .enumerate()
            .map(|(i, b)| {
                let id = BlockId(i as u32);
                let (v, w) = result.block_velocity(id).unwrap_or_default();
                b.clone()
                    .transformed(result.displacement(id, t))
                    .with_velocity(v * scale, w * scale)
            })
            .collect();
        let file = format!("{name}_blocks_{k:05}.vtu");
        voussoir::io::vtk::write_blocks(&dir.join(&file), &moved, |i| model.blocks()[i].state().pose)?;
        let _ = writeln!(
            pvd,
            "<DataSet timestep=\"{:e}\" group=\"\" part=\"0\" file=\"{file}\"/>",
            k as Real / (frames - 1) as Real
        );
    }
    pvd.push_str("</Collection>\n</VTKFile>\n");
    let path = dir.join(format!("{name}_blocks.pvd"));
    voussoir::io::write_atomically(&path, pvd.as_bytes())?;
    Ok(path)
}
