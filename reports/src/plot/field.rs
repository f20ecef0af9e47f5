//! The potential with depletion at one bias, with the undepleted region shaded.

use std::path::Path;

use hpge_solver::Detector;
use hpge_solver::field::PotentialPoint;
use plotters::coord::Shift;
use plotters::prelude::*;

use super::colormap::viridis;
use super::cross_section::{draw_outlines, rz_chart};
use super::style::err;
use crate::error::Result;

/// Colour of trapped-carrier pockets.
const POCKET: RGBColor = RGBColor(240, 120, 20);

/// Draws the potential (colour), the undepleted semiconductor joined to a contact (grey) and the
/// trapped-carrier pockets (orange) of `p`; `bridge_mm` marks (red cross) where an undepleted
/// region joins two contacts.
pub fn field_map(
    det: &Detector,
    p: &PotentialPoint,
    bridge_mm: Option<(f64, f64)>,
    path: &Path,
) -> Result<()> {
    let w = &det.world;
    let s = (700.0 / w.r_max_mm).min(900.0 / (w.z_max_mm - w.z_min_mm));
    let (pw, ph) = (
        (s * w.r_max_mm) as u32,
        (s * (w.z_max_mm - w.z_min_mm)) as u32,
    );
    let size = (pw + 260, (ph + 140).max(480));
    render!(path, size, |root, svg| {
        let cell = if svg { (ph / 250).max(1) } else { 1 };
        draw(&root, det, p, bridge_mm, (pw, ph), cell)
    })
}

fn draw<DB: DrawingBackend>(
    root: &DrawingArea<DB, Shift>,
    det: &Detector,
    p: &PotentialPoint,
    bridge_mm: Option<(f64, f64)>,
    (pw, ph): (u32, u32),
    cell: u32,
) -> Result<()> {
    root.fill(&WHITE).map_err(err)?;
    let (lo, hi) = p.potential.bounds_v;
    let span = (hi - lo).max(f64::MIN_POSITIVE);
    let w = &det.world;
    let (main, side) = root.split_horizontally(pw + 110);
    let (main, _) = main.split_vertically(ph + 140);
    let mut chart = rz_chart(
        &main,
        format!(
            "{}: U_B = {} V (grey: undepleted, orange: pocket)",
            det.name, p.bias_v
        ),
        18,
        [0.0, w.r_max_mm],
        [w.z_min_mm, w.z_max_mm],
    )?;
    let g = &p.mesh.grid;
    let nx = (pw / cell).max(1) as usize;
    let nz = (ph / cell).max(1) as usize;
    let dr = w.r_max_mm / nx as f64;
    let dz = (w.z_max_mm - w.z_min_mm) / nz as f64;
    let mut rects = Vec::with_capacity(nx * nz);
    for jz in 0..nz {
        let zc = w.z_min_mm + (jz as f64 + 0.5) * dz;
        for ix in 0..nx {
            let rc = (ix as f64 + 0.5) * dr;
            let v = g.interpolate_at(&p.potential.phi_v, rc, zc);
            let k = g.nearest(rc, zc);
            let undepleted = p.potential.undepleted[k];
            // A pocket: undepleted at a level between the contact potentials.
            let at = p.potential.phi_v[k];
            let pocket =
                undepleted && (at - lo).abs() > 1e-9 * span && (hi - at).abs() > 1e-9 * span;
            let color = if pocket {
                POCKET
            } else if undepleted {
                RGBColor(150, 150, 150)
            } else {
                viridis((v - lo) / span)
            };
            let x0 = ix as f64 * dr;
            let y0 = w.z_min_mm + jz as f64 * dz;
            rects.push(Rectangle::new(
                [(x0, y0), (x0 + dr, y0 + dz)],
                color.filled(),
            ));
        }
    }
    chart.draw_series(rects).map_err(err)?;
    // The crystal's and the contacts' outlines over the potential.
    let (ox, oz) = ((pw / 2).max(1) as usize, (ph / 2).max(1) as usize);
    draw_outlines(
        &mut chart,
        det,
        [0.0, w.r_max_mm],
        [w.z_min_mm, w.z_max_mm],
        (ox, oz),
    )?;
    if let Some(at) = bridge_mm {
        chart
            .draw_series([Cross::new(at, 9, RED.stroke_width(3))])
            .map_err(err)?
            .label("undepleted bridge between contacts")
            .legend(|(x, y)| Cross::new((x, y), 6, RED.stroke_width(3)));
        chart
            .configure_series_labels()
            .background_style(WHITE.mix(0.85))
            .border_style(BLACK)
            .draw()
            .map_err(err)?;
    }
    // Colour bar.
    let (x0, y0, bw, bh) = (20, 60, 26, 300);
    for k in 0..bh {
        let t = 1.0 - (k as f64 + 0.5) / bh as f64;
        side.draw(&Rectangle::new(
            [(x0, y0 + k), (x0 + bw, y0 + k + 1)],
            viridis(t).filled(),
        ))
        .map_err(err)?;
    }
    let font = ("sans-serif", 15).into_font();
    side.draw(&Text::new("potential (V)", (x0, y0 - 30), font.clone()))
        .map_err(err)?;
    for k in 0..=4 {
        let t = k as f64 / 4.0;
        let y = y0 + ((1.0 - t) * bh as f64) as i32;
        side.draw(&Text::new(
            format!("{:.0}", lo + t * span),
            (x0 + bw + 8, y - 8),
            font.clone(),
        ))
        .map_err(err)?;
    }
    side.draw(&Rectangle::new(
        [(x0, y0 + bh + 30), (x0 + bw, y0 + bh + 46)],
        RGBColor(150, 150, 150).filled(),
    ))
    .map_err(err)?;
    side.draw(&Text::new(
        "undepleted",
        (x0 + bw + 8, y0 + bh + 30),
        font.clone(),
    ))
    .map_err(err)?;
    side.draw(&Rectangle::new(
        [(x0, y0 + bh + 56), (x0 + bw, y0 + bh + 72)],
        POCKET.filled(),
    ))
    .map_err(err)?;
    side.draw(&Text::new("pocket", (x0 + bw + 8, y0 + bh + 56), font))
        .map_err(err)?;
    Ok(())
}
