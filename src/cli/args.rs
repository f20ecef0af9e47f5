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

/// Parses a voltage list: "START:STOP:STEP" (inclusive of STOP when it falls on the step) or
/// "V1,V2,...". Values are checked (finite, positive) and sorted by the caller.
pub fn parse_voltages(text: &str) -> Result<VoltageList, String> {
    parse_voltage_values(text).map(VoltageList)
}

/// A parsed `--voltages` list (V).
#[derive(Debug, Clone, PartialEq)]
pub struct VoltageList(pub Vec<f64>);

fn parse_voltage_values(text: &str) -> Result<Vec<f64>, String> {
    let num = |s: &str| -> Result<f64, String> {
        let v: f64 = s
            .trim()
            .parse()
            .map_err(|_| format!("`{}` in `{text}` is not a number", s.trim()))?;
        if v.is_finite() {
            Ok(v)
        } else {
            Err(format!("`{}` in `{text}` must be finite", s.trim()))
        }
    };
    if text.contains(':') {
        let parts: Vec<&str> = text.split(':').collect();
        if parts.len() != 3 {
            return Err(format!("expected START:STOP:STEP, got `{text}`"));
        }
        let (a, b, s) = (num(parts[0])?, num(parts[1])?, num(parts[2])?);
        if s <= 0.0 {
            return Err(format!("the step in `{text}` must be positive"));
        }
        if b < a {
            return Err(format!("STOP must not be below START in `{text}`"));
        }
        let n = ((b - a) / s + 1e-9).floor() as usize;
        if n > 100_000 {
            return Err(format!("`{text}` gives more than 100000 voltages"));
        }
        Ok((0..=n).map(|k| a + s * k as f64).collect())
    } else {
        text.split(',').map(num).collect()
    }
}

/// Parses "NAME=VALUE" as given to `--param`.
pub fn parse_param(text: &str) -> Result<(String, f64), String> {
    Parameters::parse_assignment(text)
}

/// Loads the detector, applies parameter overrides and the impurity file.
pub fn load_detector(input: &DetectorInput) -> Result<Detector> {
    let mut overrides = Parameters::new();
    for (k, v) in &input.params {
        overrides.set(k.clone(), *v);
    }
    let mut det = Detector::from_file(&input.detector, &overrides)?;
    if let Some(path) = &input.impurity {
        det.set_impurity_file(path)
            .with_context(|| format!("impurity model for {}", input.detector.display()))?;
    }
    Ok(det)
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn voltages() {
        assert_eq!(
            parse_voltages("25:125:50").unwrap().0,
            vec![25.0, 75.0, 125.0]
        );
        assert_eq!(parse_voltages("25:2975:50").unwrap().0.len(), 60);
        assert_eq!(
            parse_voltages("25, 75,125").unwrap().0,
            vec![25.0, 75.0, 125.0]
        );
        assert!(parse_voltages("25:10:5").is_err());
        assert!(parse_voltages("25:100:0").is_err());
        assert!(parse_voltages("25:100").is_err());
        assert!(parse_voltages("25,x").is_err());
        assert!(parse_voltages("nan").is_err());
    }

    #[test]
    fn points() {
        assert_eq!(parse_point("20,35").unwrap(), (20.0, 35.0));
        assert_eq!(parse_point(" 37.5 , -5 ").unwrap(), (37.5, -5.0));
        assert!(parse_point("20").unwrap_err().contains("expected R,Z"));
        assert!(parse_point("a,1").unwrap_err().contains("not a number"));
        assert!(parse_point("-1,1").unwrap_err().contains("R must be >= 0"));
        assert!(parse_point("1,nan").unwrap_err().contains("finite"));
    }
}
