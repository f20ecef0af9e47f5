//! The key beside the panels.

use hpge_inference::Discovery;
use hpge_solver::Detector;
use hpge_solver::geometry::BoundingBox;
use plotters::coord::Shift;
use plotters::prelude::*;

use super::layout::*;
use crate::error::Result;
use crate::plot::cross_section::{contact_color, passive_color};
use crate::plot::style::err;

/// The key beside the cross-section: materials and contacts, then the windows.
pub(super) fn draw_key<DB: DrawingBackend>(
    area: &DrawingArea<DB, Shift>,
    d: &Discovery,
    det: &Detector,
    view: &BoundingBox,
) -> Result<()> {
    let font = TextStyle::from(("sans-serif", KEY_FONT).into_font());
    let (w_px, h_px) = area.dim_in_pixel();
    let (x0, mut y) = (10, MARGIN as i32 + 4);
    let text_w = w_px.saturating_sub(x0 as u32 + 36 + 8);
    let row = 22;
    let mut entries: Vec<(RGBColor, String)> = vec![(
        CRYSTAL,
        format!(
            "{} ({})",
            det.semiconductor.name, det.semiconductor.material.name
        ),
    )];
    entries.extend(
        det.contacts
            .iter()
            .enumerate()
            .map(|(k, c)| (contact_color(k), format!("{} ({})", c.name, c.potential))),
    );
    let in_view = |b: BoundingBox| !view.intersection(&b).is_empty();
    entries.extend(
        det.passives
            .iter()
            .filter(|p| in_view(p.geometry.bbox()))
            .map(|p| (passive_color(p.kind), p.name.clone())),
    );
    for (color, text) in entries {
        area.draw(&Rectangle::new(
            [(x0, y), (x0 + 26, y + 16)],
            color.filled(),
        ))
        .map_err(err)?;
        area.draw(&Rectangle::new(
            [(x0, y), (x0 + 26, y + 16)],
            BLACK.stroke_width(1),
        ))
        .map_err(err)?;
        let t = fit_text(area, &text, &font, text_w);
        area.draw(&Text::new(t, (x0 + 36, y), font.clone()))
            .map_err(err)?;
        y += row;
    }
    y += 14;
    let s = &d.summary;
    if s.disagreement.is_empty() {
        area.draw(&Text::new(
            "no structured disagreement",
            (x0, y),
            ("sans-serif", 18).into_font(),
        ))
        .map_err(err)?;
        area.draw(&Text::new(
            format!("(no window with p < {})", s.settings.window_p),
            (x0, y + 24),
            font.clone(),
        ))
        .map_err(err)?;
        return Ok(());
    }
    area.draw(&Text::new(
        "windows of disagreement",
        (x0, y),
        ("sans-serif", 17).into_font(),
    ))
    .map_err(err)?;
    y += 24;
    for (i, w) in s.disagreement.iter().enumerate() {
        if y + 3 * row > h_px as i32 - 4 {
            let more = s.disagreement.len() - i;
            area.draw(&Text::new(
                format!("... and {more} more (see report.md)"),
                (x0, y),
                font.clone(),
            ))
            .map_err(err)?;
            break;
        }
        let c = window_color(i);
        area.draw(&Rectangle::new(
            [(x0, y), (x0 + 26, y + 16)],
            c.mix(0.35).filled(),
        ))
        .map_err(err)?;
        area.draw(&frame((x0, y), (x0 + 26, y + 16), c.stroke_width(2)))
            .map_err(err)?;
        let line1 = format!(
            "{}: p = {}",
            window_label(i, w.voltages_v),
            p_text(w.p_value)
        );
        let line2 = match (&w.region, &w.region_error) {
            (Some(g), _) => format!(
                "r {:.1}-{:.1} mm, z {:.1}-{:.1} mm",
                g.r_mm[0], g.r_mm[1], g.z_mm[0], g.z_mm[1]
            ),
            (None, Some(e)) => format!("no region: {e}"),
            (None, None) => "no region".to_string(),
        };
        let lines = std::iter::once(fit_text(area, &line1, &font, text_w))
            .chain(wrap_text(area, &line2, &font, text_w, 2));
        for line in lines {
            area.draw(&Text::new(line, (x0 + 36, y), font.clone()))
                .map_err(err)?;
            y += row - 2;
        }
        y += 8;
    }
    Ok(())
}
