//! The exact solver at points of a parameter space: the space's values set on the detector
//! (its `[parameters]` and the rz model's y knots), then a field solve per bias. Training rows
//! come from here, and so does the exact model inference checks the surrogate against.

use std::path::{Path, PathBuf};

use hpge_solver::field::{Continuation, cv_curve_with};
use hpge_solver::{Detector, FieldSettings, ImpuritySpec, Parameters, solve_point};

use super::regime::Regime;
use crate::error::{Error, Result};
use crate::hash::fnv1a;
use crate::space::{ParameterSpace, Target};

/// The resolution (V) to which [`ExactSolver::solve_labelled_switch`] bisects a switch.
pub const SWITCH_RESOLUTION_V: f64 = 0.5;

/// A detector whose parameters and impurity model are set from points of a parameter space.
#[derive(Debug, Clone)]
pub struct ExactSolver {
    /// The space.
    pub space: ParameterSpace,
    /// The detector file.
    pub detector_file: PathBuf,
    detector_text: String,
    detector_hash: String,
    /// Solver settings.
    pub settings: FieldSettings,
    targets: Vec<Target>,
}

impl ExactSolver {
    /// Checks the space against the detector (every `parameter:` target declared, the y targets
    /// knots 0, 1, ... of its rz model, one bias dimension) and builds the detector once at the
    /// centre of the space.
    pub fn new(
        space: ParameterSpace,
        detector_file: &Path,
        settings: FieldSettings,
    ) -> Result<Self> {
        let detector_text = std::fs::read_to_string(detector_file).map_err(|e| Error::Io {
            file: detector_file.into(),
            action: "cannot read the detector",
            source: e,
        })?;
        // The detector must load, and the y targets must fit its rz knots.
        let det = Detector::from_toml_str(&detector_text, detector_file, &Parameters::new())?;
        let targets = space.targets();
        let ys: Vec<&Target> = targets
            .iter()
            .filter(|t| matches!(t, Target::YBot(_) | Target::YTop(_)))
            .collect();
        for face in [0, 1] {
            let mut ks: Vec<usize> = targets
                .iter()
                .filter_map(|t| match (t, face) {
                    (Target::YBot(k), 0) | (Target::YTop(k), 1) => Some(*k),
                    _ => None,
                })
                .collect();
            ks.sort_unstable();
            if !ys.is_empty() && ks != (0..ks.len().max(1)).collect::<Vec<_>>() {
                return Err(Error::Invalid {
                    file: space.file.clone(),
                    key: "dimensions".into(),
                    message: format!(
                        "the {} targets must be knots 0, 1, ... without gaps, got {ks:?}",
                        if face == 0 { "y_bot" } else { "y_top" },
                    ),
                });
            }
        }
        for t in &targets {
            if let Target::Parameter(p) = t
                && det.parameters.get(p).is_none()
            {
                return Err(Error::Invalid {
                    file: space.file.clone(),
                    key: "dimensions".into(),
                    message: format!(
                        "target parameter:{p}: {} declares no parameter `{p}`",
                        detector_file.display()
                    ),
                });
            }
        }
        if !targets.contains(&Target::Bias) {
            return Err(Error::Invalid {
                file: space.file.clone(),
                key: "dimensions".into(),
                message: "one dimension must have target = \"bias\"".into(),
            });
        }
        let mut det_bytes = detector_text.as_bytes().to_vec();
        if let Ok(imp) = std::fs::read(det.semiconductor.impurity_file()) {
            det_bytes.extend_from_slice(&imp);
        }
        let exact = Self {
            space,
            detector_file: detector_file.into(),
            detector_text,
            detector_hash: format!("{:016x}", fnv1a(&det_bytes)),
            settings,
            targets,
        };
        // A dry run at the centre of the space: the detector and impurity model build.
        let centre = exact.space.from_unit(&vec![0.5; exact.space.dim()]);
        exact.configure(&centre)?;
        Ok(exact)
    }

    /// FNV-1a hash (hex) of the detector file's text followed by its impurity file's bytes (the
    /// `detector_hash` of a generation run's fingerprint).
    pub fn detector_hash(&self) -> String {
        self.detector_hash.clone()
    }

    /// c12 (pF) at one point `x` of the space (physical values in the space's column order,
    /// the bias included).
    pub fn solve(&self, x: &[f64]) -> Result<f64> {
        Ok(self.solve_with_error(x)?.0)
    }

    /// [`ExactSolver::solve`] with the solver's own error estimate: (c12, estimated absolute
    /// error |c12_h - c12_H|), both pF (`hpge_solver::field::Accuracy`). The estimate is above
    /// the settings' tolerance where the adaptive grid could not reach it (a pocket's neck at
    /// pinch-off).
    pub fn solve_with_error(&self, x: &[f64]) -> Result<(f64, f64)> {
        let (c, err, _) = self.solve_labelled(x)?;
        Ok((c, err))
    }

    /// [`ExactSolver::solve_labelled`] and the nearest bias within `window_v` of the row's bias
    /// at which the number of pockets changes (a pinch-off, or a pocket depleting): found on
    /// the point's final mesh with depletion solves alone (`solve_fast`, each seeded by the
    /// last), at U_B - w and U_B + w, then bisected to [`SWITCH_RESOLUTION_V`] where the
    /// count differs from the count at U_B on that mesh. NaN when neither end differs (two
    /// switches within the window that cancel are not seen). The closer side wins.
    pub fn solve_labelled_switch(
        &self,
        x: &[f64],
        window_v: f64,
    ) -> Result<(f64, f64, Regime, f64)> {
        let (det, bias, p) = self.point(x)?;
        let regime = Regime::from_pockets(&p.potential.pockets);
        let count = |u: f64, guess: &[f64]| -> Result<(usize, Vec<f64>)> {
            let s = hpge_solver::field::solve_fast(&p.mesh, &det, u, Some(guess))?;
            Ok((s.pockets.len(), s.phi_v))
        };
        let phi0 = &p.potential.phi_v;
        let (n0, _) = count(bias, phi0)?;
        let mut best = f64::NAN;
        for side in [-1.0, 1.0] {
            let far = (bias + side * window_v).max(0.0);
            if far == bias {
                continue;
            }
            let (n_far, mut guess) = count(far, phi0)?;
            if n_far == n0 {
                continue;
            }
            // Bisect between the row's bias (count n0) and `far` (another count).
            let (mut near_v, mut far_v) = (bias, far);
            while (far_v - near_v).abs() > SWITCH_RESOLUTION_V {
                let mid = 0.5 * (near_v + far_v);
                let (n, g) = count(mid, &guess)?;
                guess = g;
                if n == n0 {
                    near_v = mid;
                } else {
                    far_v = mid;
                }
            }
            let at = 0.5 * (near_v + far_v);
            if best.is_nan() || (at - bias).abs() < (best - bias).abs() {
                best = at;
            }
        }
        Ok((p.c12_pf, p.accuracy.c12_err_pf, regime, best))
    }

    /// [`ExactSolver::solve_with_error`] with the pockets the solve ended with (the training
    /// row's regime, `generate::regime`): (c12 pF, estimated error pF, regime).
    pub fn solve_labelled(&self, x: &[f64]) -> Result<(f64, f64, Regime)> {
        let (_, _, p) = self.point(x)?;
        let regime = Regime::from_pockets(&p.potential.pockets);
        Ok((p.c12_pf, p.accuracy.c12_err_pf, regime))
    }

    /// The detector at `x`, its bias and the point's solve at the settings.
    fn point(&self, x: &[f64]) -> Result<(Detector, f64, hpge_solver::PointResult)> {
        let (det, bias) = self.configure(x)?;
        let p = solve_point(&det, bias, &self.settings, None)?;
        Ok((det, bias, p))
    }

    /// The detector with the space's non-bias values `params` (column order, a surrogate's
    /// network order) set: its parameters and its rz model's y knots.
    pub fn detector(&self, params: &[f64]) -> Result<Detector> {
        let nb = self.targets.len() - 1;
        if params.len() != nb {
            return Err(Error::Argument {
                name: "params".into(),
                message: format!(
                    "{} values given, the space has {nb} besides the bias",
                    params.len()
                ),
            });
        }
        let mut x = Vec::with_capacity(nb + 1);
        let mut it = params.iter();
        for t in &self.targets {
            x.push(match t {
                Target::Bias => 1.0,
                _ => *it.next().unwrap_or(&0.0),
            });
        }
        Ok(self.configure(&x)?.0)
    }

    /// c12 (pF) along a C-V curve: `params` as for [`ExactSolver::detector`], `volts` the biases
    /// (V, increasing). Each point is seeded from its neighbour (`hpge_solver::field::cv_curve`).
    pub fn curve(&self, params: &[f64], volts: &[f64]) -> Result<Vec<f64>> {
        self.curve_with(params, volts, Continuation::Seeded)
    }

    /// [`ExactSolver::curve`] with a choice of how the points pass information on
    /// ([`Continuation`]: seeded for dense voltage lists, cold for sparse ones).
    pub fn curve_with(
        &self,
        params: &[f64],
        volts: &[f64],
        continuation: Continuation,
    ) -> Result<Vec<f64>> {
        Ok(self
            .curve_with_error(params, volts, continuation)?
            .into_iter()
            .map(|(c, _)| c)
            .collect())
    }

    /// [`ExactSolver::curve_with`] with the solver's error estimate per point: (c12, estimated
    /// absolute error), both pF, as [`ExactSolver::solve_with_error`].
    pub fn curve_with_error(
        &self,
        params: &[f64],
        volts: &[f64],
        continuation: Continuation,
    ) -> Result<Vec<(f64, f64)>> {
        Ok(self
            .curve_labelled(params, volts, continuation)?
            .into_iter()
            .map(|(c, e, _)| (c, e))
            .collect())
    }

    /// [`ExactSolver::curve_with_error`] with each point's regime (its pockets): (c12 pF,
    /// estimated error pF, regime) per bias.
    pub fn curve_labelled(
        &self,
        params: &[f64],
        volts: &[f64],
        continuation: Continuation,
    ) -> Result<Vec<(f64, f64, Regime)>> {
        let det = self.detector(params)?;
        let curve = cv_curve_with(&det, volts, &self.settings, continuation, |_, _| {})?;
        if curve.points.len() != volts.len() {
            return Err(Error::Argument {
                name: "volts".into(),
                message: "the voltages must be positive, increasing and distinct".into(),
            });
        }
        Ok(curve
            .points
            .iter()
            .map(|p| (p.c12_pf, p.c12_err_pf, Regime::from_pockets(&p.pockets)))
            .collect())
    }

    /// The detector with the sample's parameters and impurity model, and the bias (V).
    fn configure(&self, x: &[f64]) -> Result<(Detector, f64)> {
        let mut params = Parameters::new();
        let mut bias = 0.0;
        let (mut yb, mut yt) = (Vec::new(), Vec::new());
        for (t, &v) in self.targets.iter().zip(x) {
            match t {
                Target::Bias => bias = v,
                Target::Parameter(p) => params.set(p.clone(), v),
                Target::YBot(k) => yb.push((*k, v)),
                Target::YTop(k) => yt.push((*k, v)),
            }
        }
        let mut det = Detector::from_toml_str(&self.detector_text, &self.detector_file, &params)?;
        if !yb.is_empty() {
            yb.sort_by_key(|p| p.0);
            yt.sort_by_key(|p| p.0);
            let list = |v: &[(usize, f64)]| {
                v.iter()
                    .map(|p| format!("{:e}", p.1))
                    .collect::<Vec<_>>()
                    .join(", ")
            };
            let text = format!(
                "model = \"rz\"\ny_bot = [{}]\ny_top = [{}]\n",
                list(&yb),
                list(&yt)
            );
            let name = Path::new("(generated sample)");
            let spec = ImpuritySpec::from_toml_str(&text, name)?;
            det.set_impurity(&spec, name)?;
        }
        Ok((det, bias))
    }
}
