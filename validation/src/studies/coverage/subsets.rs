//! The study's statistics again over the truths whose fit ended well: those whose sampler reached
//! its R-hat and ESS targets, those whose exact check passed after refinement, and both.
//!
//! The study's verdict is the whole set's (a user gets every fit, converged or not: `fit`
//! exits 3 or 4 on the others, and `--allow-unconverged` / `--allow-exact-mismatch` keep
//! them). A subset answers a reader's next question, whether the verdict leans on fits that
//! stopped at their draw cap or whose exact check failed. It is a diagnostic, not a second
//! test: selecting truths by how their fit ended selects on the data, and a calibrated pipeline
//! need not be calibrated on such a subset (a multimodal posterior mixes worse and is wider,
//! for example), so its bands are the binomial ones of its size and nothing more.

use serde::{Deserialize, Serialize};

use super::store::TruthFit;
use super::{ParameterCoverage, parameter_coverage};

/// Which truths a subset keeps (a closed set).
#[derive(Debug, Clone, Copy, PartialEq, Eq, Serialize, Deserialize)]
#[serde(rename_all = "snake_case")]
pub enum Subset {
    /// Fits whose sampler reached its R-hat and ESS targets.
    Converged,
    /// Fits whose last exact check passed (studies with the full pipeline).
    CheckPassed,
    /// Both.
    ConvergedAndPassed,
}

impl Subset {
    /// Every subset, in the order they are reported.
    pub const ALL: [Subset; 3] = [
        Subset::Converged,
        Subset::CheckPassed,
        Subset::ConvergedAndPassed,
    ];

    /// Whether truth `t`'s fit belongs to the subset.
    pub fn keeps(self, t: &TruthFit) -> bool {
        let passed = t.check.as_ref().is_some_and(|c| c.pass);
        match self {
            Subset::Converged => t.converged,
            Subset::CheckPassed => passed,
            Subset::ConvergedAndPassed => t.converged && passed,
        }
    }

    /// The subset in words, for the text report.
    pub fn describe(self) -> &'static str {
        match self {
            Subset::Converged => "converged fits",
            Subset::CheckPassed => "fits whose exact check passed",
            Subset::ConvergedAndPassed => "converged fits whose exact check passed",
        }
    }
}

/// The study's statistics over one subset of its truths.
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
pub struct SubsetCoverage {
    /// Which truths.
    pub subset: Subset,
    /// How many.
    pub n_truths: usize,
    /// Every parameter inside its tests (the study's criterion, with this subset's bands).
    pub pass: bool,
    /// The parameters that fail a test, with the test (empty when it passes).
    pub failures: Vec<String>,
    /// Per parameter (without the ranks: `ranks.csv` and the truth files have them).
    pub parameters: Vec<ParameterCoverage>,
}

/// The subsets of `kept` (the study's truths, skipped ones left out; parameters named by
/// `names`) that are neither empty nor the whole set nor equal to a subset reported before
/// them, each with its statistics from `l` ranks.
pub(super) fn subsets(kept: &[&TruthFit], names: &[&str], l: usize) -> Vec<SubsetCoverage> {
    let d = names.len();
    let mut sizes = vec![kept.len()];
    let mut out = Vec::new();
    for subset in Subset::ALL {
        let mine: Vec<&TruthFit> = kept.iter().copied().filter(|t| subset.keeps(t)).collect();
        // ConvergedAndPassed lies inside each of the others: an equal size is an equal set.
        if mine.is_empty() || sizes.contains(&mine.len()) {
            continue;
        }
        sizes.push(mine.len());
        let mut parameters = parameter_coverage(&mine, names, l);
        let failures: Vec<String> = parameters
            .iter()
            .flat_map(|p| {
                p.failures(d)
                    .into_iter()
                    .map(|f| format!("{}: {f}", p.name))
            })
            .collect();
        for p in &mut parameters {
            p.ranks.clear();
        }
        out.push(SubsetCoverage {
            subset,
            n_truths: mine.len(),
            pass: failures.is_empty(),
            failures,
            parameters,
        });
    }
    out
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::studies::coverage::store::TruthCheck;

    /// A truth of one parameter at rank `rank` of L = 9, inside the intervals of the levels up to
    /// 68.3% when `inside`, and inside those of 90% and more unless `rank` is 0.
    fn truth(rank: usize, inside: bool, converged: bool, pass: bool) -> TruthFit {
        let inside = super::super::COVERAGE_LEVELS
            .iter()
            .map(|&level| if level >= 0.9 { rank > 0 } else { inside })
            .collect();
        TruthFit {
            fingerprint: String::new(),
            index: 0,
            truth: vec![0.5],
            skipped: None,
            ranks: vec![rank],
            jitter: vec![0.5],
            inside: vec![inside],
            converged,
            sampler: None,
            check: Some(TruthCheck {
                pass,
                rounds: 1,
                pareto_k: 0.3,
                max_abs_shift_sd: 0.1,
                seconds_split: None,
            }),
            seconds: 1.0,
        }
    }

    #[test]
    fn subsets_are_the_distinct_proper_ones_with_their_own_verdicts() {
        // 20 converged fits that pass their check, calibrated (ranks spread, 70% inside the
        // 68.3% intervals, all but the 2 at rank 0 inside the 95.5% ones), and 10 unconverged
        // ones whose truths all lie outside at the lowest rank.
        let mut fits: Vec<TruthFit> = (0..20)
            .map(|i| truth((i * 10) / 20, i % 10 < 7, true, true))
            .collect();
        fits.extend((0..10).map(|_| truth(0, false, false, true)));
        let kept: Vec<&TruthFit> = fits.iter().collect();
        let s = subsets(&kept, &["a"], 9);
        // Every check passed: CheckPassed is the whole set and ConvergedAndPassed equals
        // Converged, so only Converged is reported.
        assert_eq!(s.len(), 1, "{s:?}");
        assert_eq!((s[0].subset, s[0].n_truths), (Subset::Converged, 20));
        assert!(s[0].pass, "{:?}", s[0].failures);
        assert!((s[0].parameters[0].coverage_683 - 0.7).abs() < 1e-12);
        assert!(s[0].parameters[0].ranks.is_empty());
        // With one failed check the three subsets differ.
        fits[0].check.as_mut().expect("check").pass = false;
        let kept: Vec<&TruthFit> = fits.iter().collect();
        let s = subsets(&kept, &["a"], 9);
        let got: Vec<(Subset, usize)> = s.iter().map(|x| (x.subset, x.n_truths)).collect();
        assert_eq!(
            got,
            [
                (Subset::Converged, 20),
                (Subset::CheckPassed, 29),
                (Subset::ConvergedAndPassed, 19)
            ]
        );
        // The 29 with the check passed hold the 10 bad fits: 18 of 29 inside the 95.5%
        // intervals (0.62, below the band's 0.83), and 11 ranks of 0.
        assert!(!s[1].pass);
        assert!(
            s[1].failures
                .iter()
                .any(|f| f.starts_with("a: 95.5% coverage 0.62")),
            "{:?}",
            s[1].failures
        );
        assert!(s[1].failures.iter().any(|f| f.starts_with("a: rank KS p")));
        // No subset of a study where every fit ended well.
        let good: Vec<&TruthFit> = fits[1..20].iter().collect();
        assert!(subsets(&good, &["a"], 9).is_empty());
    }
}
