//! The paper's Fig. 11: the cross-section of the crystal with the volume still undepleted at
//! several biases, as differently shaded areas. Each point of the semiconductor is coloured by
//! the lowest listed bias at which it is depleted (so the band between two boundaries is the
//! volume the front sweeps between two biases), grey where it is still undepleted at the last.

use std::path::Path;

use hpge_solver::Detector;
use hpge_solver::field::{NodeKind, PotentialPoint};
use plotters::coord::Shift;
use plotters::prelude::*;

use super::colormap::viridis;
use super::cross_section::{draw_regions, rz_chart};
use super::style::err;
use crate::error::Result;

/// Grey of the volume undepleted at the last bias.
const UNDEPLETED: RGBColor = RGBColor(150, 150, 150);

/// Whether (r, z) (mm) is undepleted in `p`: whether a semiconductor node of the mesh cell
/// around it is (trapped-carrier pockets count as undepleted). Its nearest node alone would put
/// the cells along a contact's surface, whose nearest node is the contact's, among the depleted.
pub fn undepleted_at(p: &PotentialPoint, r_mm: f64, z_mm: f64) -> bool {
    let nodes = p.mesh.grid.cell_nodes(r_mm, z_mm);
    let semiconductor = || {
        nodes
            .iter()
            .filter(|&&k| p.mesh.kind[k] == NodeKind::Semiconductor)
    };
    if semiconductor().next().is_none() {
        // A cell with no semiconductor node: the nearest node decides.
        return p.potential.undepleted[p.mesh.grid.nearest(r_mm, z_mm)];
    }
    semiconductor().any(|&k| p.potential.undepleted[k])
}

/// The index of the first state (in the given order) in which (r, z) is depleted, or
/// `states.len()` when it is undepleted in all.
pub fn depleted_from(states: &[PotentialPoint], r_mm: f64, z_mm: f64) -> usize {
    states
        .iter()
        .position(|p| !undepleted_at(p, r_mm, z_mm))
        .unwrap_or(states.len())
}

/// The undepleted volume at each bias and where the front sweeps: integrals over the
/// semiconductor on a raster of cells (rings of volume 2 pi r dr dz).
#[derive(Debug, Clone, PartialEq)]
pub struct DepletionBands {
    /// The biases, V.
    pub bias_v: Vec<f64>,
    /// Undepleted volume at each bias, cm^3 (pockets included).
    pub undepleted_cm3: Vec<f64>,
    /// The semiconductor's volume, cm^3.
    pub crystal_cm3: f64,
    /// Volume-weighted mean radius (mm) of each band: the volume depleted first at bias k
    /// (band 0: at the first bias); NaN for an empty band.
    pub band_mean_r_mm: Vec<f64>,
}

/// [`DepletionBands`] of `det` for `states` on an `n` x `n` raster of the semiconductor's
/// bounding box.
pub fn depletion_bands(det: &Detector, states: &[PotentialPoint], n: usize) -> DepletionBands {
    let b = det.semiconductor.geometry.bbox();
    let (dr, dz) = (
        (b.r_max_mm - b.r_min_mm) / n as f64,
        (b.z_max_mm - b.z_min_mm) / n as f64,
    );
    let m = states.len();
    let mut undepleted = vec![0.0; m];
    let (mut band_v, mut band_rv) = (vec![0.0; m], vec![0.0; m]);
    let mut crystal = 0.0;
    for j in 0..n {
        let zc = b.z_min_mm + (j as f64 + 0.5) * dz;
        for i in 0..n {
            let rc = b.r_min_mm + (i as f64 + 0.5) * dr;
            if det.classify(rc, zc) != hpge_solver::detector::Region::Semiconductor {
                continue;
            }
            // mm^3 -> cm^3.
            let v = 2.0 * std::f64::consts::PI * rc * dr * dz * 1e-3;
            crystal += v;
            let k = depleted_from(states, rc, zc);
            for u in undepleted.iter_mut().take(k) {
                *u += v;
            }
            if k < m {
                band_v[k] += v;
                band_rv[k] += v * rc;
            }
        }
    }
    DepletionBands {
        bias_v: states.iter().map(|p| p.bias_v).collect(),
        undepleted_cm3: undepleted,
        crystal_cm3: crystal,
        band_mean_r_mm: band_v
            .iter()
            .zip(&band_rv)
            .map(|(v, rv)| if *v > 0.0 { rv / v } else { f64::NAN })
            .collect(),
    }
}

/// Colour of band `k` of `n` (the first state that depletes the point; `n`: never).
fn band_color(k: usize, n: usize) -> RGBColor {
    if k >= n {
        UNDEPLETED
    } else if n == 1 {
        viridis(0.2)
    } else {
        // From dark (depleted at the lowest bias) to light (the last).
        viridis(0.05 + 0.9 * k as f64 / (n - 1) as f64)
    }
}

/// Draws the depletion map of `det` for `states` (solved potentials in increasing bias) into
/// `path` (.svg or .png): the crystal and its contacts (colours as in the detector's
/// cross-section), each semiconductor point coloured by the bias band in which it depletes.
///
/// # Errors
/// No states, biases not increasing, or a figure that cannot be written.
pub fn depletion_map(det: &Detector, states: &[PotentialPoint], path: &Path) -> Result<()> {
    if states.is_empty() {
        return Err(crate::Error::invalid(
            "a depletion map needs at least one bias",
        ));
    }
    if states.windows(2).any(|w| w[1].bias_v <= w[0].bias_v) {
        return Err(crate::Error::invalid(
            "a depletion map needs its biases in increasing order",
        ));
    }
    let b = det.semiconductor.geometry.bbox();
    let pad = 0.04 * (b.r_max_mm - b.r_min_mm).max(b.z_max_mm - b.z_min_mm);
    let r = [0.0, b.r_max_mm + pad];
    let z = [b.z_min_mm - pad, b.z_max_mm + pad];
    let s = (620.0 / (r[1] - r[0])).min(760.0 / (z[1] - z[0]));
    let (pw, ph) = (((r[1] - r[0]) * s) as u32, ((z[1] - z[0]) * s) as u32);
    let size = (pw + 330, ph + 150);
    render!(path, size, |root, svg| {
        let cell = if svg { (ph / 300).max(1) } else { 1 };
        draw(&root, det, states, (r, z), (pw, ph), cell)
    })
}

fn draw<DB: DrawingBackend>(
    root: &DrawingArea<DB, Shift>,
    det: &Detector,
    states: &[PotentialPoint],
    (r, z): ([f64; 2], [f64; 2]),
    (pw, ph): (u32, u32),
    cell: u32,
) -> Result<()> {
    root.fill(&WHITE).map_err(err)?;
    let n = states.len();
    let last = states[n - 1].bias_v;
    let (main, side) = root.split_horizontally(pw + 100);
    let mut chart = rz_chart(
        &main,
        format!("{}: undepleted volume by bias", det.name),
        17,
        r,
        z,
    )?;
    let nx = (pw / cell).max(1) as usize;
    let nz = (ph / cell).max(1) as usize;
    // Each band coloured, its boundary (a cell whose right or upper neighbour depletes at
    // another bias) darkened, so that neighbouring bands stay apart. The bands of the raster's
    // cell centres, one column and row beyond for the neighbours, are found once.
    let (dr, dz) = ((r[1] - r[0]) / nx as f64, (z[1] - z[0]) / nz as f64);
    let band: Vec<usize> = (0..=nz)
        .flat_map(|j| (0..=nx).map(move |i| (i, j)))
        .map(|(i, j)| {
            let rc = r[0] + (i as f64 + 0.5) * dr;
            let zc = z[0] + (j as f64 + 0.5) * dz;
            depleted_from(states, rc, zc)
        })
        .collect();
    let at = |i: usize, j: usize| band[j * (nx + 1) + i];
    draw_regions(&mut chart, det, r, z, (nx, nz), |rr, zz| {
        let i = ((rr - r[0]) / dr - 0.5).round().clamp(0.0, nx as f64 - 1.0) as usize;
        let j = ((zz - z[0]) / dz - 0.5).round().clamp(0.0, nz as f64 - 1.0) as usize;
        let k = at(i, j);
        let c = band_color(k, n);
        if at(i + 1, j) != k || at(i, j + 1) != k {
            RGBColor(
                (f64::from(c.0) * 0.55) as u8,
                (f64::from(c.1) * 0.55) as u8,
                (f64::from(c.2) * 0.55) as u8,
            )
        } else {
            c
        }
    })?;
    // The legend: one swatch per band.
    let font = ("sans-serif", 15).into_font();
    let (x0, mut y) = (10, 60);
    side.draw(&Text::new("depleted at U_B <=", (x0, y - 30), font.clone()))
        .map_err(err)?;
    for (k, p) in states.iter().enumerate() {
        side.draw(&Rectangle::new(
            [(x0, y), (x0 + 26, y + 16)],
            band_color(k, n).filled(),
        ))
        .map_err(err)?;
        side.draw(&Text::new(
            format!("{:.0} V", p.bias_v),
            (x0 + 36, y),
            font.clone(),
        ))
        .map_err(err)?;
        y += 22;
    }
    side.draw(&Rectangle::new(
        [(x0, y + 6), (x0 + 26, y + 22)],
        UNDEPLETED.filled(),
    ))
    .map_err(err)?;
    side.draw(&Text::new(
        format!("undepleted at {last:.0} V"),
        (x0 + 36, y + 6),
        font.clone(),
    ))
    .map_err(err)?;
    side.draw(&Text::new(
        "contacts and passives as in",
        (x0, y + 44),
        font.clone(),
    ))
    .map_err(err)?;
    side.draw(&Text::new("the detector cross-section", (x0, y + 62), font))
        .map_err(err)?;
    Ok(())
}
