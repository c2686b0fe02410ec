//! The conic programme in Clarabel's form and its solution.

use clarabel::algebra::CscMatrix;
use clarabel::solver::{DefaultSettings, DefaultSolver, IPSolver, SolverStatus, SupportedConeT};

use super::FEASIBILITY_TOLERANCE;
use crate::error::{Error, Result};
use crate::math::{Real, Vector};

#[derive(Debug, Clone, Copy)]
pub(super) struct Scales {
    /// Reference force (N): the free blocks' weight.
    pub(super) force: Real,
    /// Reference length (m): their mean radius.
    pub(super) length: Real,
    /// Sum of the live loads' magnitudes (N).
    pub(super) live: Real,
    /// `λ = multiplier × λ̂`.
    pub(super) multiplier: Real,
}

#[derive(Debug, Clone, Copy)]
pub(super) struct Corner {
    pub(super) contact: usize,
    pub(super) point: Vector,
    pub(super) n: usize,
    pub(super) t: Option<(usize, usize)>,
}

#[derive(Debug, Default)]
pub(super) struct Triplets {
    pub(super) rows: Vec<usize>,
    pub(super) cols: Vec<usize>,
    pub(super) values: Vec<Real>,
}

impl Triplets {
    pub(super) fn push(&mut self, r: usize, c: usize, v: Real) {
        if v != 0.0 {
            self.rows.push(r);
            self.cols.push(c);
            self.values.push(v);
        }
    }
    pub(super) fn into_csc(self, m: usize, n: usize) -> CscMatrix<Real> {
        CscMatrix::new_from_triplets(m, n, self.rows, self.cols, self.values)
    }
}

pub(super) struct Programme {
    /// Number of equilibrium rows (the first rows).
    pub(super) equations: usize,
    pub(super) a: CscMatrix<Real>,
    pub(super) b: Vec<Real>,
    pub(super) q: Vec<Real>,
    pub(super) cones: Vec<SupportedConeT<Real>>,
    pub(super) row_of: Vec<Option<usize>>,
    pub(super) corners: Vec<Corner>,
}

pub(super) struct Solution {
    pub(super) x: Vec<Real>,
    pub(super) z: Vec<Real>,
}

impl Programme {
    pub(super) fn run(&self, max_iterations: u32) -> Result<(Solution, SolverStatus, u32)> {
        let n = self.q.len();
        if n == 0 || self.equations == 0 {
            // Nothing to solve: no contact forces, or no equation. With no equation the
            // multiplier is unbounded (the programme's only cost) and the dead loads are carried.
            let carried = self.b[..self.equations]
                .iter()
                .all(|v| v.abs() <= FEASIBILITY_TOLERANCE);
            let status = match (carried, n > 0 && self.q[0] != 0.0 && self.equations == 0) {
                (false, _) => SolverStatus::PrimalInfeasible,
                (true, true) => SolverStatus::DualInfeasible,
                (true, false) => SolverStatus::Solved,
            };
            // Infeasible: the unbalanced loads themselves are the certificate (`z = −b` on the
            // equilibrium rows; `Aᵀz = 0` with no variable, `bᵀz < 0`), the free blocks moving
            // along their dead loads.
            let mut z = vec![0.0; self.b.len()];
            if !carried {
                for (z, b) in z.iter_mut().zip(&self.b[..self.equations]) {
                    *z = -b;
                }
            }
            return Ok((Solution { x: vec![0.0; n], z }, status, 0));
        }
        let p = CscMatrix::zeros((n, n));
        let settings = DefaultSettings {
            verbose: false,
            max_iter: max_iterations,
            ..DefaultSettings::default()
        };
        let mut solver = DefaultSolver::new(&p, &self.q, &self.a, &self.b, &self.cones, settings).map_err(|e| {
            Error::LimitSolver {
                status: format!("refused the programme: {e}"),
                iterations: 0,
            }
        })?;
        solver.solve();
        let s = &solver.solution;
        Ok((
            Solution {
                x: s.x.clone(),
                z: s.z.clone(),
            },
            s.status,
            s.iterations,
        ))
    }
}
