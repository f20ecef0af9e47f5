//! The multigrid figure of reports/solver-performance.md: seconds against unknowns on log-log
//! axes for the sparse Cholesky and the smoothed-aggregation multigrid with CG, a cold solve and
//! an active-set step each, from the CSV of the `amg_timing` example
//! (`RAYON_NUM_THREADS=1 cargo run --release -p hpge-benches --example amg_timing`).
//! `cargo run --release -p hpge-reports --example amg_figure -- CSV OUT_STEM` writes
//! OUT_STEM.svg and OUT_STEM.png.

use std::path::PathBuf;

use hpge_reports::plot::{Corner, Curve, LineFigure, line_figure};

fn main() -> Result<(), Box<dyn std::error::Error>> {
    let args: Vec<String> = std::env::args().skip(1).collect();
    let [csv, stem] = args.as_slice() else {
        return Err("usage: amg_figure CSV OUT_STEM".into());
    };
    let text = std::fs::read_to_string(csv).map_err(|e| format!("{csv}: {e}"))?;
    let mut lines = text.lines();
    let header: Vec<&str> = lines
        .next()
        .ok_or(format!("{csv}: empty"))?
        .split(',')
        .collect();
    let col = |name: &str| {
        header
            .iter()
            .position(|h| *h == name)
            .ok_or(format!("{csv}: no column {name}"))
    };
    let rows: Vec<Vec<f64>> = lines
        .map(|l| {
            l.split(',')
                .map(|v| v.parse().unwrap_or(f64::NAN))
                .collect()
        })
        .collect();
    let n = col("unknowns")?;
    let sum = |names: &[&str]| -> Result<Vec<(f64, Option<f64>)>, String> {
        let cols: Vec<usize> = names.iter().map(|c| col(c)).collect::<Result<_, _>>()?;
        Ok(rows
            .iter()
            .map(|r| {
                let t: f64 = cols.iter().map(|&c| r[c]).sum();
                (r[n].log10(), Some(t.log10()))
            })
            .collect())
    };
    let curve = |label: &str, points| Curve {
        label: label.into(),
        points,
    };
    let first = rows.first().ok_or(format!("{csv}: no rows"))?;
    let (n0, t0) = (
        first[n],
        first[col("chol_factor_s")?] + first[col("chol_solve_s")?],
    );
    let reference = |label: &str, p: f64| Curve {
        label: label.into(),
        points: rows
            .iter()
            .map(|r| (r[n].log10(), Some((t0 * (r[n] / n0).powf(p)).log10())))
            .collect(),
    };
    let fig = LineFigure {
        title: "Super-Siegfried's field system: sparse Cholesky against multigrid".into(),
        x_desc: "log10(unknowns)".into(),
        y_desc: "log10(seconds)".into(),
        curves: vec![
            curve(
                "Cholesky: symbolic + factor + solve",
                sum(&["chol_symbolic_s", "chol_factor_s", "chol_solve_s"])?,
            ),
            curve(
                "multigrid-CG: setup + solve to 1e-10",
                sum(&["amg_setup_s", "pcg_s"])?,
            ),
            curve(
                "active-set step, Cholesky: refactor + solve",
                sum(&["step_refactor_solve_s"])?,
            ),
            curve(
                "active-set step, multigrid: new setup + warm CG",
                sum(&["step_setup_pcg_s"])?,
            ),
            reference("N (through the first factor + solve)", 1.0),
            reference("N^1.5", 1.5),
        ],
        y_from_zero: false,
        legend: Corner::UpperLeft,
        footnotes: vec![format!("2-core VM, release build, one thread; data {csv}")],
    };
    for ext in ["svg", "png"] {
        line_figure(&fig, &PathBuf::from(format!("{stem}.{ext}")))?;
    }
    Ok(())
}
