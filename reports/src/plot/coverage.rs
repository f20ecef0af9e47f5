//! Figures of a simulation-based-calibration study (Talts et al. 2018): the histograms of the
//! normalised ranks of the truths among the posterior draws, with the 99% band of a uniform rank;
//! the ECDF of the ranks against the uniform one with simultaneous 95% and 99% bands (Säilynoja,
//! Bürkner and Vehtari 2022: a panel tests its parameter, where the per-bin band of a histogram
//! does not); and the coverage of the smallest intervals against their nominal level, with the
//! 99% binomial band of a calibrated fit around the diagonal. Each as SVG and PNG.

use std::path::{Path, PathBuf};

use hpge_validation::CoverageReport;
use hpge_validation::studies::coverage::ecdf::{EcdfBand, ecdf_band, ecdf_difference, inside_band};
use hpge_validation::studies::coverage::{ParameterCoverage, binomial_interval};
use plotters::coord::Shift;
use plotters::prelude::*;
use plotters::style::text_anchor::{HPos, Pos, VPos};

use super::style::{PALETTE, err};
use crate::error::{Error, Result};

/// Bins of a rank histogram (fewer when L + 1 is smaller).
const RANK_BINS: usize = 20;
/// Probability mass of the bands.
const BAND_MASS: f64 = 0.99;
/// Panels per row of the rank figure.
const COLUMNS: usize = 3;
/// The 99% bands.
const BAND: RGBColor = RGBColor(215, 215, 215);
/// The 95% band of the ECDF figure (inside the 99% one).
const BAND_95: RGBColor = RGBColor(175, 175, 175);
/// Histogram bars.
const BARS: RGBColor = RGBColor(87, 153, 199);
/// The edges of a band drawn over the bars.
const BAND_EDGE: RGBColor = RGBColor(150, 150, 150);
/// A failed KS test in a panel title.
const FAIL: RGBColor = RGBColor(214, 39, 40);

/// Writes the figures of a coverage study into `dir` (created if missing), .svg and .png each;
/// returns the paths.
///
/// The figures: `ranks`, one panel per parameter with the histogram of the normalised ranks
/// rank/(L+1) in 20 bins, the expected count and its 99% binomial band, the KS p-value in the
/// panel title (red below the pass threshold 0.01/d); and `coverage`, the empirical coverage of
/// the smallest intervals against the nominal level per parameter, the diagonal and its 99%
/// binomial band for n = `report.n_truths`; and `ecdf`, one panel per parameter with the ECDF
/// difference F(z) - z of its ranks and the simultaneous 95% and 99% bands
/// ([`hpge_validation::studies::coverage::ecdf`]), the panel's title saying which band it
/// leaves. Every title starts with `title`.
pub fn coverage_figures(dir: &Path, report: &CoverageReport, title: &str) -> Result<Vec<PathBuf>> {
    let params = &report.parameters;
    if params.is_empty() {
        invalid!("the coverage report has no parameters to plot");
    }
    for p in params {
        if let Some(r) = p.ranks.iter().find(|&&r| r > report.ranks) {
            invalid!("{}: rank {r} exceeds L = {} draws", p.name, report.ranks);
        }
        if p.coverage_curve.len() != report.levels.len() {
            invalid!(
                "{}: {} coverage values for {} levels",
                p.name,
                p.coverage_curve.len(),
                report.levels.len()
            );
        }
    }
    std::fs::create_dir_all(dir).map_err(Error::io(dir, "cannot create the folder"))?;
    let mut out = Vec::new();
    let cols = COLUMNS.min(params.len());
    let rows = params.len().div_ceil(cols);
    let size = (1500, 110 + 330 * rows as u32);
    for ext in ["svg", "png"] {
        let p = dir.join(format!("ranks.{ext}"));
        let done: Result<()> = render!(&p, size, |root, _svg| ranks(&root, report, title, cols));
        done?;
        out.push(p);
    }
    let n = params.iter().map(|p| p.ranks.len()).max().unwrap_or(0);
    if n > 0 && report.ranks > 0 {
        let bands = [
            ecdf_band(n, report.ranks, 0.99),
            ecdf_band(n, report.ranks, 0.95),
        ];
        for ext in ["svg", "png"] {
            let p = dir.join(format!("ecdf.{ext}"));
            let done: Result<()> = render!(&p, size, |root, _svg| ecdf(
                &root, report, title, cols, &bands
            ));
            done?;
            out.push(p);
        }
    }
    for ext in ["svg", "png"] {
        let p = dir.join(format!("coverage.{ext}"));
        let done: Result<()> =
            render!(&p, (1000, 950), |root, _svg| coverage(&root, report, title));
        done?;
        out.push(p);
    }
    Ok(out)
}

/// "0.43", or "3.2e-4" below 0.01.
fn p_value(p: f64) -> String {
    if p.is_finite() && p > 0.0 && p < 0.01 {
        format!("{p:.1e}")
    } else {
        format!("{p:.2}")
    }
}

/// The probability of each of `bins` equal bins of rank/(L+1) under a uniform rank on 0..=L:
/// the share of the L + 1 rank values that fall into it (1/bins when bins divides L + 1).
fn bin_probabilities(l: usize, bins: usize) -> Vec<f64> {
    let mut p = vec![0.0; bins];
    for r in 0..=l {
        p[bin_of(r, l, bins)] += 1.0 / (l + 1) as f64;
    }
    p
}

/// The bin of rank r (0..=L) among `bins` equal bins of rank/(L+1).
fn bin_of(r: usize, l: usize, bins: usize) -> usize {
    (r * bins / (l + 1)).min(bins - 1)
}

/// The central `BAND_MASS` interval of k/n for k ~ Binomial(n, p), degenerate at p = 0 and 1.
fn band(n: usize, p: f64) -> [f64; 2] {
    if p <= 0.0 || p >= 1.0 || n == 0 {
        [p.clamp(0.0, 1.0); 2]
    } else {
        binomial_interval(n, p, BAND_MASS)
    }
}

/// A legend entry's symbol.
#[derive(Debug, Clone, Copy)]
enum Key {
    /// A filled box.
    Fill(RGBColor),
    /// A dashed line.
    Dashed(RGBColor),
    /// A solid line.
    Line(RGBColor),
}

/// Splits a one-row legend strip off the top of `area`, draws `keys` into it and returns the
/// rest.
fn key_strip<DB: DrawingBackend>(
    area: &DrawingArea<DB, Shift>,
    keys: &[(Key, String)],
) -> Result<DrawingArea<DB, Shift>> {
    let (strip, rest) = area.split_vertically(36);
    let font =
        TextStyle::from(("sans-serif", 17).into_font()).pos(Pos::new(HPos::Left, VPos::Center));
    let (mut x, y) = (24, 18);
    for (key, text) in keys {
        match *key {
            Key::Fill(c) => strip.draw(&Rectangle::new([(x, y - 8), (x + 24, y + 8)], c.filled())),
            Key::Line(c) => strip.draw(&PathElement::new(
                vec![(x, y), (x + 24, y)],
                c.stroke_width(3),
            )),
            Key::Dashed(c) => strip
                .draw(&PathElement::new(
                    vec![(x, y), (x + 9, y)],
                    c.stroke_width(3),
                ))
                .and_then(|_| {
                    strip.draw(&PathElement::new(
                        vec![(x + 15, y), (x + 24, y)],
                        c.stroke_width(3),
                    ))
                }),
        }
        .map_err(err)?;
        strip
            .draw(&Text::new(text.clone(), (x + 32, y), font.clone()))
            .map_err(err)?;
        let (tw, _) = strip.estimate_text_size(text, &font).map_err(err)?;
        x += 32 + tw as i32 + 36;
    }
    Ok(rest)
}

/// The grid of rank histograms.
fn ranks<DB: DrawingBackend>(
    root: &DrawingArea<DB, Shift>,
    report: &CoverageReport,
    title: &str,
    cols: usize,
) -> Result<()> {
    root.fill(&WHITE).map_err(err)?;
    let params = &report.parameters;
    let root = root
        .titled(
            &format!(
                "{title}: ranks of the truths among L = {} posterior draws ({} truths)",
                report.ranks, report.n_truths
            ),
            ("sans-serif", 24),
        )
        .map_err(err)?;
    let threshold = 0.01 / params.len() as f64;
    let keys = [
        (Key::Fill(BARS), "truths per bin"),
        (Key::Dashed(BLACK), "expected for uniform ranks"),
        (Key::Fill(BAND), "its 99% binomial band"),
    ];
    let mut keys: Vec<(Key, String)> = keys.map(|(k, t)| (k, t.to_string())).to_vec();
    keys.push((
        Key::Fill(FAIL),
        format!(
            "title in red: KS p < 0.01/{} = {}",
            params.len(),
            p_value(threshold)
        ),
    ));
    let body = key_strip(&root, &keys)?;
    let rows = params.len().div_ceil(cols);
    let panels = body.split_evenly((rows, cols));
    for (p, area) in params.iter().zip(&panels) {
        rank_panel(area, p, report.ranks, threshold)?;
    }
    Ok(())
}

/// The grid of ECDF-difference panels.
fn ecdf<DB: DrawingBackend>(
    root: &DrawingArea<DB, Shift>,
    report: &CoverageReport,
    title: &str,
    cols: usize,
    bands: &[EcdfBand; 2],
) -> Result<()> {
    root.fill(&WHITE).map_err(err)?;
    let params = &report.parameters;
    let root = root
        .titled(
            &format!(
                "{title}: ECDF of the ranks minus the uniform one (L = {}, {} truths)",
                report.ranks, report.n_truths
            ),
            ("sans-serif", 24),
        )
        .map_err(err)?;
    let keys = [
        (Key::Fill(BAND), "simultaneous 99% band".to_string()),
        (Key::Fill(BAND_95), "simultaneous 95% band".to_string()),
        (Key::Line(BARS), "F(z) - z of the truths' ranks".to_string()),
        (
            Key::Fill(FAIL),
            "title in red: leaves the 99% band".to_string(),
        ),
    ];
    let body = key_strip(&root, &keys)?;
    let rows = params.len().div_ceil(cols);
    let panels = body.split_evenly((rows, cols));
    let limit = params
        .iter()
        .flat_map(|p| ecdf_difference(&p.ranks, report.ranks))
        .chain(bands[0].upper.iter().copied())
        .chain(bands[0].lower.iter().map(|x| -x))
        .fold(0.01_f64, |a, x| a.max(x.abs()))
        * 1.1;
    for (p, area) in params.iter().zip(&panels) {
        ecdf_panel(area, p, report.ranks, bands, limit)?;
    }
    Ok(())
}

/// One parameter's ECDF difference over the two bands.
fn ecdf_panel<DB: DrawingBackend>(
    area: &DrawingArea<DB, Shift>,
    p: &ParameterCoverage,
    l: usize,
    bands: &[EcdfBand; 2],
    limit: f64,
) -> Result<()> {
    let (in99, in95) = (
        inside_band(&p.ranks, l, &bands[0]),
        inside_band(&p.ranks, l, &bands[1]),
    );
    let (word, color) = match (in99, in95) {
        (true, true) => ("inside both bands", BLACK),
        (true, false) => ("leaves the 95% band", BLACK),
        _ => ("leaves the 99% band", FAIL),
    };
    let mut chart = ChartBuilder::on(area)
        .margin(12)
        .margin_right(22)
        .caption(
            format!("{}: {word}", p.name),
            ("sans-serif", 19).into_font().color(&color),
        )
        .x_label_area_size(46)
        .y_label_area_size(70)
        .build_cartesian_2d(0.0..1.0, -limit..limit)
        .map_err(err)?;
    chart
        .configure_mesh()
        .x_desc("z = rank / (L + 1)")
        .y_desc("F(z) - z")
        .x_labels(6)
        .y_labels(7)
        .x_label_formatter(&|v| format!("{v:.1}"))
        // A label within rounding of 0 is "0.00", not "-0.00".
        .y_label_formatter(&|v| format!("{:.2}", if v.abs() < 5e-3 { 0.0 } else { *v }))
        .label_style(("sans-serif", 15))
        .axis_desc_style(("sans-serif", 17))
        .light_line_style(WHITE)
        .draw()
        .map_err(err)?;
    for (band, c) in bands.iter().zip([BAND, BAND_95]) {
        // The band at z = 0 and 1 is a point (F - z = 0 there).
        let upper = std::iter::once((0.0, 0.0))
            .chain(band.z.iter().copied().zip(band.upper.iter().copied()))
            .chain(std::iter::once((1.0, 0.0)));
        let lower: Vec<(f64, f64)> = band
            .z
            .iter()
            .copied()
            .zip(band.lower.iter().copied())
            .rev()
            .collect();
        let outline: Vec<(f64, f64)> = upper.chain(lower).collect();
        chart
            .draw_series(std::iter::once(Polygon::new(outline, c.filled())))
            .map_err(err)?;
    }
    chart
        .draw_series(LineSeries::new(
            [(0.0, 0.0), (1.0, 0.0)],
            BLACK.stroke_width(1),
        ))
        .map_err(err)?;
    let d = ecdf_difference(&p.ranks, l);
    let pts: Vec<(f64, f64)> = std::iter::once((0.0, 0.0))
        .chain(bands[0].z.iter().copied().zip(d))
        .chain(std::iter::once((1.0, 0.0)))
        .collect();
    chart
        .draw_series(LineSeries::new(pts, BARS.stroke_width(2)))
        .map_err(err)?;
    Ok(())
}

/// One parameter's rank histogram over the band and the expected count.
fn rank_panel<DB: DrawingBackend>(
    area: &DrawingArea<DB, Shift>,
    p: &ParameterCoverage,
    l: usize,
    threshold: f64,
) -> Result<()> {
    let bins = RANK_BINS.min(l + 1);
    let n = p.ranks.len();
    let mut counts = vec![0usize; bins];
    for &r in &p.ranks {
        counts[bin_of(r, l, bins)] += 1;
    }
    let prob = bin_probabilities(l, bins);
    let bands: Vec<[f64; 2]> = prob
        .iter()
        .map(|&q| band(n, q).map(|b| b * n as f64))
        .collect();
    let top = counts
        .iter()
        .map(|&c| c as f64)
        .chain(bands.iter().map(|b| b[1]))
        .fold(1.0, f64::max)
        * 1.12;
    let color = if p.ks_p < threshold { FAIL } else { BLACK };
    let caption = format!("{}, KS p = {}", p.name, p_value(p.ks_p));
    let mut chart = ChartBuilder::on(area)
        .margin(12)
        .margin_right(22)
        .caption(caption, ("sans-serif", 19).into_font().color(&color))
        .x_label_area_size(46)
        .y_label_area_size(58)
        .build_cartesian_2d(0.0..1.0, 0.0..top)
        .map_err(err)?;
    chart
        .configure_mesh()
        .x_desc("rank / (L + 1)")
        .y_desc("truths")
        .x_labels(6)
        .y_labels(6)
        .x_label_formatter(&|v| format!("{v:.1}"))
        .y_label_formatter(&|v| format!("{v:.0}"))
        .label_style(("sans-serif", 15))
        .axis_desc_style(("sans-serif", 17))
        .light_line_style(WHITE)
        .draw()
        .map_err(err)?;
    let w = 1.0 / bins as f64;
    let edge = |b: usize| b as f64 * w;
    chart
        .draw_series(
            bands.iter().enumerate().map(|(b, iv)| {
                Rectangle::new([(edge(b), iv[0]), (edge(b + 1), iv[1])], BAND.filled())
            }),
        )
        .map_err(err)?;
    chart
        .draw_series(
            counts
                .iter()
                .enumerate()
                .filter(|(_, c)| **c > 0)
                .map(|(b, &c)| {
                    Rectangle::new(
                        [(edge(b) + 0.1 * w, 0.0), (edge(b + 1) - 0.1 * w, c as f64)],
                        BARS.filled(),
                    )
                }),
        )
        .map_err(err)?;
    // The band's edges over the bars, so that a bar short of the lower edge shows.
    for side in 0..2 {
        let pts: Vec<(f64, f64)> = bands
            .iter()
            .enumerate()
            .flat_map(|(b, iv)| [(edge(b), iv[side]), (edge(b + 1), iv[side])])
            .collect();
        chart
            .draw_series(LineSeries::new(pts, BAND_EDGE.stroke_width(1)))
            .map_err(err)?;
    }
    let expected: Vec<(f64, f64)> = prob
        .iter()
        .enumerate()
        .flat_map(|(b, &q)| [(edge(b), q * n as f64), (edge(b + 1), q * n as f64)])
        .collect();
    chart
        .draw_series(DashedLineSeries::new(expected, 8, 5, BLACK.stroke_width(2)))
        .map_err(err)?;
    Ok(())
}

/// The title of a study's figures: its prior and where its data came from.
pub fn coverage_title(prior: &str, data_from: &str) -> String {
    match data_from {
        "exact" => format!("{prior} coverage, exact-solver data"),
        "" => format!("{prior} coverage"),
        other => format!("{prior} coverage, {other} data"),
    }
}

/// Draws the figures of the study in `dir` again from its `coverage.json` (into
/// `dir/figures`), e.g. after a change of the figures; the study itself is not run.
///
/// # Errors
/// A missing or unreadable `coverage.json` (named), and every error of [`coverage_figures`].
pub fn redraw_coverage(dir: &Path) -> Result<Vec<PathBuf>> {
    let file = dir.join("coverage.json");
    let v = crate::json_file::read_json(&file, "a coverage study's results")?;
    let report: CoverageReport =
        serde_json::from_value(v.clone()).map_err(|source| crate::Error::Json {
            file: file.clone(),
            what: "not a coverage study's coverage.json",
            source,
        })?;
    let title = coverage_title(
        v["inputs"]["prior"].as_str().unwrap_or("?"),
        v["data_from"].as_str().unwrap_or(""),
    );
    coverage_figures(&dir.join("figures"), &report, &title)
}

/// Coverage against nominal level, per parameter, over the diagonal and its band.
fn coverage<DB: DrawingBackend>(
    root: &DrawingArea<DB, Shift>,
    report: &CoverageReport,
    title: &str,
) -> Result<()> {
    root.fill(&WHITE).map_err(err)?;
    // The verdict per parameter, in the title and the legend.
    let d = report.parameters.len();
    let failures: Vec<Vec<String>> = report.parameters.iter().map(|p| p.failures(d)).collect();
    let failing: Vec<&str> = report
        .parameters
        .iter()
        .zip(&failures)
        .filter(|(_, f)| !f.is_empty())
        .map(|(p, _)| p.name.as_str())
        .collect();
    let verdict = if failing.is_empty() {
        format!("all {d} parameters pass")
    } else {
        format!("{} of {d} parameters pass (legend: why)", d - failing.len())
    };
    let mut sub = format!(
        "{verdict}; n = {} truths, L = {}",
        report.n_truths, report.ranks
    );
    if report.unconverged > 0 {
        sub += &format!(", {} unconverged", report.unconverged);
    }
    if report.skipped > 0 {
        sub += &format!(", {} skipped", report.skipped);
    }
    let root = root
        .titled(
            &format!("{title}: coverage of the smallest intervals"),
            ("sans-serif", 24),
        )
        .map_err(err)?;
    let mut chart = ChartBuilder::on(&root)
        .margin(20)
        .margin_right(30)
        .caption(sub, ("sans-serif", 18))
        .x_label_area_size(52)
        .y_label_area_size(70)
        .build_cartesian_2d(0.0..1.0, 0.0..1.0)
        .map_err(err)?;
    chart
        .configure_mesh()
        .x_desc("nominal level")
        .y_desc("fraction of truths inside the smallest interval")
        .x_labels(11)
        .y_labels(11)
        .x_label_formatter(&|v| format!("{v:.1}"))
        .y_label_formatter(&|v| format!("{v:.1}"))
        .label_style(("sans-serif", 16))
        .axis_desc_style(("sans-serif", 18))
        .light_line_style(WHITE)
        .draw()
        .map_err(err)?;
    // The exact binomial band of the converged truths at each of the study's levels, joined
    // between them (the band is the fraction of n truths inside a calibrated interval).
    let n = report
        .parameters
        .iter()
        .map(|p| p.ranks.len())
        .max()
        .unwrap_or(0)
        .max(1);
    let bands: Vec<(f64, [f64; 2])> = std::iter::once((0.0, [0.0, 0.0]))
        .chain(
            report
                .levels
                .iter()
                .filter(|l| l.is_finite() && **l > 0.0 && **l < 1.0)
                .map(|&l| (l, band(n, l))),
        )
        .chain(std::iter::once((1.0, [1.0, 1.0])))
        .collect();
    let outline: Vec<(f64, f64)> = bands
        .iter()
        .map(|(l, b)| (*l, b[1]))
        .chain(bands.iter().rev().map(|(l, b)| (*l, b[0])))
        .collect();
    chart
        .draw_series(std::iter::once(Polygon::new(outline, BAND.filled())))
        .map_err(err)?
        .label(format!("99% binomial band of a calibrated fit, n = {n}"))
        .legend(|(x, y)| Rectangle::new([(x, y - 6), (x + 20, y + 6)], BAND.filled()));
    chart
        .draw_series(DashedLineSeries::new(
            [(0.0, 0.0), (1.0, 1.0)],
            8,
            5,
            BLACK.stroke_width(2),
        ))
        .map_err(err)?
        .label("calibrated: y = x")
        .legend(|(x, y)| {
            EmptyElement::at((x, y))
                + PathElement::new(vec![(0, 0), (8, 0)], BLACK.stroke_width(2))
                + PathElement::new(vec![(12, 0), (20, 0)], BLACK.stroke_width(2))
        });
    for (k, p) in report.parameters.iter().enumerate() {
        let c = PALETTE[k % PALETTE.len()];
        let pts: Vec<(f64, f64)> = report
            .levels
            .iter()
            .zip(&p.coverage_curve)
            .map(|(l, v)| (*l, *v))
            .filter(|(l, v)| l.is_finite() && v.is_finite())
            .collect();
        chart
            .draw_series(LineSeries::new(pts.clone(), c.stroke_width(2)))
            .map_err(err)?
            .label(if failures[k].is_empty() {
                format!("{}: pass", p.name)
            } else {
                format!("{}: {}", p.name, failures[k].join("; "))
            })
            .legend(move |(x, y)| {
                EmptyElement::at((x, y))
                    + PathElement::new(vec![(0, 0), (20, 0)], c.stroke_width(2))
                    + Circle::new((10, 0), 4, c.filled())
            });
        chart
            .draw_series(pts.iter().map(|&q| Circle::new(q, 4, c.filled())))
            .map_err(err)?;
    }
    chart
        .configure_series_labels()
        .position(SeriesLabelPosition::UpperLeft)
        .label_font(("sans-serif", 16))
        .background_style(WHITE.mix(0.8))
        .border_style(BLACK)
        .draw()
        .map_err(err)
}

#[cfg(test)]
mod tests {
    use hpge_validation::studies::coverage::{COVERAGE_LEVELS, ks_uniform};

    use super::*;

    /// A 64-bit LCG (Knuth's MMIX constants): uniform draws on [0, 1).
    struct Lcg(u64);

    impl Lcg {
        fn uniform(&mut self) -> f64 {
            self.0 = self
                .0
                .wrapping_mul(6_364_136_223_846_793_005)
                .wrapping_add(1_442_695_040_888_963_407);
            (self.0 >> 11) as f64 / (1u64 << 53) as f64
        }
    }

    /// A synthetic study of `d` parameters and `n` truths ranked among `l` draws: uniform ranks,
    /// except parameter 1 (posterior too narrow: ranks pile up at the ends) and parameter 2
    /// (too wide: ranks pile up in the middle).
    fn report(d: usize, n: usize, l: usize) -> CoverageReport {
        let mut rng = Lcg(12345);
        let levels = COVERAGE_LEVELS.to_vec();
        let parameters: Vec<ParameterCoverage> = (0..d)
            .map(|j| {
                let u: Vec<f64> = (0..n)
                    .map(|_| {
                        let u = rng.uniform();
                        match j {
                            1 => {
                                0.5 + 0.5 * (2.0 * u - 1.0).signum() * (2.0 * u - 1.0).abs().sqrt()
                            }
                            2 => 0.5 + 0.5 * (2.0 * u - 1.0).powi(3),
                            _ => u,
                        }
                    })
                    .collect();
                let ranks: Vec<usize> = u
                    .iter()
                    .map(|u| ((u * (l + 1) as f64) as usize).min(l))
                    .collect();
                let inside = |level: f64| {
                    u.iter().filter(|u| (*u - 0.5).abs() <= level / 2.0).count() as f64 / n as f64
                };
                let coverage_curve: Vec<f64> = levels.iter().map(|&lv| inside(lv)).collect();
                ParameterCoverage {
                    name: format!("theta_{j}"),
                    ks_p: ks_uniform(&u),
                    coverage_683: inside(0.683),
                    coverage_955: inside(0.955),
                    expected_683: binomial_interval(n, 0.683, 0.99),
                    expected_955: binomial_interval(n, 0.955, 0.99),
                    coverage_curve,
                    ranks,
                }
            })
            .collect();
        let pass = parameters.iter().all(|p| p.ks_p > 0.01 / d as f64);
        CoverageReport {
            n_truths: n,
            parameters,
            pass,
            ranks: l,
            unconverged: 2,
            converged: n - 2,
            unconverged_sampler: None,
            skipped: 0,
            levels,
            seconds: 1.0,
            resumed: 0,
            truth_seconds: 2.0,
            exact_check: None,
            subsets: vec![],
        }
    }

    /// Writes the figures into a fresh temporary folder and checks both stems in both formats,
    /// none empty. HPGE_KEEP_FIGURES=1 keeps the folder.
    fn check(tag: &str, report: &CoverageReport) {
        let dir =
            std::env::temp_dir().join(format!("hpge-cv-coverage-{tag}-{}", std::process::id()));
        let paths = coverage_figures(&dir, report, &format!("{tag}, synthetic")).unwrap();
        assert_eq!(paths.len(), 6, "{paths:?}");
        for stem in ["ranks", "ecdf", "coverage"] {
            for ext in ["svg", "png"] {
                let p = dir.join(format!("{stem}.{ext}"));
                assert!(paths.contains(&p), "{} not listed", p.display());
                let len = std::fs::metadata(&p).map(|m| m.len()).unwrap_or(0);
                assert!(len > 0, "{} missing or empty", p.display());
            }
        }
        if std::env::var_os("HPGE_KEEP_FIGURES").is_none() {
            std::fs::remove_dir_all(&dir).unwrap();
        }
    }

    #[test]
    fn figures_of_a_synthetic_study() {
        check("B_Z", &report(3, 200, 99));
        check("B_RZ", &report(8, 200, 100));
    }

    #[test]
    fn uneven_bins_keep_their_expected_share() {
        let p = bin_probabilities(100, 20);
        assert!((p.iter().sum::<f64>() - 1.0).abs() < 1e-12);
        assert!((p[0] - 6.0 / 101.0).abs() < 1e-12);
        assert!(
            bin_probabilities(99, 20)
                .iter()
                .all(|q| (q - 0.05).abs() < 1e-12)
        );
        assert_eq!(bin_of(100, 100, 20), 19);
    }

    #[test]
    fn bad_reports_are_refused_before_drawing() {
        let dir = std::env::temp_dir().join("hpge-cv-coverage-never-written");
        let mut r = report(3, 50, 20);
        r.parameters[0].ranks[0] = 21;
        assert!(coverage_figures(&dir, &r, "x").is_err());
        let mut r = report(3, 50, 20);
        r.parameters[1].coverage_curve.pop();
        assert!(coverage_figures(&dir, &r, "x").is_err());
        r.parameters.clear();
        assert!(coverage_figures(&dir, &r, "x").is_err());
        assert!(!dir.exists());
    }
}
