//! The accuracy table of issue 18 (reports/accuracy/): every shipped detector type at three
//! biases, c12 at the default tolerance with its estimate against the final grid divided into 4.
//! `cargo run --release -p hpge-validation --example accuracy_table [-- PARTS [DETECTOR_SUBSTRING]]`
//! prints a Markdown table and writes reports/accuracy/table.json.

use hpge_solver::FieldSettings;
use hpge_validation::{accuracy_cases, accuracy_row, repo_path};

fn main() -> Result<(), Box<dyn std::error::Error>> {
    let args: Vec<String> = std::env::args().skip(1).collect();
    let parts: usize = args.first().map_or(Ok(4), |a| a.parse())?;
    let only = args.get(1).cloned().unwrap_or_default();
    let settings = FieldSettings::default();
    let mut rows = Vec::new();
    println!(
        "| detector | bias (V) | kind | c12 (pF) | estimate | actual vs {parts}x finer | estimate / actual | nodes | reference nodes | s | reference s |"
    );
    println!("|---|---|---|---|---|---|---|---|---|---|---|");
    for case in accuracy_cases() {
        if !case.detector.contains(&only) {
            continue;
        }
        for (bias, kind) in &case.biases {
            let r = accuracy_row(case.detector, *bias, kind, &settings, parts)?;
            println!(
                "| {} | {} | {}{} | {:.5} | {:.3}% | {:.3}% | {:.1} | {} | {} | {:.2} | {:.1} |",
                case.detector.trim_start_matches("detectors/"),
                bias,
                kind,
                if r.fully_depleted { " (depleted)" } else { "" },
                r.c12_pf,
                100.0 * r.estimate_rel,
                100.0 * r.actual_rel,
                r.estimate_rel / r.actual_rel.max(1e-12),
                r.nodes,
                r.reference_nodes,
                r.seconds,
                r.reference_seconds
            );
            rows.push(r);
        }
    }
    if only.is_empty() {
        let out = repo_path("reports/accuracy/table.json");
        std::fs::create_dir_all(out.parent().unwrap_or(&repo_path("reports")))?;
        std::fs::write(
            &out,
            serde_json::to_string_pretty(&serde_json::json!({
                "parts": parts,
                "settings": settings,
                "rows": rows,
                "version": env!("CARGO_PKG_VERSION"),
                "made": hpge_solver::made(),
            }))?,
        )?;
    }
    Ok(())
}
