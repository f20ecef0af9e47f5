//! The scaling figure of reports/solver-performance.md: time per point against grid nodes on
//! log-log axes, from the CSV of `validation/examples/solver_scaling.rs`, with N log N and
//! N^1.5 reference lines through the first `fast` point.
//! `cargo run --release -p hpge-reports --example solver_scaling_figure -- CSV OUT_STEM`
//! writes OUT_STEM.svg and OUT_STEM.png.

use std::path::PathBuf;

use hpge_reports::plot::{Corner, Curve, LineFigure, line_figure};

fn main() -> Result<(), Box<dyn std::error::Error>> {
    let args: Vec<String> = std::env::args().skip(1).collect();
    let (csv, stem) = match args.as_slice() {
        [c, s] => (PathBuf::from(c), s.clone()),
        _ => return Err("usage: solver_scaling_figure CSV OUT_STEM".into()),
    };
    let text = std::fs::read_to_string(&csv).map_err(|e| format!("{}: {e}", csv.display()))?;
    let mut rows: Vec<(String, f64, f64)> = Vec::new();
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
    let series = |m: &str| -> Vec<(f64, f64)> {
        rows.iter()
            .filter(|r| r.0 == m)
            .map(|r| (r.1.log10(), r.2.log10()))
            .collect()
    };
    let fast = series("fast");
    let sor = series("sor");
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
        ],
        y_from_zero: false,
        legend: Corner::UpperLeft,
        footnotes: vec![format!(
            "one cold point per uniform grid (solve_point_on_grid), data {}",
            csv.display()
        )],
    };
    for ext in ["svg", "png"] {
        line_figure(&fig, &PathBuf::from(format!("{stem}.{ext}")))?;
    }
    Ok(())
}
