//! How smooth the exact solver's curve is on the scale of `discover`'s forward differences:
//! c12 at x and at x + h e_j (h = 1% of dimension j's range, `LaplaceSettings::fd_step`) at a
//! given tolerance (or `fixed`: no adaptive passes), and the forward-difference derivative against the one at a tighter
//! tolerance. `cargo run --release -p hpge-validation --example fd_noise -- TOL TOL_REF j x1 ... x9`
//! (the shipped space and detector; x in the space's column order without the bias).

use hpge_solver::FieldSettings;
use hpge_surrogate::{ExactSolver, ParameterSpace};
use hpge_validation::repo_path;

fn main() -> Result<(), Box<dyn std::error::Error>> {
    let args: Vec<String> = std::env::args().skip(1).collect();
    if args.len() < 4 {
        return Err("usage: fd_noise TOL TOL_REF j x1 ... xN".into());
    }
    // A tolerance, or `fixed` for the grid without adaptive passes (adaptive = false).
    let parse = |a: &str| -> Result<f64, std::num::ParseFloatError> {
        if a == "fixed" { Ok(0.0) } else { a.parse() }
    };
    let tol = parse(&args[0])?;
    let tol_ref = parse(&args[1])?;
    let j: usize = args[2].parse()?;
    let x: Vec<f64> = args[3..]
        .iter()
        .map(|a| a.parse())
        .collect::<Result<_, _>>()?;
    let space = ParameterSpace::from_file(&repo_path("spaces/super-siegfried-rz.toml"))?;
    let range = space.dimensions[j].range;
    let h = 0.01 * (range[1] - range[0]);
    let volts: Vec<f64> = (0..30).map(|k| 25.0 + 100.0 * k as f64).collect();
    let mut xh = x.clone();
    xh[j] += h;
    let derivative = |t: f64| -> Result<Vec<f64>, Box<dyn std::error::Error>> {
        let mut s = FieldSettings::default();
        if t == 0.0 {
            s.grid.adaptive = false;
        } else {
            s.grid.tolerance = t;
        }
        let ex = ExactSolver::new(
            space.clone(),
            &repo_path("detectors/super-siegfried-k1.toml"),
            s,
        )?;
        let c0 = ex.curve(&x, &volts)?;
        let c1 = ex.curve(&xh, &volts)?;
        Ok(c0.iter().zip(&c1).map(|(a, b)| (b - a) / h).collect())
    };
    let d = derivative(tol)?;
    let r = derivative(tol_ref)?;
    println!(
        "dimension {} h {h}: dc12/dx at tolerance {tol} against {tol_ref}",
        space.dimensions[j].name
    );
    let mut worst: f64 = 0.0;
    for ((v, a), b) in volts.iter().zip(&d).zip(&r) {
        let rel = (a - b).abs() / b.abs().max(1e-12);
        worst = worst.max(rel);
        println!("{v:6.0} V  {a:12.5}  {b:12.5}  rel diff {rel:.2e}");
    }
    println!("largest relative difference {worst:.2e}");
    Ok(())
}
