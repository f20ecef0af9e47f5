//! Issue 59's learning curves: held-out accuracy against the CPU-hours of generation spent on
//! rows beyond the 54 000 training rows, rows added uniformly against rows chosen by
//! `generate --where` (active learning) and rows at low bias only, from
//! `models/learning-curves.jsonl`
//! (`models/learning-curve.sh` appends one line per trained point).
//!
//! `cargo run --release -p hpge-reports --example learning_curves_figure -- JSONL OUT_STEM`
//! writes OUT_STEM-sigma.{svg,png} (Gaussian sigma of the relative error) and
//! OUT_STEM-q99.{svg,png} (99th percentile of |relative error|), each with one curve per arm
//! and held-out set (a point trained on several arms' rows together is its own series, named by them; lines of a seed
//! other than 0 are left out).

use std::collections::BTreeMap;
use std::path::PathBuf;

use hpge_reports::plot::{Corner, Curve, LineFigure, line_figure};

/// One trained point: (arm, recipe) -> [(CPU-hours, figures on heldout-300000, on heldout)].
type Series = BTreeMap<(String, String), Vec<(f64, serde_json::Value, serde_json::Value)>>;

fn read(path: &PathBuf) -> Result<Series, Box<dyn std::error::Error>> {
    let text = std::fs::read_to_string(path).map_err(|e| format!("{}: {e}", path.display()))?;
    let mut series = Series::new();
    for (i, line) in text
        .lines()
        .enumerate()
        .filter(|(_, l)| !l.trim().is_empty())
    {
        let v: serde_json::Value = serde_json::from_str(line)
            .map_err(|e| format!("{} line {}: {e}", path.display(), i + 1))?;
        let field = |k: &str| {
            v.get(k)
                .cloned()
                .ok_or_else(|| format!("{} line {}: no `{k}`", path.display(), i + 1))
        };
        // Other seeds than 0 are the seed-scatter checks, not points of a curve.
        if v.get("seed")
            .and_then(serde_json::Value::as_u64)
            .unwrap_or(0)
            != 0
        {
            continue;
        }
        let mut arm = field("arm")?.as_str().unwrap_or_default().to_string();
        // A point whose extra folders hold another arm's rows (not only the B_Z slice's low-bias
        // rows, which belong to the low-bias arm) is a mixture: its own series.
        let mixed = v
            .get("extra")
            .and_then(serde_json::Value::as_array)
            .is_some_and(|e| {
                e.iter()
                    .filter_map(serde_json::Value::as_str)
                    .any(|f| !f.ends_with("bz-low-bias-800000"))
            });
        if mixed {
            let short = |f: &str| match f.rsplit('/').next().unwrap_or(f) {
                "uniform-400000" => "uniform".to_string(),
                "active-500000" => "active".to_string(),
                "bz-low-bias-800000" => "B_Z low-bias".to_string(),
                other => other.to_string(),
            };
            let k = v.get("k").and_then(serde_json::Value::as_u64).unwrap_or(0);
            let mut parts: Vec<String> = if k > 0 { vec![arm.clone()] } else { vec![] };
            parts.extend(
                v["extra"]
                    .as_array()
                    .into_iter()
                    .flatten()
                    .filter_map(serde_json::Value::as_str)
                    .map(short),
            );
            arm = parts.join(" + ");
        }
        let recipe = field("recipe")?.as_str().unwrap_or_default().to_string();
        let hours = field("cpu_s")?.as_f64().unwrap_or(f64::NAN) / 3600.0;
        series.entry((arm, recipe)).or_default().push((
            hours,
            field("heldout_300000")?,
            field("heldout")?,
        ));
    }
    // An arm without its own point at 0 CPU-hours (e.g. `low-bias`) starts from the same
    // recipe's 54 000-row model, which every arm shares.
    let bases: BTreeMap<String, (f64, serde_json::Value, serde_json::Value)> = series
        .iter()
        .flat_map(|((_, recipe), points)| {
            points
                .iter()
                .filter(|p| p.0 == 0.0)
                .map(move |p| (recipe.clone(), p.clone()))
        })
        .collect();
    for ((_, recipe), points) in series.iter_mut() {
        if !points.iter().any(|p| p.0 == 0.0)
            && let Some(base) = bases.get(recipe)
        {
            points.push(base.clone());
        }
    }
    for points in series.values_mut() {
        points.sort_by(|a, b| a.0.total_cmp(&b.0));
    }
    Ok(series)
}

fn main() -> Result<(), Box<dyn std::error::Error>> {
    let args: Vec<String> = std::env::args().skip(1).collect();
    let [jsonl, stem] = args.as_slice() else {
        return Err("usage: learning_curves_figure JSONL OUT_STEM".into());
    };
    let series = read(&PathBuf::from(jsonl))?;
    if series.is_empty() {
        return Err(format!("{jsonl}: no points").into());
    }
    for (key, name, what) in [
        (
            "rel_sigma",
            "sigma",
            "Gaussian sigma of (c_p - c_s)/c_s (%)",
        ),
        ("abs_rel_q99", "q99", "q99 of |c_p - c_s|/c_s (%)"),
    ] {
        let mut curves = Vec::new();
        for ((arm, recipe), points) in &series {
            for (set, pick) in [("heldout-300000", 1usize), ("heldout", 2)] {
                curves.push(Curve {
                    label: format!("{arm} rows, {recipe}, on {set}.csv"),
                    points: points
                        .iter()
                        .map(|p| {
                            let figs = if pick == 1 { &p.1 } else { &p.2 };
                            (
                                p.0,
                                figs.get(key).and_then(|x| x.as_f64()).map(|x| 100.0 * x),
                            )
                        })
                        .collect(),
                });
            }
        }
        let fig = LineFigure {
            title: format!("held-out {name} against CPU-hours of new rows (lines join the points)"),
            x_desc: "CPU-hours of generation beyond the 54 000 training rows".into(),
            y_desc: what.into(),
            curves,
            y_from_zero: true,
            legend: Corner::LowerRight,
            footnotes: vec![format!(
                "{} {}: {jsonl} (models/learning-curve.sh); issue 59, item 3",
                hpge_reports::PROGRAM,
                hpge_reports::VERSION
            )],
        };
        for ext in ["svg", "png"] {
            line_figure(&fig, &PathBuf::from(format!("{stem}-{name}.{ext}")))?;
        }
    }
    Ok(())
}
