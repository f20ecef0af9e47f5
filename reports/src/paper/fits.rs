//! The paper's section 8 (Figs. 20-28: the B_Z and B_RZ posteriors, posterior predictives and
//! fitted densities) from two runs of `fit` on the shipped data with the shipped priors.

use std::path::{Path, PathBuf};

use hpge_inference::fit::FitOptions;
use hpge_solver::impurity::LogTransform;
use serde_json::{Value, json};

use super::{Ctx, verdict};
use crate::fit::run_fit as fit;
use crate::{Error, Result};

/// The figures each fit contributes: (fit's figure stem, report stem suffix, paper figure).
const BZ_FIGS: [(&str, &str, &str); 5] = [
    ("marginals", "marginals", "Figs. 20, 21 (sec. 8.1)"),
    (
        "posterior-2d-y_bot-y_top",
        "posterior-2d",
        "Fig. 22 (sec. 8.1)",
    ),
    ("predictive", "predictive", "Fig. 23 (sec. 8.1)"),
    ("zeta-z", "zeta-z", "Fig. 24a (sec. 8.1)"),
    ("zeta-r", "zeta-r", "Fig. 24b (sec. 8.1)"),
];
const BRZ_FIGS: [(&str, &str, &str); 5] = [
    ("marginals", "marginals", "Figs. 25, 26 (sec. 8.2)"),
    (
        "posterior-2d-y4_bot-y4_top",
        "posterior-2d",
        "Fig. 26 (sec. 8.2), zeta_4 pair",
    ),
    ("predictive", "predictive", "Fig. 27 (sec. 8.2)"),
    ("zeta-z", "zeta-z", "Fig. 28 (sec. 8.2), along z"),
    ("zeta-r", "zeta-r", "Fig. 28 (sec. 8.2), along r"),
];

/// The paper's manufacturer levels (cm^-3) at the bottom and the top.
const ZETA_M: (f64, f64) = (1.3e10, 0.44e10);

pub(super) fn fit_dir(ctx: &Ctx, key: &str) -> PathBuf {
    ctx.out.join("fits").join(key)
}

/// Runs `fit` with the shipped defaults into fits/<key>; returns summary.json.
fn run_fit(ctx: &Ctx, key: &str, prior: &Path, truth: Option<&Path>) -> Result<Value> {
    let out = fit_dir(ctx, key);
    let run = fit(
        &FitOptions {
            data: ctx.inputs.data.clone(),
            model: ctx.inputs.fit_model.clone(),
            prior: prior.to_path_buf(),
            detector: ctx.inputs.detector.clone(),
            out: Some(out),
            no_exact_check: !ctx.exact_check,
            truth: truth.map(Path::to_path_buf),
            ..FitOptions::default()
        },
        ctx.fit_observer.as_ref(),
    )?;
    ctx.fit_observer.finished(&run);
    Ok(run.summary_json)
}

/// The global mode of parameter `name` and its 68.3% smallest intervals, as text.
fn param(s: &Value, name: &str) -> (f64, String) {
    let p = s["parameters"]
        .as_array()
        .and_then(|ps| ps.iter().find(|p| p["name"] == name));
    let mode = p
        .and_then(|p| p["global_mode"].as_f64())
        .unwrap_or(f64::NAN);
    let si = p
        .and_then(|p| p["smallest_intervals"]["0.683"].as_array())
        .map(|iv| {
            iv.iter()
                .filter_map(|i| Some((i[0].as_f64()?, i[1].as_f64()?)))
                .map(|(a, b)| format!("[{a:.3}, {b:.3}]"))
                .collect::<Vec<_>>()
                .join(" ")
        })
        .unwrap_or_default();
    (mode, si)
}

/// Largest |pull at the mode| below and from 1000 V (from predictive.csv).
fn pulls(dir: &Path) -> Result<(f64, f64)> {
    let path = dir.join("predictive.csv");
    let mut r = csv::ReaderBuilder::new()
        .comment(Some(b'#'))
        .from_path(&path)
        .map_err(|e| Error::from(e).context(format!("cannot read {}", path.display())))?;
    let h = r.headers()?.clone();
    let col = |n: &str| {
        h.iter()
            .position(|x| x == n)
            .ok_or_else(|| Error::invalid("predictive.csv: no column"))
    };
    let (u, p) = (col("voltage_V")?, col("pull_at_mode")?);
    let (mut lo, mut hi) = (0.0_f64, 0.0_f64);
    for rec in r.records() {
        let rec = rec?;
        let num = |i: usize| -> Result<f64> {
            let t = rec.get(i).unwrap_or("");
            t.parse().map_err(|e| Error::Content {
                file: path.clone(),
                message: format!("`{t}`: {e}"),
            })
        };
        let (v, pull) = (num(u)?, num(p)?);
        if v < 1000.0 {
            lo = lo.max(pull.abs());
        } else {
            hi = hi.max(pull.abs());
        }
    }
    Ok((lo, hi))
}

fn skipped(ctx: &mut Ctx, key: &str, figs: &[(&str, &str, &str)]) {
    for (_, suffix, paper) in figs {
        ctx.row(
            &format!("fit-{key}-{suffix}"),
            paper,
            "(the fits are left out of a --quick run)",
            String::new(),
            "not run (--quick)".into(),
        );
    }
}

fn copy_figures(ctx: &mut Ctx, key: &str, figs: &[(&str, &str, &str)]) -> Result<()> {
    let dir = fit_dir(ctx, key).join("figures");
    for (src, suffix, _) in figs {
        ctx.copy_both(&dir, src, &format!("fit-{key}-{suffix}"))?;
    }
    Ok(())
}

fn chi2(s: &Value) -> String {
    format!(
        "chi2/ndf at the mode {:.1}/{}; converged {}; {:.0} s{}",
        s["chi2"].as_f64().unwrap_or(f64::NAN),
        s["ndf"],
        s["converged"],
        s["seconds"].as_f64().unwrap_or(f64::NAN),
        if s["exact_check"].is_null() {
            ", no exact-solver check"
        } else {
            ""
        }
    )
}

pub fn run_bz(ctx: &mut Ctx) -> Result<()> {
    if ctx.quick {
        skipped(ctx, "b-z", &BZ_FIGS);
        return Ok(());
    }
    let prior = ctx.inputs.prior_bz.clone();
    let s = run_fit(ctx, "b-z", &prior, None)?;
    copy_figures(ctx, "b-z", &BZ_FIGS)?;
    let t = LogTransform::default();
    let (d_li, d_si) = param(&s, "d_li_mm");
    let (yb, _) = param(&s, "y_bot");
    let (yt, _) = param(&s, "y_top");
    let (zb, zt) = (t.zeta_cm3_of_y(yb), t.zeta_cm3_of_y(yt));
    let modes = s["local_modes"].as_array().map_or(0, Vec::len);
    let (p_lo, p_hi) = pulls(&fit_dir(ctx, "b-z"))?;
    let c2 = chi2(&s);
    let levels = format!(
        "global mode: d_Li = {d_li:.2} mm (68.3% SI {d_si}), zeta_bot = {zb:.3e}, zeta_top = {zt:.3e} cm^-3 (manufacturer {:.2e}, {:.2e}); local modes found {modes}; {c2}",
        ZETA_M.0, ZETA_M.1
    );
    let near_m = |z: f64, m: f64| (z / m).max(m / z) < 2.0;
    let d_ok = (d_li - 3.0).abs() < 1.0;
    ctx.row(
        "fit-b-z-marginals",
        BZ_FIGS[0].2,
        "d_Li about 3 mm; the posteriors of zeta_bot and zeta_top peak not far from the manufacturer's levels and have two modes (top/bottom symmetry).",
        levels.clone(),
        verdict(
            d_ok && near_m(zb, ZETA_M.0) && near_m(zt, ZETA_M.1),
            "on the stand-in data (made with d_Li = 3 mm and a radial profile) B_Z puts d_Li or the levels elsewhere; see the numbers",
        ),
    );
    ctx.row(
        "fit-b-z-posterior-2d",
        BZ_FIGS[1].2,
        "The 2D posterior of zeta_top and zeta_bot shows the two modes.",
        levels.clone(),
        verdict(modes >= 2, "one mode only"),
    );
    ctx.row(
        "fit-b-z-predictive",
        BZ_FIGS[2].2,
        "c_p - c_m is centred on 0 above 1000 V, but B_Z cannot describe the data below 1000 V (a radial dependence is needed).",
        format!("max |pull| at the mode: {p_lo:.2} below 1000 V, {p_hi:.2} from 1000 V; {c2}"),
        verdict(
            p_lo > 3.0 && p_hi < 3.0,
            &if p_lo > 3.0 {
                format!("B_Z misses the data at low bias as in the paper, but also at the highest biases (|pull| up to {p_hi:.1}), with d_Li at {d_li:.2} mm")
            } else {
                "B_Z describes the data at low bias too".into()
            },
        ),
    );
    for k in [3, 4] {
        ctx.row(
            &format!("fit-b-z-{}", BZ_FIGS[k].1),
            BZ_FIGS[k].2,
            "zeta_RZ at the global mode of B_Z: no radial dependence, levels near the manufacturer's.",
            levels.clone(),
            verdict(
                near_m(zb, ZETA_M.0) && near_m(zt, ZETA_M.1),
                "the levels are more than 2x from the manufacturer's",
            ),
        );
    }
    ctx.number(
        "fit_b_z",
        json!({"d_li_mm": d_li, "zeta_bot_cm3": zb, "zeta_top_cm3": zt,
        "chi2": s["chi2"], "ndf": s["ndf"], "max_pull_below_1000V": p_lo,
        "max_pull_from_1000V": p_hi, "local_modes": modes, "converged": s["converged"]}),
    );
    Ok(())
}

pub fn run_brz(ctx: &mut Ctx) -> Result<()> {
    if ctx.quick {
        skipped(ctx, "b-rz", &BRZ_FIGS);
        return Ok(());
    }
    let prior = ctx.inputs.prior_brz.clone();
    let truth = ctx.inputs.data.with_file_name("truth-b-rz.toml");
    let s = run_fit(
        ctx,
        "b-rz",
        &prior,
        truth.is_file().then_some(truth.as_path()),
    )?;
    copy_figures(ctx, "b-rz", &BRZ_FIGS)?;
    let t = LogTransform::default();
    let z = |n: &str| t.zeta_cm3_of_y(param(&s, n).0);
    let (d_li, d_si) = param(&s, "d_li_mm");
    let (z1b, z4b, z1t, z4t) = (z("y1_bot"), z("y4_bot"), z("y1_top"), z("y4_top"));
    let (_, si4b) = param(&s, "y4_bot");
    let (_, si4t) = param(&s, "y4_top");
    let (p_lo, p_hi) = pulls(&fit_dir(ctx, "b-rz"))?;
    let c2 = chi2(&s);
    let truth_txt = s["truth"].as_array().map_or(String::new(), |t| {
        let inside = t.iter().filter(|r| r["inside_683"] == true).count();
        format!(
            "; stand-in truth inside the 68.3% SI for {inside} of {}",
            t.len()
        )
    });
    let levels = format!(
        "global mode: d_Li = {d_li:.2} mm (68.3% SI {d_si}); zeta_1 = {z1b:.3e} (bot), {z1t:.3e} (top); zeta_4 = {z4b:.3e} (bot), {z4t:.3e} (top) cm^-3; 68.3% SI of y4_bot {si4b}, y4_top {si4t}{truth_txt}"
    );
    let low_mantle = z4b < 0.5 * z1b && z4t < 0.5 * z1t;
    ctx.row(
        "fit-b-rz-marginals",
        BRZ_FIGS[0].2,
        "d_Li as in B_Z (~3 mm); zeta_1 like B_Z's levels; zeta_4 (mantle) broad, favouring very low or p-type density.",
        levels.clone(),
        verdict(
            low_mantle && (d_li - 3.0).abs() < 1.0,
            "see the numbers",
        ),
    );
    ctx.row(
        "fit-b-rz-posterior-2d",
        BRZ_FIGS[1].2,
        "zeta_4^bot and zeta_4^top are broad and favour low or p-type densities at the mantle.",
        levels.clone(),
        verdict(low_mantle, "the mantle levels are not low"),
    );
    ctx.row(
        "fit-b-rz-predictive",
        BRZ_FIGS[2].2,
        "The bands of c_p - c_m are centred on 0 at all voltages, wider towards low bias.",
        format!("max |pull| at the mode: {p_lo:.2} below 1000 V, {p_hi:.2} from 1000 V; {c2}"),
        verdict(p_lo.max(p_hi) < 3.0, "pulls above 3 remain"),
    );
    for k in [3, 4] {
        ctx.row(
            &format!("fit-b-rz-{}", BRZ_FIGS[k].1),
            BRZ_FIGS[k].2,
            "zeta_RZ at the global mode of B_RZ: the density falls towards the mantle, very low near the edge.",
            levels.clone(),
            verdict(low_mantle, "the density does not fall towards the mantle"),
        );
    }
    ctx.number(
        "fit_b_rz",
        json!({"d_li_mm": d_li, "zeta1_bot_cm3": z1b, "zeta4_bot_cm3": z4b,
        "zeta1_top_cm3": z1t, "zeta4_top_cm3": z4t, "chi2": s["chi2"], "ndf": s["ndf"],
        "max_pull_below_1000V": p_lo, "max_pull_from_1000V": p_hi, "converged": s["converged"]}),
    );
    Ok(())
}
