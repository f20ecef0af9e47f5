//! The record of a hidden-effect study (`hpge-cv validate discovery`) and its two summary
//! files, `summary.json` and `summary.md`.

use std::fmt::Write as _;
use std::path::Path;

use serde::Serialize;

use super::hidden::HiddenOutcome;
use crate::error::{Error, Result};

/// A hidden-effect study's result.
#[derive(Debug, Clone, Serialize)]
pub struct HiddenStudy {
    /// Every data set named its hidden effect (none in the null case) with a chi^2
    /// consistent with ndf after.
    pub pass: bool,
    /// The study's seed.
    pub seed: u64,
    /// What makes two studies the same run: the effects, the start model, the inputs with
    /// their hashes and the workflow's settings (compared before a study replaces this one).
    pub run: serde_json::Value,
    /// What made this file: program, version, date and the solver's physics revision.
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub made: Option<hpge_foundation::Made>,
    /// The program version.
    pub program_version: String,
    /// One outcome per data set.
    pub outcomes: Vec<HiddenOutcome>,
    /// Wall time, s.
    pub seconds: f64,
}

impl HiddenStudy {
    /// The study of `outcomes`: it passes when every outcome is correct and consistent.
    pub fn new(
        seed: u64,
        run: serde_json::Value,
        outcomes: Vec<HiddenOutcome>,
        seconds: f64,
    ) -> Self {
        Self {
            pass: outcomes.iter().all(|o| o.correct && o.consistent),
            seed,
            run,
            made: Some(hpge_solver::made()),
            program_version: env!("CARGO_PKG_VERSION").into(),
            outcomes,
            seconds,
        }
    }

    /// The study as the markdown table of `summary.md`.
    pub fn markdown(&self, out: &Path) -> String {
        let mut md = String::new();
        // Writing into a String cannot fail.
        let _ = writeln!(
            md,
            "# Hidden-effect tests of model discovery\n\n`hpge-cv validate discovery --seed {} --out {}` ({:.0} s). Pass: {}.\n",
            self.seed,
            out.display(),
            self.seconds,
            self.pass
        );
        let _ = writeln!(
            md,
            "| hidden effect | noise x | expected | chosen | right | chi^2/ndf before | after | chi^2 p after | best scores (ln B) |"
        );
        let _ = writeln!(md, "|---|---|---|---|---|---|---|---|---|");
        for o in &self.outcomes {
            let scores: Vec<String> = o
                .scores
                .iter()
                .take(3)
                .map(|(n, v)| format!("{n} {v:.1}"))
                .collect();
            let _ = writeln!(
                md,
                "| {} | {} | {} | {} | {} | {:.2} | {:.2} | {:.3} | {} |",
                o.effect,
                o.noise_scale,
                o.expected.as_deref().unwrap_or("none"),
                o.chosen.as_deref().unwrap_or("none"),
                if o.correct { "yes" } else { "**no**" },
                o.chi2_ndf_before,
                o.chi2_ndf_after,
                o.chi2_p_after,
                scores.join(", ")
            );
        }
        md
    }

    /// Writes `summary.json` and `summary.md` into the study's folder `out`.
    ///
    /// Errors: a file that cannot be written ([`Error::File`], naming it).
    pub fn write(&self, out: &Path) -> Result<()> {
        let path = out.join("summary.json");
        let text =
            serde_json::to_string_pretty(self).map_err(|e| Error::cannot_write(&path, &e))? + "\n";
        hpge_files::write(&path, text).map_err(|e| Error::cannot_write(&path, &e))?;
        let path = out.join("summary.md");
        hpge_files::write(&path, self.markdown(out)).map_err(|e| Error::cannot_write(&path, &e))
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    fn outcome(effect: &str, correct: bool, consistent: bool) -> HiddenOutcome {
        HiddenOutcome {
            effect: effect.into(),
            noise_scale: 1.0,
            chosen: correct.then(|| effect.to_string()),
            expected: Some(effect.into()),
            correct,
            chi2_ndf_after: 1.1,
            ndf_after: 50,
            chi2_p_after: 0.3,
            consistent,
            chi2_ndf_before: 4.0,
            scores: vec![(effect.into(), 12.0)],
            delta_elpd: [3.0, 1.0],
            seconds: 1.0,
        }
    }

    #[test]
    fn a_study_passes_only_when_every_data_set_is_named_and_consistent() {
        let run = serde_json::json!({});
        let ok = vec![outcome("a", true, true), outcome("b", true, true)];
        assert!(HiddenStudy::new(1, run.clone(), ok, 2.0).pass);
        let wrong = vec![outcome("a", true, true), outcome("b", false, true)];
        let s = HiddenStudy::new(1, run.clone(), wrong, 2.0);
        assert!(!s.pass);
        let md = s.markdown(Path::new("out"));
        assert!(md.contains("Pass: false"));
        assert_eq!(md.lines().filter(|l| l.starts_with("| a |")).count(), 1);
        assert!(md.contains("| b | 1 | b | none | **no** |"));
        let inconsistent = vec![outcome("a", true, false)];
        assert!(!HiddenStudy::new(1, run, inconsistent, 2.0).pass);
    }
}
