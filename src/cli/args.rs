//! Value parsers for command-line arguments, and loading a detector from them.

use anyhow::{Context, Result};
use hpge_solver::{Detector, Parameters};

use super::DetectorInput;

/// Parses "R,Z" (mm) as given to `--at`.
pub fn parse_point(text: &str) -> Result<(f64, f64), String> {
    let (r, z) = text
        .split_once(',')
        .ok_or_else(|| format!("expected R,Z in mm (e.g. 20,35), got `{text}`"))?;
    let num = |s: &str, what: &str| -> Result<f64, String> {
        let v: f64 = s
            .trim()
            .parse()
            .map_err(|_| format!("{what} `{}` in `{text}` is not a number", s.trim()))?;
        if v.is_finite() {
            Ok(v)
        } else {
            Err(format!("{what} in `{text}` must be finite"))
        }
    };
    let r = num(r, "R")?;
    let z = num(z, "Z")?;
    if r < 0.0 {
        return Err(format!(
            "R must be >= 0 mm (r is the distance from the axis), got {r}"
        ));
    }
    Ok((r, z))
}

/// Parses "R,PHI,Z" (mm, degrees, mm) as given to `pulse --at`; returns (r mm, phi deg, z mm).
pub fn parse_cylindrical(text: &str) -> Result<(f64, f64, f64), String> {
    let parts: Vec<&str> = text.split(',').collect();
    if parts.len() != 3 {
        return Err(format!(
            "expected R,PHI,Z (mm, degrees, mm; e.g. 37,30,35), got `{text}`"
        ));
    }
    let mut v = [0.0f64; 3];
    for (k, (s, what)) in parts.iter().zip(["R", "PHI", "Z"]).enumerate() {
        v[k] = s
            .trim()
            .parse()
            .map_err(|_| format!("{what} `{}` in `{text}` is not a number", s.trim()))?;
        if !v[k].is_finite() {
            return Err(format!("{what} in `{text}` must be finite"));
        }
    }
    if v[0] < 0.0 {
        return Err(format!(
            "R must be >= 0 mm (r is the distance from the axis), got {}",
            v[0]
        ));
    }
    Ok((v[0], v[1], v[2]))
}

/// A parsed `--r-range LO:HI:N`: N radii (mm) evenly from LO to HI inclusive.
#[derive(Debug, Clone, PartialEq)]
pub struct RadiusRange(pub Vec<f64>);

/// Parses "LO:HI:N" (mm, N >= 2 points, LO < HI, LO >= 0).
pub fn parse_r_range(text: &str) -> Result<RadiusRange, String> {
    let parts: Vec<&str> = text.split(':').collect();
    if parts.len() != 3 {
        return Err(format!("expected LO:HI:N (mm, mm, count), got `{text}`"));
    }
    let num = |s: &str| -> Result<f64, String> {
        s.trim()
            .parse::<f64>()
            .ok()
            .filter(|v| v.is_finite())
            .ok_or_else(|| format!("`{}` in `{text}` is not a finite number", s.trim()))
    };
    let (lo, hi) = (num(parts[0])?, num(parts[1])?);
    let n: usize = parts[2]
        .trim()
        .parse()
        .map_err(|_| format!("N `{}` in `{text}` is not a whole number", parts[2].trim()))?;
    if lo < 0.0 || hi <= lo {
        return Err(format!("need 0 <= LO < HI in `{text}`"));
    }
    if !(2..=100_000).contains(&n) {
        return Err(format!("N in `{text}` must be between 2 and 100000"));
    }
    Ok(RadiusRange(
        (0..n)
            .map(|k| lo + (hi - lo) * k as f64 / (n - 1) as f64)
            .collect(),
    ))
}

/// Bias-voltage lists (`--voltages`): declared once, in the solver library.
pub use hpge_solver::options::{VoltageList, parse_voltages};

/// Grid and accuracy options: declared once, in the solver library.
pub use hpge_solver::GridOverrides as GridArgs;

/// The `--param NAME=VALUE` overrides as parameters; a name given twice is refused (the last
/// would otherwise silently win).
pub fn param_overrides(params: &[(String, f64)]) -> Result<Parameters> {
    let mut overrides = Parameters::new();
    for (k, v) in params {
        if overrides.get(k).is_some() {
            anyhow::bail!("--param {k}: given twice; give each parameter once");
        }
        overrides.set(k.clone(), *v);
    }
    Ok(overrides)
}

/// Loads the detector, applies parameter overrides and the impurity file.
pub fn load_detector(input: &DetectorInput) -> Result<Detector> {
    let overrides = param_overrides(&input.params)?;
    let mut det = Detector::from_file(&input.detector, &overrides)?;
    if let Some(path) = &input.impurity {
        det.set_impurity_file(path)
            .with_context(|| format!("impurity model for {}", input.detector.display()))?;
    }
    Ok(det)
}

/// Adds what every single-detector JSON record carries (the detector and impurity files, the
/// parameters and the program version) to the object `v`. serde_json's maps are sorted, so the
/// record prints the same wherever the keys were inserted.
pub fn with_detector_provenance(mut v: serde_json::Value, det: &Detector) -> serde_json::Value {
    // The jobs' records carry the same fields (`hpge_solver::jobs::DetectorProvenance`).
    if let (Some(o), Ok(serde_json::Value::Object(p))) = (
        v.as_object_mut(),
        serde_json::to_value(hpge_solver::jobs::DetectorProvenance::of(det)),
    ) {
        o.extend(p);
    }
    v
}

/// The command line's spelling of a solver job's option (`hpge_solver::jobs`; its library name
/// is the Python argument's): `voltage` -> `--voltage`, `phi_deg` -> `--phi`, `z_mm` -> `--z`,
/// `r_mm` -> `--r-range`, `zetas_cm3` -> `--zeta-range`, `method/backend` ->
/// `--method/--backend`; otherwise `--` and the name with `-` for `_`.
pub fn flag(option: &str) -> String {
    match option {
        "phi_deg" => "--phi".into(),
        "z_mm" => "--z".into(),
        "r_mm" => "--r-range".into(),
        "zetas_cm3" => "--zeta-range".into(),
        "method/backend" => "--method/--backend".into(),
        o => format!("--{}", o.replace('_', "-")),
    }
}

/// The input files of a [`DetectorInput`] as (flag, path).
pub fn detector_inputs(input: &DetectorInput) -> Vec<(&'static str, &std::path::Path)> {
    let mut v = vec![("--detector", input.detector.as_path())];
    if let Some(i) = &input.impurity {
        v.push(("--impurity", i.as_path()));
    }
    v
}

/// Refuses, before any work, an output that would write over one of the command's inputs or
/// into an input folder (the same path once `.`, `..` and links are resolved, or the same file
/// through a hard link: [`hpge_files::overlaps`]), and two outputs on the same file. `outputs`
/// and `inputs` are (flag, path); the one check of every command that writes files (issue 66).
pub fn check_outputs<O: AsRef<std::path::Path>>(
    outputs: &[(&str, O)],
    inputs: &[(&str, &std::path::Path)],
) -> Result<()> {
    for (k, (flag, out)) in outputs.iter().enumerate() {
        let out = out.as_ref();
        if let Some((input_flag, input)) = hpge_files::first_overlap(out, inputs) {
            anyhow::bail!(
                "{flag} {}: {} the input {input_flag} {}; writing there would destroy the input: \
                 choose another output path",
                out.display(),
                if input.is_dir() { "lies inside" } else { "is" },
                input.display()
            );
        }
        if let Some((other, _)) = outputs[..k]
            .iter()
            .find(|(_, o)| hpge_files::overlaps(out, o.as_ref()) && !o.as_ref().is_dir())
        {
            anyhow::bail!(
                "{flag} {}: {other} names the same file; give each output its own path",
                out.display()
            );
        }
    }
    Ok(())
}

/// The outputs of a command with a CSV `--out` (and its sidecar) and a `--plot` figure, named
/// by flag, for [`check_outputs`].
pub fn csv_and_plot_outputs(
    out: Option<&std::path::Path>,
    plot: Option<&std::path::Path>,
) -> Vec<(&'static str, std::path::PathBuf)> {
    let mut outputs = Vec::new();
    if let Some(p) = out {
        outputs.push(("--out", p.to_path_buf()));
        outputs.push(("--out's sidecar", hpge_foundation::sidecar::path(p)));
    }
    if let Some(p) = plot {
        outputs.push(("--plot", p.to_path_buf()));
    }
    outputs
}

/// Puts a command's staged outputs under their names ([`hpge_files::Staged::commit`]), naming
/// the file that could not be renamed.
pub fn commit(outputs: hpge_files::Staged) -> Result<()> {
    outputs
        .commit()
        .map_err(|(file, e)| anyhow::anyhow!("{}: cannot write the file: {e}", file.display()))
}

pub use hpge_files::parent_or_here;

/// `x` as `{}` writes it, or in exponent form where that would be long (`1e300`, not 301
/// digits; issue 66).
pub fn short(x: f64) -> String {
    if x != 0.0 && x.is_finite() && !(1e-4..1e15).contains(&x.abs()) {
        format!("{x:e}")
    } else {
        format!("{x}")
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn points() {
        assert_eq!(parse_point("20,35").unwrap(), (20.0, 35.0));
        assert_eq!(parse_point(" 37.5 , -5 ").unwrap(), (37.5, -5.0));
        assert!(parse_point("20").unwrap_err().contains("expected R,Z"));
        assert!(parse_point("a,1").unwrap_err().contains("not a number"));
        assert!(parse_point("-1,1").unwrap_err().contains("R must be >= 0"));
        assert!(parse_point("1,nan").unwrap_err().contains("finite"));
    }

    #[test]
    fn cylindrical_points_and_radius_ranges() {
        assert_eq!(parse_cylindrical("37,30,35").unwrap(), (37.0, 30.0, 35.0));
        assert!(parse_cylindrical("37,30").unwrap_err().contains("R,PHI,Z"));
        assert!(parse_cylindrical("37,x,35").unwrap_err().contains("PHI"));
        assert!(
            parse_cylindrical("-1,0,35")
                .unwrap_err()
                .contains("R must be")
        );
        let r = parse_r_range("0:10:11").unwrap().0;
        assert_eq!(r.len(), 11);
        assert!((r[3] - 3.0).abs() < 1e-12);
        assert!(parse_r_range("5:1:10").is_err());
        assert!(parse_r_range("0:1:1").is_err());
        assert!(parse_r_range("0:1").is_err());
    }
}
