//! How far the full-depletion and pinch-off voltages at the defaults sit from a 4x finer grid,
//! and what the coarsened grids say (issue 64, item 1). For each detector in `detectors/` that
//! depletes below 6000 V: a coarse curve (250 V steps) brackets U_fd; the first fully depleted
//! point's grid h (the depleted reference's) gives U_fd(h); the two complementary coarsenings
//! H_0, H_1 of h and h with every interval divided into PARTS (default 4) give U_fd again; the
//! estimate with its error bar is `full_depletion_voltage_estimate`'s. Where the curve has a
//! pocket, the pinch-off voltage with its error bar on the same grid
//! (`pinch_off_voltage_estimate`), and (unless NO_FINE_PINCH is set) on the grid divided into
//! PARTS inside a bracket of twice the error bar (`pinch_off_fine` does the 4x finer one in a
//! given bracket); COMPARE_GRIDS adds the same on the first pocket point's own potential grid
//! (what the pinch-off used before issue 64). Prints one JSON object per detector
//! (`reports/accuracy/depletion-error.jsonl`).
//!
//! `[PARTS=4] [NO_FINE_PINCH=1] cargo run --release -p hpge-validation --example depletion_error [-- detectors/x.toml ...]`

use hpge_solver::field::{
    Mesh, cv_curve, full_depletion_voltage_estimate, pinch_off_voltage_estimate,
};
use hpge_solver::{
    Detector, FieldSettings, Parameters, full_depletion_voltage, pinch_off_voltage, solve_point,
    solve_potential,
};
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
    for f in &files {
        let det = Detector::from_file(f, &Parameters::new())?;
        let s = FieldSettings::default().for_detector(&det);
        let coarse: Vec<f64> = (1..=24).map(|k| 250.0 * f64::from(k)).collect();
        let t0 = std::time::Instant::now();
        let c = cv_curve(&det, &coarse, &s, |_, _| {})?;
        let Some(k) = c.points.iter().position(|p| p.fully_depleted) else {
            println!("{}", serde_json::json!({"detector": f, "u_fd_V": null}));
            continue;
        };
        let hi = c.points[k].voltage_v;
        let p = solve_point(&det, hi, &s, None)?;
        let grid = p.mesh.grid.clone();
        let (kr, kz) = det.ticks();
        let on = |g: hpge_solver::grid::Grid| -> AnyResult<(f64, usize)> {
            let n = g.nr() * g.nz();
            let m = Mesh::new(&det, g);
            Ok((full_depletion_voltage(&m, &det, 0.0, 2.0 * hi)?, n))
        };
        let h = on(grid.clone())?;
        let h0 = match grid.coarsened_phase(&kr, &kz, 0) {
            Some(g) => Some(on(g)?),
            None => None,
        };
        let h1 = match grid.coarsened_phase(&kr, &kz, 1) {
            Some(g) => Some(on(g)?),
            None => None,
        };
        let parts: usize = std::env::var("PARTS")
            .ok()
            .and_then(|p| p.parse().ok())
            .unwrap_or(4);
        let fine = on(grid.subdivided(parts))?;
        let lo = if k > 0 {
            c.points[k - 1].voltage_v
        } else {
            0.0
        };
        let est = full_depletion_voltage_estimate(&det, &grid, lo, hi)?;
        // Pinch-off, where the coarse curve has a pocket: on the reference grid and on the first
        // pocket point's own grid, each against the same grid divided into `parts`.
        let mut pinch = Vec::new();
        if let Some(j) = c.points.iter().position(|p| !p.pockets.is_empty()) {
            let (plo, phi) = (c.points[j - 1].voltage_v, c.points[j].voltage_v);
            let mut grids = vec![("reference", grid.clone())];
            if std::env::var("COMPARE_GRIDS").is_ok() {
                grids.push((
                    "first-pocket point",
                    solve_potential(&det, phi, &s, None)?.mesh.grid,
                ));
            }
            for (name, g) in grids {
                let t = std::time::Instant::now();
                let e = pinch_off_voltage_estimate(&det, &g, (plo, phi), hi)?;
                let secs = t.elapsed().as_secs_f64();
                let fine = match e {
                    Some(e) if std::env::var("NO_FINE_PINCH").is_err() => {
                        let d = 2.0 * e.err_v.min(0.05 * e.voltage_v) + 1.0;
                        let m = Mesh::new(&det, g.subdivided(parts));
                        pinch_off_voltage(&m, &det, e.voltage_v - d, e.voltage_v + d)?
                            .map(|u| (u, e.voltage_v - d, e.voltage_v + d))
                    }
                    _ => None,
                };
                pinch.push(serde_json::json!({
                    "grid": name, "nodes": g.nr() * g.nz(), "estimate": e, "seconds": secs,
                    "fine": fine, "fine_seconds": t.elapsed().as_secs_f64() - secs,
                }));
            }
        }
        let mut out = serde_json::json!({
            "parts": parts, "u_fd_estimate": est, "pinch_off": pinch,
            "detector": f.file_name().map(|n| n.to_string_lossy().to_string()),
            "u_fd_curve_V": c.depletion_voltage_v,
            "u_fd_h_V": h.0, "nodes_h": h.1,
            "u_fd_H0_V": h0.map(|x| x.0), "u_fd_H1_V": h1.map(|x| x.0),
            "u_fd_fine4_V": fine.0, "nodes_fine4": fine.1,
            "seconds": t0.elapsed().as_secs_f64(),
        });
        out[hpge_foundation::MADE_KEY] = serde_json::to_value(hpge_solver::made())?;
        println!("{out}");
    }
    Ok(())
}
