//! The C-V curve across the pinch-off window two ways, on one fixed grid (reports/pockets/):
//! - c12 of the weighting potentials, every pocket a floating conductor (the small-signal
//!   response of a pulser or an AC bridge: trapped carriers cannot follow);
//! - the quasi-static C = -dQ/dU of the read-out contact's charge in the nonlinear solutions
//!   (`hpge_solver::field::contact_charge_c`: a slow ramp, carriers spilling from the pocket counted).
//!
//! Writes `reports/pockets/<name>-quasi-static.{csv,svg,png}` and prints the largest jump of each
//! curve between neighbouring biases.
//!
//! `cargo run --release -p hpge-validation --example quasi_static_cv -- [DETECTOR U0 U1 STEP SPACING_MM]`
//! (defaults: detectors/icpc-example.toml 1200 1700 10 0.5).

use hpge_solver::field::{Mesh, contact_charge_c, solve_fast, solve_point_on_grid};
use hpge_solver::grid::Grid;
use hpge_solver::{Detector, FieldSettings, Parameters};
use hpge_validation::repo_path;
use plotters::prelude::*;

fn main() -> Result<(), Box<dyn std::error::Error>> {
    // plotters draws text only with a registered font (no system fonts: issue 61).
    plotters::style::register_font(
        "sans-serif",
        plotters::style::FontStyle::Normal,
        include_bytes!("../../reports/fonts/DejaVuSans.ttf"),
    )
    .map_err(|_| "reports/fonts/DejaVuSans.ttf is not a font file")?;
    let args: Vec<String> = std::env::args().skip(1).collect();
    let file = args.first().map_or("detectors/icpc-example.toml", |s| s);
    let num = |k: usize, d: f64| args.get(k).map_or(Ok(d), |a| a.parse::<f64>());
    let (u0, u1, step, spacing) = (
        num(1, 1200.0)?,
        num(2, 1700.0)?,
        num(3, 10.0)?,
        num(4, 0.5)?,
    );
    let det = Detector::from_file(&repo_path(file), &Parameters::new())?;
    let mut s = FieldSettings::for_detector(&FieldSettings::default(), &det);
    s.grid.adaptive = false;
    s.grid.max_spacing_semiconductor_mm = spacing;
    let grid = Grid::initial(&det, &s.grid);
    let mesh = Mesh::new(&det, grid.clone());
    let bias = det.bias_contacts();
    let readout = (0..det.contacts.len())
        .find(|k| !bias.contains(k))
        .ok_or("no read-out contact")?;
    println!("{file}: fixed grid {} x {} nodes", grid.nr(), grid.nz());
    let n = ((u1 - u0) / step).round() as usize;
    let volts: Vec<f64> = (0..=n).map(|k| u0 + step * k as f64).collect();
    let mut q = Vec::new();
    let mut pockets = Vec::new();
    for &u in &volts {
        let sol = solve_fast(&mesh, &det, u, None)?;
        q.push(contact_charge_c(&mesh, &det, u, &sol, readout)?);
        pockets.push(sol.pockets.len());
    }
    let name = std::path::Path::new(file)
        .file_stem()
        .and_then(|s| s.to_str())
        .unwrap_or("detector");
    let out = repo_path("reports/pockets");
    let mut csv = String::from("voltage_V,c12_floating_pF,c12_quasi_static_pF,pockets\n");
    let mut rows = Vec::new();
    for k in 0..n {
        let mid = 0.5 * (volts[k] + volts[k + 1]);
        let qs = -(q[k + 1] - q[k]) / step * 1e12;
        let p = solve_point_on_grid(&det, mid, &s, grid.clone(), None)?;
        let pk = p.potential.pockets.len();
        csv.push_str(&format!("{mid},{},{qs},{pk}\n", p.c12_pf));
        rows.push((mid, p.c12_pf, qs, pk));
    }
    std::fs::write(out.join(format!("{name}-quasi-static.csv")), csv)?;
    let jump = |f: &dyn Fn(&Row) -> f64| {
        rows.windows(2)
            .map(|w| ((f(&w[1]) / f(&w[0]) - 1.0).abs(), w[0].0, w[1].0))
            .fold((0.0, 0.0, 0.0), |a, b| if b.0 > a.0 { b } else { a })
    };
    let (jf, af, bf) = jump(&|r| r.1);
    let (jq, aq, bq) = jump(&|r| r.2);
    println!("largest relative change between neighbouring biases ({step} V apart):");
    println!(
        "  floating pockets (weighting c12): {:.1}% ({af} -> {bf} V)",
        100.0 * jf
    );
    println!(
        "  quasi-static -dQ/dU:              {:.1}% ({aq} -> {bq} V)",
        100.0 * jq
    );
    for ext in ["svg", "png"] {
        let path = out.join(format!("{name}-quasi-static.{ext}"));
        if ext == "svg" {
            plot(
                SVGBackend::new(&path, (900, 600)).into_drawing_area(),
                name,
                &rows,
            )?;
        } else {
            plot(
                BitMapBackend::new(&path, (900, 600)).into_drawing_area(),
                name,
                &rows,
            )?;
        }
        println!("wrote {}", path.display());
    }
    Ok(())
}

type Row = (f64, f64, f64, usize);

fn plot<DB: DrawingBackend>(
    root: DrawingArea<DB, plotters::coord::Shift>,
    name: &str,
    rows: &[Row],
) -> Result<(), Box<dyn std::error::Error>>
where
    DB::ErrorType: 'static,
{
    root.fill(&WHITE)?;
    let (x0, x1) = (rows[0].0, rows[rows.len() - 1].0);
    let ymax = rows.iter().map(|r| r.1.max(r.2)).fold(0.0, f64::max) * 1.1;
    let mut chart = ChartBuilder::on(&root)
        .caption(
            format!("{name}: C-V across the pinch-off window (one fixed grid)"),
            ("sans-serif", 20),
        )
        .margin(15)
        .x_label_area_size(45)
        .y_label_area_size(60)
        .build_cartesian_2d(x0..x1, 0.0..ymax)?;
    chart
        .configure_mesh()
        .x_desc("bias U_B (V)")
        .y_desc("C (pF)")
        .draw()?;
    if let Some(first) = rows.iter().find(|r| r.3 > 0) {
        let x = first.0;
        chart
            .draw_series(std::iter::once(Rectangle::new(
                [(x, 0.0), (x1, ymax)],
                RGBColor(255, 200, 150).mix(0.25).filled(),
            )))?
            .label("pocket present (first at the shaded edge)")
            .legend(|(x, y)| {
                Rectangle::new(
                    [(x, y - 5), (x + 18, y + 5)],
                    RGBColor(255, 200, 150).filled(),
                )
            });
    }
    let blue = RGBColor(31, 119, 180);
    let red = RGBColor(214, 39, 40);
    chart
        .draw_series(LineSeries::new(
            rows.iter().map(|r| (r.0, r.1)),
            blue.stroke_width(2),
        ))?
        .label("c12, weighting potentials, pocket floating (small signal)")
        .legend(move |(x, y)| PathElement::new(vec![(x, y), (x + 18, y)], blue.stroke_width(2)));
    chart.draw_series(
        rows.iter()
            .map(|r| Circle::new((r.0, r.1), 3, blue.filled())),
    )?;
    chart
        .draw_series(LineSeries::new(
            rows.iter().map(|r| (r.0, r.2)),
            red.stroke_width(2),
        ))?
        .label("-dQ/dU of the nonlinear solutions (quasi-static, slow ramp)")
        .legend(move |(x, y)| PathElement::new(vec![(x, y), (x + 18, y)], red.stroke_width(2)));
    chart.draw_series(
        rows.iter()
            .map(|r| Cross::new((r.0, r.2), 4, red.stroke_width(1))),
    )?;
    chart
        .configure_series_labels()
        .position(SeriesLabelPosition::UpperRight)
        .background_style(WHITE.mix(0.9))
        .border_style(BLACK)
        .draw()?;
    root.present()?;
    Ok(())
}
