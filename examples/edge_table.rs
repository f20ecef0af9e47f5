//! The surrogate against the exact solver at the edges of its input space (issue 24): the bias at
//! 10, 10.1, 12, 20, 2990 and 3000 V with every parameter at its range's centre, and the lower and
//! upper edges of three parameters at 1000 V. Prints a table with the support guard's verdict.
//!   cargo run --release --example edge_table -- MODEL.safetensors DETECTOR.toml
//! (in the space's column order, which for the shipped models is the network order).

use std::path::Path;

fn main() -> Result<(), Box<dyn std::error::Error>> {
    let args: Vec<String> = std::env::args().skip(1).collect();
    if args.len() < 2 {
        return Err("usage: edge_table MODEL.safetensors DETECTOR.toml".into());
    }
    let model = hpge_surrogate::Surrogate::load(Path::new(&args[0]))?;
    let exact = hpge_surrogate::ExactSolver::new(
        model.info.space.clone(),
        Path::new(&args[1]),
        hpge_solver::FieldSettings::default(),
    )?;
    let np = model.n_params();
    let centre: Vec<f64> = (0..np)
        .map(|k| 0.5 * (model.range(k)[0] + model.range(k)[1]))
        .collect();
    let mut points: Vec<(String, Vec<f64>, f64)> = Vec::new();
    for v in [10.0, 10.1, 12.0, 20.0, 2990.0, 3000.0] {
        points.push((format!("U_B={v}"), centre.clone(), v));
    }
    let names = model.parameter_names();
    for name in ["d_li_mm", "y1_bot", "y4_top"] {
        let Some(k) = names.iter().position(|n| *n == name) else {
            continue;
        };
        let [lo, hi] = model.range(k);
        let w = hi - lo;
        for x in [
            lo,
            lo + 1e-4 * w,
            lo + 0.01 * w,
            hi - 0.01 * w,
            hi - 1e-4 * w,
            hi,
        ] {
            let mut p = centre.clone();
            p[k] = x;
            points.push((format!("{name}={x:.6}"), p, 1000.0));
        }
    }
    println!("point,U_B_V,c12_exact_pF,c12_surrogate_pF,rel_error_pct,support_guard");
    for (label, p, v) in points {
        let mut x = p.clone();
        x.push(v);
        let c_exact = exact.solve(&x).map_or(f64::NAN, |c| c);
        let c_sur = model.curve(&p, &[v])?[0];
        let guard = match model.check_support(&p, &[v]) {
            Ok(()) => "ok".to_string(),
            Err(e) => match e {
                hpge_surrogate::Error::OutsideSupport { name, lo, hi, .. } => {
                    format!("refused ({name} outside [{lo:.6}; {hi:.6}])")
                }
                other => other.to_string(),
            },
        };
        println!(
            "{label},{v},{c_exact:.3},{c_sur:.3},{:+.2},{guard}",
            100.0 * (c_sur - c_exact) / c_exact
        );
    }
    Ok(())
}
