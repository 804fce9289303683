//! clarabel's interior-point QP on a cell's lists (the fallback of the LPs and QPs of the crate when the exact
//! active-set method fails on a degenerate problem, and the tests' cross-check). A leaf module: it takes the rows and
//! offsets as plain arrays.

use clarabel::algebra::CscMatrix;
use clarabel::solver::{DefaultSettingsBuilder, DefaultSolver, IPSolver, NonnegativeConeT, SolverStatus};

/// `min 1/2 sum h_i x_i^2 + g . x  s.t.  rows_j . x <= b_j` with clarabel; `Solved` only.
pub(crate) fn clarabel_qp<const D: usize>(
    h: &[f64; D],
    g: &[f64; D],
    rows: &[[f64; 4]],
    b: &[f64],
) -> Result<Vec<f64>, String> {
    let m = rows.len();
    // P: diagonal, upper triangle, explicit zeros dropped
    let mut colptr = vec![0usize];
    let mut rowval = Vec::new();
    let mut nzval = Vec::new();
    for i in 0..D {
        if h[i] != 0.0 {
            rowval.push(i);
            nzval.push(h[i]);
        }
        colptr.push(rowval.len());
    }
    let p = CscMatrix::new(D, D, colptr, rowval, nzval);
    let mut colptr = vec![0usize];
    let mut rowval = Vec::new();
    let mut nzval = Vec::new();
    for i in 0..D {
        for (j, r) in rows.iter().enumerate() {
            if r[i] != 0.0 {
                rowval.push(j);
                nzval.push(r[i]);
            }
        }
        colptr.push(rowval.len());
    }
    let a = CscMatrix::new(m, D, colptr, rowval, nzval);
    let cones = [NonnegativeConeT(m)];
    // with clarabel's equilibration first, then without: on some small, well-scaled QPs the equilibrated problem
    // never converges (a 3-variable, 9-row cell of a 4096-case run, seed 2718: the gap stays at 0.47 relative for
    // 200 iterations, at these tolerances and at the defaults) while the plain one solves in 10 iterations
    // (upstream: oxfordcontrol/Clarabel.rs issue 217, "Fail to solve small QP problems", equilibration enabled)
    let mut status = SolverStatus::Unsolved;
    for equilibrate in [true, false] {
        let settings = DefaultSettingsBuilder::default()
            .verbose(false)
            .tol_gap_abs(1e-11)
            .tol_gap_rel(1e-11)
            .tol_feas(1e-11)
            .tol_ktratio(1e-9)
            .max_iter(200)
            .equilibrate_enable(equilibrate)
            .build()
            .map_err(|e| format!("settings: {e}"))?;
        let mut solver = DefaultSolver::new(&p, g, &a, b, &cones, settings).map_err(|e| format!("setup: {e}"))?;
        solver.solve();
        status = solver.solution.status;
        if status == SolverStatus::Solved {
            return Ok(solver.solution.x.clone());
        }
        tracing::debug!(?status, equilibrate, rows = m, "clarabel QP not solved");
    }
    Err(format!("{status:?}"))
}
