//! The exact solver at points of a parameter space: the space's values set on the detector
//! (its `[parameters]`, and the space's impurity table with the `impurity:` targets' values,
//! any model), then a field solve per bias. Training rows
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
    /// The impurity table the `impurity:` targets fill in (None: the detector's model stays).
    impurity_base: Option<toml::Table>,
}

impl ExactSolver {
    /// Checks the space against the detector (every `parameter:` target declared, the
    /// `impurity:` targets filling the space's impurity table, one bias dimension) and builds
    /// the detector once at the centre of the space.
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
        // The detector must load, and the impurity targets must fill the space's table.
        let det = Detector::from_toml_str(&detector_text, detector_file, &Parameters::new())?;
        let targets = space.targets();
        let impurity_base = impurity_base(&space, &targets)?;
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
            impurity_base,
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
    /// network order) set: its parameters and its impurity model's values.
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
        let mut table = self.impurity_base.clone();
        for (t, &v) in self.targets.iter().zip(x) {
            match t {
                Target::Bias => bias = v,
                Target::Parameter(p) => params.set(p.clone(), v),
                Target::Impurity { key, index } => {
                    if let Some(table) = &mut table {
                        set_value(table, key, *index, v);
                    }
                }
            }
        }
        let mut det = Detector::from_toml_str(&self.detector_text, &self.detector_file, &params)?;
        if let Some(table) = table {
            // Errors of the table name the space's file; the model is the generated sample's.
            let spec = ImpuritySpec::from_table(table, &self.space.file)?;
            let name = Path::new("(generated sample)");
            det.set_impurity(&spec, name)?;
        }
        Ok((det, bias))
    }
}

/// The impurity table a space's `impurity:` targets fill in: its `[impurity]`, or `model =
/// "rz"` for the paper's `y_bot[K]` / `y_top[K]` without one; None without impurity targets.
/// A list's targets must be its elements 0, 1, ... without gaps, or elements of a list the
/// table already has; a single value's target must not be a list's.
fn impurity_base(space: &ParameterSpace, targets: &[Target]) -> Result<Option<toml::Table>> {
    let invalid = |message: String| Error::Invalid {
        file: space.file.clone(),
        key: "dimensions".into(),
        message,
    };
    let mut lists: std::collections::BTreeMap<&str, Vec<usize>> = Default::default();
    let mut singles: Vec<&str> = Vec::new();
    for t in targets {
        if let Target::Impurity { key, index } = t {
            match index {
                Some(k) => lists.entry(key.as_str()).or_default().push(*k),
                None => singles.push(key.as_str()),
            }
        }
    }
    if lists.is_empty() && singles.is_empty() {
        return Ok(None);
    }
    let base = match &space.impurity {
        Some(t) => t.clone(),
        None => {
            if let Some(k) = singles
                .first()
                .or_else(|| lists.keys().find(|k| !matches!(**k, "y_bot" | "y_top")))
            {
                return Err(invalid(format!(
                    "target `impurity:{k}` needs the space's `[impurity]` table (which model it is a key of)"
                )));
            }
            let mut t = toml::Table::new();
            t.insert("model".into(), toml::Value::String("rz".into()));
            t
        }
    };
    for key in &singles {
        if lists.contains_key(key) {
            return Err(invalid(format!(
                "`impurity:{key}` is targeted both as a single value and as a list's elements"
            )));
        }
    }
    for (key, ks) in &mut lists {
        ks.sort_unstable();
        let given = base.get(*key).and_then(toml::Value::as_array).map(Vec::len);
        let ok = match given {
            Some(n) => ks.iter().all(|&k| k < n),
            None => *ks == (0..ks.len()).collect::<Vec<_>>(),
        };
        if !ok {
            return Err(invalid(match given {
                Some(n) => format!(
                    "the {key} targets must be elements of the [impurity] table's list of {n}, got {ks:?}"
                ),
                None => {
                    format!("the {key} targets must be knots 0, 1, ... without gaps, got {ks:?}")
                }
            }));
        }
    }
    Ok(Some(base))
}

/// Sets `table[key]` (element `index` of a list, which grows by one where `index` is its
/// length) to `value`.
fn set_value(table: &mut toml::Table, key: &str, index: Option<usize>, value: f64) {
    let v = toml::Value::Float(value);
    match index {
        None => {
            table.insert(key.to_string(), v);
        }
        Some(k) => {
            let entry = table
                .entry(key.to_string())
                .or_insert_with(|| toml::Value::Array(Vec::new()));
            if let toml::Value::Array(list) = entry {
                if k < list.len() {
                    list[k] = v;
                } else {
                    list.resize(k, toml::Value::Float(f64::NAN));
                    list.push(v);
                }
            }
        }
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    fn space(dims: &[&str], impurity: &str) -> ParameterSpace {
        let mut text = String::from("name = \"t\"\n");
        for (k, t) in dims.iter().enumerate() {
            text.push_str(&format!(
                "[[dimensions]]\nname = \"d{k}\"\nunit = \"1\"\nrange = [0.1, 0.5]\ntarget = \"{t}\"\n"
            ));
        }
        text.push_str(impurity);
        ParameterSpace::from_toml_str(&text, Path::new("space.toml")).unwrap()
    }

    fn base(dims: &[&str], impurity: &str) -> Result<Option<toml::Table>> {
        let s = space(dims, impurity);
        impurity_base(&s, &s.targets())
    }

    #[test]
    fn the_targets_fill_the_spaces_impurity_table() {
        assert_eq!(base(&["bias", "parameter:a"], "").unwrap(), None);
        // The paper's spaces: y targets without a table mean the rz model.
        let t = base(&["y_bot[0]", "y_top[0]", "bias"], "")
            .unwrap()
            .unwrap();
        assert_eq!(t["model"].as_str(), Some("rz"));
        let t = base(
            &["impurity:z0_cm3", "bias"],
            "[impurity]\nmodel = \"polynomial-z\"\ngradient_cm3_per_mm = 0.0\n",
        )
        .unwrap()
        .unwrap();
        let mut t = t;
        set_value(&mut t, "z0_cm3", None, -1e10);
        set_value(&mut t, "y", Some(1), 2.0);
        set_value(&mut t, "y", Some(0), 1.0);
        assert_eq!(t["z0_cm3"].as_float(), Some(-1e10));
        assert_eq!(
            t["y"].as_array().unwrap(),
            &vec![toml::Value::Float(1.0), toml::Value::Float(2.0)]
        );
        // Elements of a list the table gives may be any of its elements.
        assert!(
            base(
                &["impurity:values_cm3[2]", "bias"],
                "[impurity]\nmodel = \"z-table\"\nz_mm = [0.0, 1.0, 2.0]\nvalues_cm3 = [1.0, 2.0, 3.0]\n"
            )
            .is_ok()
        );
    }

    #[test]
    fn targets_that_cannot_fill_the_table_are_refused() {
        let msg = |r: Result<Option<toml::Table>>| r.unwrap_err().to_string();
        let m = msg(base(&["impurity:z0_cm3", "bias"], ""));
        assert!(m.contains("needs the space's `[impurity]` table"), "{m}");
        let m = msg(base(&["y_bot[0]", "y_bot[2]", "bias"], ""));
        assert!(m.contains("without gaps"), "{m}");
        let m = msg(base(
            &["impurity:values_cm3[3]", "bias"],
            "[impurity]\nmodel = \"z-table\"\nz_mm = [0.0, 1.0]\nvalues_cm3 = [1.0, 2.0]\n",
        ));
        assert!(m.contains("list of 2"), "{m}");
        let m = msg(base(
            &["impurity:y_bot", "impurity:y_bot[0]", "bias"],
            "[impurity]\nmodel = \"rz\"\n",
        ));
        assert!(m.contains("both as a single value"), "{m}");
    }
}
