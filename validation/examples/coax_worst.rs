//! Worst relative c12 error of the 2D solver on the long coax over 25..2975 V (step 50) for
//! given grid settings. `cargo run --release -p hpge-validation --example coax_worst -- SPACING FRONT`

use hpge_solver::{Detector, FieldSettings, Parameters, solve_point};
use hpge_validation::{LongCoax, repo_path};

fn main() -> Result<(), Box<dyn std::error::Error>> {
    let args: Vec<f64> = std::env::args()
        .skip(1)
        .map(|a| a.parse())
        .collect::<Result<_, _>>()?;
    let det = Detector::from_file(
        &repo_path("detectors/coax-analytic.toml"),
        &Parameters::new(),
    )?;
    let mut s = FieldSettings::default();
    if let Some(h) = args.first() {
        s.grid.max_spacing_semiconductor_mm = *h;
    }
    if let Some(f) = args.get(1) {
        s.grid.front_spacing_mm = *f;
    }
    if let Ok(l) = std::env::var("LIMITS") {
        s.grid.refinement_limits = l
            .split(',')
            .filter(|x| !x.is_empty())
            .map(|x| x.parse())
            .collect::<Result<_, _>>()?;
    }
    let verbose = std::env::var("VERBOSE").is_ok();
    let exact = LongCoax::validation();
    let (mut worst, mut at, mut sum2) = (0.0f64, 0.0, 0.0);
    let t = std::time::Instant::now();
    for k in 0..60 {
        let v = 25.0 + 50.0 * k as f64;
        let p = solve_point(&det, v, &s, None)?;
        let e = p.c12_pf / 10.0 / exact.c12_per_mm_pf(v)? - 1.0;
        sum2 += e * e;
        if verbose {
            println!(
                "{v:>6} {e:>10.2e} {}x{}",
                p.mesh.grid.nr(),
                p.mesh.grid.nz()
            );
        }
        if e.abs() > worst {
            worst = e.abs();
            at = v;
        }
    }
    println!(
        "spacing {} front {}: worst {:.2e} at {} V, rms {:.2e}, {:.2} s",
        s.grid.max_spacing_semiconductor_mm,
        s.grid.front_spacing_mm,
        worst,
        at,
        (sum2 / 60.0).sqrt(),
        t.elapsed().as_secs_f64()
    );
    Ok(())
}
