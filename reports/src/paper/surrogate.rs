//! The paper's Figs. 17-19 (section 7): the learning curves of the paper's network and its
//! predictions on samples it never saw (scatter of c_p over c_s, histograms of the absolute and
//! relative errors with the Gaussian whose sigma becomes sigma_p). The held-out set
//! (`data/training/heldout.csv`) replaces the paper's test set (the test set chose nothing here,
//! but the held-out set is the one `reports/surrogate.md` quotes). The model the fits use is
//! evaluated too (numbers only).

use std::path::Path;

use hpge_surrogate::model::EpochRecord;
use hpge_surrogate::{DataSet, Figures, Surrogate};
use serde_json::json;

use super::criterion::{Cmp, Criterion, Judgement};
use super::ctx::Ctx;
use crate::error::{Error, Result};
use crate::plot;

/// The learning curves `train` wrote beside a model (`<stem>.curves.csv`).
fn read_curves(path: &Path) -> Result<Vec<EpochRecord>> {
    let text = std::fs::read_to_string(path).map_err(|source| Error::Read {
        file: path.to_path_buf(),
        what: "the learning curves",
        source,
    })?;
    let mut out = Vec::new();
    for line in text
        .lines()
        .filter(|l| !l.starts_with('#') && !l.starts_with("member") && !l.trim().is_empty())
    {
        out.push(
            EpochRecord::from_csv_line(line).ok_or_else(|| Error::Content {
                file: path.to_path_buf(),
                message: format!("malformed line `{line}`"),
            })?,
        );
    }
    if out.is_empty() {
        return Err(Error::Content {
            file: path.to_path_buf(),
            message: "no learning-curve rows".into(),
        });
    }
    Ok(out)
}

/// Held-out predictions and figures of one model.
fn heldout(model: &Surrogate, data: &Path) -> Result<(Vec<f64>, Vec<f64>, Figures, usize)> {
    let set = DataSet::read(data, &model.info.space)?;
    let pred = model.predict_set(&set);
    let f = Figures::of(&pred, &set.c12_pf);
    Ok((pred, set.c12_pf.clone(), f, set.excluded))
}

/// Why the errors are not the paper's Gaussian, where their tail is heavier.
fn tail_reading(f: &Figures) -> String {
    let ratio = f.abs_rel_q99 / (2.576 * f.rel_sigma);
    if ratio > 2.0 {
        format!(
            "the errors have a tail a Gaussian does not describe: 1 prediction in 100 is off by more than {:.1}%, {ratio:.1}x the Gaussian's q99; reports/surrogate.md traces the tail to jumps of c12 where p-type pockets pinch off",
            100.0 * f.abs_rel_q99
        )
    } else {
        String::new()
    }
}

/// Draws the learning curves and the held-out errors and adds their README rows.
pub fn run(ctx: &mut Ctx) -> Result<()> {
    let tmp = ctx.out.join("surrogate");
    std::fs::create_dir_all(&tmp).map_err(Error::io(&tmp, "cannot create the folder"))?;
    let model = Surrogate::load(&ctx.inputs.paper_model)?;
    let curves = read_curves(&ctx.inputs.paper_model.with_extension("curves.csv"))?;
    plot::learning_curves(&curves, &model.info, &tmp)?;
    ctx.copy_both(&tmp, "learning-curves", "surrogate-learning-curves")?;
    let last = curves.last().ok_or_else(|| Error::invalid("no epochs"))?;
    let first = &curves[0];
    let cycles = curves.iter().map(|r| r.cycle).max().unwrap_or(0);
    ctx.row(
        "surrogate-learning-curves",
        "Fig. 17 (sec. 7)",
        "Mean loss of training and test set per epoch over three Adam cycles (dashed lines at the cycle changes); both fall and flatten, test close to training.",
        format!(
            "recipe {}: {} epochs in {cycles} cycles; train loss {:.3} -> {:.4}, test loss {:.3} -> {:.4} (test/train at the end {:.2})",
            model.info.recipe_name,
            last.epoch,
            first.train_loss,
            last.train_loss,
            first.test_loss,
            last.test_loss,
            last.test_loss / last.train_loss
        ),
        Judgement::by(
            vec![
                Criterion::new("Adam cycles", cycles as f64, Cmp::Eq, 3.0),
                Criterion::new(
                    "test loss, last / first epoch",
                    last.test_loss / first.test_loss,
                    Cmp::Lt,
                    1.0,
                ),
                Criterion::new(
                    "test / training loss at the last epoch",
                    last.test_loss / last.train_loss,
                    Cmp::Lt,
                    2.0,
                ),
            ],
            "",
        ),
    );
    let (pred, truth, f, excluded) = heldout(&model, &ctx.inputs.heldout)?;
    plot::surrogate_errors(&pred, &truth, &model.info, "heldout", &tmp)?;
    ctx.copy_both(&tmp, "heldout-scatter", "surrogate-scatter")?;
    ctx.copy_both(&tmp, "heldout-errors", "surrogate-errors")?;
    let (_, _, fit_f, _) = heldout(
        &Surrogate::load(&ctx.inputs.fit_model)?,
        &ctx.inputs.heldout,
    )?;
    let fit_name = ctx
        .inputs
        .fit_model
        .file_stem()
        .map_or("?".into(), |s| s.to_string_lossy().to_string());
    let nums = format!(
        "held-out {} samples ({excluded} failed solves left out): paper recipe sigma {:.3}%, |rel. error| q50 {:.2}% q90 {:.2}% q99 {:.1}%; the fits' model ({fit_name}) sigma {:.3}%",
        f.n,
        100.0 * f.rel_sigma,
        100.0 * f.abs_rel_q50,
        100.0 * f.abs_rel_q90,
        100.0 * f.abs_rel_q99,
        100.0 * fit_f.rel_sigma
    );
    ctx.row(
        "surrogate-scatter",
        "Fig. 18 (sec. 7)",
        "c_p over c_s: most points on the diagonal, a few outliers.",
        nums.clone(),
        Judgement::by(
            vec![
                Criterion::new("|rel. error| q50", f.abs_rel_q50, Cmp::Lt, 0.02),
                Criterion::new("|rel. error| q90", f.abs_rel_q90, Cmp::Lt, 0.1),
            ],
            "",
        ),
    );
    ctx.row(
        "surrogate-errors",
        "Fig. 19 (sec. 7)",
        "Absolute and relative differences c_p - c_s; a Gaussian fitted to the relative ones has sigma = 1.5%, used as sigma_p.",
        nums,
        Judgement::by(
            vec![
                Criterion::new(
                    "Gaussian sigma of the relative error",
                    f.rel_sigma,
                    Cmp::Le,
                    0.015,
                ),
                // A Gaussian of that sigma has q99 = 2.576 sigma: within 2x of it the Gaussian
                // describes the errors, as the paper's sigma_p assumes.
                Criterion::new(
                    "|rel. error| q99 / (2.576 sigma)",
                    f.abs_rel_q99 / (2.576 * f.rel_sigma),
                    Cmp::Le,
                    2.0,
                ),
            ],
            tail_reading(&f),
        ),
    );
    ctx.number(
        "surrogate",
        json!({
            "paper_model": ctx.inputs.paper_model.display().to_string(),
            "paper_heldout": f,
            "fit_model": ctx.inputs.fit_model.display().to_string(),
            "fit_model_heldout": fit_f,
            "epochs": last.epoch,
            "final_train_loss": last.train_loss,
            "final_test_loss": last.test_loss,
        }),
    );
    Ok(())
}
