//! Tests of the discovery figure.

use std::collections::BTreeMap;

use hpge_inference::DiscoverSettings;
use hpge_inference::discover::{
    Disagreement, DiscoverySummary, Elpd, Gap, ModelFit, ProbedRegion, ResidualCheck, Window,
};

use super::layout::*;
use super::*;

#[test]
fn bands_reach_halfway_to_the_neighbours() {
    let v = [0.0, 10.0, 20.0, 30.0, 50.0];
    assert_eq!(band_edges(&v, [10.0, 20.0]), [5.0, 25.0]);
    assert_eq!(band_edges(&v, [20.0, 30.0]), [15.0, 40.0]);
    // At the ends: half the median gap (10).
    assert_eq!(band_edges(&v, [0.0, 10.0]), [-5.0, 15.0]);
    assert_eq!(band_edges(&v, [30.0, 50.0]), [25.0, 55.0]);
    assert_eq!(band_edges(&[7.0], [7.0, 7.0]), [7.0, 7.0]);
}

#[test]
fn the_residual_axis_keeps_room_for_legend_and_labels() {
    // Residuals within +-2.5: the axis covers +-2.5 plus 5% and the two strips.
    let (lo, hi) = residual_range([1.0, -1.0, f64::NAN].into_iter(), 400.0, 100.0, 50.0);
    let per_px = 5.5 / 250.0;
    assert!((lo - (-2.75 - 50.0 * per_px)).abs() < 1e-12, "{lo}");
    assert!((hi - (2.75 + 100.0 * per_px)).abs() < 1e-12, "{hi}");
    // An outlier widens the data range; the strips stay free in pixels.
    let (lo, hi) = residual_range([9.0, -1.0].into_iter(), 400.0, 100.0, 0.0);
    let top_of_data = 9.0 + 0.05 * 11.5;
    assert!(lo < -2.5 && hi > top_of_data);
    assert!(((hi - top_of_data) / (hi - lo) * 400.0 - 100.0).abs() < 1e-9);
    // Strips never take more than 60% of the plot.
    let (lo, hi) = residual_range(std::iter::empty(), 100.0, 90.0, 90.0);
    assert!(((2.75 - -2.75) / (hi - lo) - 40.0 / 220.0).abs() < 1e-12);
}

#[test]
fn labels_move_apart_and_stay_inside() {
    let boxes = [
        [10, 10, 50, 20],
        [30, 15, 50, 20],
        [210, 0, 50, 20],
        [290, 0, 50, 20],
    ];
    let placed = place_labels(&boxes, [0, 300], 22);
    assert_eq!(placed[0], boxes[0]);
    assert_eq!(placed[1], [30, 37, 50, 20]);
    assert_eq!(placed[2], boxes[2]);
    // Clamped to x <= 300 - 50, where it overlaps the third: moved down once.
    assert_eq!(placed[3], [250, 22, 50, 20]);
    assert_eq!(window_label(0, [1025.0, 1374.6]), "W1 (1025-1375 V)");
    assert_eq!(p_text(0.0123), "0.0123");
    assert_eq!(p_text(3.2e-5), "3.2e-5");
    let ticks: Vec<String> = [500.0, 2.5, -0.25, 0.0, -1e-9, 70.0]
        .iter()
        .map(tick)
        .collect();
    assert_eq!(ticks, ["500", "2.5", "-0.25", "0", "0", "70"]);
}

fn gap(model: &str, chi2_ndf: f64) -> Gap {
    Gap {
        chi2_ndf,
        max_pull: 3.0,
        ppc_p: 0.01,
        chi2: chi2_ndf * 57.0,
        ndf: 57,
        model: model.into(),
        method: "mcmc".into(),
        converged: true,
        mode: BTreeMap::new(),
    }
}

fn model_fit(model: &str, residuals: Vec<f64>) -> ModelFit {
    let n = residuals.len();
    ModelFit {
        model: model.into(),
        names: vec!["d_li_mm".into()],
        mcmc: None,
        laplace: None,
        check: ResidualCheck {
            residuals,
            windows: Vec::new(),
            ppc_p: 0.01,
            replicates: 1000,
        },
        elpd: Elpd {
            blocks: vec![[0, n - 1]],
            per_block: vec![0.0],
            total: 0.0,
            max_k_hat: 0.1,
        },
        c_mode: vec![40.0; n],
        sigma_mode: vec![1.0; n],
    }
}

fn window(v: &[f64], lo: f64, hi: f64, p: f64, region: Option<ProbedRegion>) -> Disagreement {
    let first = v.iter().position(|&x| x == lo).unwrap();
    let last = v.iter().position(|&x| x == hi).unwrap();
    Disagreement {
        voltages_v: [lo, hi],
        region_error: region
            .is_none()
            .then(|| "the depletion front does not move there".into()),
        region,
        p_value: p,
        window: Window {
            first,
            last,
            sign: 1,
            statistic: 30.0,
            p_value: p,
        },
    }
}

/// A B_Z-like start model with three windows of disagreement, one of them without a region,
/// and an extension that removes them (or, `extended` false, none chosen and no windows).
fn synthetic(extended: bool) -> Discovery {
    let v: Vec<f64> = (0..60).map(|k| 25.0 + 50.0 * k as f64).collect();
    let wiggle = |k: usize, a: f64| a * ((k as f64 * 1.7).sin() + 0.5 * (k as f64 * 0.37).cos());
    let bump = |x: f64, c: f64, w: f64| (-((x - c) / w).powi(2)).exp();
    let before: Vec<f64> = v
        .iter()
        .enumerate()
        .map(|(k, &x)| {
            3.2 * bump(x, 1200.0, 220.0) - 2.6 * bump(x, 2400.0, 180.0)
                + 2.4 * bump(x, 2750.0, 120.0)
                + wiggle(k, 0.5)
        })
        .collect();
    let after: Vec<f64> = (0..v.len()).map(|k| wiggle(k, 0.7)).collect();
    let region = |r: [f64; 2], z: [f64; 2]| ProbedRegion {
        r_mm: r,
        z_mm: z,
        nodes: 100,
        volume_cm3: 50.0,
    };
    let disagreement = if extended {
        vec![
            window(
                &v,
                1025.0,
                1375.0,
                4e-4,
                Some(region([28.0, 33.5], [0.0, 70.0])),
            ),
            window(&v, 2275.0, 2525.0, 0.003, None),
            window(
                &v,
                2675.0,
                2825.0,
                0.008,
                Some(region([24.0, 29.0], [0.0, 70.0])),
            ),
        ]
    } else {
        Vec::new()
    };
    let mut inputs = BTreeMap::new();
    inputs.insert("data".into(), "cv.csv".into());
    let summary = DiscoverySummary {
        start_model: "b-z".into(),
        disagreement,
        candidates: Vec::new(),
        chosen: extended.then(|| "radial".into()),
        before: gap("b-z", 3.41),
        after: gap(if extended { "b-z+radial" } else { "b-z" }, 1.02),
        delta_elpd: 12.0,
        delta_elpd_se: 3.0,
        seconds: 100.0,
        ln_bayes_factor: extended.then_some(9.0),
        elpd_method: "psis".into(),
        elpd_blocks: 10,
        elpd_max_k_hat: [0.2, 0.3],
        runs: Vec::new(),
        predictor: "exact".into(),
        surrogate_start: gap("b-z", 3.41),
        not_applicable: Vec::new(),
        verdict: "synthetic".into(),
        made: None,
        program_version: "0".into(),
        inputs,
        settings: DiscoverSettings::default(),
        resumed_stages: Vec::new(),
    };
    Discovery {
        summary,
        before: model_fit("b-z", before),
        after: extended.then(|| model_fit("b-z+radial", after)),
        c_m_pf: vec![40.0; v.len()],
        voltage_v: v,
        start_inputs: vec![1.0],
    }
}

fn detector() -> Detector {
    let path = Path::new(env!("CARGO_MANIFEST_DIR")).join("../detectors/super-siegfried-k1.toml");
    Detector::from_file(&path, &Default::default()).unwrap()
}

/// Writes the figure into a fresh temporary folder and checks both files, none empty.
/// HPGE_KEEP_FIGURES=1 keeps the folder.
fn check(tag: &str, d: &Discovery) {
    let dir = std::env::temp_dir().join(format!("hpge-cv-discovery-{tag}-{}", std::process::id()));
    let paths = discovery_figures(d, &detector(), &dir).unwrap();
    assert_eq!(paths.len(), 2, "{paths:?}");
    for ext in ["svg", "png"] {
        let p = dir.join(format!("residuals.{ext}"));
        assert!(paths.contains(&p), "{} not listed", p.display());
        let len = std::fs::metadata(&p).map(|m| m.len()).unwrap_or(0);
        assert!(len > 0, "{} missing or empty", p.display());
    }
    if std::env::var_os("HPGE_KEEP_FIGURES").is_none() {
        std::fs::remove_dir_all(&dir).unwrap();
    }
}

#[test]
fn figures_of_a_synthetic_discovery() {
    check("extended", &synthetic(true));
    check("nothing", &synthetic(false));
}

#[test]
fn mismatched_residuals_are_refused_before_drawing() {
    let dir = std::env::temp_dir().join("hpge-cv-discovery-never-written");
    let mut d = synthetic(true);
    d.after.as_mut().unwrap().check.residuals.pop();
    assert!(discovery_figures(&d, &detector(), &dir).is_err());
    d.voltage_v.clear();
    assert!(discovery_figures(&d, &detector(), &dir).is_err());
    assert!(!dir.exists());
}
