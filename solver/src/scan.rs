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
