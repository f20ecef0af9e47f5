//! The paper's Fig. 14 (the transform y -> x = T(y) -> zeta), Fig. 15 (the example density
//! p_zeta,E along z and r) and the detector's cross-section (Fig. 9): with the manufacturer's model
//! and with the example density (d_Li = 3 mm, as `reports/make-figures.sh` draws it).

use hpge_solver::impurity::LogTransform;
use hpge_solver::{Detector, Parameters};
use serde_json::json;

use super::criterion::{Cmp, Criterion, Judgement};
use super::ctx::Ctx;
use crate::error::Result;
use crate::plot::{self, Corner, Curve, LineFigure};

/// y = 0.018566145 is zeta_l = 1e8 cm^-3 (the paper's prior bound).
const Y_L: f64 = 0.018566145;

/// Draws the transform, the example density and both cross-sections, with their README rows.
pub fn run(ctx: &mut Ctx) -> Result<()> {
    transform(ctx)?;
    example(ctx)?;
    let det = Detector::from_file(&ctx.inputs.detector, &Parameters::new())?;
    ctx.both("detector-cross-section", |p| plot::cross_section(&det, p))?;
    ctx.row(
        "detector-cross-section",
        "Fig. 9 (sec. 5)",
        "Super-Siegfried in K1 as implemented in the simulation (geometry, contacts, holding structure).",
        format!(
            "{}: {}, {} contacts, {} passive parts, manufacturer's impurity model",
            ctx.inputs.detector.display(),
            det.name,
            det.contacts.len(),
            det.passives.len()
        ),
        Judgement::Shown(
            "the detector description the solver uses; the paper's 3D holder is modelled in r-z"
                .into(),
        ),
    );
    Ok(())
}

fn transform(ctx: &mut Ctx) -> Result<()> {
    let t = LogTransform::default();
    let ys: Vec<f64> = (0..=2000).map(|k| -1.0 + k as f64 / 1000.0).collect();
    let curve = |label: &str, f: &dyn Fn(f64) -> f64| Curve {
        label: label.into(),
        points: ys.iter().map(|&y| (y, Some(f(y)))).collect(),
    };
    let fig = LineFigure {
        title: "parameter transform: zeta(T(y)) and x = T(y) against y".into(),
        x_desc: "y".into(),
        y_desc: "value (see legend)".into(),
        curves: vec![
            curve("zeta(T(y)) in 1e10 cm^-3", &|y| t.zeta_cm3_of_y(y) / 1e10),
            curve(
                "x = T(y) (log10 of zeta in m^-3, x_l = 14, x_u = 17)",
                &|y| t.x_of_y(y),
            ),
            curve("sign(zeta) log10(|zeta| / cm^-3)", &|y| {
                let z = t.zeta_cm3_of_y(y);
                if z == 0.0 {
                    0.0
                } else {
                    z.signum() * z.abs().log10().max(0.0)
                }
            }),
        ],
        y_from_zero: false,
        legend: Corner::UpperLeft,
        footnotes: vec![format!(
            "hpge-cv {} report paper: LogTransform defaults v = {}, g = {}; paper Eqs. (18)-(20)",
            crate::provenance::VERSION,
            t.v,
            t.g
        )],
    };
    ctx.both("transform", |p| plot::line_figure(&fig, p))?;
    let (z_l, z_u) = (t.zeta_cm3_of_y(Y_L), t.zeta_cm3_of_y(1.0));
    ctx.row(
        "transform",
        "Fig. 14 (sec. 6)",
        "T maps y in [-1, 1] onto x with T(+-1) = +-x_u; y = 0.018566145 is zeta_l = 1e8 cm^-3; |y| below it is squeezed into |zeta| < zeta_l, so a linear change in y is a logarithmic one in zeta.",
        format!(
            "zeta(0.018566145) = {z_l:.4e} cm^-3, zeta(1) = {z_u:.4e} cm^-3, T(1) = {} (m^-3 units), zeta(0.001) = {:.3e} cm^-3",
            t.x_of_y(1.0),
            t.zeta_cm3_of_y(0.001)
        ),
        Judgement::by(
            vec![
                Criterion::new("|zeta(y_l) / 1e8 cm^-3 - 1|", (z_l / 1e8 - 1.0).abs(), Cmp::Lt, 1e-3),
                Criterion::new("|zeta(1) / 1e11 cm^-3 - 1|", (z_u / 1e11 - 1.0).abs(), Cmp::Lt, 1e-9),
            ],
            "",
        ),
    );
    ctx.number(
        "transform",
        json!({"zeta_at_y_l_cm3": z_l, "zeta_at_1_cm3": z_u}),
    );
    Ok(())
}

fn example(ctx: &mut Ctx) -> Result<()> {
    let mut p = Parameters::new();
    p.set("d_li_mm".to_string(), 3.0);
    let mut det = Detector::from_file(&ctx.inputs.detector, &p)?;
    det.set_impurity_file(&ctx.inputs.example_impurity)?;
    ctx.both("example-density-cross-section", |path| {
        plot::cross_section(&det, path)
    })?;
    let b = det.semiconductor.geometry.bbox();
    let inside = |r: f64, z: f64| det.semiconductor.geometry.contains(r, z, -1e-6);
    let model = det.impurity();
    let zeta = |r: f64, z: f64| inside(r, z).then(|| model.density_cm3(r, z) / 1e10);
    let n = 301;
    let lin = |a: f64, c: f64| (0..n).map(move |i| a + (c - a) * i as f64 / (n - 1) as f64);
    let foot = format!(
        "hpge-cv {} report paper: {} with {} (p_zeta,E), d_Li = 3 mm; gaps: outside the semiconductor",
        crate::provenance::VERSION,
        ctx.inputs.detector.display(),
        ctx.inputs.example_impurity.display()
    );
    // Inside the bulk, between the knots and near the mantle (r = 37.5 mm is the surface).
    let radii = [10.0, 25.0, 33.0, 35.5, 37.3];
    let along_z = LineFigure {
        title: "example density p_zeta,E along z (a)".into(),
        x_desc: "z (mm)".into(),
        y_desc: "zeta (1e10 cm^-3)".into(),
        curves: radii
            .iter()
            .map(|&r| Curve {
                label: format!("r = {r} mm"),
                points: lin(b.z_min_mm, b.z_max_mm)
                    .map(|z| (z, zeta(r, z)))
                    .collect(),
            })
            .collect(),
        y_from_zero: false,
        legend: Corner::LowerRight,
        footnotes: vec![foot.clone()],
    };
    let heights = [
        b.z_min_mm + 0.01 * (b.z_max_mm - b.z_min_mm),
        0.5 * (b.z_min_mm + b.z_max_mm),
        b.z_max_mm - 0.01 * (b.z_max_mm - b.z_min_mm),
    ];
    let along_r = LineFigure {
        title: "example density p_zeta,E along r (b)".into(),
        x_desc: "r (mm)".into(),
        y_desc: "zeta (1e10 cm^-3)".into(),
        curves: heights
            .iter()
            .map(|&z| Curve {
                label: format!("z = {z:.1} mm"),
                points: lin(b.r_min_mm, b.r_max_mm)
                    .map(|r| (r, zeta(r, z)))
                    .collect(),
            })
            .collect(),
        y_from_zero: false,
        legend: Corner::LowerRight,
        footnotes: vec![foot],
    };
    ctx.both("example-density-z", |path| {
        plot::line_figure(&along_z, path)
    })?;
    ctx.both("example-density-r", |path| {
        plot::line_figure(&along_r, path)
    })?;
    let (z_lo, z_mid, z_hi) = (heights[0], heights[1], heights[2]);
    let bulk = model.density_cm3(20.0, z_mid);
    let mantle_bot = model.density_cm3(37.5, z_lo);
    let mantle_top = model.density_cm3(37.5, z_hi);
    let ours = format!(
        "zeta(r = 20 mm, mid-height) = {:.3e}, zeta(37.5 mm, bottom) = {:.3e}, zeta(37.5 mm, top) = {:.3e} cm^-3",
        bulk, mantle_bot, mantle_top
    );
    let statement = "With p_zeta,E the bulk is n-type and the volume near the mantle p-type (the model allows a type boundary).";
    let criteria = vec![
        Criterion::new("zeta(20 mm, mid-height) (cm^-3)", bulk, Cmp::Gt, 0.0),
        Criterion::new("zeta(37.5 mm, bottom) (cm^-3)", mantle_bot, Cmp::Lt, 0.0),
        Criterion::new("zeta(37.5 mm, top) (cm^-3)", mantle_top, Cmp::Lt, 0.0),
    ];
    for (stem, paper) in [
        ("example-density-z", "Fig. 15a (sec. 6)"),
        ("example-density-r", "Fig. 15b (sec. 6)"),
        (
            "example-density-cross-section",
            "Fig. 15 (sec. 6), as a map",
        ),
    ] {
        ctx.row(
            stem,
            paper,
            statement,
            ours.clone(),
            Judgement::by(criteria.clone(), ""),
        );
    }
    ctx.number(
        "example_density",
        json!({"bulk_cm3": bulk, "mantle_bottom_cm3": mantle_bot, "mantle_top_cm3": mantle_top}),
    );
    Ok(())
}
