//! The impurity-level sensitivity scan (paper section 5, Fig. 13): the capacitance c12 at one
//! bias U_B for a list of spatially constant net impurity densities zeta.
//!
//! For each zeta the detector's impurity model is replaced by the constant model
//! zeta(r, z) = zeta and c12(U_B; zeta) = -C*_12 is solved ([`solve_point`]). Where the crystal
//! is fully depleted at U_B, c12 is its depleted limit and hardly depends on zeta; above the
//! density at which U_B no longer depletes the crystal, c12 rises with zeta. The paper reads the
//! range of densities a C-V curve is sensitive to (zeta_l .. zeta_u, 1e8 .. 1e11 cm^-3 for its
//! detector at 25 V) off this scan.

use std::path::Path;

use crate::detector::Detector;
use crate::error::{Error, Result};
use crate::field::{FieldSettings, solve_point};
use crate::impurity::ImpuritySpec;

/// The bias of the paper's scan (section 5, Fig. 13), V.
pub const SCAN_VOLTAGE_V: f64 = 25.0;
/// The densities of the scan when none are given, as `--zeta-range` writes them: 18 values from
/// 1e7 to 2e11 cm^-3, evenly in log (around the paper's sensitive range 1e8 .. 1e11 cm^-3).
pub const DEFAULT_ZETA_RANGE: &str = "1e7:2e11:18";

/// The densities of a scan (cm^-3), as parsed from `MIN:MAX:N` ([`parse_zeta_range`]).
#[derive(Debug, Clone, PartialEq)]
pub struct ZetaRange(pub Vec<f64>);

/// Parses `MIN:MAX:N`: N densities (cm^-3, 2 <= N <= 1000) spaced evenly in log between MIN and
/// MAX (0 < MIN < MAX).
///
/// # Errors
/// [`Error::Syntax`] saying what was expected (the command line shows it beside the option).
pub fn parse_zeta_range(s: &str) -> Result<ZetaRange> {
    let bad = |message: String| Error::Syntax {
        text: s.into(),
        message,
    };
    let parts: Vec<&str> = s.split(':').map(str::trim).collect();
    let [a, b, n] = parts.as_slice() else {
        return Err(bad(format!("`{s}`: expected MIN:MAX:N, e.g. 1e7:2e11:17")));
    };
    let num = |t: &str| {
        t.parse::<f64>()
            .map_err(|e| bad(format!("`{t}` in `{s}`: {e}")))
    };
    let (lo, hi) = (num(a)?, num(b)?);
    let n: usize = n.parse().map_err(|e| {
        bad(format!(
            "`{n}` in `{s}`: the count must be a whole number ({e})"
        ))
    })?;
    if !(lo.is_finite() && hi.is_finite() && lo > 0.0 && hi > lo) {
        return Err(bad(format!(
            "`{s}`: need 0 < MIN < MAX (densities in cm^-3)"
        )));
    }
    if !(2..=1000).contains(&n) {
        return Err(bad(format!(
            "`{s}`: the count N must lie in 2..=1000, got {n}"
        )));
    }
    log_spaced(lo, hi, n)
        .map(ZetaRange)
        .map_err(|e| bad(format!("`{s}`: {e}")))
}

/// The scan's own options (the detector and the solver's are
/// [`crate::options::DetectorInput`] and [`crate::options::SolverOptions`]). The command line
/// flattens this struct (feature `clap`), so every option and default is declared here once.
#[derive(Debug, Clone, PartialEq)]
#[cfg_attr(feature = "clap", derive(clap::Args))]
pub struct ScanOptions {
    /// Bias voltage in V.
    #[cfg_attr(
        feature = "clap",
        arg(
            long,
            value_name = "U",
            default_value_t = SCAN_VOLTAGE_V,
            allow_hyphen_values = true
        )
    )]
    pub voltage: f64,
    /// Densities MIN:MAX:N in cm^-3, N values spaced evenly in log.
    #[cfg_attr(
        feature = "clap",
        arg(
            long = "zeta-range",
            value_name = "MIN:MAX:N",
            default_value = DEFAULT_ZETA_RANGE,
            value_parser = parse_zeta_range
        )
    )]
    pub zeta_range: ZetaRange,
}

/// Name of the constant impurity model in messages.
const SCAN_MODEL_NAME: &str = "(sensitivity scan: constant model)";

/// One point of the scan.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct ScanPoint {
    /// Constant net impurity density, cm^-3 (positive: n-type).
    pub zeta_cm3: f64,
    /// c12 at the bias, pF.
    pub c12_pf: f64,
    /// No undepleted semiconductor at the bias.
    pub fully_depleted: bool,
}

/// c12 (pF) at the bias `voltage_v` (V) for each constant density of `zetas_cm3` (cm^-3, in
/// order), the rest of `det` (geometry, contacts, parameters) unchanged: the paper's section 5
/// scan, c12(U_B; zeta) with zeta(r, z) = zeta.
///
/// `progress(k)` is called after the k-th density (k = 1, 2, ...).
///
/// Errors: a density the constant model refuses, and a failed solve as
/// [`Error::ScanPointFailed`] naming the density and the bias (the solver's error as its source).
pub fn sensitivity_scan(
    det: &Detector,
    voltage_v: f64,
    zetas_cm3: &[f64],
    settings: &FieldSettings,
    progress: &dyn Fn(usize),
) -> Result<Vec<ScanPoint>> {
    let mut det = det.clone();
    let name = Path::new(SCAN_MODEL_NAME);
    let mut points = Vec::with_capacity(zetas_cm3.len());
    for (k, &zeta) in zetas_cm3.iter().enumerate() {
        let spec = ImpuritySpec::from_toml_str(
            &format!("model = \"constant\"\nzeta_cm3 = {zeta:e}\n"),
            name,
        )?;
        det.set_impurity(&spec, name)?;
        let p =
            solve_point(&det, voltage_v, settings, None).map_err(|e| Error::ScanPointFailed {
                zeta_cm3: zeta,
                voltage_v,
                source: Box::new(e),
            })?;
        points.push(ScanPoint {
            zeta_cm3: zeta,
            c12_pf: p.c12_pf,
            fully_depleted: p.fully_depleted(),
        });
        progress(k + 1);
    }
    Ok(points)
}

/// `n` values from `lo` to `hi` (ends included) evenly spaced in log:
/// x_k = exp(ln lo + (ln hi - ln lo) k / (n - 1)), k = 0 .. n-1.
///
/// Errors ([`Error::Argument`] naming the value): `lo` or `hi` not finite, 0 < lo < hi violated,
/// or fewer than 2 points.
pub fn log_spaced(lo: f64, hi: f64, n: usize) -> Result<Vec<f64>> {
    if !(lo.is_finite() && lo > 0.0) {
        return Err(Error::Argument {
            name: "lo".into(),
            message: format!("{lo}: the lower end must be a positive finite number"),
        });
    }
    if !(hi.is_finite() && hi > lo) {
        return Err(Error::Argument {
            name: "hi".into(),
            message: format!("{hi}: the upper end must be finite and above lo = {lo}"),
        });
    }
    if n < 2 {
        return Err(Error::Argument {
            name: "n".into(),
            message: format!("{n}: at least 2 points are needed"),
        });
    }
    let (la, lb) = (lo.ln(), hi.ln());
    Ok((0..n)
        .map(|k| (la + (lb - la) * k as f64 / (n - 1) as f64).exp())
        .collect())
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn zeta_ranges() {
        assert_eq!(parse_zeta_range(DEFAULT_ZETA_RANGE).unwrap().0.len(), 18);
        let r = parse_zeta_range("1e7:1e11:5").unwrap().0;
        assert_eq!(r.len(), 5);
        for (a, b) in r.iter().zip([1e7, 1e8, 1e9, 1e10, 1e11]) {
            assert!((a / b - 1.0).abs() < 1e-12);
        }
        let message = |text: &str| parse_zeta_range(text).unwrap_err().to_string();
        assert!(parse_zeta_range("1e7:1e11").is_err());
        assert!(message("0:1e11:5").contains("0 < MIN < MAX"));
        assert!(message("1e7:1e11:1").contains("2..=1000"));
        assert!(parse_zeta_range("1e7:x:5").is_err());
    }

    #[test]
    fn log_spaced_decades() {
        let r = log_spaced(1e7, 1e11, 5).unwrap();
        assert_eq!(r.len(), 5);
        for (a, b) in r.iter().zip([1e7, 1e8, 1e9, 1e10, 1e11]) {
            assert!((a / b - 1.0).abs() < 1e-12);
        }
    }

    /// The planar wafer (detectors/planar-pn.toml, T = 10 mm, R = 20 mm): fully depleted at
    /// 200 V for 1e9 cm^-3 (U_fd = 56.6 V, c12 = eps A / T = 17.802 pF); for 1e11 cm^-3
    /// (U_fd = 5655 V) the depleted layer is w = T sqrt(U / U_fd) and c12 = eps A / w.
    #[test]
    fn scan_of_the_planar_wafer_matches_the_closed_form() {
        let path = Path::new(env!("CARGO_MANIFEST_DIR")).join("../detectors/planar-pn.toml");
        let det = Detector::from_file(&path, &crate::Parameters::new()).unwrap();
        let calls = std::cell::Cell::new(0);
        let points = sensitivity_scan(&det, 200.0, &[1e9, 1e11], &FieldSettings::default(), &|k| {
            calls.set(k)
        })
        .unwrap();
        assert_eq!(calls.get(), 2);
        let plate_pf: f64 = 17.802;
        let u_fd_v: f64 = 5655.0;
        let expected = [plate_pf, plate_pf / (200.0 / u_fd_v).sqrt()];
        for (p, (zeta, c)) in points.iter().zip([1e9, 1e11].into_iter().zip(expected)) {
            assert_eq!(p.zeta_cm3, zeta);
            assert!((p.c12_pf / c - 1.0).abs() < 0.01, "{p:?} vs {c} pF");
        }
        assert!(points[0].fully_depleted && !points[1].fully_depleted);
        // The caller's detector keeps its own impurity model.
        assert_eq!(det.impurity().evaluate(10.0, 5.0).zeta_cm3, 1e10);
    }

    #[test]
    fn log_spaced_refuses_bad_ranges() {
        let name = |r: Result<Vec<f64>>| match r {
            Err(Error::Argument { name, .. }) => name,
            other => panic!("{other:?}"),
        };
        assert_eq!(name(log_spaced(0.0, 1e11, 5)), "lo");
        assert_eq!(name(log_spaced(f64::NAN, 1e11, 5)), "lo");
        assert_eq!(name(log_spaced(1e9, 1e8, 5)), "hi");
        assert_eq!(name(log_spaced(1e9, f64::INFINITY, 5)), "hi");
        assert_eq!(name(log_spaced(1e7, 1e11, 1)), "n");
    }
}
