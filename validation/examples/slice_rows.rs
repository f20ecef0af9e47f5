//! Training rows on the B_Z slice of the paper's space, in the rows format of
//! `spaces/super-siegfried-rz.toml` (so `train` reads them beside `generate`'s rows): points of
//! the golden sequence in 4 dimensions (d_Li, y_bot, y_top, U_B, each uniform over the space's
//! range; y_bot and y_top over [0.0186, 1], the range of y1 and y2) mapped to the four knots of
//! each face, solved by the exact solver as `generate` does. Indices from FIRST.
//! `cargo run --release -p hpge-validation --example slice_rows -- N FIRST OUT.csv`

use std::io::Write;

use hpge_solver::FieldSettings;
use hpge_surrogate::{ExactSolver, ParameterSpace, Sequence, SequenceKind};
use hpge_validation::repo_path;
use rayon::prelude::*;

fn main() -> Result<(), Box<dyn std::error::Error>> {
    let args: Vec<String> = std::env::args().skip(1).collect();
    let n: u64 = args.first().ok_or("N")?.parse()?;
    let first: u64 = args.get(1).ok_or("FIRST")?.parse()?;
    let out = args.get(2).ok_or("OUT.csv")?;
    let space = ParameterSpace::from_file(&repo_path("spaces/super-siegfried-rz.toml"))?;
    let ex = ExactSolver::new(
        space.clone(),
        &repo_path("detectors/super-siegfried-k1.toml"),
        FieldSettings::default(),
    )?;
    let seq = Sequence::new(SequenceKind::Golden, 4, 0);
    let dims = &space.dimensions;
    let lin = |j: usize, u: f64| dims[j].range[0] + u * (dims[j].range[1] - dims[j].range[0]);
    let unit = |j: usize, x: f64| (x - dims[j].range[0]) / (dims[j].range[1] - dims[j].range[0]);
    let rows: Vec<String> = (first..first + n)
        .into_par_iter()
        .map(|k| {
            let p = seq.point(k);
            let (d, yb, yt, ub) = (lin(0, p[0]), lin(1, p[1]), lin(5, p[2]), lin(9, p[3]));
            let x = [d, yb, yb, yb, yb, yt, yt, yt, yt, ub];
            let u: Vec<f64> = (0..10).map(|j| unit(j, x[j])).collect();
            let t = std::time::Instant::now();
            let (c, status) = match ex.solve(&x) {
                Ok(c) => (c, "ok".to_string()),
                Err(e) => (f64::NAN, format!("failed: {e}").replace(',', ";")),
            };
            let mut line = k.to_string();
            for v in u.iter().chain(&x) {
                line.push_str(&format!(",{v}"));
            }
            line.push_str(&format!(",{c},{status},{}", t.elapsed().as_secs_f64()));
            line
        })
        .collect();
    let mut f = std::fs::File::create(out)?;
    let mut header = vec!["index".to_string()];
    header.extend(dims.iter().map(|d| format!("u_{}", d.name)));
    header.extend(dims.iter().map(|d| d.name.clone()));
    header.extend(["c12_pF", "status", "seconds"].map(String::from));
    writeln!(f, "{}", header.join(","))?;
    for r in rows {
        writeln!(f, "{r}")?;
    }
    Ok(())
}
