//! The right panel: the detector's r-z cross-section with each window's probed region.

use hpge_inference::Discovery;
use hpge_solver::Detector;
use hpge_solver::geometry::BoundingBox;
use plotters::coord::Shift;
use plotters::prelude::*;

use super::key::draw_key;
use super::layout::*;
use crate::error::Result;
use crate::plot::cross_section::draw_regions;
use crate::plot::style::err;

/// The r-z box shown: the semiconductor and the contacts, padded by 6% of the larger side, r
/// from 0, within the world.
fn view_box(det: &Detector) -> BoundingBox {
    let b = det
        .contacts
        .iter()
        .fold(det.semiconductor.geometry.bbox(), |b, c| {
            b.union(&c.geometry.bbox())
        });
    let w = &det.world;
    let pad = 0.06 * (b.r_max_mm - b.r_min_mm).max(b.z_max_mm - b.z_min_mm);
    BoundingBox::new(
        0.0,
        (b.r_max_mm + pad).min(w.r_max_mm),
        (b.z_min_mm - pad).max(w.z_min_mm),
        (b.z_max_mm + pad).min(w.z_max_mm),
    )
}

/// The cross-section with the probed regions, and its key.
pub(super) fn region_panel<DB: DrawingBackend>(
    root: &DrawingArea<DB, Shift>,
    area: &DrawingArea<DB, Shift>,
    d: &Discovery,
    det: &Detector,
) -> Result<()> {
    let s = &d.summary;
    let body = caption(
        area,
        &format!("regions the windows probe: {}, r-z", det.name),
    )?;
    let (w_px, h_px) = body.dim_in_pixel();
    let v = view_box(det);
    let (dr, dz) = (v.r_max_mm - v.r_min_mm, v.z_max_mm - v.z_min_mm);
    let avail_w = w_px
        .saturating_sub(KEY_MIN_W + Y_LABEL_W + 2 * MARGIN)
        .max(50);
    let avail_h = h_px.saturating_sub(X_LABEL_H + 2 * MARGIN).max(50);
    let scale = (f64::from(avail_w) / dr).min(f64::from(avail_h) / dz);
    let plot_w = (scale * dr).round().max(20.0) as u32;
    let plot_h = (scale * dz).round().max(20.0) as u32;
    let (chart_area, key_area) = body.split_horizontally(plot_w + Y_LABEL_W + 2 * MARGIN);
    let (chart_area, _) = chart_area.split_vertically(plot_h + X_LABEL_H + 2 * MARGIN);
    let mut chart = ChartBuilder::on(&chart_area)
        .margin(MARGIN)
        .x_label_area_size(X_LABEL_H)
        .y_label_area_size(Y_LABEL_W)
        .build_cartesian_2d(v.r_min_mm..v.r_max_mm, v.z_min_mm..v.z_max_mm)
        .map_err(err)?;
    chart
        .configure_mesh()
        .disable_mesh()
        .x_desc("r (mm)")
        .y_desc("z (mm)")
        .x_labels(6)
        .x_label_formatter(&tick)
        .y_label_formatter(&tick)
        .label_style(("sans-serif", 16))
        .axis_desc_style(("sans-serif", 18))
        .draw()
        .map_err(err)?;
    // One cell per pixel: the interior is one colour, so rows merge into few runs.
    let cells = (plot_w as usize, plot_h as usize);
    draw_regions(
        &mut chart,
        det,
        [v.r_min_mm, v.r_max_mm],
        [v.z_min_mm, v.z_max_mm],
        cells,
        |_, _| CRYSTAL,
    )?;

    let mut wanted = Vec::new();
    let mut texts = Vec::new();
    let font = TextStyle::from(("sans-serif", KEY_FONT).into_font());
    for (i, w) in s.disagreement.iter().enumerate() {
        let Some(g) = &w.region else { continue };
        let c = window_color(i);
        chart
            .draw_series([Rectangle::new(
                [(g.r_mm[0], g.z_mm[0]), (g.r_mm[1], g.z_mm[1])],
                c.mix(0.35).filled(),
            )])
            .map_err(err)?;
        chart
            .draw_series([frame(
                (g.r_mm[0], g.z_mm[0]),
                (g.r_mm[1], g.z_mm[1]),
                c.stroke_width(2),
            )])
            .map_err(err)?;
        let text = window_label(i, w.voltages_v);
        let (tw, th) = body.estimate_text_size(&text, &font).map_err(err)?;
        let (x, y) = chart.backend_coord(&(g.r_mm[0], g.z_mm[1]));
        wanted.push([x + 3, y + 3, tw as i32 + 6, th as i32 + 4]);
        texts.push((i, text));
    }
    let (px, _) = chart.plotting_area().get_pixel_range();
    let step = wanted.first().map_or(0, |b| b[3] + 2);
    for (b, (i, text)) in place_labels(&wanted, [px.start, px.end], step)
        .into_iter()
        .zip(&texts)
    {
        boxed_label(root, b, text, window_color(*i))?;
    }
    draw_key(&key_area, d, det, &v)
}
