//! The shipped stand-in detector as the exact solver sees it: Super-Siegfried
//! (`detectors/super-siegfried-k1.toml`) on the rz parameter space
//! (`spaces/super-siegfried-rz.toml`) at the default field settings, the stand-in data's truth
//! (read from `data/super-siegfried-k1/truth-b-rz.toml`), and draws of a two-mode posterior around it, as
//! the exact-solver check of a B_Z fit meets them (bottom and top levels swapped).

use hpge_solver::FieldSettings;
use hpge_surrogate::{ExactSolver, ParameterSpace};

use crate::{Error, Result, repo_path};

/// The file of the stand-in's truth in the B_RZ parameters.
pub const STAND_IN_TRUTH_FILE: &str = "data/super-siegfried-k1/truth-b-rz.toml";

/// The stand-in's truth ([`STAND_IN_TRUTH_FILE`]) in `solver`'s inputs, in their order
/// (d_li_mm, y1..y4_bot, y1..y4_top for the rz space).
///
/// # Errors
/// The file does not read or parse, or lacks one of the inputs as a number.
pub fn stand_in_truth(solver: &ExactSolver) -> Result<Vec<f64>> {
    let path = repo_path(STAND_IN_TRUTH_FILE);
    let file = |message: String| Error::File {
        path: path.clone(),
        message,
    };
    let text = std::fs::read_to_string(&path).map_err(|e| file(e.to_string()))?;
    let table: toml::Table = text
        .parse()
        .map_err(|e: toml::de::Error| file(e.to_string()))?;
    let n = solver.space.dimensions.len() - 1;
    solver.space.dimensions[..n]
        .iter()
        .map(|d| {
            table
                .get(&d.name)
                .and_then(|v| v.as_float().or_else(|| v.as_integer().map(|i| i as f64)))
                .ok_or_else(|| file(format!("`{}`: missing, or not a number", d.name)))
        })
        .collect()
}

/// The exact solver of the stand-in: the rz space on Super-Siegfried, default field settings.
///
/// # Errors
/// A shipped file that does not load.
pub fn stand_in_solver() -> Result<ExactSolver> {
    let space = ParameterSpace::from_file(&repo_path("spaces/super-siegfried-rz.toml"))
        .map_err(surrogate)?;
    ExactSolver::new(
        space,
        &repo_path("detectors/super-siegfried-k1.toml"),
        FieldSettings::default(),
    )
    .map_err(surrogate)
}

/// The width of each input's range (the solver's space without its bias), in the inputs'
/// order: the scale of a distance between parameter points.
pub fn input_widths(solver: &ExactSolver) -> Vec<f64> {
    let n = solver.space.dimensions.len() - 1;
    solver.space.dimensions[..n]
        .iter()
        .map(|d| d.range[1] - d.range[0])
        .collect()
}

/// `per_mode` draws around `truth` (rz inputs: d_li_mm, four bottom knots, four top knots) and
/// as many around its mirror (the bottom and top knots swapped), interleaved: draw k of a mode
/// moves d_Li by +0.08 (k + 1) mm, y1_bot by -0.004 (k + 1) and y1_top by +0.004 (k + 1).
pub fn two_mode_draws(truth: &[f64; 9], per_mode: usize) -> Vec<Vec<f64>> {
    let t = *truth;
    let mirror = [t[0], t[5], t[6], t[7], t[8], t[1], t[2], t[3], t[4]];
    let mut xs = Vec::with_capacity(2 * per_mode);
    for k in 0..per_mode {
        let e = 0.004 * (k as f64 + 1.0);
        for centre in [t, mirror] {
            let mut x = centre;
            x[0] += 20.0 * e;
            x[1] -= e;
            x[5] += e;
            xs.push(x.to_vec());
        }
    }
    xs
}

/// A surrogate-crate error (the exact solver's set-up) as this crate's.
fn surrogate(e: hpge_surrogate::Error) -> Error {
    Error::Inference(hpge_inference::Error::Surrogate(e))
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn the_truth_reads_in_the_inputs_order() {
        let t = stand_in_truth(&stand_in_solver().unwrap()).unwrap();
        assert_eq!(t.len(), 9);
        assert_eq!(t[0], 3.0);
        assert_eq!(t[1], 0.6641665582231558);
        assert_eq!(t[8], -0.32334667109273946);
    }

    #[test]
    fn the_draws_alternate_between_the_truth_and_its_mirror() {
        let t = [3.0, 0.66, 0.66, 0.58, -0.38, 0.55, 0.54, 0.48, -0.32];
        let xs = two_mode_draws(&t, 2);
        assert_eq!(xs.len(), 4);
        assert!((xs[0][1] - (t[1] - 0.004)).abs() < 1e-15);
        assert!((xs[1][1] - (t[5] - 0.004)).abs() < 1e-15);
        assert!((xs[3][0] - 3.16).abs() < 1e-12);
        assert_eq!(xs[1][6], t[2]);
    }

    #[test]
    fn the_widths_are_the_inputs_ranges() {
        let s = stand_in_solver().unwrap();
        let w = input_widths(&s);
        assert_eq!(w.len(), 9);
        assert!((w[0] - 4.8).abs() < 1e-12, "d_li_mm 0.2-5 mm");
        assert!((w[4] - 2.0).abs() < 1e-12, "y4_bot -1..1");
    }
}
