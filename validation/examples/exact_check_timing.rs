//! Times the exact-solver check of a fit curve by curve: reads a fit's `samples.csv`, thins it
//! to N draws as the check does, and solves each draw's exact curve at the data's voltages one
//! after the other, printing its wall time and the slowest point's solve counters.
//! `cargo run --release -p hpge-validation --example exact_check_timing -- fits/b-rz/samples.csv [N [TOLERANCE [FIRST [COUNT]]]]`
//! (draws FIRST.. FIRST+COUNT-1 of the N thinned ones; `CURVES=DIR` writes each curve to DIR)
//! (the shipped data, model, prior and detector).

use hpge_inference::fit::{FitJob, outputs, thin_indices};
use hpge_solver::GridOverrides;
use hpge_solver::field::{Continuation, cv_curve_with};
use hpge_validation::shipped_fit_files;

fn main() -> Result<(), Box<dyn std::error::Error>> {
    let args: Vec<String> = std::env::args().skip(1).collect();
    let samples = args
        .first()
        .ok_or("usage: exact_check_timing SAMPLES.csv [N]")?;
    let n: usize = args.get(1).map_or(Ok(100), |a| a.parse())?;
    let files = shipped_fit_files();
    let grid = GridOverrides {
        tolerance: args.get(2).map(|a| a.parse()).transpose()?,
        grid: Vec::new(),
    };
    let first: usize = args.get(3).map_or(Ok(0), |a| a.parse())?;
    let count: usize = args.get(4).map_or(Ok(n), |a| a.parse())?;
    let job = FitJob::from_files(&files, Default::default(), &grid)?;
    let draws = outputs::read_samples(std::path::Path::new(samples))?;
    let nx = job.prior.input_names.len();
    let volts = &job.data.voltage_v;
    let mut total = 0.0;
    for (i, theta) in thin_indices(draws.len(), n)
        .into_iter()
        .map(|k| &draws[k])
        .enumerate()
        .skip(first)
        .take(count)
    {
        let mut x = vec![0.0; nx];
        job.prior.expand(theta, &mut x);
        let det = job.exact.detector(&x)?;
        let t = std::time::Instant::now();
        let r = cv_curve_with(
            &det,
            volts,
            &job.exact.settings,
            Continuation::Seeded,
            |_, _| {},
        );
        let s = t.elapsed().as_secs_f64();
        total += s;
        let what = match &r {
            Ok(c) => {
                if let Ok(dir) = std::env::var("CURVES") {
                    let rows: Vec<String> = c
                        .points
                        .iter()
                        .map(|p| format!("{},{},{}", p.voltage_v, p.c12_pf, p.c12_err_pf))
                        .collect();
                    std::fs::write(format!("{dir}/curve-{i}.csv"), rows.join("\n"))?;
                }
                let slow = c
                    .points
                    .iter()
                    .max_by(|a, b| a.seconds.total_cmp(&b.seconds))
                    .map(|p| format!("slowest {:.0} V {:.2} s", p.voltage_v, p.seconds))
                    .unwrap_or_default();
                let n = c.points.len().max(1) as f64;
                let passes: usize = c.points.iter().map(|p| p.adaptive_passes).sum();
                let solves: usize = c.points.iter().map(|p| p.passes).sum();
                let nodes: usize = c.points.iter().map(|p| p.grid.0 * p.grid.1).sum();
                format!(
                    "ok, {slow}, per point {:.2} adaptive passes, {:.2} potential solves, final grid {:.0} nodes",
                    passes as f64 / n,
                    solves as f64 / n,
                    nodes as f64 / n
                )
            }
            Err(e) => format!("error: {e}"),
        };
        let th: Vec<String> = theta.iter().map(|v| format!("{v:.4}")).collect();
        println!("{i:3} {s:8.2} s  {what}  theta [{}]", th.join(", "));
    }
    println!("total {total:.1} s");
    Ok(())
}
