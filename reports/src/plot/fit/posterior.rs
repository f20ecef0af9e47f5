//! Figures of the draws: marginals, 2D marginals of pairs, traces.

use hpge_inference::Fit;
use hpge_inference::fit::{LEVELS, ParameterSummary};
use plotters::coord::Shift;
use plotters::prelude::*;

use super::layout::{
    Axes, Key, LEVEL_COLORS, OUTSIDE, PRIOR, TRUTH, axis_label, draw_axes, grid, key_strip, padded,
    ticks, view_range,
};
use crate::error::Result;
use crate::plot::colormap::t_color;
use crate::plot::style::PALETTE;
use crate::plot::style::err;

/// Bins of a 1D marginal.
const BINS_1D: usize = 60;
/// Bins per axis of a 2D marginal.
const BINS_2D: usize = 50;
/// Most plotted points per chain in a trace.
const TRACE_POINTS: usize = 2000;

/// All chains' draws of parameter j.
fn draws_of(fit: &Fit, j: usize) -> Vec<f64> {
    fit.samples
        .chains
        .iter()
        .flat_map(|c| c.theta.iter().map(move |t| t[j]))
        .collect()
}

/// The index of the narrowest level whose smallest intervals (mapped onto the panel's axis by
/// `view`, an increasing map) hold the axis value x.
fn level_of(p: &ParameterSummary, x: f64, view: &dyn PanelView) -> Option<usize> {
    LEVELS.iter().position(|l| {
        p.smallest_intervals.get(&format!("{l}")).is_some_and(|iv| {
            iv.iter()
                .any(|[a, b]| (view.map(*a)..=view.map(*b)).contains(&x))
        })
    })
}

/// The legend entries of the markers: global mode, truth (where any value of it is known).
fn marker_keys(truth: Option<&[f64]>, mode: Key) -> Vec<(Key, String)> {
    let mut keys = vec![(mode, "global mode".to_string())];
    if truth.is_some_and(|t| t.iter().any(|v| v.is_finite())) {
        keys.push((Key::Dashed(TRUTH), "truth".to_string()));
    }
    keys
}

/// The grid of 1D marginals: histogram coloured by the smallest intervals, prior, mode, truth.
///
/// With `zeta`, the transform coordinates y (parameters named y... of unit 1) are shown as the
/// density zeta = zeta(T(y)) in 1e10 cm^-3 (the paper's Figs. 21 and 26): the transform is
/// increasing, so draws, smallest intervals, mode and truth map point by point and the prior's
/// density becomes p(y(zeta)) dy/dzeta.
pub(super) fn marginals<DB: DrawingBackend>(
    root: &DrawingArea<DB, Shift>,
    fit: &Fit,
    truth: Option<&[f64]>,
    title: &str,
    cols: usize,
    zeta: bool,
) -> Result<()> {
    root.fill(&WHITE).map_err(err)?;
    let params = &fit.summary.parameters;
    let n: usize = fit.samples.chains.iter().map(|c| c.theta.len()).sum();
    let root = root
        .titled(
            &format!(
                "{title}: marginal posteriors{} ({n} draws, {} chains)",
                if zeta { " of the densities" } else { "" },
                fit.samples.chains.len()
            ),
            ("sans-serif", 24),
        )
        .map_err(err)?;
    let mut keys: Vec<(Key, String)> = LEVELS
        .iter()
        .zip(LEVEL_COLORS)
        .map(|(l, c)| (Key::Fill(c), format!("{:.1}% smallest interval", 100.0 * l)))
        .collect();
    keys.push((Key::Line(PRIOR), "prior".into()));
    keys.extend(marker_keys(truth, Key::Line(BLACK)));
    let body = key_strip(&root, &keys)?;
    let (rows, cols) = grid(params.len(), cols);
    let panels = body.split_evenly((rows, cols));
    for (j, (p, area)) in params.iter().zip(&panels).enumerate() {
        let t = truth.map(|t| t[j]).filter(|t| t.is_finite());
        if zeta && is_density_coordinate(p) {
            marginal(area, &ZetaView::of(p), &draws_of(fit, j), t)?;
        } else {
            marginal(area, &Identity(p), &draws_of(fit, j), t)?;
        }
    }
    Ok(())
}

/// Whether a parameter is a transform coordinate y of the impurity density (the priors name
/// them y..., dimensionless): shown as zeta in the density marginals.
pub(super) fn is_density_coordinate(p: &ParameterSummary) -> bool {
    p.name.starts_with('y') && matches!(p.unit.trim(), "" | "1")
}

/// How a marginal panel shows its parameter: the axis, the map of values onto it and the
/// prior's density there.
trait PanelView {
    fn summary(&self) -> &ParameterSummary;
    fn label(&self) -> String;
    /// The parameter's value on the axis.
    fn map(&self, x: f64) -> f64;
    /// The prior's density at axis value v (with the Jacobian of the map).
    fn prior_pdf(&self, v: f64) -> f64;
    /// Whether the view spans the central 99% of the draws rather than all of them (a map
    /// with long tails, such as zeta's exponential one, would squeeze the draws to a spike).
    fn central_view(&self) -> bool {
        false
    }
}

struct Identity<'a>(&'a ParameterSummary);

impl PanelView for Identity<'_> {
    fn summary(&self) -> &ParameterSummary {
        self.0
    }
    fn label(&self) -> String {
        axis_label(self.0)
    }
    fn map(&self, x: f64) -> f64 {
        x
    }
    fn prior_pdf(&self, v: f64) -> f64 {
        self.0.prior.ln_pdf(v, self.0.support).exp()
    }
}

/// y shown as zeta(T(y)) in 1e10 cm^-3.
struct ZetaView<'a> {
    p: &'a ParameterSummary,
    t: hpge_solver::impurity::LogTransform,
}

impl<'a> ZetaView<'a> {
    fn of(p: &'a ParameterSummary) -> Self {
        Self {
            p,
            t: hpge_solver::impurity::LogTransform::default(),
        }
    }
}

impl PanelView for ZetaView<'_> {
    fn summary(&self) -> &ParameterSummary {
        self.p
    }
    fn label(&self) -> String {
        let bound = if self.p.at_prior_bound.is_empty() {
            ""
        } else {
            " (at prior bound)"
        };
        format!("zeta of {} [1e10 cm^-3]{bound}", self.p.name)
    }
    fn map(&self, y: f64) -> f64 {
        self.t.zeta_cm3_of_y(y) / 1e10
    }
    fn central_view(&self) -> bool {
        true
    }
    fn prior_pdf(&self, v: f64) -> f64 {
        // p(zeta) = p(y(zeta)) dy/dzeta, dy/dzeta by a central difference of the inverse.
        let y_of = |v: f64| self.t.y_of_zeta_cm3(v * 1e10).ok();
        let h = 1e-6 * v.abs().max(1e-3);
        match (y_of(v), y_of(v - h), y_of(v + h)) {
            (Some(y), Some(a), Some(b)) if b > a => {
                self.p.prior.ln_pdf(y, self.p.support).exp() * (b - a) / (2.0 * h)
            }
            _ => f64::NAN,
        }
    }
}

fn marginal<DB: DrawingBackend>(
    area: &DrawingArea<DB, Shift>,
    view: &dyn PanelView,
    draws: &[f64],
    truth: Option<f64>,
) -> Result<()> {
    let p = view.summary();
    let draws: Vec<f64> = draws.iter().map(|&x| view.map(x)).collect();
    let truth = truth.map(|t| view.map(t));
    let support = [view.map(p.support[0]), view.map(p.support[1])];
    let m = view.map(p.global_mode);
    let extra: Vec<f64> = [Some(m), truth].into_iter().flatten().collect();
    let (lo, hi) = if view.central_view() {
        let mut sorted = draws.clone();
        sorted.sort_by(f64::total_cmp);
        let q = |f: f64| sorted[((sorted.len() - 1) as f64 * f).round() as usize];
        view_range(&[q(0.005), q(0.995)], &extra, support)
    } else {
        view_range(&draws, &extra, support)
    };
    // A global mode at the view's edge (a domain edge: d_Li at its prior's bound) would hide
    // behind the axis: the view reaches 3% beyond it there.
    let edge = 0.015 * (hi - lo);
    let lo = if (m - lo).abs() <= edge {
        lo - 0.03 * (hi - lo)
    } else {
        lo
    };
    let hi = if (hi - m).abs() <= edge {
        hi + 0.03 * (hi - lo)
    } else {
        hi
    };
    let w = (hi - lo) / BINS_1D as f64;
    let mut h = vec![0.0; BINS_1D];
    for &v in &draws {
        let k = ((v - lo) / w).floor();
        if k >= 0.0 && (k as usize) < BINS_1D {
            h[k as usize] += 1.0;
        }
    }
    let norm = 1.0 / (draws.len() as f64 * w);
    h.iter_mut().for_each(|c| *c *= norm);
    let prior: Vec<(f64, f64)> = (0..=300)
        .map(|i| lo + (hi - lo) * i as f64 / 300.0)
        .map(|x| (x, view.prior_pdf(x)))
        .filter(|(_, y)| y.is_finite())
        .collect();
    let top = h
        .iter()
        .copied()
        .chain(prior.iter().map(|q| q.1))
        .fold(0.0, f64::max)
        .max(1e-300)
        * 1.08;
    // Room for the longest density label (a posterior squeezed against an edge reaches 1e5).
    let label_chars = ticks(top)(&top).len() as f64;
    let mut chart = ChartBuilder::on(area)
        .margin(12)
        .margin_right(22)
        .x_label_area_size(48)
        .y_label_area_size((26.0 + 8.5 * label_chars).max(62.0) as u32)
        .build_cartesian_2d(lo..hi, 0.0..top)
        .map_err(err)?;
    draw_axes(
        &mut chart,
        Axes {
            desc: (&view.label(), "posterior density"),
            span: (hi - lo, top),
            labels: Some((6, 6)),
            font: (15, 17),
        },
    )?;
    chart
        .draw_series(
            h.iter()
                .enumerate()
                .filter(|(_, c)| **c > 0.0)
                .map(|(i, &c)| {
                    let x0 = lo + i as f64 * w;
                    let color =
                        level_of(p, x0 + 0.5 * w, view).map_or(OUTSIDE, |l| LEVEL_COLORS[l]);
                    Rectangle::new([(x0, 0.0), (x0 + w, c)], color.filled())
                }),
        )
        .map_err(err)?;
    let outline = h.iter().enumerate().flat_map(|(i, &c)| {
        let x0 = lo + i as f64 * w;
        [(x0, c), (x0 + w, c)]
    });
    let outline: Vec<(f64, f64)> = std::iter::once((lo, 0.0))
        .chain(outline)
        .chain(std::iter::once((hi, 0.0)))
        .collect();
    chart
        .draw_series(LineSeries::new(
            outline,
            RGBColor(70, 70, 70).stroke_width(1),
        ))
        .map_err(err)?;
    chart
        .draw_series(LineSeries::new(prior, PRIOR.stroke_width(2)))
        .map_err(err)?;
    chart
        .draw_series(LineSeries::new([(m, 0.0), (m, top)], BLACK.stroke_width(3)))
        .map_err(err)?;
    if let Some(t) = truth {
        chart
            .draw_series(DashedLineSeries::new(
                [(t, 0.0), (t, top)],
                8,
                5,
                TRUTH.stroke_width(2),
            ))
            .map_err(err)?;
    }
    Ok(())
}

/// The 2D marginal of parameters a and b: density map, colour bar, mode and truth.
pub(super) fn pair<DB: DrawingBackend>(
    root: &DrawingArea<DB, Shift>,
    fit: &Fit,
    (a, b): (usize, usize),
    truth: Option<&[f64]>,
    title: &str,
) -> Result<()> {
    root.fill(&WHITE).map_err(err)?;
    let (pa, pb) = (&fit.summary.parameters[a], &fit.summary.parameters[b]);
    let root = root
        .titled(
            &format!("{title}: 2D marginal of {} and {}", pa.name, pb.name),
            ("sans-serif", 24),
        )
        .map_err(err)?;
    let tr = truth
        .map(|t| (t[a], t[b]))
        .filter(|t| t.0.is_finite() && t.1.is_finite());
    let mut keys = marker_keys(None, Key::Cross(BLACK));
    if tr.is_some() {
        keys.push((Key::Dot(TRUTH), "truth".into()));
    }
    let body = key_strip(&root, &keys)?;
    let (xs, ys) = (draws_of(fit, a), draws_of(fit, b));
    let extra =
        |m: f64, t: Option<f64>| -> Vec<f64> { [Some(m), t].into_iter().flatten().collect() };
    let (x0, x1) = view_range(&xs, &extra(pa.global_mode, tr.map(|t| t.0)), pa.support);
    let (y0, y1) = view_range(&ys, &extra(pb.global_mode, tr.map(|t| t.1)), pb.support);
    let (wx, wy) = ((x1 - x0) / BINS_2D as f64, (y1 - y0) / BINS_2D as f64);
    let mut h = vec![0.0; BINS_2D * BINS_2D];
    for (&x, &y) in xs.iter().zip(&ys) {
        let (i, k) = (((x - x0) / wx).floor(), ((y - y0) / wy).floor());
        if i >= 0.0 && k >= 0.0 && (i as usize) < BINS_2D && (k as usize) < BINS_2D {
            h[i as usize * BINS_2D + k as usize] += 1.0;
        }
    }
    let norm = 1.0 / (xs.len() as f64 * wx * wy);
    h.iter_mut().for_each(|c| *c *= norm);
    let top = h.iter().copied().fold(0.0, f64::max).max(1e-300);
    let width = body.dim_in_pixel().0;
    let (left, bar) = body.split_horizontally(width - 150);
    let mut chart = ChartBuilder::on(&left)
        .margin(15)
        .x_label_area_size(52)
        .y_label_area_size(72)
        .build_cartesian_2d(x0..x1, y0..y1)
        .map_err(err)?;
    draw_axes(
        &mut chart,
        Axes {
            desc: (&axis_label(pa), &axis_label(pb)),
            span: (x1 - x0, y1 - y0),
            labels: None,
            font: (16, 18),
        },
    )?;
    chart
        .draw_series(
            h.iter()
                .enumerate()
                .filter(|(_, c)| **c > 0.0)
                .map(|(n, &c)| {
                    let (i, k) = ((n / BINS_2D) as f64, (n % BINS_2D) as f64);
                    let (xa, ya) = (x0 + i * wx, y0 + k * wy);
                    Rectangle::new([(xa, ya), (xa + wx, ya + wy)], t_color(c / top, 0).filled())
                }),
        )
        .map_err(err)?;
    chart
        .draw_series(std::iter::once(Cross::new(
            (pa.global_mode, pb.global_mode),
            9,
            BLACK.stroke_width(3),
        )))
        .map_err(err)?;
    if let Some(t) = tr {
        chart
            .draw_series([
                Circle::new(t, 7, TRUTH.filled()),
                Circle::new(t, 7, WHITE.stroke_width(1)),
            ])
            .map_err(err)?;
    }
    // The colour bar, aligned with the plot area.
    let mut cb = ChartBuilder::on(&bar)
        .margin(15)
        .margin_left(5)
        .x_label_area_size(52)
        .right_y_label_area_size(85)
        .build_cartesian_2d(0.0..1.0, 0.0..top)
        .map_err(err)?;
    cb.configure_mesh()
        .disable_mesh()
        .x_labels(0)
        .y_labels(8)
        .y_desc("density")
        .y_label_formatter(&ticks(top))
        .label_style(("sans-serif", 14))
        .axis_desc_style(("sans-serif", 16))
        .draw()
        .map_err(err)?;
    cb.draw_series((0..200).map(|i| {
        let (u0, u1) = (i as f64 / 200.0, (i + 1) as f64 / 200.0);
        Rectangle::new([(0.0, u0 * top), (1.0, u1 * top)], t_color(u1, 0).filled())
    }))
    .map_err(err)?;
    Ok(())
}

/// Per parameter, draw index against value, one colour per chain.
pub(super) fn traces<DB: DrawingBackend>(
    root: &DrawingArea<DB, Shift>,
    fit: &Fit,
    truth: Option<&[f64]>,
    title: &str,
    cols: usize,
) -> Result<()> {
    root.fill(&WHITE).map_err(err)?;
    let chains = &fit.samples.chains;
    let root = root
        .titled(
            &format!("{title}: traces of the kept draws"),
            ("sans-serif", 24),
        )
        .map_err(err)?;
    let mut keys: Vec<(Key, String)> = (0..chains.len())
        .map(|c| {
            (
                Key::Line(PALETTE[c % PALETTE.len()]),
                format!("chain {}", c + 1),
            )
        })
        .collect();
    keys.extend(marker_keys(truth, Key::Line(BLACK)));
    let body = key_strip(&root, &keys)?;
    let params = &fit.summary.parameters;
    let (rows, cols) = grid(params.len(), cols);
    let panels = body.split_evenly((rows, cols));
    let len = chains
        .iter()
        .map(|c| c.theta.len())
        .max()
        .unwrap_or(1)
        .max(2);
    let step = len.div_ceil(TRACE_POINTS);
    for (j, (p, area)) in params.iter().zip(&panels).enumerate() {
        let t = truth.map(|t| t[j]).filter(|t| t.is_finite());
        let values = chains.iter().flat_map(|c| c.theta.iter().map(|d| d[j]));
        let (lo, hi) = padded(values.chain([p.global_mode]).chain(t), 0.04);
        let mut chart = ChartBuilder::on(area)
            .margin(10)
            .margin_right(20)
            .x_label_area_size(40)
            .y_label_area_size(70)
            .build_cartesian_2d(0.0..(len - 1) as f64, lo..hi)
            .map_err(err)?;
        draw_axes(
            &mut chart,
            Axes {
                desc: ("draw", &axis_label(p)),
                span: (len as f64, hi - lo),
                labels: Some((6, 5)),
                font: (14, 16),
            },
        )?;
        for (c, chain) in chains.iter().enumerate() {
            let color = PALETTE[c % PALETTE.len()].mix(0.75);
            let pts = chain
                .theta
                .iter()
                .enumerate()
                .step_by(step)
                .map(|(i, d)| (i as f64, d[j]));
            chart
                .draw_series(LineSeries::new(pts, color.stroke_width(1)))
                .map_err(err)?;
        }
        let end = (len - 1) as f64;
        let m = p.global_mode;
        chart
            .draw_series(LineSeries::new([(0.0, m), (end, m)], BLACK.stroke_width(2)))
            .map_err(err)?;
        if let Some(t) = t {
            chart
                .draw_series(DashedLineSeries::new(
                    [(0.0, t), (end, t)],
                    10,
                    6,
                    TRUTH.stroke_width(2),
                ))
                .map_err(err)?;
        }
    }
    Ok(())
}
