//! The shipped stand-in detector as the exact solver sees it: Super-Siegfried
//! (`detectors/super-siegfried-k1.toml`) on the rz parameter space
//! (`spaces/super-siegfried-rz.toml`) at the default field settings, the stand-in data's truth
//! (`data/super-siegfried-k1/truth-b-rz.toml`), and draws of a two-mode posterior around it, as
//! the exact-solver check of a B_Z fit meets them (bottom and top levels swapped).

use hpge_solver::FieldSettings;
use hpge_surrogate::{ExactSolver, ParameterSpace};

use crate::{Error, Result, repo_path};

/// The stand-in's truth in the rz space's inputs (d_li_mm, y1..y4_bot, y1..y4_top;
/// `data/super-siegfried-k1/truth-b-rz.toml`).
pub const STAND_IN_TRUTH: [f64; 9] = [
    3.0,
    0.6641665582231558,
    0.6565589955022244,
    0.5773215797217719,
    -0.37587850097731035,
    0.5506015329628319,
    0.5439239787452446,
    0.47512927644699526,
    -0.32334667109273946,
];

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

/// `per_mode` draws around [`STAND_IN_TRUTH`] and as many around its mirror (the bottom and top
/// knots swapped), interleaved: draw k of a mode moves d_Li by +0.08 (k + 1) mm, y1_bot by
/// -0.004 (k + 1) and y1_top by +0.004 (k + 1).
pub fn two_mode_draws(per_mode: usize) -> Vec<Vec<f64>> {
    let t = STAND_IN_TRUTH;
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
    fn the_draws_alternate_between_the_truth_and_its_mirror() {
        let xs = two_mode_draws(2);
        assert_eq!(xs.len(), 4);
        assert!((xs[0][1] - (STAND_IN_TRUTH[1] - 0.004)).abs() < 1e-15);
        assert!((xs[1][1] - (STAND_IN_TRUTH[5] - 0.004)).abs() < 1e-15);
        assert!((xs[3][0] - 3.16).abs() < 1e-12);
        assert_eq!(xs[1][6], STAND_IN_TRUTH[2]);
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
