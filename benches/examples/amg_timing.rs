//! The smoothed-aggregation multigrid (`hpge_benches::amg`) against the solver's sparse Cholesky
//! on Super-Siegfried's weighting system, from 10^4 to 10^6 unknowns: a measurement of minutes,
//! one CSV line per grid on stdout. Its conclusion (the factorisation stays) and the data are in
//! `reports/solver-performance.md` and `reports/data/amg-vs-cholesky.csv`:
//!
//! ```text
//! RAYON_NUM_THREADS=1 cargo run --release -p hpge-benches --example amg_timing > reports/data/amg-vs-cholesky.csv
//! ```

use std::time::Instant;

use hpge_benches::amg::{Amg, csr, max_rel_diff, weighting_system};

fn main() -> Result<(), Box<dyn std::error::Error>> {
    println!(
        "h_mm,unknowns,chol_symbolic_s,chol_factor_s,chol_solve_s,amg_levels,amg_complexity,amg_setup_s,pcg_iterations,pcg_s,max_rel_diff,step_refactor_solve_s,step_setup_pcg_s,step_pcg_iterations,step_old_hierarchy_pcg_s,step_old_hierarchy_iterations"
    );
    for h in [1.0, 0.5, 0.35, 0.25, 0.18, 0.125, 0.09, 0.0625] {
        let (sys, b) = weighting_system("super-siegfried-k1.toml", h, 0)?;
        let t = Instant::now();
        let sym = sys.symbolic()?;
        let t_sym = t.elapsed().as_secs_f64();
        let t = Instant::now();
        let f = sys.factor(&sym, &sys.val)?;
        let t_fac = t.elapsed().as_secs_f64();
        let t = Instant::now();
        let want = f.solve(&b);
        let t_sol = t.elapsed().as_secs_f64();
        let t = Instant::now();
        let amg = Amg::new(csr(&sys, &sys.val), 0.08);
        let t_setup = t.elapsed().as_secs_f64();
        let t = Instant::now();
        let mut x = vec![0.0; sys.n];
        let r = amg.pcg(&b, &mut x, 1e-10, 500);
        let t_pcg = t.elapsed().as_secs_f64();
        // An active-set step: 1% of the unknowns (a block of grid rows) become active, at 90% of
        // their present value; Cholesky refactorises and solves, multigrid warm-starts from the last
        // solution with a new hierarchy or with the old one.
        let (lo, hi) = (sys.n / 2, sys.n / 2 + sys.n / 100);
        let mut val = sys.val.clone();
        let mut b2 = b.clone();
        for u in lo..hi {
            for e in sys.col_ptr[u]..sys.col_ptr[u + 1] {
                let v = sys.row_idx[e];
                if v != u {
                    val[e] = 0.0;
                    val[sys.mirror[e]] = 0.0;
                    if !(lo..hi).contains(&v) {
                        b2[v] -= sys.val[e] * 0.9 * want[u];
                    }
                }
            }
            b2[u] = val[sys.diag_pos[u]] * 0.9 * want[u];
        }
        let t = Instant::now();
        let mut f = f;
        sys.refactor(&mut f, &val)?;
        let want2 = f.solve(&b2);
        let t_step_chol = t.elapsed().as_secs_f64();
        let t = Instant::now();
        let amg2 = Amg::new(csr(&sys, &val), 0.08);
        let mut x2 = x.clone();
        let r2 = amg2.pcg(&b2, &mut x2, 1e-10, 500);
        let t_step_amg = t.elapsed().as_secs_f64();
        if max_rel_diff(&x2, &want2) >= 1e-7 {
            return Err(format!("h {h} mm: multigrid and Cholesky disagree after the step").into());
        }
        // The old hierarchy as the preconditioner of the new matrix.
        let t = Instant::now();
        let mut x3 = x.clone();
        let a2 = csr(&sys, &val);
        let r3 = amg.pcg_with(&a2, &b2, &mut x3, 1e-10, 500);
        let t_step_old = t.elapsed().as_secs_f64();
        println!(
            "{h},{},{t_sym:.4},{t_fac:.4},{t_sol:.4},{},{:.2},{t_setup:.4},{},{t_pcg:.4},{:.1e},{t_step_chol:.4},{t_step_amg:.4},{},{t_step_old:.4},{}",
            sys.n,
            amg.depth(),
            amg.complexity(),
            r.iterations,
            max_rel_diff(&x, &want),
            r2.iterations,
            r3.iterations
        );
    }
    Ok(())
}
