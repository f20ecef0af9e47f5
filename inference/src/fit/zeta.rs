//! The fitted net impurity density zeta (cm^-3) along lines through the crystal: zeta(z) at five
//! radii and zeta(r) at three heights (the paper's Figs. 20 and 25), at the global mode, with
//! the posterior's 68.3% and 95.5% bands over thinned draws and the truth where one is known.

use hpge_solver::Detector;
use hpge_surrogate::ExactSolver;

use crate::Result;
use crate::prior::Prior;
use crate::rejection::unless_rejected;

/// zeta (cm^-3) along one line through the detector.
#[derive(Debug, Clone, PartialEq)]
pub struct ZetaProfile {
    /// Legend entry, e.g. "r = 20 mm".
    pub label: String,
    /// Position along the line (z or r), mm.
    pub x_mm: Vec<f64>,
    /// Net impurity density at the global mode at those positions, cm^-3.
    pub zeta_cm3: Vec<f64>,
    /// The posterior's central 68.3% band at each position, [lo, hi] in cm^-3 (the 15.85% and
    /// 84.15% quantiles over the draws); empty when not computed.
    pub band_683_cm3: Vec<[f64; 2]>,
    /// The central 95.5% band (2.25% and 97.75% quantiles); empty when not computed.
    pub band_955_cm3: Vec<[f64; 2]>,
    /// zeta of the known truth; empty when none was given.
    pub truth_cm3: Vec<f64>,
    /// Where along the line the impurity model has a knot (mm; the rz model's radii on a line
    /// along r), for a figure to mark the fitted values there; empty for none.
    pub knots_mm: Vec<f64>,
}

/// zeta(z) at several radii and zeta(r) at several heights.
#[derive(Debug, Clone, PartialEq, Default)]
pub struct ZetaAtMode {
    /// Profiles along z (one per radius); `zeta-z` is skipped when empty.
    pub along_z: Vec<ZetaProfile>,
    /// Profiles along r (one per height); `zeta-r` is skipped when empty.
    pub along_r: Vec<ZetaProfile>,
    /// Posterior draws the bands are made of (0: no bands).
    pub band_draws: usize,
}

/// How far beyond a line's end (mm) a knot is still marked, at the end.
const KNOT_REACH_MM: f64 = 1.0;

/// Points per profile.
const POINTS: usize = 141;

/// Posterior draws (evenly thinned) behind the bands of a fit's profiles.
pub const ZETA_BAND_DRAWS: usize = 400;

/// One line: its label and the (coordinate, r, z) of its points, mm.
type Line = (String, Vec<(f64, f64, f64)>);

/// The lines of [`zeta_profiles`] through `det`'s semiconductor: along z at 2, 25, 50, 75 and 98%
/// of the radial span at mid-height, along r at 2, 50 and 98% of the height, inside the active
/// semiconductor only (a borehole, a groove and a contact's volume such as the lithium layer
/// are left out).
fn lines(det: &Detector) -> (Vec<Line>, Vec<Line>) {
    let b = det.semiconductor.geometry.bbox();
    // Strictly inside (a negative tolerance), so the axis of a borehole does not count, and
    // not in a contact.
    let inside = |r: f64, z: f64| {
        det.semiconductor.geometry.contains(r, z, -1e-6)
            && det.classify(r, z) == hpge_solver::detector::Region::Semiconductor
    };
    let lin = |a: f64, c: f64| -> Vec<f64> {
        (0..POINTS)
            .map(|i| a + (c - a) * i as f64 / (POINTS - 1) as f64)
            .collect()
    };
    let z_mid = 0.5 * (b.z_min_mm + b.z_max_mm);
    let rs_mid: Vec<f64> = lin(b.r_min_mm, b.r_max_mm)
        .into_iter()
        .filter(|&r| inside(r, z_mid))
        .collect();
    let (r_lo, r_hi) = (
        rs_mid.first().copied().unwrap_or(b.r_min_mm),
        rs_mid.last().copied().unwrap_or(b.r_max_mm),
    );
    let along_z = [0.02, 0.25, 0.5, 0.75, 0.98]
        .iter()
        .map(|f| {
            let r = r_lo + f * (r_hi - r_lo);
            let pts = lin(b.z_min_mm, b.z_max_mm)
                .into_iter()
                .filter(|&z| inside(r, z))
                .map(|z| (z, r, z))
                .collect();
            (format!("r = {r:.1} mm"), pts)
        })
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
            (format!("z = {z:.1} mm"), pts)
        })
        .collect();
    (along_z, along_r)
}

/// The q-quantile of sorted values (linear interpolation).
fn quantile(sorted: &[f64], q: f64) -> f64 {
    let h = q * (sorted.len() - 1) as f64;
    let (i, f) = (h.floor() as usize, h.fract());
    if i + 1 < sorted.len() {
        sorted[i] * (1.0 - f) + sorted[i + 1] * f
    } else {
        sorted[i]
    }
}

/// The fitted zeta at the global mode `mode` (the prior's free parameters) along the lines of
/// the mode's detector (see `lines`); with `draws`, the 68.3% and 95.5% central bands over
/// their densities at the same points, and with `truth` (the prior's parameters), the truth's.
/// A draw whose detector cannot be built (outside the model's domain) is left out of the bands.
///
/// # Errors
/// The detector cannot be built at the mode or at the truth (a solver error).
pub fn zeta_profiles(
    exact: &ExactSolver,
    prior: &Prior,
    mode: &[f64],
    draws: &[&[f64]],
    truth: Option<&[f64]>,
) -> Result<ZetaAtMode> {
    let build = |theta: &[f64]| -> Result<Detector> {
        let mut x = vec![0.0; prior.input_names.len()];
        prior.expand(theta, &mut x);
        Ok(exact.detector(&x)?)
    };
    let det = build(mode)?;
    let (along_z, along_r) = lines(&det);
    let along = |det: &Detector, pts: &[(f64, f64, f64)]| -> Vec<f64> {
        let model = det.impurity();
        pts.iter().map(|p| model.density_cm3(p.1, p.2)).collect()
    };
    let mut dets = Vec::with_capacity(draws.len());
    for theta in draws {
        if let Some(d) = unless_rejected(build(theta))? {
            dets.push(d);
        }
    }
    let truth_det = truth.map(build).transpose()?;
    let knots_r = det.impurity().knots_r_mm();
    let profile = |(label, pts): Line, radial: bool| {
        let mut band_683 = Vec::new();
        let mut band_955 = Vec::new();
        if !dets.is_empty() {
            let per_draw: Vec<Vec<f64>> = dets.iter().map(|d| along(d, &pts)).collect();
            for k in 0..pts.len() {
                let mut v: Vec<f64> = per_draw.iter().map(|c| c[k]).collect();
                v.sort_by(f64::total_cmp);
                band_683.push([quantile(&v, 0.1585), quantile(&v, 0.8415)]);
                band_955.push([quantile(&v, 0.0225), quantile(&v, 0.9775)]);
            }
        }
        ZetaProfile {
            zeta_cm3: along(&det, &pts),
            truth_cm3: truth_det.as_ref().map_or_else(Vec::new, |t| along(t, &pts)),
            x_mm: pts.iter().map(|p| p.0).collect(),
            label,
            knots_mm: if radial {
                let (lo, hi) = (
                    pts.first().map_or(f64::NAN, |p| p.0),
                    pts.last().map_or(f64::NAN, |p| p.0),
                );
                // A knot on the crystal's surface (the rz model's r_4 at the mantle) is just
                // beyond the line, which stops short of the contact: it is marked at the end.
                knots_r
                    .iter()
                    .filter(|k| **k >= lo && **k <= hi + KNOT_REACH_MM)
                    .map(|k| k.min(hi))
                    .collect()
            } else {
                Vec::new()
            },
            band_683_cm3: band_683,
            band_955_cm3: band_955,
        }
    };
    let keep = |v: Vec<Line>, radial: bool| -> Vec<ZetaProfile> {
        v.into_iter()
            .filter(|l| !l.1.is_empty())
            .map(|l| profile(l, radial))
            .collect()
    };
    Ok(ZetaAtMode {
        along_z: keep(along_z, false),
        along_r: keep(along_r, true),
        band_draws: dets.len(),
    })
}
