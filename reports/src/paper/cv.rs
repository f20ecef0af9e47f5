//! The paper's Fig. 12 (with the data of Fig. 8a): the measured C-V curve with its error bars
//! beside the curve the field solver gives for the manufacturer's impurity model with
//! d_Li = 1 mm (section 5).

use std::path::Path;

use hpge_solver::{CvCurve, Detector, FieldSettings, Parameters, cv_curve};
use plotters::coord::Shift;
use plotters::prelude::*;
use serde_json::json;

use super::criterion::{Cmp, Criterion, Judgement};
use super::ctx::Ctx;
use crate::error::{Error, Result};
use crate::plot::Format;
use crate::plot::fonts::Glyphs;
use crate::plot::style::err;

/// The figure's stem.
pub const STEM: &str = "cv-data-vs-manufacturer";

/// The paper's lithium thickness for the manufacturer's curve (section 5), mm.
const D_LI_MM: f64 = 1.0;

/// The slope (pF/V) that defines the full-depletion voltage of the data (section 4).
const FD_SLOPE: f64 = 1e-3;

/// Draws the figure and adds its README row.
pub fn run(ctx: &mut Ctx) -> Result<()> {
    let data = ctx.inputs.data_curve()?;
    let mut p = Parameters::new();
    p.set("d_li_mm".to_string(), D_LI_MM);
    let det = Detector::from_file(&ctx.inputs.detector, &p)?;
    let volts: Vec<f64> = if ctx.quick {
        data.voltage_v.iter().step_by(12).copied().collect()
    } else {
        data.voltage_v.clone()
    };
    let curve = cv_curve(&det, &volts, &FieldSettings::default(), |_, _| {})?;
    // The data's full-depletion voltage as `measure` defines it: where -dc12/dU_B last falls
    // to 1e-3 pF/V, interpolated between the difference quotients' midpoints.
    let u_fd = hpge_measurement::depletion_voltage(&data.voltage_v, &data.c12_pf, FD_SLOPE);
    let (first, last) = match (curve.points.first(), curve.points.last()) {
        (Some(a), Some(b)) => (a, b),
        _ => return Err(Error::invalid("the simulated curve is empty")),
    };
    let c_m = |u: f64| {
        data.voltage_v
            .iter()
            .position(|&v| (v - u).abs() < 1e-9)
            .map(|i| data.c12_pf[i])
    };
    let (m_first, m_last) = (
        c_m(first.voltage_v).unwrap_or(f64::NAN),
        c_m(last.voltage_v).unwrap_or(f64::NAN),
    );
    let foot = [
        format!(
            "hpge-cv {} report paper: data {} ({} points, a stand-in: see its README);",
            crate::provenance::VERSION,
            ctx.inputs.data.display(),
            data.voltage_v.len(),
        ),
        format!(
            "simulation: {} with its default (manufacturer's) impurity model, d_Li = {D_LI_MM} mm, field solver defaults",
            ctx.inputs.detector.display(),
        ),
    ];
    let pts: Vec<(f64, f64, f64)> = (0..data.voltage_v.len())
        .map(|i| (data.voltage_v[i], data.c12_pf[i], data.sigma_pf[i]))
        .collect();
    ctx.both(STEM, |path| figure(path, &pts, &curve, &foot))?;
    let not_depleted = curve.depletion_voltage_v.is_none();
    let ours = format!(
        "simulated: {}; c_s/c_m at {} V = {:.1}/{:.1} pF, at {} V = {:.2}/{:.2} pF; data U_fd (-dc12/dU_B falls to 1e-3 pF/V, as `measure`) = {}",
        curve
            .depletion_voltage_v
            .map_or("not fully depleted at any bias".into(), |v| format!(
                "fully depleted at {v:.0} V"
            )),
        first.voltage_v,
        first.c12_pf,
        m_first,
        last.voltage_v,
        last.c12_pf,
        m_last,
        u_fd.map_or("none".into(), |u| format!("{u:.0} V"))
    );
    let criteria = vec![
        Criterion::flag(
            format!("the simulation fully depleted at {} V", last.voltage_v),
            !not_depleted,
            false,
        ),
        Criterion::new(
            format!("c_s / c_m at {} V", first.voltage_v),
            first.c12_pf / m_first,
            Cmp::Gt,
            1.0,
        ),
        Criterion::new(
            format!("c_s / c_m at {} V", last.voltage_v),
            last.c12_pf / m_last,
            Cmp::Lt,
            1.0,
        ),
        Criterion::new(
            "|data U_fd - 2600 V| (V)",
            u_fd.map_or(f64::NAN, |u| (u - 2600.0).abs()),
            Cmp::Le,
            200.0,
        ),
    ];
    // Why the last bias can differ: a model still depleting there lies above its own limit.
    let reading = if not_depleted && last.c12_pf >= m_last {
        format!(
            "the manufacturer's model is still depleting at {} V, so its c12 there ({:.2} pF) lies above the limit it would reach; the stand-in data reach theirs near {}",
            last.voltage_v,
            last.c12_pf,
            u_fd.map_or("no bias".into(), |u| format!("{u:.0} V"))
        )
    } else {
        String::new()
    };
    ctx.row(
        STEM,
        "Fig. 12 (sec. 5; data: Fig. 8a)",
        "The manufacturer's model (d_Li = 1 mm) is not fully depleted at 2975 V; it lies above the data at low bias (depletes too slowly) and below the data's limit capacitance at the last bias. Data U_fd ~ 2600 V.",
        ours,
        Judgement::by(criteria, reading),
    );
    ctx.number(
        "cv",
        json!({
            "d_li_mm": D_LI_MM,
            "voltage_V": curve.points.iter().map(|p| p.voltage_v).collect::<Vec<_>>(),
            "c12_sim_pF": curve.points.iter().map(|p| p.c12_pf).collect::<Vec<_>>(),
            "depletion_voltage_sim_V": curve.depletion_voltage_v,
            "data_full_depletion_V": u_fd,
        }),
    );
    Ok(())
}

fn figure(path: &Path, data: &[(f64, f64, f64)], sim: &CvCurve, foot: &[String]) -> Result<()> {
    let size = (1000, 720);
    crate::plot::fonts::register();
    match Format::from_path(path) {
        Some(Format::Svg) => {
            let root = Glyphs(SVGBackend::new(path, size)).into_drawing_area();
            draw(&root, data, sim, foot)?;
            root.present().map_err(err)
        }
        Some(Format::Png) => {
            let root = Glyphs(BitMapBackend::new(path, size)).into_drawing_area();
            draw(&root, data, sim, foot)?;
            root.present().map_err(err)
        }
        None => Err(Error::UnknownFormat {
            file: path.to_path_buf(),
            message: "use .svg or .png",
        }),
    }
}

fn draw<DB: DrawingBackend>(
    root: &DrawingArea<DB, Shift>,
    data: &[(f64, f64, f64)],
    sim: &CvCurve,
    foot: &[String],
) -> Result<()> {
    root.fill(&WHITE).map_err(err)?;
    let (plot_area, foot_area) = root.split_vertically(root.dim_in_pixel().1 - 50);
    let hi = data
        .iter()
        .map(|p| p.1 + p.2)
        .chain(sim.points.iter().map(|p| p.c12_pf))
        .fold(0.0, f64::max);
    let umax = data
        .iter()
        .map(|p| p.0)
        .chain(sim.points.iter().map(|p| p.voltage_v))
        .fold(0.0, f64::max);
    let mut chart = ChartBuilder::on(&plot_area)
        .caption(
            "C-V curve: data vs the manufacturer's model (d_Li = 1 mm)",
            ("sans-serif", 22),
        )
        .margin(20)
        .x_label_area_size(50)
        .y_label_area_size(80)
        .build_cartesian_2d(0.0..umax * 1.03, 0.0..hi * 1.05)
        .map_err(err)?;
    chart
        .configure_mesh()
        .x_desc("bias U_B (V)")
        .y_desc("c12 (pF)")
        .label_style(("sans-serif", 16))
        .axis_desc_style(("sans-serif", 18))
        .draw()
        .map_err(err)?;
    let black = RGBColor(30, 30, 30);
    chart
        .draw_series(
            data.iter()
                .map(|&(u, c, s)| ErrorBar::new_vertical(u, c - s, c, c + s, black.filled(), 6)),
        )
        .map_err(err)?
        .label("data c12^m with its 1-sigma uncertainty")
        .legend(move |(x, y)| Circle::new((x + 10, y), 3, black.filled()));
    chart
        .draw_series(
            data.iter()
                .map(|&(u, c, _)| Circle::new((u, c), 3, black.filled())),
        )
        .map_err(err)?;
    let blue = RGBColor(31, 119, 180);
    let line: Vec<(f64, f64)> = sim.points.iter().map(|p| (p.voltage_v, p.c12_pf)).collect();
    chart
        .draw_series(LineSeries::new(line, blue.stroke_width(3)))
        .map_err(err)?
        .label("field solver, manufacturer's model zeta_M, d_Li = 1 mm")
        .legend(move |(x, y)| PathElement::new(vec![(x, y), (x + 24, y)], blue.stroke_width(3)));
    chart
        .configure_series_labels()
        .position(SeriesLabelPosition::UpperRight)
        .border_style(BLACK)
        .background_style(WHITE.mix(0.9))
        .label_font(("sans-serif", 16))
        .draw()
        .map_err(err)?;
    let font = ("sans-serif", 14).into_font().color(&RGBColor(80, 80, 80));
    for (i, line) in foot.iter().enumerate() {
        foot_area
            .draw(&Text::new(line.as_str(), (20, 22 * i as i32), font.clone()))
            .map_err(err)?;
    }
    Ok(())
}
