//! How much of the fully depleted reference an undepleted point should carry over
//! (`field::depleted`): for every accuracy case (`accuracy_cases`) and a point 3% below each
//! detector's full depletion, c12 at the settings (`--ci`: the CI test's coarse settings, 1%
//! tolerance) with nothing, the whole difference, s = c12_dep/c12_U and s^2 of it carried
//! over, each against the same point on the final grid divided into 4 (no reference carried:
//! an independent answer). Prints a JSON line per point.
//!
//! `cargo run --release -p hpge-validation --example carry_over [-- --ci]`

use hpge_solver::field::solve_point_on_grid;
use hpge_solver::{Detector, FieldSettings, Parameters, solve_point};
use hpge_validation::{accuracy_cases, repo_path};

type AnyResult<T> = Result<T, Box<dyn std::error::Error>>;

fn main() -> AnyResult<()> {
    let ci = std::env::args().any(|a| a == "--ci");
    let mut base = FieldSettings::default();
    if ci {
        base.grid.max_spacing_semiconductor_mm = 2.0;
        base.grid.max_spacing_mm = 8.0;
        base.grid.front_spacing_mm = 0.5;
        base.grid.tolerance = 1e-2;
    }
    println!(
        "{}",
        serde_json::json!({"example": "carry_over", "ci_settings": ci,
            "solver": hpge_solver::field::PHYSICS_REVISION,
            "version": env!("CARGO_PKG_VERSION")})
    );
    let mut cases: Vec<(String, f64)> = Vec::new();
    for c in accuracy_cases() {
        for (b, _) in &c.biases {
            cases.push((c.detector.to_string(), *b));
        }
    }
    // 97% of the full-depletion voltages of monotone_sweep (2026-12-06).
    for (f, u) in [
        ("detectors/super-siegfried-k1.toml", 3775.6_f64),
        ("detectors/bege.toml", 1262.2),
        ("detectors/ppc.toml", 3126.2),
        ("detectors/icpc-legend.toml", 2281.1),
        ("detectors/coax-closed-end.toml", 2582.4),
    ] {
        cases.push((f.to_string(), (0.97 * u).round()));
    }
    for (file, bias) in cases {
        let det = Detector::from_file(&repo_path(&file), &Parameters::new())?;
        let s = base.for_detector(&det);
        let p = solve_point(&det, bias, &s, None)?;
        let r = solve_point_on_grid(
            &det,
            bias,
            &s,
            p.mesh.grid.subdivided(4),
            Some((&p.mesh.grid, &p.potential.phi_v)),
        )?;
        let truth = r.c12_pf;
        let line = match p.carried {
            None => serde_json::json!({"detector": file, "bias_V": bias, "depleted": true,
                "c12_pF": p.c12_pf, "reference_pF": truth, "err": p.c12_pf / truth - 1.0}),
            Some(c) => {
                let raw = p.c12_pf - c.shift_pf;
                let full = c.reference_pf - c.here_pf;
                let s1 = (c.here_pf / raw).clamp(0.0, 1.0);
                let err = |x: f64| x / truth - 1.0;
                serde_json::json!({"detector": file, "bias_V": bias, "depleted": false,
                    "raw_pF": raw, "full_shift_pF": full, "s": s1, "reference_pF": truth,
                    "err_none": err(raw), "err_full": err(raw + full),
                    "err_s": err(raw + s1 * full), "err_s2": err(raw + s1 * s1 * full),
                    "estimate": p.accuracy.c12_err_pf / p.c12_pf})
            }
        };
        println!("{line}");
    }
    Ok(())
}
