//! Rows where they are needed (`generate --where MODEL`): active learning by query-by-committee.
//!
//! The run's `--n` indices of the sequence are *candidates*; each is scored by the disagreement
//! of the given surrogates there, and only the top `--share` of them is solved. The score of a
//! point x is the committee's relative spread
//!
//!   s(x) = sqrt( Var_models(c_m(x)) + mean_models(spread_m(x)^2) ) / mean_models(c_m(x)),
//!
//! c_m a model's (ensemble-mean) prediction and spread_m its members' standard deviation; with a
//! single one-member model, its calibrated relative sigma_s(x) (smooth in x: it finds the broad
//! regions of large error, not the switching surface). Where two independently trained networks
//! disagree, at least one is wrong: at the pinch-off surface, which a smooth network places
//! differently with every seed and recipe, the spread is largest.
//!
//! The choice depends only on the candidates and the model files (their hashes are in the run's
//! fingerprint), so a resumed or sharded run solves the same rows; ties go to the lower index.

use serde::{Deserialize, Serialize};

use super::setup::Generator;
use crate::error::{Error, Result};
use crate::hash::fnv1a;
use crate::model::Surrogate;
use crate::space::Target;

/// What a selective run chose its rows by (part of its fingerprint).
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
pub struct SelectionInfo {
    /// The scoring models: (file as given, FNV-1a hash of its bytes).
    pub models: Vec<(String, String)>,
    /// The share of the candidates solved, (0, 1].
    pub share: f64,
    /// The score: `committee` (several predictions) or `sigma_s` (one model's own).
    pub score: String,
}

impl Eq for SelectionInfo {}

/// The committee's relative disagreement at each of `xs` (physical values in the space's
/// column order): see the module's formula.
pub fn committee_scores(models: &[&Surrogate], g: &Generator, xs: &[Vec<f64>]) -> Result<Vec<f64>> {
    let targets = g.space.targets();
    let b = targets
        .iter()
        .position(|t| *t == Target::Bias)
        .ok_or_else(|| Error::Argument {
            name: "--where".into(),
            message: format!("the space `{}` has no bias dimension", g.space.name),
        })?;
    let single = models.len() == 1 && models[0].members() == 1;
    let mut out = Vec::with_capacity(xs.len());
    for x in xs {
        let params: Vec<f64> = x
            .iter()
            .enumerate()
            .filter(|(j, _)| *j != b)
            .map(|(_, v)| *v)
            .collect();
        let volts = [x[b]];
        let (mut sum, mut sum2, mut within) = (0.0, 0.0, 0.0);
        let mut sigma = f64::NAN;
        for m in models {
            let u = m.voltages(&volts)?;
            let (mut c, mut s) = ([0.0], [0.0]);
            m.curve_into(&params, &u, &mut c, Some(&mut s))?;
            sum += c[0];
            sum2 += c[0] * c[0];
            within += s[0] * s[0];
            if single {
                let mut var = [0.0];
                m.curve_variance_into(&params, &u, &mut var, None)?;
                sigma = var[0].sqrt();
            }
        }
        let k = models.len() as f64;
        let mean = sum / k;
        out.push(if single {
            sigma
        } else {
            let between = (sum2 / k - mean * mean).max(0.0);
            (between + within / k).sqrt() / mean.abs().max(f64::MIN_POSITIVE)
        });
    }
    Ok(out)
}

/// Checks that every model was trained on `g`'s space and detector (else an error naming both
/// hashes) and that `share` lies in (0, 1]; returns the run's [`SelectionInfo`].
pub fn selection_info(
    g: &Generator,
    models: &[(String, Vec<u8>, Surrogate)],
    share: f64,
) -> Result<SelectionInfo> {
    if !(share > 0.0 && share <= 1.0) {
        return Err(Error::Argument {
            name: "--share".into(),
            message: format!("{share} is not in (0, 1]: the share of the candidates to solve"),
        });
    }
    if models.is_empty() {
        return Err(Error::Argument {
            name: "--where".into(),
            message: "needs at least one model file".into(),
        });
    }
    let space_hash = |s: &crate::space::ParameterSpace| {
        format!(
            "{:016x}",
            fnv1a(toml::to_string(s).unwrap_or_default().as_bytes())
        )
    };
    for (file, _, m) in models {
        let mh = space_hash(&m.info.space);
        if mh != g.fingerprint.space_hash {
            return Err(Error::Argument {
                name: "--where".into(),
                message: format!(
                    "{file} was trained on space `{}` (hash {mh}), this run's space is `{}` \
                     (hash {})",
                    m.info.space.name, g.space.name, g.fingerprint.space_hash
                ),
            });
        }
        let Some(d) = &m.info.detector else {
            return Err(Error::Argument {
                name: "--where".into(),
                message: format!(
                    "{file} records no detector, this run's is {} (hash {}): a model trained \
                     without --detector cannot choose rows for one",
                    g.fingerprint.detector, g.fingerprint.detector_hash
                ),
            });
        };
        if d.hash != g.fingerprint.detector_hash {
            return Err(Error::Argument {
                name: "--where".into(),
                message: format!(
                    "{file} was trained for detector {} (hash {}), this run's is {} (hash {})",
                    d.file, d.hash, g.fingerprint.detector, g.fingerprint.detector_hash
                ),
            });
        }
    }
    let single = models.len() == 1 && models[0].2.members() == 1;
    Ok(SelectionInfo {
        models: models
            .iter()
            .map(|(f, bytes, _)| (f.clone(), format!("{:016x}", fnv1a(bytes))))
            .collect(),
        share,
        score: if single { "sigma_s" } else { "committee" }.into(),
    })
}

/// The chosen indices: the top ceil(share n) of the run's candidates by score (ties: lower
/// index first), in increasing index order.
pub fn choose(g: &Generator, models: &[&Surrogate], share: f64) -> Result<Vec<u64>> {
    let candidates: Vec<u64> = (g.offset..g.offset + g.n).collect();
    let xs: Vec<Vec<f64>> = candidates
        .iter()
        .map(|&i| g.space.from_sampled_unit(&g.sequence.point(i)).1)
        .collect();
    let scores = committee_scores(models, g, &xs)?;
    let keep = ((share * candidates.len() as f64).ceil() as usize).clamp(1, candidates.len());
    let mut order: Vec<usize> = (0..candidates.len()).collect();
    order.sort_by(|&a, &b| scores[b].total_cmp(&scores[a]).then(a.cmp(&b)));
    let mut chosen: Vec<u64> = order[..keep].iter().map(|&k| candidates[k]).collect();
    chosen.sort_unstable();
    Ok(chosen)
}

#[cfg(test)]
#[path = "select_tests.rs"]
mod tests;
