//! Figures of a Bayesian fit (paper, section 8): the marginal posteriors with their smallest
//! intervals and the prior, 2D marginals of chosen pairs, the posterior predictive of c_p - c_m
//! against the bias, the impurity density at the global mode along z and r, and the chains'
//! traces. Each as SVG and PNG, in BAT.jl's colours (green, yellow and red for the 68.3, 95.5 and
//! 99.7% intervals).

use std::path::{Path, PathBuf};

use anyhow::{Context as _, Result, bail};
use hpge_inference::Fit;
use hpge_inference::fit::ParameterSummary;
use plotters::coord::Shift;
use plotters::prelude::*;
use plotters::style::text_anchor::{HPos, Pos, VPos};

use super::err;

mod curves;
mod posterior;

/// zeta (cm^-3) along one line through the detector at the global mode.
#[derive(Debug, Clone, PartialEq)]
pub struct ZetaProfile {
    /// Legend entry, e.g. "r = 20 mm".
    pub label: String,
    /// Position along the line (z or r), mm.
    pub x_mm: Vec<f64>,
    /// Net impurity density at those positions, cm^-3.
    pub zeta_cm3: Vec<f64>,
}

/// zeta(z) at several radii and zeta(r) at several heights.
#[derive(Debug, Clone, PartialEq, Default)]
pub struct ZetaAtMode {
    /// Profiles along z (one per radius); `zeta-z` is skipped when empty.
    pub along_z: Vec<ZetaProfile>,
    /// Profiles along r (one per height); `zeta-r` is skipped when empty.
    pub along_r: Vec<ZetaProfile>,
}

/// Writes `$stem.svg` and `$stem.png` into `$dir` by `$body` (which sees the drawing area as
/// `$root`) and pushes both paths onto `$out`.
macro_rules! both {
    ($out:expr, $dir:expr, $stem:expr, $size:expr, |$root:ident| $body:expr) => {{
        for ext in ["svg", "png"] {
            let p = $dir.join(format!("{}.{ext}", $stem));
            let one = |f: Result<()>| f;
            one(render!(&p, $size, |$root, _svg| $body))?;
            $out.push(p);
        }
    }};
}

/// Writes every figure of a fit into `dir` (created if missing), each as .svg and .png; returns the paths written.
///
/// The figures: `marginals`, `posterior-2d-<nameA>-<nameB>` per pair of parameter indices in
/// `pairs`, `predictive`, `zeta-z` and `zeta-r` (each skipped when it has no profiles) and
/// `traces`. `truth` (one value per parameter; NaN where unknown) is marked where given; every
/// title starts with `title`.
pub fn fit_figures(
    dir: &Path,
    fit: &Fit,
    zeta: &ZetaAtMode,
    pairs: &[(usize, usize)],
    truth: Option<&[f64]>,
    title: &str,
) -> Result<Vec<PathBuf>> {
    let params = &fit.summary.parameters;
    let d = params.len();
    if d == 0 {
        bail!("the fit has no parameters to plot");
    }
    let draws: usize = fit.samples.chains.iter().map(|c| c.theta.len()).sum();
    if draws == 0 {
        bail!("the fit has no draws to plot");
    }
    let all_d = fit.samples.chains.iter().flat_map(|c| &c.theta);
    if let Some(t) = all_d.clone().find(|t| t.len() != d) {
        bail!("a draw has {} values, the summary {d} parameters", t.len());
    }
    if let Some(t) = truth
        && t.len() != d
    {
        bail!("the truth has {} values, the fit {d} parameters", t.len());
    }
    for &(a, b) in pairs {
        if a >= d || b >= d || a == b {
            bail!("the pair ({a}, {b}) needs two different parameter indices below {d}");
        }
    }
    std::fs::create_dir_all(dir)
        .with_context(|| format!("cannot create the folder {}", dir.display()))?;
    let mut out = Vec::new();
    let (rows, cols) = grid(d, 3);
    let size = (1500, 100 + 380 * rows as u32);
    both!(out, dir, "marginals", size, |root| posterior::marginals(
        &root, fit, truth, title, cols
    ));
    for &(a, b) in pairs {
        let stem = format!(
            "posterior-2d-{}-{}",
            file_part(&params[a].name),
            file_part(&params[b].name)
        );
        both!(out, dir, stem, (1000, 860), |root| posterior::pair(
            &root,
            fit,
            (a, b),
            truth,
            title
        ));
    }
    if !fit.predictive.voltage_v.is_empty() {
        both!(out, dir, "predictive", (1200, 760), |root| {
            curves::predictive(&root, &fit.predictive, title)
        });
    }
    for (stem, profiles, axis) in [
        ("zeta-z", &zeta.along_z, "z"),
        ("zeta-r", &zeta.along_r, "r"),
    ] {
        if !profiles.is_empty() {
            both!(out, dir, stem, (1100, 720), |root| curves::zeta(
                &root, profiles, axis, title
            ));
        }
    }
    let cols = if d <= 4 { 1 } else { 3 };
    let (rows, _) = grid(d, cols);
    let size = (1500, 110 + 240 * rows as u32);
    both!(out, dir, "traces", size, |root| posterior::traces(
        &root, fit, truth, title, cols
    ));
    Ok(out)
}

/// Rows and columns of a grid of `n` panels with at most `cols` columns.
fn grid(n: usize, cols: usize) -> (usize, usize) {
    let cols = cols.min(n).max(1);
    (n.div_ceil(cols), cols)
}

/// A parameter name as part of a file name (anything but letters, digits, '-' and '_' as '_').
fn file_part(name: &str) -> String {
    name.chars()
        .map(|c| {
            if c.is_ascii_alphanumeric() || c == '-' || c == '_' {
                c
            } else {
                '_'
            }
        })
        .collect()
}

/// "name [unit]", or the name alone for a dimensionless parameter (unit "1" or empty).
fn axis_label(p: &ParameterSummary) -> String {
    match p.unit.trim() {
        "" | "1" => p.name.clone(),
        u => format!("{} [{u}]", p.name),
    }
}

/// Fill colours of the 68.3, 95.5 and 99.7% intervals (LEVELS order), as in BAT.jl's plots.
const LEVEL_COLORS: [RGBColor; 3] = [
    RGBColor(77, 175, 74),
    RGBColor(255, 210, 60),
    RGBColor(235, 95, 75),
];
/// Histogram bins outside every interval.
const OUTSIDE: RGBColor = RGBColor(200, 200, 200);
/// The prior.
const PRIOR: RGBColor = RGBColor(31, 119, 180);
/// The truth (dashed).
const TRUTH: RGBColor = RGBColor(118, 42, 131);
/// One colour per chain, profile or parameter (tab10); the coverage figures use it too.
pub(super) const PALETTE: [RGBColor; 10] = [
    RGBColor(31, 119, 180),
    RGBColor(255, 127, 14),
    RGBColor(44, 160, 44),
    RGBColor(214, 39, 40),
    RGBColor(148, 103, 189),
    RGBColor(140, 86, 75),
    RGBColor(227, 119, 194),
    RGBColor(127, 127, 127),
    RGBColor(188, 189, 34),
    RGBColor(23, 190, 207),
];

/// [lo, hi] around `values` and `extra` (padded by 5%), within `support`; the whole support when
/// the values span more than half of it.
fn view_range(values: &[f64], extra: &[f64], support: [f64; 2]) -> (f64, f64) {
    let (mut lo, mut hi) = values
        .iter()
        .chain(extra)
        .filter(|v| v.is_finite())
        .fold((f64::INFINITY, f64::NEG_INFINITY), |(a, b), &v| {
            (a.min(v), b.max(v))
        });
    if !lo.is_finite() {
        (lo, hi) = (0.0, 1.0);
    }
    let span = support[1] - support[0];
    if span.is_finite() && span > 0.0 && hi - lo > 0.5 * span {
        return (support[0], support[1]);
    }
    let pad = if hi > lo {
        0.05 * (hi - lo)
    } else {
        1e-3 * lo.abs().max(1.0)
    };
    let (lo, hi) = (lo - pad, hi + pad);
    if support[0] < support[1] {
        (lo.max(support[0]), hi.min(support[1]))
    } else {
        (lo, hi)
    }
}

/// Padded [lo, hi] around finite values (an empty or flat set gets a unit or 10% span).
fn padded(values: impl Iterator<Item = f64>, frac: f64) -> (f64, f64) {
    let (lo, hi) = values
        .filter(|v| v.is_finite())
        .fold((f64::INFINITY, f64::NEG_INFINITY), |(a, b), v| {
            (a.min(v), b.max(v))
        });
    if !lo.is_finite() {
        return (-1.0, 1.0);
    }
    let pad = if hi > lo {
        frac * (hi - lo)
    } else {
        0.1 * lo.abs().max(1e-12)
    };
    (lo - pad, hi + pad)
}

/// A tick-label formatter for an axis spanning `span`: as many decimals as a step of about
/// span/6 needs (none for steps of 1 and more), exponent notation for very small or large steps.
fn ticks(span: f64) -> impl Fn(&f64) -> String {
    let step = (span / 6.0).abs();
    let exp = !(1e-4..1e6).contains(&step);
    let decimals = (-step.log10().floor()).max(0.0) as usize;
    move |v: &f64| {
        if exp {
            format!("{v:.1e}")
        } else {
            format!("{v:.decimals$}")
        }
    }
}

/// A legend entry's symbol.
#[derive(Debug, Clone, Copy)]
enum Key {
    /// A filled box.
    Fill(RGBColor),
    /// A solid line.
    Line(RGBColor),
    /// A dashed line.
    Dashed(RGBColor),
    /// A filled dot.
    Dot(RGBColor),
    /// A cross.
    Cross(RGBColor),
}

const KEY_FONT: (&str, u32) = ("sans-serif", 17);
const KEY_ROW_H: i32 = 26;

/// Positions (x, row) of the entries of a legend strip `width` pixels wide.
fn key_layout<DB: DrawingBackend>(
    area: &DrawingArea<DB, Shift>,
    keys: &[(Key, String)],
    width: i32,
) -> Result<Vec<(i32, i32)>> {
    let font = TextStyle::from(KEY_FONT.into_font());
    let (mut x, mut row) = (20, 0);
    let mut out = Vec::with_capacity(keys.len());
    for (_, text) in keys {
        let (tw, _) = area.estimate_text_size(text, &font).map_err(err)?;
        let w = 34 + tw as i32;
        if x > 20 && x + w > width - 10 {
            (x, row) = (20, row + 1);
        }
        out.push((x, row));
        x += w + 30;
    }
    Ok(out)
}

/// Splits a legend strip off the top of `area`, draws `keys` into it and returns the rest.
fn key_strip<DB: DrawingBackend>(
    area: &DrawingArea<DB, Shift>,
    keys: &[(Key, String)],
) -> Result<DrawingArea<DB, Shift>> {
    let width = area.dim_in_pixel().0 as i32;
    let at = key_layout(area, keys, width)?;
    let rows = at.last().map_or(0, |p| p.1 + 1);
    let (strip, rest) = area.split_vertically(rows * KEY_ROW_H + 10);
    let font = TextStyle::from(KEY_FONT.into_font()).pos(Pos::new(HPos::Left, VPos::Center));
    for ((key, text), &(x, row)) in keys.iter().zip(&at) {
        let y = row * KEY_ROW_H + KEY_ROW_H / 2 + 4;
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
            Key::Dot(c) => strip.draw(&Circle::new((x + 12, y), 5, c.filled())),
            Key::Cross(c) => strip.draw(&Cross::new((x + 12, y), 7, c.stroke_width(3))),
        }
        .map_err(err)?;
        strip
            .draw(&Text::new(text.clone(), (x + 32, y), font.clone()))
            .map_err(err)?;
    }
    Ok(rest)
}

#[cfg(test)]
mod tests;
