//! The r-z cross-section of a detector: materials, contacts, passives, world boundaries and the
//! impurity map, drawn at equal scale in r and z.

use std::path::Path;

use hpge_solver::Detector;
use hpge_solver::detector::BoundaryKind;
use hpge_solver::detector::PassiveKind;
use hpge_solver::detector::Region;
use hpge_solver::detector::WorldSide;
use plotters::coord::Shift;
use plotters::coord::types::RangedCoordf64;
use plotters::prelude::*;

use super::colormap::{density_color, t_color};
use super::style::err;
use crate::error::Result;

/// Largest plot width and height in pixels (the scale is chosen so that both fit).
const MAX_PLOT_W: f64 = 700.0;
const MAX_PLOT_H: f64 = 900.0;
const TITLE_H: u32 = 70;
const PANEL_W: u32 = 430;
const MARGIN: u32 = 15;
const Y_LABEL_W: u32 = 60;
const X_LABEL_H: u32 = 50;
/// Colour levels per sign of the impurity map in SVG files (keeps them small); PNG is continuous.
const SVG_LEVELS: usize = 32;

const CONTACT_COLORS: [RGBColor; 5] = [
    RGBColor(44, 160, 44),
    RGBColor(148, 103, 189),
    RGBColor(230, 184, 0),
    RGBColor(23, 190, 207),
    RGBColor(227, 119, 194),
];
const GROUNDED: RGBColor = RGBColor(105, 105, 105);
const FLOATING: RGBColor = RGBColor(175, 175, 175);
const DIELECTRIC: RGBColor = RGBColor(222, 203, 160);
const OUTLINE: RGBColor = RGBColor(20, 20, 20);
const REFLECTING: RGBColor = RGBColor(31, 119, 180);

pub(super) fn contact_color(i: usize) -> RGBColor {
    CONTACT_COLORS[i % CONTACT_COLORS.len()]
}

pub(super) fn passive_color(kind: PassiveKind) -> RGBColor {
    match kind {
        PassiveKind::Grounded => GROUNDED,
        PassiveKind::Floating => FLOATING,
        PassiveKind::Dielectric => DIELECTRIC,
    }
}

struct Layout {
    plot_w: u32,
    plot_h: u32,
    width: u32,
    height: u32,
}

impl Layout {
    fn new(det: &Detector) -> Self {
        let w = &det.world;
        let dz = w.z_max_mm - w.z_min_mm;
        let s = (MAX_PLOT_W / w.r_max_mm).min(MAX_PLOT_H / dz);
        let plot_w = (s * w.r_max_mm).round().max(50.0) as u32;
        let plot_h = (s * dz).round().max(50.0) as u32;
        // The legend panel grows with its longest line (about 8 px per character at 15 px).
        let longest = det
            .contacts
            .iter()
            .map(|c| c.name.len() + 30)
            .chain(det.passives.iter().map(|p| p.name.len() + 30))
            .chain([det.semiconductor.name.len() + 50])
            .chain(det.world.labels.iter().flatten().map(|l| l.len() + 40))
            .max()
            .unwrap_or(0) as u32;
        let panel_w = PANEL_W.max(70 + 8 * longest);
        let width = plot_w + Y_LABEL_W + 2 * MARGIN + panel_w;
        let height = (TITLE_H + plot_h + X_LABEL_H + 2 * MARGIN).max(760);
        Layout {
            plot_w,
            plot_h,
            width,
            height,
        }
    }
}

/// Draws the cross-section of `det` into `path` (.svg or .png).
pub fn cross_section(det: &Detector, path: &Path) -> Result<()> {
    let layout = Layout::new(det);
    let size = (layout.width, layout.height);
    render!(path, size, |root, svg| if svg {
        let cell = (layout.plot_h / 450).max(1);
        draw(&root, det, &layout, cell, SVG_LEVELS)
    } else {
        draw(&root, det, &layout, 1, 0)
    })
}

fn draw<DB: DrawingBackend>(
    root: &DrawingArea<DB, Shift>,
    det: &Detector,
    layout: &Layout,
    cell_px: u32,
    levels: usize,
) -> Result<()> {
    root.fill(&WHITE).map_err(err)?;
    let (title, body) = root.split_vertically(TITLE_H);
    draw_title(&title, det)?;
    let chart_w = layout.plot_w + Y_LABEL_W + 2 * MARGIN;
    let (left, right) = body.split_horizontally(chart_w);
    let (chart_area, _) = left.split_vertically(layout.plot_h + X_LABEL_H + 2 * MARGIN);

    let w = &det.world;
    let mut chart = ChartBuilder::on(&chart_area)
        .margin(MARGIN)
        .x_label_area_size(X_LABEL_H)
        .y_label_area_size(Y_LABEL_W)
        .build_cartesian_2d(0.0..w.r_max_mm, w.z_min_mm..w.z_max_mm)
        .map_err(err)?;
    chart
        .configure_mesh()
        .disable_mesh()
        .x_desc("r (mm)")
        .y_desc("z (mm)")
        .label_style(("sans-serif", 16))
        .axis_desc_style(("sans-serif", 18))
        .draw()
        .map_err(err)?;

    let nx = (layout.plot_w / cell_px).max(1) as usize;
    let nz = (layout.plot_h / cell_px).max(1) as usize;
    draw_regions(
        &mut chart,
        det,
        [0.0, w.r_max_mm],
        [w.z_min_mm, w.z_max_mm],
        (nx, nz),
        |r, z| density_color(det.impurity().density_cm3(r, z), levels),
    )?;

    // World boundaries and the axis.
    let sides = [
        (
            WorldSide::RMax,
            [(w.r_max_mm, w.z_min_mm), (w.r_max_mm, w.z_max_mm)],
        ),
        (
            WorldSide::ZMin,
            [(0.0, w.z_min_mm), (w.r_max_mm, w.z_min_mm)],
        ),
        (
            WorldSide::ZMax,
            [(0.0, w.z_max_mm), (w.r_max_mm, w.z_max_mm)],
        ),
    ];
    for (side, pts) in sides {
        match w.boundary(side) {
            BoundaryKind::Grounded => chart
                .draw_series(LineSeries::new(pts, GROUNDED.stroke_width(6)))
                .map_err(err)?,
            BoundaryKind::Reflecting => chart
                .draw_series(DashedLineSeries::new(
                    pts,
                    10,
                    6,
                    REFLECTING.stroke_width(4),
                ))
                .map_err(err)?,
        };
    }
    chart
        .draw_series(DashedLineSeries::new(
            [(0.0, w.z_min_mm), (0.0, w.z_max_mm)],
            12,
            5,
            BLACK.mix(0.6).stroke_width(2),
        ))
        .map_err(err)?;

    draw_panel(&right, det)?;
    Ok(())
}

/// Draws the regions of `det` over `r` x `z` (mm) into `chart` as a raster of (nx, nz) cells
/// merged into runs of equal colour per row -- contacts and passives in their colours, the
/// medium white, the semiconductor's edge cells in `OUTLINE` and its interior in `interior(r, z)`
/// -- then the zero-thickness contact and passive surfaces as thick lines.
pub(super) fn draw_regions<DB: DrawingBackend>(
    chart: &mut ChartContext<'_, DB, Cartesian2d<RangedCoordf64, RangedCoordf64>>,
    det: &Detector,
    r: [f64; 2],
    z: [f64; 2],
    (nx, nz): (usize, usize),
    interior: impl Fn(f64, f64) -> RGBColor,
) -> Result<()> {
    // Raster of regions, merged into runs of equal colour per row.
    let dr = (r[1] - r[0]) / nx as f64;
    let dzc = (z[1] - z[0]) / nz as f64;
    let regions: Vec<Region> = (0..nz)
        .flat_map(|j| (0..nx).map(move |i| (i, j)))
        .map(|(i, j)| det.classify(r[0] + (i as f64 + 0.5) * dr, z[0] + (j as f64 + 0.5) * dzc))
        .collect();
    let at = |i: usize, j: usize| regions[j * nx + i];
    let is_outside_crystal = |r: Region| matches!(r, Region::Medium | Region::Passive(_));
    let mut rects = Vec::new();
    for j in 0..nz {
        let z0 = z[0] + j as f64 * dzc;
        let mut run_start = 0;
        let mut run_color: Option<RGBColor> = None;
        for i in 0..=nx {
            let color = (i < nx).then(|| {
                let reg = at(i, j);
                match reg {
                    Region::Contact(k) => contact_color(k),
                    Region::Passive(k) => passive_color(det.passives[k].kind),
                    Region::Medium => WHITE,
                    Region::Semiconductor => {
                        let edge = (i > 0 && is_outside_crystal(at(i - 1, j)))
                            || (i + 1 < nx && is_outside_crystal(at(i + 1, j)))
                            || (j > 0 && is_outside_crystal(at(i, j - 1)))
                            || (j + 1 < nz && is_outside_crystal(at(i, j + 1)));
                        if edge {
                            OUTLINE
                        } else {
                            interior(r[0] + (i as f64 + 0.5) * dr, z[0] + (j as f64 + 0.5) * dzc)
                        }
                    }
                }
            });
            if color != run_color {
                if let Some(c) = run_color {
                    rects.push(Rectangle::new(
                        [
                            (r[0] + run_start as f64 * dr, z0),
                            (r[0] + i as f64 * dr, z0 + dzc),
                        ],
                        c.filled(),
                    ));
                }
                run_start = i;
                run_color = color;
            }
        }
    }
    chart.draw_series(rects).map_err(err)?;

    // Zero-thickness surfaces (e.g. the p+ mantle) as thick lines.
    draw_contact_surfaces(chart, det, 5)?;
    for p in &det.passives {
        for (a, b) in p.geometry.surface_segments() {
            chart
                .draw_series(LineSeries::new(
                    [(a[0], a[1]), (b[0], b[1])],
                    passive_color(p.kind).stroke_width(4),
                ))
                .map_err(err)?;
        }
    }
    Ok(())
}

/// Draws the outlines of `det`'s regions over a figure of something else (a field, a
/// potential): on an (nx, nz) raster of `r` x `z` (mm), each cell whose region differs from
/// its right or upper neighbour's, in black where the semiconductor meets another region, in
/// the contact's colour along a contact and in dark grey around a passive part; then the
/// zero-thickness contact surfaces.
pub(super) fn draw_outlines<DB: DrawingBackend>(
    chart: &mut ChartContext<'_, DB, Cartesian2d<RangedCoordf64, RangedCoordf64>>,
    det: &Detector,
    r: [f64; 2],
    z: [f64; 2],
    (nx, nz): (usize, usize),
) -> Result<()> {
    let dr = (r[1] - r[0]) / nx as f64;
    let dz = (z[1] - z[0]) / nz as f64;
    let at = |i: usize, j: usize| {
        det.classify(r[0] + (i as f64 + 0.5) * dr, z[0] + (j as f64 + 0.5) * dz)
    };
    let mut rects = Vec::new();
    let mut prev: Vec<Region> = (0..nx).map(|i| at(i, 0)).collect();
    for j in 0..nz {
        let row: Vec<Region> = if j == 0 {
            prev.clone()
        } else {
            (0..nx).map(|i| at(i, j)).collect()
        };
        for i in 0..nx {
            let here = row[i];
            let others = [(i + 1 < nx).then(|| row[i + 1]), (j > 0).then(|| prev[i])];
            let Some(other) = others.into_iter().flatten().find(|o| *o != here) else {
                continue;
            };
            let color = match (here, other) {
                (Region::Contact(k), _) | (_, Region::Contact(k)) => contact_color(k),
                (Region::Semiconductor, _) | (_, Region::Semiconductor) => BLACK,
                (Region::Passive(_), _) | (_, Region::Passive(_)) => RGBColor(90, 90, 90),
                _ => continue,
            };
            let (x0, y0) = (r[0] + i as f64 * dr, z[0] + j as f64 * dz);
            rects.push(Rectangle::new(
                [(x0, y0), (x0 + 1.5 * dr, y0 + 1.5 * dz)],
                color.filled(),
            ));
        }
        prev = row;
    }
    chart.draw_series(rects).map_err(err)?;
    draw_contact_surfaces(chart, det, 4)
}

/// The zero-thickness contact surfaces of `det` (e.g. the p+ mantle) as lines `width` px wide
/// in the contacts' colours.
fn draw_contact_surfaces<DB: DrawingBackend>(
    chart: &mut ChartContext<'_, DB, Cartesian2d<RangedCoordf64, RangedCoordf64>>,
    det: &Detector,
    width: u32,
) -> Result<()> {
    for (k, c) in det.contacts.iter().enumerate() {
        for (a, b) in c.geometry.surface_segments() {
            chart
                .draw_series(LineSeries::new(
                    [(a[0], a[1]), (b[0], b[1])],
                    contact_color(k).stroke_width(width),
                ))
                .map_err(err)?;
        }
    }
    Ok(())
}

/// A chart of r x z (mm) with `caption` on `area`, its axes labelled: the frame of the figures
/// drawn over the cross-section (potential, depletion bands).
pub(super) fn rz_chart<'a, DB: DrawingBackend>(
    area: &'a DrawingArea<DB, Shift>,
    caption: String,
    caption_size: u32,
    r: [f64; 2],
    z: [f64; 2],
) -> Result<ChartContext<'a, DB, Cartesian2d<RangedCoordf64, RangedCoordf64>>> {
    let mut chart = ChartBuilder::on(area)
        .caption(caption, ("sans-serif", caption_size))
        .margin(15)
        .x_label_area_size(45)
        .y_label_area_size(60)
        .build_cartesian_2d(r[0]..r[1], z[0]..z[1])
        .map_err(err)?;
    chart
        .configure_mesh()
        .disable_mesh()
        .x_desc("r (mm)")
        .y_desc("z (mm)")
        .draw()
        .map_err(err)?;
    Ok(chart)
}

fn draw_title<DB: DrawingBackend>(area: &DrawingArea<DB, Shift>, det: &Detector) -> Result<()> {
    let params: Vec<String> = det
        .parameters
        .iter()
        .map(|(k, v)| format!("{k} = {v}"))
        .collect();
    let line1 = format!(
        "{}: r-z cross-section (axisymmetric)   [{} {}]",
        det.name,
        crate::provenance::PROGRAM,
        crate::provenance::VERSION
    );
    let line2 = format!(
        "impurity model \"{}\" ({}){}",
        det.impurity().name(),
        det.semiconductor.impurity_file().display(),
        if params.is_empty() {
            String::new()
        } else {
            format!("; {}", params.join(", "))
        }
    );
    area.draw(&Text::new(line1, (15, 12), ("sans-serif", 24).into_font()))
        .map_err(err)?;
    area.draw(&Text::new(line2, (15, 42), ("sans-serif", 16).into_font()))
        .map_err(err)?;
    Ok(())
}

/// Colour bar of the impurity map and the legend.
fn draw_panel<DB: DrawingBackend>(area: &DrawingArea<DB, Shift>, det: &Detector) -> Result<()> {
    let font = ("sans-serif", 15).into_font();
    let (x0, y0, bar_w, bar_h) = (20, 40, 26, 300);
    area.draw(&Text::new(
        "impurity density (cm^-3)",
        (x0, y0 - 30),
        ("sans-serif", 17).into_font(),
    ))
    .map_err(err)?;
    for k in 0..bar_h {
        let t = 1.0 - 2.0 * (k as f64 + 0.5) / bar_h as f64;
        area.draw(&Rectangle::new(
            [(x0, y0 + k), (x0 + bar_w, y0 + k + 1)],
            t_color(t, 0).filled(),
        ))
        .map_err(err)?;
    }
    area.draw(&Rectangle::new(
        [(x0, y0), (x0 + bar_w, y0 + bar_h)],
        BLACK.stroke_width(1),
    ))
    .map_err(err)?;
    let ticks = [
        (1.0, "+1e11  n-type"),
        (2.0 / 3.0, "+1e10"),
        (1.0 / 3.0, "+1e9"),
        (0.0, "|zeta| <= 1e8"),
        (-1.0 / 3.0, "-1e9"),
        (-2.0 / 3.0, "-1e10"),
        (-1.0, "-1e11  p-type"),
    ];
    for (t, label) in ticks {
        let y = y0 + ((1.0 - t) / 2.0 * bar_h as f64).round() as i32;
        area.draw(&PathElement::new(
            vec![(x0 + bar_w, y), (x0 + bar_w + 6, y)],
            BLACK.stroke_width(1),
        ))
        .map_err(err)?;
        area.draw(&Text::new(label, (x0 + bar_w + 10, y - 8), font.clone()))
            .map_err(err)?;
    }

    // Legend.
    let mut y = y0 + bar_h + 35;
    let swatch =
        |y: i32, color: RGBColor| Rectangle::new([(x0, y), (x0 + 26, y + 16)], color.filled());
    let w = &det.world;
    let mut entries: Vec<(RGBColor, String)> = det
        .contacts
        .iter()
        .enumerate()
        .map(|(k, c)| {
            (
                contact_color(k),
                format!("contact {}: {} ({})", c.id, c.name, c.potential),
            )
        })
        .collect();
    for p in &det.passives {
        let kind = match p.kind {
            PassiveKind::Grounded => "grounded".to_string(),
            PassiveKind::Floating => "floating".to_string(),
            PassiveKind::Dielectric => format!("eps_r {}", p.material.eps_r),
        };
        entries.push((
            passive_color(p.kind),
            format!("{} ({}, {kind})", p.name, p.material.name),
        ));
    }
    entries.push((
        RGBColor(240, 240, 240),
        format!(
            "{} ({}, eps_r {}): colour = impurity density",
            det.semiconductor.name,
            det.semiconductor.material.name,
            det.semiconductor.material.eps_r
        ),
    ));
    entries.push((
        WHITE,
        format!("{} (eps_r {})", w.medium.name, w.medium.eps_r),
    ));
    for (color, text) in entries {
        area.draw(&swatch(y, color)).map_err(err)?;
        area.draw(&Rectangle::new(
            [(x0, y), (x0 + 26, y + 16)],
            BLACK.stroke_width(1),
        ))
        .map_err(err)?;
        area.draw(&Text::new(text, (x0 + 36, y), font.clone()))
            .map_err(err)?;
        y += 24;
    }
    y += 8;
    for side in [WorldSide::RMax, WorldSide::ZMin, WorldSide::ZMax] {
        let kind = w.boundary(side);
        let name = match side {
            WorldSide::RMax => "r = r_max",
            WorldSide::ZMin => "z = z_min",
            WorldSide::ZMax => "z = z_max",
        };
        let (style, kind_s) = match kind {
            BoundaryKind::Grounded => (GROUNDED.stroke_width(6), "grounded, 0 V"),
            BoundaryKind::Reflecting => (REFLECTING.stroke_width(4), "reflecting, E.n = 0"),
        };
        area.draw(&PathElement::new(
            vec![(x0, y + 8), (x0 + 26, y + 8)],
            style,
        ))
        .map_err(err)?;
        let label = w.label(side).map(|l| format!(": {l}")).unwrap_or_default();
        area.draw(&Text::new(
            format!("{name} ({kind_s}){label}"),
            (x0 + 36, y),
            font.clone(),
        ))
        .map_err(err)?;
        y += 24;
    }
    area.draw(&PathElement::new(
        vec![(x0, y + 8), (x0 + 26, y + 8)],
        BLACK.mix(0.6).stroke_width(2),
    ))
    .map_err(err)?;
    area.draw(&Text::new("r = 0: symmetry axis", (x0 + 36, y), font))
        .map_err(err)?;
    Ok(())
}
