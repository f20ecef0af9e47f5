//! Every detector in `detectors/` at three biases (undepleted, near pinch-off or full depletion,
//! depleted), the checks a solver change is run through outside CI:
//!
//! - c12 at the default settings, and against the same point on a finer grid (half the
//!   tolerance and half every largest spacing): |c12 / c12(finer) - 1|;
//! - the exact check's nearby solves on every type: six detectors in two clusters of the
//!   detector's first parameter (li_mm, d_li_mm or thickness_mm: +0.01, +0.02, +0.03 and
//!   +0.31, +0.32, +0.33 mm) on the base point's grids, seeded from the base and along a
//!   nearest-neighbour chain (`field::SeedChain`): the largest relative difference of c12 and
//!   the active-set steps either way;
//! - the scaling law of a uniform density (the long coax and the planar p-n detector): c12(U, N)
//!   = c12(3U, 3N) (a factor of 3, not 2: a power of two scales every float exactly);
//! - the peers: fieldgen's capacitances at the same biases (`validation/references/fieldgen/`;
//!   crystal-internal C, so agreement to a few percent is expected, not exact) and this solver's
//!   values in `reports/accuracy/table.json` (an earlier physics revision).
//!
//! `cargo run --release -p hpge-validation --example detector_sweep` (about 10 min on 2 cores).

use std::collections::BTreeMap;
use std::path::Path;

use hpge_solver::field::{Continuation, NearSeeding, SeedChain, cv_curves_near_each};
use hpge_solver::{Detector, FieldSettings, Parameters, solve_point};
use hpge_validation::{LongCoax, accuracy_cases, repo_path};

type AnyResult<T> = Result<T, Box<dyn std::error::Error>>;

/// Biases of the detectors that `accuracy_cases` does not list.
fn extra_cases() -> Vec<(&'static str, Vec<f64>)> {
    let u_fd = LongCoax::validation().full_depletion_v();
    vec![
        (
            "detectors/coax-analytic.toml",
            vec![0.3 * u_fd, 0.9 * u_fd, 1.5 * u_fd],
        ),
        // U_fd = q N d^2 / (2 eps) = 565 V for 10 mm at 1e10 cm^-3.
        ("detectors/planar-pn.toml", vec![100.0, 500.0, 1000.0]),
        ("detectors/ppc-example.toml", vec![500.0, 2500.0, 4000.0]),
    ]
}

/// The detector's first parameter (the one perturbed) and its default, from the file.
fn first_parameter(path: &Path) -> AnyResult<Option<(String, f64)>> {
    let table: toml::Table = std::fs::read_to_string(path)?.parse()?;
    Ok(table
        .get("parameters")
        .and_then(|p| p.as_table())
        .and_then(|p| p.iter().next())
        .and_then(|(k, v)| v.as_float().map(|f| (k.clone(), f))))
}

fn with_parameter(path: &Path, name: &str, value: f64) -> AnyResult<Detector> {
    let mut p = Parameters::new();
    p.set(name, value);
    Ok(Detector::from_file(path, &p)?)
}

/// The file with its uniform density scaled by `k` (zeta_cm3 = 1.0e10 in both files).
fn scaled(path: &Path, k: f64) -> AnyResult<Detector> {
    let text = std::fs::read_to_string(path)?;
    let text = text.replace("zeta_cm3 = 1.0e10", &format!("zeta_cm3 = {:e}", 1.0e10 * k));
    Ok(Detector::from_toml_str(&text, path, &Parameters::new())?)
}

fn main() -> AnyResult<()> {
    let s = FieldSettings::default();
    let mut finer = s.clone();
    finer.grid.tolerance = s.grid.tolerance / 2.0;
    finer.grid.max_spacing_semiconductor_mm = s.grid.max_spacing_semiconductor_mm / 2.0;
    finer.grid.max_spacing_mm = s.grid.max_spacing_mm / 2.0;
    finer.grid.front_spacing_mm = s.grid.front_spacing_mm / 2.0;
    let fieldgen: serde_json::Value = serde_json::from_str(&std::fs::read_to_string(repo_path(
        "validation/references/fieldgen/reference.json",
    ))?)?;
    let table: serde_json::Value = serde_json::from_str(&std::fs::read_to_string(repo_path(
        "reports/accuracy/table.json",
    ))?)?;
    let mut earlier: BTreeMap<(String, u64), f64> = BTreeMap::new();
    for row in table["rows"].as_array().into_iter().flatten() {
        if let (Some(d), Some(v), Some(c)) = (
            row["detector"].as_str(),
            row["bias_v"].as_f64(),
            row["c12_pf"].as_f64(),
        ) {
            earlier.insert((d.to_string(), v.to_bits()), c);
        }
    }
    let mut cases: Vec<(&str, Vec<f64>)> = accuracy_cases()
        .into_iter()
        .map(|c| (c.detector, c.biases.iter().map(|b| b.0).collect()))
        .collect();
    cases.extend(extra_cases());
    println!(
        "| detector | bias (V) | depleted | c12 (pF) | vs finer grid | vs accuracy table | vs fieldgen | chain vs base: max rel diff | steps chain / base |"
    );
    println!("|---|---|---|---|---|---|---|---|---|");
    for (file, biases) in cases {
        let path = repo_path(file);
        let det = Detector::from_file(&path, &Parameters::new())?;
        let name = file
            .trim_start_matches("detectors/")
            .trim_end_matches(".toml");
        // The nearby solves: two clusters of the first parameter.
        let near_solves = match first_parameter(&path)? {
            Some((pname, p0)) => {
                let values: Vec<f64> = [0.01, 0.02, 0.03, 0.31, 0.32, 0.33]
                    .iter()
                    .map(|d| p0 + d)
                    .collect();
                let near: Vec<Detector> = values
                    .iter()
                    .map(|&v| with_parameter(&path, &pname, v))
                    .collect::<AnyResult<_>>()?;
                let xs: Vec<Vec<f64>> = values.iter().map(|&v| vec![v]).collect();
                let chain = SeedChain::nearest_neighbour(&[p0], &xs, &[1.0]);
                let run = |seeding| {
                    cv_curves_near_each(
                        &det,
                        &near,
                        &biases,
                        &s,
                        (Continuation::Seeded, seeding),
                        |_, _| {},
                    )
                };
                let (a, b) = (run(NearSeeding::Base)?, run(chain.seeding())?);
                let mut worst = 0.0f64;
                for (ca, cb) in a.near_pf.iter().zip(&b.near_pf) {
                    match (ca, cb) {
                        (Ok(ca), Ok(cb)) => {
                            for (x, y) in ca.iter().zip(cb) {
                                worst = worst.max(((x - y) / x).abs());
                            }
                        }
                        (Err(_), Err(_)) => {}
                        _ => worst = f64::INFINITY,
                    }
                }
                Some((worst, b.iterations, a.iterations))
            }
            None => None,
        };
        for (j, &v) in biases.iter().enumerate() {
            let p = solve_point(&det, v, &s, None)?;
            let q = solve_point(&det, v, &finer, None)?;
            let vs_finer = (p.c12_pf / q.c12_pf - 1.0).abs();
            let vs_table = earlier
                .get(&(file.to_string(), v.to_bits()))
                .map_or("-".to_string(), |c| {
                    format!("{:+.3}%", 100.0 * (p.c12_pf / c - 1.0))
                });
            let vs_peer = fieldgen["detectors"][name]["capacitance_pF"][format!("{v:.0}")]
                .as_f64()
                .map_or("-".to_string(), |c| {
                    format!("{:+.2}% ({c} pF)", 100.0 * (p.c12_pf / c - 1.0))
                });
            let near = match (&near_solves, j) {
                (Some((w, c, b)), 0) => (format!("{w:.1e}"), format!("{c} / {b}")),
                (Some(_), _) => ("\"".into(), "\"".into()),
                (None, _) => ("no parameter".into(), "-".into()),
            };
            println!(
                "| {name} | {v:.0} | {} | {:.5} | {:.3}% | {vs_table} | {vs_peer} | {} | {} |",
                if p.fully_depleted() { "yes" } else { "no" },
                p.c12_pf,
                100.0 * vs_finer,
                near.0,
                near.1
            );
        }
    }
    // The scaling law of a uniform density.
    println!("\n| detector | U (V) | c12(U, N) pF | c12(3U, 3N) pF | rel diff |");
    println!("|---|---|---|---|---|");
    let u_fd = LongCoax::validation().full_depletion_v();
    for (file, biases) in [
        (
            "detectors/coax-analytic.toml",
            vec![0.3 * u_fd, 0.9 * u_fd, 1.5 * u_fd],
        ),
        ("detectors/planar-pn.toml", vec![100.0, 500.0, 1000.0]),
    ] {
        let path = repo_path(file);
        let (one, three) = (scaled(&path, 1.0)?, scaled(&path, 3.0)?);
        for v in biases {
            let a = solve_point(&one, v, &s, None)?.c12_pf;
            let b = solve_point(&three, 3.0 * v, &s, None)?.c12_pf;
            println!(
                "| {} | {v:.0} | {a:.5} | {b:.5} | {:.1e} |",
                file.trim_start_matches("detectors/"),
                b / a - 1.0
            );
        }
    }
    Ok(())
}
