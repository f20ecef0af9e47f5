//! Is every shipped detector's C-V curve non-increasing in U_B away from pinch-off? For each
//! detector in `detectors/` (default parameters and impurity model, default settings) and the
//! stand-in's truth (`data/super-siegfried-k1/truth-impurity.toml`, d_Li = 3 mm): a coarse
//! curve (250 V steps to 6000 V) finds where it depletes, then a curve of 20 points from 2% to
//! 80% of that voltage and 31 points 1% apart from 80% to 110% is solved; every step where c12
//! rises is listed, with whether the pocket count changes across it (a pinch-off: a rise is
//! physics there) and the two points' own error estimates. Prints one JSON object per detector.
//!
//! `cargo run --release -p hpge-validation --example monotone_sweep [-- detectors/x.toml ...]`

use hpge_solver::field::cv_curve;
use hpge_solver::{Detector, FieldSettings, Parameters};
use hpge_validation::repo_path;

type AnyResult<T> = Result<T, Box<dyn std::error::Error>>;

fn main() -> AnyResult<()> {
    let args: Vec<String> = std::env::args().skip(1).collect();
    let files: Vec<std::path::PathBuf> = if args.is_empty() {
        let mut v: Vec<_> = std::fs::read_dir(repo_path("detectors"))?
            .filter_map(|e| e.ok().map(|e| e.path()))
            .filter(|p| p.extension().is_some_and(|x| x == "toml"))
            .collect();
        v.sort();
        v
    } else {
        args.iter().map(|a| repo_path(a)).collect()
    };
    let stand_in = repo_path("data/super-siegfried-k1/truth-impurity.toml");
    let mut cases: Vec<(String, Detector)> = Vec::new();
    for f in &files {
        let name = f.file_name().map(|n| n.to_string_lossy().to_string());
        cases.push((
            name.unwrap_or_default(),
            Detector::from_file(f, &Parameters::new())?,
        ));
    }
    if args.is_empty() {
        let mut p = Parameters::new();
        p.set("d_li_mm", 3.0);
        let mut det = Detector::from_file(&repo_path("detectors/super-siegfried-k1.toml"), &p)?;
        det.set_impurity_file(&stand_in)?;
        cases.push(("stand-in truth".into(), det));
    }
    for (name, det) in cases {
        let s = FieldSettings::default().for_detector(&det);
        let coarse: Vec<f64> = (1..=24).map(|k| 250.0 * f64::from(k)).collect();
        let t0 = std::time::Instant::now();
        let c = cv_curve(&det, &coarse, &s, |_, _| {})?;
        let u_fd = c.depletion_voltage_v.unwrap_or(6000.0);
        let volts: Vec<f64> = (0..20)
            .map(|k| 0.02 + 0.78 * f64::from(k) / 20.0)
            .chain((0..=30).map(|k| 0.8 + 0.01 * f64::from(k)))
            .map(|x| (x * u_fd).round())
            .collect();
        let curve = cv_curve(&det, &volts, &s, |_, _| {})?;
        let mut rises = Vec::new();
        let mut worst = 0.0f64;
        for w in curve.points.windows(2) {
            let (a, b) = (&w[0], &w[1]);
            let rise = b.c12_pf / a.c12_pf - 1.0;
            let pinch = a.pockets.len() != b.pockets.len();
            if rise > 0.0 {
                if !pinch {
                    worst = worst.max(rise);
                }
                rises.push(serde_json::json!({
                    "from_V": a.voltage_v, "to_V": b.voltage_v,
                    "c12_pF": [a.c12_pf, b.c12_pf], "rise": rise,
                    "err_pF": [a.c12_err_pf, b.c12_err_pf],
                    "depleted": [a.fully_depleted, b.fully_depleted],
                    "pockets": [a.pockets.len(), b.pockets.len()],
                }));
            }
        }
        let out = serde_json::json!({
            "detector": name,
            "u_fd_V": curve.depletion_voltage_v, "u_fd_coarse_V": c.depletion_voltage_v,
            "worst_rise_away_from_pinch_off": worst, "rises": rises,
            "seconds": t0.elapsed().as_secs_f64(),
            "curve": curve.points.iter().map(|p| [p.voltage_v, p.c12_pf]).collect::<Vec<_>>(),
        });
        println!("{out}");
    }
    Ok(())
}
