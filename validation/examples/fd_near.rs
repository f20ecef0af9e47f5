//! Forward differences of the exact solver's curve on the base point's grids
//! (`hpge_solver::cv_curves_near`) against two adaptive solves (what `discover` did before) and a
//! reference at a tighter tolerance: `cargo run --release -p hpge-validation --example fd_near --
//! TOL TOL_REF j x1 ... x9` (the shipped space and detector; x in the space's column order
//! without the bias; h = 1% of dimension j's range, `LaplaceSettings::fd_step`). Also prints the
//! near derivative with h/2 (a smooth difference halves with the step) and the times.

use std::time::Instant;

use hpge_solver::FieldSettings;
use hpge_solver::field::{Continuation, cv_curves_near};
use hpge_surrogate::{ExactSolver, ParameterSpace};
use hpge_validation::repo_path;

type Res<T> = Result<T, Box<dyn std::error::Error>>;

fn main() -> Res<()> {
    let args: Vec<String> = std::env::args().skip(1).collect();
    if args.len() < 4 {
        return Err("usage: fd_near TOL TOL_REF j x1 ... xN".into());
    }
    let tol: f64 = args[0].parse()?;
    let tol_ref: f64 = args[1].parse()?;
    let j: usize = args[2].parse()?;
    let x: Vec<f64> = args[3..]
        .iter()
        .map(|a| a.parse())
        .collect::<Result<_, _>>()?;
    let space = ParameterSpace::from_file(&repo_path("spaces/super-siegfried-rz.toml"))?;
    let range = space.dimensions[j].range;
    let h = 0.01 * (range[1] - range[0]);
    let volts: Vec<f64> = (0..30).map(|k| 25.0 + 100.0 * k as f64).collect();
    let shifted = |step: f64| {
        let mut xh = x.clone();
        xh[j] += step;
        xh
    };
    let solver = |t: f64| -> Res<ExactSolver> {
        let mut s = FieldSettings::default();
        s.grid.tolerance = t;
        Ok(ExactSolver::new(
            space.clone(),
            &repo_path("detectors/super-siegfried-k1.toml"),
            s,
        )?)
    };
    let adaptive = |ex: &ExactSolver| -> Res<(Vec<f64>, f64)> {
        let t = Instant::now();
        let c0 = ex.curve(&x, &volts)?;
        let c1 = ex.curve(&shifted(h), &volts)?;
        let d = c0.iter().zip(&c1).map(|(a, b)| (b - a) / h).collect();
        Ok((d, t.elapsed().as_secs_f64()))
    };
    let ex = solver(tol)?;
    let (d_adaptive, t_adaptive) = adaptive(&ex)?;
    let (d_ref, _) = adaptive(&solver(tol_ref)?)?;
    let t = Instant::now();
    let near = [ex.detector(&shifted(h))?, ex.detector(&shifted(0.5 * h))?];
    let nc = cv_curves_near(
        &ex.detector(&x)?,
        &near,
        &volts,
        &ex.settings,
        Continuation::Seeded,
    )?;
    let t_near = t.elapsed().as_secs_f64();
    let c0: Vec<f64> = nc.base.points.iter().map(|p| p.c12_pf).collect();
    let d_near: Vec<f64> = c0
        .iter()
        .zip(&nc.near_pf[0])
        .map(|(a, b)| (b - a) / h)
        .collect();
    let d_half: Vec<f64> = c0
        .iter()
        .zip(&nc.near_pf[1])
        .map(|(a, b)| (b - a) / (0.5 * h))
        .collect();
    println!(
        "dimension {} h {h}: dc12/dx (pF per unit) at tolerance {tol}; reference: two adaptive solves at {tol_ref}",
        space.dimensions[j].name
    );
    println!("     U_B    adaptive        near   near h/2   reference");
    let (mut wa, mut wn, mut wh) = (0.0f64, 0.0f64, 0.0f64);
    let scale = d_ref.iter().fold(0.0f64, |m, d| m.max(d.abs())).max(1e-12);
    for k in 0..volts.len() {
        println!(
            "{:6.0} V {:11.5} {:11.5} {:11.5} {:11.5}",
            volts[k], d_adaptive[k], d_near[k], d_half[k], d_ref[k]
        );
        wa = wa.max((d_adaptive[k] - d_ref[k]).abs() / scale);
        wn = wn.max((d_near[k] - d_ref[k]).abs() / scale);
        wh = wh.max((d_near[k] - d_half[k]).abs() / scale);
    }
    println!(
        "largest difference from the reference, relative to its largest |derivative|: adaptive {wa:.2e}, near {wn:.2e}; near h vs h/2 {wh:.2e}"
    );
    println!(
        "time: adaptive (2 curves) {t_adaptive:.2} s; near (base curve + 2 nearby) {t_near:.2} s; points regridded {}",
        nc.regridded
    );
    Ok(())
}
