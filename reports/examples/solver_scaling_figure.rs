//! The scaling figure of reports/solver-performance.md: time per point against grid nodes on
//! log-log axes, from the CSV of `validation/examples/solver_scaling.rs`, with N log N and
//! N^1.5 reference lines through the first `fast` point, and (optional BEFORE_CSV, the same
//! columns) the `fast` rows of an earlier build for comparison.
//! `cargo run --release -p hpge-reports --example solver_scaling_figure -- CSV OUT_STEM [BEFORE_CSV]`
//! writes OUT_STEM.svg and OUT_STEM.png.

use std::path::PathBuf;

use hpge_reports::plot::{Corner, Curve, LineFigure, line_figure};

fn main() -> Result<(), Box<dyn std::error::Error>> {
    let args: Vec<String> = std::env::args().skip(1).collect();
    let (csv, stem, before) = match args.as_slice() {
        [c, s] => (PathBuf::from(c), s.clone(), None),
        [c, s, b] => (PathBuf::from(c), s.clone(), Some(PathBuf::from(b))),
        _ => return Err("usage: solver_scaling_figure CSV OUT_STEM [BEFORE_CSV]".into()),
    };
    let rows = read_rows(&csv)?;
    let before_rows = before.as_deref().map(read_rows).transpose()?;
    let fast = series(&rows, "fast");
    let sor = series(&rows, "sor");
    let (x0, y0) = *fast.first().ok_or("no fast rows")?;
    let n0 = 10f64.powf(x0);
    let reference = |label: &str, f: &dyn Fn(f64) -> f64| Curve {
        label: label.into(),
        points: fast
            .iter()
            .map(|&(x, _)| (x, Some(y0 + (f(10f64.powf(x)) / f(n0)).log10())))
            .collect(),
    };
    let fig = LineFigure {
        title: "Super-Siegfried, 1025 V: time per point against grid size".into(),
        x_desc: "log10(nodes)".into(),
        y_desc: "log10(seconds per point)".into(),
        curves: vec![
            Curve {
                label: "fast (active set, sparse Cholesky)".into(),
                points: fast.iter().map(|&(x, y)| (x, Some(y))).collect(),
            },
            Curve {
                label: "sor (red-black SOR)".into(),
                points: sor.iter().map(|&(x, y)| (x, Some(y))).collect(),
            },
            reference("N log N (through the first fast point)", &|n| n * n.ln()),
            reference("N^1.5", &|n| n.powf(1.5)),
        ]
        .into_iter()
        .chain(before_rows.as_deref().map(|b| {
            Curve {
                label: "fast before band steps (plain active set)".into(),
                points: series(b, "fast")
                    .iter()
                    .map(|&(x, y)| (x, Some(y)))
                    .collect(),
            }
        }))
        .collect(),
        y_from_zero: false,
        legend: Corner::UpperLeft,
        footnotes: vec![format!(
            "one cold point per uniform grid (solve_point_on_grid), data {}{}",
            csv.display(),
            before
                .as_ref()
                .map_or(String::new(), |b| format!(", before: {}", b.display()))
        )],
    };
    for ext in ["svg", "png"] {
        line_figure(&fig, &PathBuf::from(format!("{stem}.{ext}")))?;
    }
    Ok(())
}

/// (method, nodes, seconds per point) of one row of a `solver_scaling` CSV.
type Row = (String, f64, f64);

/// Every row of a `solver_scaling` CSV.
fn read_rows(csv: &std::path::Path) -> Result<Vec<Row>, Box<dyn std::error::Error>> {
    let text = std::fs::read_to_string(csv).map_err(|e| format!("{}: {e}", csv.display()))?;
    let mut rows = Vec::new();
    for (k, line) in text.lines().enumerate().skip(1) {
        let f: Vec<&str> = line.split(',').collect();
        let bad = || {
            format!(
                "{} line {}: expected method,h_mm,nodes,iterations,potential_s,point_s,c12_pF",
                csv.display(),
                k + 1
            )
        };
        if f.len() != 7 {
            return Err(bad().into());
        }
        let nodes: f64 = f[2].parse().map_err(|_| bad())?;
        let point_s: f64 = f[5].parse().map_err(|_| bad())?;
        rows.push((f[0].to_string(), nodes, point_s));
    }
    Ok(rows)
}

/// (log10 nodes, log10 seconds) of one method's rows.
fn series(rows: &[Row], method: &str) -> Vec<(f64, f64)> {
    rows.iter()
        .filter(|r| r.0 == method)
        .map(|r| (r.1.log10(), r.2.log10()))
        .collect()
}
