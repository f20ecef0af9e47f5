//! Tests of the fit figures: synthetic B_Z- and B_RZ-like fits drawn into a temporary folder.

use std::collections::BTreeMap;

use hpge_inference::diagnostics::Diagnostics;
use hpge_inference::fit::{FitSummary, LEVELS, ParameterSummary, Predictive};
use hpge_inference::prior::PriorDistribution;
use hpge_inference::sampler::{ChainDraws, SamplerStop, Samples};
use hpge_inference::summary::{marginal_mode, smallest_intervals};
use hpge_inference::{NoiseSettings, SampleSettings};

use super::*;

/// splitmix64 with Box-Muller: a seeded normal generator (rand is no dependency of this
/// crate).
struct Normal(u64);

impl Normal {
    fn uniform(&mut self) -> f64 {
        self.0 = self.0.wrapping_add(0x9e37_79b9_7f4a_7c15);
        let mut z = self.0;
        z = (z ^ (z >> 30)).wrapping_mul(0xbf58_476d_1ce4_e5b9);
        z = (z ^ (z >> 27)).wrapping_mul(0x94d0_49bb_1331_11eb);
        ((z ^ (z >> 31)) >> 11) as f64 / (1u64 << 53) as f64
    }
    fn draw(&mut self) -> f64 {
        let (u, v) = (self.uniform().max(1e-300), self.uniform());
        (-2.0 * u.ln()).sqrt() * (std::f64::consts::TAU * v).cos()
    }
}

/// A B_Z-like fit (d = 3: d_li_mm, a bimodal y_bot, y_top) or a B_RZ-like one (d = 9), with
/// `chains` chains of 3000 draws.
fn synthetic_fit(d: usize, chains: usize) -> Fit {
    let mut rng = Normal(7);
    let names: Vec<String> = match d {
        3 => ["d_li_mm", "y_bot", "y_top"].map(String::from).to_vec(),
        _ => std::iter::once("d_li_mm".to_string())
            .chain(
                (1..d).map(|k| format!("y{}_{}", (k - 1) % 4 + 1, ["bot", "top"][(k - 1) / 4 % 2])),
            )
            .collect(),
    };
    // Centres (the global mode); y_bot or y1_bot has a second mode at 0.45.
    let centre: Vec<f64> = (0..d)
        .map(|j| match j {
            0 => 1.1,
            1 => 0.68,
            _ => 0.52 + 0.02 * j as f64,
        })
        .collect();
    let chains: Vec<ChainDraws> = (0..chains)
        .map(|c| {
            let theta: Vec<Vec<f64>> = (0..3000)
                .map(|i| {
                    let second = (i / 700 + c) % 3 == 0;
                    (0..d)
                        .map(|j| match j {
                            0 => 1.1 + 0.08 * rng.draw(),
                            1 if second => 0.45 + 0.025 * rng.draw(),
                            _ => centre[j] + 0.03 * rng.draw(),
                        })
                        .collect()
                })
                .collect();
            let ln_posterior = theta.iter().map(|t| -(t[0] - 1.1).powi(2)).collect();
            ChainDraws {
                theta,
                ln_posterior,
                acceptance: 0.25,
                divergences: 0,
                evaluations: 4000,
                scale: 0.1,
            }
        })
        .collect();
    let diagnostics = vec![
        Diagnostics {
            rhat: 1.001,
            ess_bulk: 2500.0,
            ess_tail: 2000.0
        };
        d
    ];
    let samples = Samples {
        names: names.clone(),
        settings: SampleSettings::default(),
        chains,
        diagnostics,
        stop: SamplerStop::Converged,
        tuned: true,
        cycles: 3,
        local_modes: Vec::new(),
        tuning_seconds: 1.0,
        seconds: 2.0,
    };
    let mode = centre.clone();
    let parameters = (0..d)
        .map(|j| {
            let all: Vec<f64> = samples.parameter(j).concat();
            let (prior, support, unit) = if j == 0 {
                (
                    PriorDistribution::Uniform { lo: 0.2, hi: 5.0 },
                    [0.2, 5.0],
                    "mm",
                )
            } else {
                let prior = PriorDistribution::TruncatedNormal {
                    mean: 0.6,
                    sd: 0.4,
                    lo: None,
                    hi: None,
                };
                (prior, [0.0, 1.5], "1")
            };
            let n = all.len() as f64;
            let mean = all.iter().sum::<f64>() / n;
            let si = smallest_intervals(&all, None, None, support, 100, &LEVELS);
            ParameterSummary {
                name: names[j].clone(),
                mean,
                std: (all.iter().map(|v| (v - mean).powi(2)).sum::<f64>() / n).sqrt(),
                global_mode: mode[j],
                marginal_mode: marginal_mode(&all, None, support, 100),
                smallest_intervals: LEVELS
                    .iter()
                    .zip(si)
                    .map(|(l, v)| (format!("{l}"), v))
                    .collect(),
                rhat: 1.001,
                ess_bulk: 2500.0,
                ess_tail: 2000.0,
                unit: unit.into(),
                prior,
                support,
                at_prior_bound: Vec::new(),
            }
        })
        .collect();
    let summary = FitSummary {
        converged: true,
        seconds: 2.0,
        chi2: 12.0,
        ndf: 9,
        posterior_predictive_p: 0.5,
        calibration_factor: None,
        parameters,
        modes: Vec::new(),
        local_modes: Vec::new(),
        exact_check: None,
        exact_check_skipped: None,
        refinement: None,
        posterior_outside_support: None,
        made: None,
        program_version: "test".into(),
        inputs: BTreeMap::new(),
        likelihood: NoiseSettings::default(),
        settings: SampleSettings::default(),
        stop: SamplerStop::Converged,
        tuned: true,
        tuning_cycles: 3,
        tuning_seconds: 1.0,
        draws_per_chain: 3000,
        acceptance: vec![0.25; samples.chains.len()],
        divergences: 0,
        evaluations: 12000,
        ess_bulk_per_second: 1000.0,
        ln_posterior_at_mode: -1.0,
        max_abs_pull: 1.5,
    };
    // A misfit below 1000 V, as in the paper's B_Z fit.
    let voltage_v: Vec<f64> = (0..12).map(|k| 100.0 + 300.0 * k as f64).collect();
    let c_m_pf: Vec<f64> = voltage_v.iter().map(|v| 40.0 + 4e4 / (v + 100.0)).collect();
    let off = |v: f64| 3.0 * (-v / 400.0).exp();
    let sigma_pf: Vec<f64> = c_m_pf.iter().map(|c| 0.03 * c + 0.5).collect();
    let predictive = Predictive {
        c_mode_pf: voltage_v
            .iter()
            .zip(&c_m_pf)
            .map(|(v, c)| c + off(*v) + 0.1)
            .collect(),
        median_pf: voltage_v.iter().map(|v| off(*v)).collect(),
        bands_pf: voltage_v
            .iter()
            .map(|v| [0.3, 0.6, 0.9].map(|w| [off(*v) - w, off(*v) + w]).to_vec())
            .collect(),
        voltage_v,
        c_m_pf,
        sigma_pf,
        draws: 1000,
        ppp: 0.5,
        calibration: None,
    };
    Fit {
        samples,
        summary,
        predictive,
        mode,
    }
}

fn zeta_cm3_of(x_mm: &[f64], f: &impl Fn(f64) -> f64) -> Vec<f64> {
    x_mm.iter().map(|&x| f(x)).collect()
}

fn profile(label: String, f: impl Fn(f64) -> f64) -> ZetaProfile {
    let x_mm: Vec<f64> = (0..=40).map(|i| 2.0 * i as f64).collect();
    let zeta_cm3 = x_mm.iter().map(|&x| f(x)).collect();
    let band = |w: f64| -> Vec<[f64; 2]> {
        zeta_cm3_of(&x_mm, &f)
            .iter()
            .map(|z| [z - w * 1e9, z + w * 1e9])
            .collect()
    };
    ZetaProfile {
        label,
        band_683_cm3: band(1.0),
        band_955_cm3: band(2.0),
        truth_cm3: zeta_cm3_of(&x_mm, &f).iter().map(|z| z + 5e8).collect(),
        knots_mm: if x_mm.len() > 20 {
            vec![20.0, 28.0, 33.0]
        } else {
            Vec::new()
        },
        x_mm,
        zeta_cm3,
    }
}

fn zeta() -> ZetaAtMode {
    let along_z = [0.0, 20.0, 37.5].map(|r| {
        profile(format!("r = {r} mm"), move |z| {
            (1.3 - 0.011 * z - 0.004 * r) * 1e10
        })
    });
    let along_r = [0.0, 40.0, 80.0].map(|z| {
        profile(format!("z = {z} mm"), move |r| {
            (1.3 - 0.011 * z - 0.0003 * r * r) * 1e10
        })
    });
    ZetaAtMode {
        along_z: along_z.to_vec(),
        along_r: along_r.to_vec(),
        band_draws: 400,
    }
}

/// Writes the figures into a fresh temporary folder and checks that `stems` (each as .svg and
/// .png) and nothing else were written, none empty. HPGE_KEEP_FIGURES=1 keeps the folder.
fn check(tag: &str, fit: &Fit, pairs: &[(usize, usize)], truth: Option<&[f64]>, stems: &[&str]) {
    let dir = std::env::temp_dir().join(format!("hpge-cv-fit-{tag}-{}", std::process::id()));
    let title = format!("{tag} fit, synthetic");
    let paths = fit_figures(&dir, fit, &zeta(), pairs, truth, &title).unwrap();
    assert_eq!(paths.len(), 2 * stems.len(), "{paths:?}");
    for stem in stems {
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
fn b_z_figures() {
    let fit = synthetic_fit(3, 3);
    let truth = [1.0, 0.7, 0.55];
    let stems = [
        "marginals",
        "marginals-zeta",
        "posterior-2d-y_bot-y_top",
        "posterior-2d-d_li_mm-y_bot",
        "predictive",
        "zeta-z",
        "zeta-r",
        "traces",
    ];
    check("B_Z", &fit, &[(1, 2), (0, 1)], Some(&truth), &stems);
    // Bad input is refused before anything is drawn.
    let dir = std::env::temp_dir().join("hpge-cv-fit-never-written");
    assert!(fit_figures(&dir, &fit, &zeta(), &[(0, 3)], None, "x").is_err());
    assert!(fit_figures(&dir, &fit, &zeta(), &[(1, 1)], None, "x").is_err());
    assert!(fit_figures(&dir, &fit, &zeta(), &[], Some(&truth[..2]), "x").is_err());
    assert!(!dir.exists());
}

/// `fit` with an exact check at the mode: the exact curve 3% below the data, pulls of a few
/// sigma with a structure, the calibration factor 1.03.
fn with_exact_check(mut fit: Fit) -> Fit {
    let c_m = &fit.predictive.c_m_pf;
    let exact: Vec<f64> = c_m.iter().map(|c| c / 1.03).collect();
    let pulls: Vec<f64> = (0..c_m.len())
        .map(|k| 4.0 * (k as f64 * 0.7).sin())
        .collect();
    let check = serde_json::json!({
        "draws": 100, "failed": 0, "pareto_k": 0.3, "ess": 80.0, "log_ratio_sd": 0.1,
        "log_ratio_range": 0.5, "parameters": [], "max_rel_diff_at_mode": 0.01,
        "chi2_exact_at_mode": 60.0, "chi2_data_at_mode": 39313.5, "p_data_at_mode": 0.0,
        "max_abs_shift_sd": 0.1, "pass": true, "seconds": 1.0, "grids": "mode",
        "c_exact_at_mode_pf": exact,
        "own_errors_at_mode": {
            "sigma_pf": vec![0.004; c_m.len()],
            "sigma_total_pf": c_m.iter().map(|c| 0.03 * c).collect::<Vec<f64>>(),
            "pulls": pulls,
            "calibration": {"factor": 1.03, "factor_sd": 1e-4, "prior_sd": 0.03},
            "scale_chi2": 1.0
        }
    });
    fit.summary.exact_check = Some(serde_json::from_value(check).unwrap());
    fit
}

#[test]
fn b_rz_figures() {
    let fit = with_exact_check(synthetic_fit(9, 4));
    let stems = [
        "marginals",
        "marginals-zeta",
        "posterior-2d-y1_bot-y1_top",
        "predictive",
        "zeta-z",
        "zeta-r",
        "traces",
    ];
    // A truth known only in part (NaN elsewhere), as the CLI passes it.
    let mut truth = [f64::NAN; 9];
    truth[1] = 0.7;
    truth[6] = 0.62;
    check("B_RZ", &fit, &[(1, 5)], Some(&truth), &stems);
}
