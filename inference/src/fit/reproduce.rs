//! The `hpge-cv fit` command line that reproduces a fit, for the first lines of its report.

use std::path::Path;

use super::options::FitOptions;

impl FitOptions {
    /// The arguments of `hpge-cv fit` (after `fit`) that reproduce these options writing to
    /// `out`: the four input files, the sampler, seed and likelihood always, every other option
    /// only where it differs from its default (`--max-seconds`, `--no-exact-check`, a grid
    /// override, ...), so the line is short for a default fit and complete for any other.
    pub fn reproduce_args(&self, out: &Path) -> Vec<String> {
        let d = Self::default();
        let mut a: Vec<String> = Vec::new();
        let mut push = |flag: &str, value: String| {
            a.push(flag.into());
            a.push(value);
        };
        push("--data", self.data.display().to_string());
        push("--model", self.model.display().to_string());
        push("--prior", self.prior.display().to_string());
        push("--detector", self.detector.display().to_string());
        push("--sampler", self.sampler.clone());
        push("--seed", self.seed.to_string());
        push("--likelihood", self.likelihood.clone());
        for (flag, v, dv) in [
            ("--ess", self.ess, d.ess),
            ("--rhat", self.rhat, d.rhat),
            ("--max-seconds", self.max_seconds, d.max_seconds),
        ] {
            if v != dv {
                push(flag, v.to_string());
            }
        }
        if let Some(t) = self.grid.tolerance {
            push("--tolerance", t.to_string());
        }
        for (flag, v, dv) in [
            ("--chains", self.chains, d.chains),
            ("--exact-draws", self.exact_draws, d.exact_draws),
            (
                "--exact-grid-check",
                self.exact_grid_check,
                d.exact_grid_check,
            ),
            ("--exact-ascents", self.exact_ascents, d.exact_ascents),
            ("--refine-rounds", self.refine_rounds, d.refine_rounds),
            ("--mode-starts", self.mode_starts, d.mode_starts),
        ] {
            if v != dv {
                push(flag, v.to_string());
            }
        }
        for (flag, v, dv) in [
            ("--exact-grids", &self.exact_grids, &d.exact_grids),
            (
                "--refine-variance",
                &self.refine_variance,
                &d.refine_variance,
            ),
        ] {
            if v != dv {
                push(flag, v.clone());
            }
        }
        for (k, v) in &self.grid.grid {
            push("--grid", format!("{k}={v}"));
        }
        if let Some(t) = &self.truth {
            push("--truth", t.display().to_string());
        }
        let switches = [
            ("--no-exact-check", self.no_exact_check),
            ("--extrapolate", self.extrapolate),
            ("--allow-exact-mismatch", self.allow_exact_mismatch),
            ("--constant-sigma", self.constant_sigma),
            ("--no-plots", self.no_plots),
        ];
        a.extend(
            switches
                .into_iter()
                .filter(|&(_, on)| on)
                .map(|(flag, _)| flag.to_string()),
        );
        a.push("--out".into());
        a.push(out.display().to_string());
        a
    }

    /// What makes two fits the same run, as `summary.json` records it (`run`): the arguments
    /// of [`Self::reproduce_args`] without `--out` and `--allow-exact-mismatch` (which change no
    /// result, only the exit code). A fit into a folder whose summary records other arguments
    /// is another run's ([`FitOptions::force`]).
    pub fn run_args(&self) -> Vec<String> {
        let mut a = self.reproduce_args(Path::new(""));
        a.truncate(a.len() - 2);
        a.retain(|x| x != "--allow-exact-mismatch");
        a
    }
}

#[cfg(test)]
mod tests {
    use std::path::PathBuf;

    use super::*;

    #[test]
    fn a_default_fit_names_its_inputs_and_nothing_else() {
        let a = FitOptions::default().reproduce_args(Path::new("fits/b-rz"));
        let flags: Vec<&str> = a
            .iter()
            .filter(|s| s.starts_with("--"))
            .map(String::as_str)
            .collect();
        assert_eq!(
            flags,
            [
                "--data",
                "--model",
                "--prior",
                "--detector",
                "--sampler",
                "--seed",
                "--likelihood",
                "--out"
            ]
        );
        assert_eq!(a.last().map(String::as_str), Some("fits/b-rz"));
    }

    #[test]
    fn the_run_is_the_line_without_the_folder_and_the_exit_code_switch() {
        let o = FitOptions {
            out: Some(PathBuf::from("fits/x")),
            allow_exact_mismatch: true,
            force: true,
            seed: 3,
            ..FitOptions::default()
        };
        let a = o.run_args();
        assert!(a.windows(2).any(|w| w == ["--seed", "3"]), "{a:?}");
        for gone in ["--out", "fits/x", "--allow-exact-mismatch", "--force"] {
            assert!(!a.iter().any(|x| x == gone), "{gone} in {a:?}");
        }
        assert_eq!(
            a,
            FitOptions {
                seed: 3,
                ..FitOptions::default()
            }
            .run_args()
        );
    }

    #[test]
    fn every_changed_option_is_on_the_line() {
        let o = FitOptions {
            max_seconds: 120.0,
            no_exact_check: true,
            refine_rounds: 1,
            exact_grids: "own".into(),
            truth: Some(PathBuf::from("t.toml")),
            grid: hpge_solver::GridOverrides {
                tolerance: Some(0.005),
                grid: vec![("adaptive".into(), "false".into())],
            },
            ..FitOptions::default()
        };
        let line = o.reproduce_args(Path::new("o")).join(" ");
        for part in [
            "--max-seconds 120",
            "--no-exact-check",
            "--refine-rounds 1",
            "--exact-grids own",
            "--truth t.toml",
            "--tolerance 0.005",
            "--grid adaptive=false",
        ] {
            assert!(line.contains(part), "{part} missing from {line}");
        }
        assert!(!line.contains("--ess"), "{line}");
    }

    /// The line is what the command line reads back to the same options.
    #[cfg(feature = "clap")]
    #[test]
    fn the_line_parses_back_to_the_same_options() {
        use clap::Parser;
        #[derive(Parser)]
        struct Fit {
            #[command(flatten)]
            o: FitOptions,
        }
        let o = FitOptions {
            out: Some(PathBuf::from("out/x")),
            sampler: "nuts".into(),
            seed: 7,
            ess: 400.0,
            max_seconds: 90.5,
            chains: 6,
            exact_draws: 40,
            refine_rounds: 3,
            refine_variance: "local".into(),
            truth: Some(PathBuf::from("t.toml")),
            allow_exact_mismatch: true,
            no_plots: true,
            grid: hpge_solver::GridOverrides {
                tolerance: Some(0.005),
                grid: vec![("front_spacing_mm".into(), "0.1".into())],
            },
            ..FitOptions::default()
        };
        let args = o.reproduce_args(Path::new("out/x"));
        let back = Fit::try_parse_from(std::iter::once("fit".to_string()).chain(args))
            .expect("the line parses")
            .o;
        assert_eq!(back, o);
        let plain = FitOptions {
            out: Some(PathBuf::from("o")),
            ..FitOptions::default()
        };
        let back = Fit::try_parse_from(
            std::iter::once("fit".to_string()).chain(plain.reproduce_args(Path::new("o"))),
        )
        .expect("the line parses")
        .o;
        assert_eq!(back, plain);
    }
}
