//! Probe for issue 21: the surrogate's error across a fit's posterior. Reads a fit's
//! `samples.csv` and `summary.json`, thins to N draws, solves their exact curves on the global
//! mode's grids (as the exact check does) and writes theta, the surrogate curve and the exact
//! curve of each draw (the mode last) to OUT.csv.
//! `cargo run --release -p hpge-validation --example refine_probe -- FITDIR N OUT.csv [SKIP]`

use hpge_inference::CvModel;
use hpge_inference::fit::{FitJob, outputs, thin_indices};
use hpge_inference::model::ExactModel;
use hpge_solver::GridOverrides;
use hpge_validation::shipped_fit_files;

fn main() -> Result<(), Box<dyn std::error::Error>> {
    let args: Vec<String> = std::env::args().skip(1).collect();
    let dir = std::path::PathBuf::from(args.first().ok_or("usage: FITDIR N OUT")?);
    let n: usize = args.get(1).ok_or("N")?.parse()?;
    let out = args.get(2).ok_or("OUT")?;
    let skip: usize = args.get(3).map_or(Ok(0), |a| a.parse())?;
    let files = shipped_fit_files();
    let job = FitJob::from_files(&files, Default::default(), &GridOverrides::default())?;
    let draws = outputs::read_samples(&dir.join("samples.csv"))?;
    let summary: serde_json::Value =
        serde_json::from_str(&std::fs::read_to_string(dir.join("summary.json"))?)?;
    let mode: Vec<f64> = summary["parameters"]
        .as_array()
        .ok_or("parameters")?
        .iter()
        .map(|p| p["global_mode"].as_f64().unwrap())
        .collect();
    let nx = job.prior.input_names.len();
    let expand = |t: &[f64]| {
        let mut x = vec![0.0; nx];
        job.prior.expand(t, &mut x);
        x
    };
    // Offset thinning (SKIP) gives a set disjoint from the check's.
    let idx: Vec<usize> = thin_indices(draws.len(), n)
        .into_iter()
        .map(|i| (i + skip).min(draws.len() - 1))
        .collect();
    let thetas: Vec<&Vec<f64>> = idx.iter().map(|&i| &draws[i]).collect();
    let xs: Vec<Vec<f64>> = thetas.iter().map(|t| expand(t)).collect();
    let exact = ExactModel::new(job.exact.clone(), &job.data.voltage_v)?;
    let t = std::time::Instant::now();
    let (c_mode, near) = exact.curves_near(&expand(&mode), &xs, &|d, all| {
        if d % 20 == 0 {
            eprintln!("{d}/{all} {:.0} s", t.elapsed().as_secs_f64())
        }
    })?;
    let nv = job.data.voltage_v.len();
    let mut rows = vec![];
    let mut head = vec!["i".to_string()];
    head.extend(job.prior.names());
    head.extend((0..nv).map(|k| format!("s{k}")));
    head.extend((0..nv).map(|k| format!("e{k}")));
    rows.push(head.join(","));
    let mut push = |i: usize, th: &[f64], ce: &[f64]| {
        let mut cs = vec![0.0; nv];
        job.surrogate.curve(&expand(th), &mut cs).unwrap();
        let mut r = vec![i.to_string()];
        r.extend(th.iter().map(|v| format!("{v:.10e}")));
        r.extend(cs.iter().map(|v| format!("{v:.10e}")));
        r.extend(ce.iter().map(|v| format!("{v:.10e}")));
        rows.push(r.join(","));
    };
    for (i, (th, c)) in thetas.iter().zip(&near).enumerate() {
        if let Ok(c) = c {
            push(i, th, c);
        }
    }
    push(usize::MAX, &mode, &c_mode);
    std::fs::write(out, rows.join("\n"))?;
    let mut v = vec!["U".to_string()];
    v.extend(job.data.voltage_v.iter().map(|u| format!("{u}")));
    let mut m = vec!["cm".to_string()];
    m.extend(job.data.c12_pf.iter().map(|u| format!("{u}")));
    std::fs::write(
        format!("{out}.data"),
        format!("{}\n{}", v.join(","), m.join(",")),
    )?;
    eprintln!("done {:.0} s", t.elapsed().as_secs_f64());
    Ok(())
}
