//! The fitted net impurity density zeta (cm^-3) at the global mode, along lines through the
//! crystal: zeta(z) at five radii and zeta(r) at three heights (the paper's Figs. 20 and 25).

use hpge_surrogate::ExactSolver;

use crate::Result;
use crate::prior::Prior;

/// zeta (cm^-3) along one line through the detector at the global mode.
#[derive(Debug, Clone, PartialEq)]
pub struct ZetaProfile {
    /// Legend entry, e.g. "r = 20 mm".
    pub label: String,
    /// Position along the line (z or r), mm.
    pub x_mm: Vec<f64>,
    /// Net impurity density at those positions, cm^-3.
    pub zeta_cm3: Vec<f64>,
}

/// zeta(z) at several radii and zeta(r) at several heights.
#[derive(Debug, Clone, PartialEq, Default)]
pub struct ZetaAtMode {
    /// Profiles along z (one per radius); `zeta-z` is skipped when empty.
    pub along_z: Vec<ZetaProfile>,
    /// Profiles along r (one per height); `zeta-r` is skipped when empty.
    pub along_r: Vec<ZetaProfile>,
}

/// Points per profile.
const POINTS: usize = 141;

/// The fitted zeta at the global mode `mode` (the prior's free parameters) along z at five radii
/// (2, 25, 50, 75, 98% of the radial span at mid-height) and along r at three heights (2, 50,
/// 98% of the height), inside the semiconductor only (a borehole or groove is left out).
///
/// # Errors
/// The detector cannot be built at the mode (a solver error).
pub fn zeta_at_mode(exact: &ExactSolver, prior: &Prior, mode: &[f64]) -> Result<ZetaAtMode> {
    let mut x = vec![0.0; prior.input_names.len()];
    prior.expand(mode, &mut x);
    let det = exact.detector(&x)?;
    let b = det.semiconductor.geometry.bbox();
    // Strictly inside (a negative tolerance), so the axis of a borehole does not count.
    let inside = |r: f64, z: f64| det.semiconductor.geometry.contains(r, z, -1e-6);
    let model = det.impurity();
    let lin = |a: f64, c: f64| -> Vec<f64> {
        (0..POINTS)
            .map(|i| a + (c - a) * i as f64 / (POINTS - 1) as f64)
            .collect()
    };
    // The radii the semiconductor spans at mid-height.
    let z_mid = 0.5 * (b.z_min_mm + b.z_max_mm);
    let rs_mid: Vec<f64> = lin(b.r_min_mm, b.r_max_mm)
        .into_iter()
        .filter(|&r| inside(r, z_mid))
        .collect();
    let (r_lo, r_hi) = (
        rs_mid.first().copied().unwrap_or(b.r_min_mm),
        rs_mid.last().copied().unwrap_or(b.r_max_mm),
    );
    let profile = |label: String, pts: Vec<(f64, f64, f64)>| ZetaProfile {
        label,
        x_mm: pts.iter().map(|p| p.0).collect(),
        zeta_cm3: pts.iter().map(|p| model.density_cm3(p.1, p.2)).collect(),
    };
    let along_z = [0.02, 0.25, 0.5, 0.75, 0.98]
        .iter()
        .map(|f| {
            let r = r_lo + f * (r_hi - r_lo);
            let pts = lin(b.z_min_mm, b.z_max_mm)
                .into_iter()
                .filter(|&z| inside(r, z))
                .map(|z| (z, r, z))
                .collect();
            profile(format!("r = {r:.1} mm"), pts)
        })
        .filter(|p| !p.x_mm.is_empty())
        .collect();
    let along_r = [0.02, 0.5, 0.98]
        .iter()
        .map(|f| {
            let z = b.z_min_mm + f * (b.z_max_mm - b.z_min_mm);
            let pts = lin(b.r_min_mm, b.r_max_mm)
                .into_iter()
                .filter(|&r| inside(r, z))
                .map(|r| (r, r, z))
                .collect();
            profile(format!("z = {z:.1} mm"), pts)
        })
        .filter(|p| !p.x_mm.is_empty())
        .collect();
    Ok(ZetaAtMode { along_z, along_r })
}
