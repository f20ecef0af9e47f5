//! The paper's sensitivity scan (its Fig. "impurity_level_sensitivity"): c12 of Super-Siegfried at
//! U_B = 25 V, d_Li = 1 mm, for constant densities from 1e7 to 2e11 cm^-3 in log steps; prints CSV.
//! `cargo run --release -p hpge-validation --example sensitivity_scan > scan.csv`

use std::path::Path;

use hpge_solver::{Detector, FieldSettings, ImpuritySpec, Parameters, solve_point};
use hpge_validation::repo_path;

fn main() -> Result<(), Box<dyn std::error::Error>> {
    let mut det = Detector::from_file(
        &repo_path("detectors/super-siegfried-k1.toml"),
        &Parameters::new(),
    )?;
    let s = FieldSettings::default();
    println!("zeta_cm3,c12_pF,fully_depleted,seconds");
    // 1e7 .. 2e11 in quarter decades, plus zero (the geometric limit).
    let mut zetas: Vec<f64> = vec![0.0];
    let mut z = 1e7;
    while z <= 2.0001e11 {
        zetas.push(z);
        z *= 10f64.powf(0.25);
    }
    for zeta in zetas {
        let text = format!("model = \"constant\"\nzeta_cm3 = {zeta:e}\n");
        let spec = ImpuritySpec::from_toml_str(&text, Path::new("scan.toml"))?;
        det.set_impurity(&spec, Path::new("scan.toml"))?;
        let t = std::time::Instant::now();
        let p = solve_point(&det, 25.0, &s, None)?;
        println!(
            "{zeta:e},{},{},{:.2}",
            p.c12_pf,
            p.fully_depleted(),
            t.elapsed().as_secs_f64()
        );
    }
    Ok(())
}
