//! Figures of a Bayesian fit (paper, section 8): the marginal posteriors with their smallest
//! intervals and the prior, 2D marginals of chosen pairs, the posterior predictive of c_p - c_m
//! against the bias, the impurity density at the global mode along z and r, and the chains'
//! traces. Each as SVG and PNG, in BAT.jl's colours (green, yellow and red for the 68.3, 95.5 and
//! 99.7% intervals).

use std::path::{Path, PathBuf};

use hpge_inference::Fit;
use plotters::prelude::*;

use crate::error::{Error, Result};

mod curves;
mod layout;
mod posterior;
mod predictive;

pub use hpge_inference::fit::{ZetaAtMode, ZetaProfile};
use layout::grid;

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
/// The figures: `marginals`, `marginals-zeta` (the impurity parameters y as densities zeta,
/// where the fit has any), `posterior-2d-<nameA>-<nameB>` per pair of parameter indices in
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
        invalid!("the fit has no parameters to plot");
    }
    let draws: usize = fit.samples.chains.iter().map(|c| c.theta.len()).sum();
    if draws == 0 {
        invalid!("the fit has no draws to plot");
    }
    let all_d = fit.samples.chains.iter().flat_map(|c| &c.theta);
    if let Some(t) = all_d.clone().find(|t| t.len() != d) {
        invalid!("a draw has {} values, the summary {d} parameters", t.len());
    }
    if let Some(t) = truth
        && t.len() != d
    {
        invalid!("the truth has {} values, the fit {d} parameters", t.len());
    }
    for &(a, b) in pairs {
        if a >= d || b >= d || a == b {
            invalid!("the pair ({a}, {b}) needs two different parameter indices below {d}");
        }
    }
    std::fs::create_dir_all(dir).map_err(Error::io(dir, "cannot create the folder"))?;
    let mut out = Vec::new();
    let (rows, cols) = grid(d, 3);
    let size = (1500, 100 + 380 * rows as u32);
    both!(out, dir, "marginals", size, |root| posterior::marginals(
        &root, fit, truth, title, cols, false
    ));
    // The transform coordinates y as densities (the paper's Figs. 21 and 26).
    if params.iter().any(posterior::is_density_coordinate) {
        both!(out, dir, "marginals-zeta", size, |root| {
            posterior::marginals(&root, fit, truth, title, cols, true)
        });
    }
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
        both!(out, dir, "predictive", (1200, 1250), |root| {
            predictive::predictive(&root, fit, title)
        });
    }
    for (stem, profiles, axis) in [
        ("zeta-z", &zeta.along_z, "z"),
        ("zeta-r", &zeta.along_r, "r"),
    ] {
        if !profiles.is_empty() {
            both!(out, dir, stem, (1100, 720), |root| curves::zeta(
                &root,
                profiles,
                zeta.band_draws,
                axis,
                title
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

#[cfg(test)]
mod tests;
