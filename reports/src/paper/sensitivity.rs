//! The paper's Fig. 13 (section 6): c12 at 25 V with d_Li = 1 mm for constant impurity
//! densities, which sets the sensitive range zeta_l = 1e8 .. zeta_u = 1e11 cm^-3.

use hpge_solver::scan::sensitivity_scan;
use hpge_solver::{Detector, FieldSettings, Parameters};
use serde_json::json;

use super::{Cmp, Criterion, Ctx, Judgement};
use crate::{Error, Result, plot};

/// The file stem of the figure and its record.
pub const STEM: &str = "sensitivity-25V";
const VOLTAGE_V: f64 = 25.0;

/// Scans c12 at 25 V over constant densities, draws Fig. 13 and judges the sensitive range
/// against the paper's zeta_l and zeta_u.
pub fn run(ctx: &mut Ctx) -> Result<()> {
    // Four densities a decade from 1e7 to 1e11 (so 1e8 and 1e11 are on the grid), and 2e11.
    let zetas: Vec<f64> = if ctx.quick {
        vec![1e7, 1e8, 1e9, 1e10, 1e11]
    } else {
        (0..=16)
            .map(|k| 10f64.powf(7.0 + k as f64 / 4.0))
            .chain([2e11])
            .collect()
    };
    let mut p = Parameters::new();
    p.set("d_li_mm".to_string(), 1.0);
    let det = Detector::from_file(&ctx.inputs.detector, &p)?;
    let points = sensitivity_scan(&det, VOLTAGE_V, &zetas, &FieldSettings::default(), &|_| {})?;
    let data = ctx.inputs.data_curve()?;
    let c_m = data
        .voltage_v
        .iter()
        .position(|&u| (u - VOLTAGE_V).abs() < 1e-9)
        .map_or(f64::NAN, |i| data.c12_pf[i]);
    // As the paper's figure: the sensitive range, the manufacturer's levels and the data.
    let mut marks = plot::ScanMarks::sensitive_range();
    for (label, z) in [
        ("bottom", super::fits::ZETA_M.0),
        ("top", super::fits::ZETA_M.1),
    ] {
        marks.densities.push(plot::Mark {
            label: format!("manufacturer's level, {label} ({z:.2e} cm^-3)"),
            value: z,
        });
    }
    if c_m.is_finite() {
        marks.capacitances.push(plot::Mark {
            label: format!("data c12^m({VOLTAGE_V:.0} V) = {c_m:.0} pF"),
            value: c_m,
        });
    }
    ctx.both(STEM, |path| {
        plot::sensitivity(&points, VOLTAGE_V, &det.name, &marks, path)
    })?;
    let at = |z: f64| {
        points
            .iter()
            .find(|p| (p.zeta_cm3 / z - 1.0).abs() < 1e-9)
            .ok_or_else(|| Error::invalid("a density of the scan is missing"))
    };
    let (p7, p8, p11) = (at(1e7)?, at(1e8)?, at(1e11)?);
    let near_limit = (p8.c12_pf / p7.c12_pf - 1.0).abs();
    let ours = format!(
        "c12(1e7) = {:.2} pF, c12(1e8) = {:.2} pF ({:+.2}%, fully depleted: {}); c12(1e11) = {:.0} pF vs data c12^m(25 V) = {:.0} pF",
        p7.c12_pf,
        p8.c12_pf,
        100.0 * (p8.c12_pf / p7.c12_pf - 1.0),
        p8.fully_depleted,
        p11.c12_pf,
        c_m
    );
    let criteria = vec![
        Criterion::flag("1e8 cm^-3 fully depleted at 25 V", p8.fully_depleted, true),
        Criterion::new("c12(1e8) / c12(1e7) - 1", near_limit, Cmp::Lt, 0.01),
        Criterion::new("c12(1e11) / c12^m(25 V)", p11.c12_pf / c_m, Cmp::Gt, 1.5),
    ];
    let reading = if !p8.fully_depleted || near_limit >= 0.01 {
        "here a constant 1e8 cm^-3 does not yet deplete the detector at 25 V: c12 is still above its 1e7 value, so the insensitive range ends lower than the paper's zeta_l"
    } else {
        ""
    };
    ctx.row(
        STEM,
        "Fig. 13 (sec. 6)",
        "At 25 V (d_Li = 1 mm) a constant 1e8 cm^-3 already depletes the detector (c12 ~ its limit), 1e11 gives c12 far above the measured value; between them c12 changes linearly in log zeta.",
        ours,
        Judgement::by(criteria, reading),
    );
    ctx.number(
        "sensitivity",
        json!({
            "voltage_V": VOLTAGE_V,
            "d_li_mm": 1.0,
            "zeta_cm3": points.iter().map(|p| p.zeta_cm3).collect::<Vec<_>>(),
            "c12_pF": points.iter().map(|p| p.c12_pf).collect::<Vec<_>>(),
            "fully_depleted": points.iter().map(|p| p.fully_depleted).collect::<Vec<_>>(),
        }),
    );
    Ok(())
}
