//! The pinch-off voltage on the fully depleted reference's grid with every interval divided
//! into PARTS (issue 64's check of `pinch_off_voltage_err_V`), bisected inside a given bracket
//! to 1e-4 relative, or to WIDTH_V when given: the reference value for
//! `reports/accuracy/depletion.md`. A 4x finer ICPC grid has about 4 million nodes (about 2 min
//! per nonlinear solve here), so the bracket should come from the 2x finer run of
//! `depletion_error` (PARTS=2). A bracket narrower than the estimate's error bar is enough to
//! say whether the bar bounds the finer value: the result gives `lo_V` and `hi_V` (the pinch-off
//! lies in (lo_V, hi_V]) and `depletion_table.py` checks both ends.
//!
//! `cargo run --release -p hpge-validation --example pinch_off_fine -- DETECTOR DEPLETED_V PARTS LO_V HI_V [WIDTH_V]`

use hpge_solver::field::{Mesh, Pocket, solve_fast};
use hpge_solver::{Detector, FieldSettings, Parameters, solve_point};
use hpge_validation::repo_path;

type AnyResult<T> = Result<T, Box<dyn std::error::Error>>;

fn main() -> AnyResult<()> {
    let a: Vec<String> = std::env::args().skip(1).collect();
    if a.len() != 5 && a.len() != 6 {
        return Err("usage: pinch_off_fine DETECTOR DEPLETED_V PARTS LO_V HI_V [WIDTH_V]".into());
    }
    let det = Detector::from_file(&repo_path(&a[0]), &Parameters::new())?;
    let s = FieldSettings::default().for_detector(&det);
    let depleted: f64 = a[1].parse()?;
    let parts: usize = a[2].parse()?;
    let (mut lo, mut hi): (f64, f64) = (a[3].parse()?, a[4].parse()?);
    let width_v: f64 = match a.get(5) {
        Some(w) => w.parse()?,
        None => 1e-4 * hi,
    };
    if width_v.is_nan() || width_v <= 0.0 {
        return Err(format!("WIDTH_V must be > 0, got {width_v}").into());
    }
    let t0 = std::time::Instant::now();
    // A fully depleted point's grid is the reference's.
    let grid = solve_point(&det, depleted, &s, None)?
        .mesh
        .grid
        .subdivided(parts);
    let nodes = grid.nr() * grid.nz();
    let mesh = Mesh::new(&det, grid);
    let mut guess: Option<Vec<f64>> = None;
    let mut pocket = |u: f64| -> AnyResult<bool> {
        let sol = solve_fast(&mesh, &det, u, guess.as_deref())?;
        let p = sol.pockets.iter().any(Pocket::resolved);
        eprintln!(
            "{u:.3} V: resolved pocket {p} ({:.0} s)",
            t0.elapsed().as_secs_f64()
        );
        guess = Some(sol.phi_v);
        Ok(p)
    };
    let bracketed = !pocket(lo)? && pocket(hi)?;
    if bracketed {
        while hi - lo > width_v {
            let mid = 0.5 * (lo + hi);
            if pocket(mid)? {
                hi = mid;
            } else {
                lo = mid;
            }
        }
    }
    let mut out = serde_json::json!({
        "detector": a[0], "parts": parts, "nodes": nodes, "bracketed": bracketed,
        "pinch_off_V": bracketed.then_some(hi), "width_V": hi - lo,
        "lo_V": lo, "hi_V": hi,
        "seconds": t0.elapsed().as_secs_f64(),
    });
    out[hpge_foundation::MADE_KEY] = serde_json::to_value(hpge_solver::made())?;
    println!("{out}");
    Ok(())
}
