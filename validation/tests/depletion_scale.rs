//! Issue 64, item 5: the posterior of the impurity scale factor given a measured depletion
//! voltage (`hpge_inference::depletion`), which takes U_fd(f) = f U_fd(1) from one search,
//! against a brute-force grid of exact U_fd searches on the detector with its density scaled
//! (icpc-example: U_fd with trapped-carrier pockets).

use hpge_inference::depletion::{Measured, ScalePrior, scale_posterior};
use hpge_solver::field::{depletion_voltages, scales_with_density};
use hpge_solver::{Detector, FieldSettings, Parameters};
use hpge_validation::repo_path;

#[test]
fn the_scale_posterior_matches_a_brute_force_grid_of_exact_solves() {
    let det = Detector::from_file(
        &repo_path("detectors/icpc-example.toml"),
        &Parameters::new(),
    )
    .unwrap();
    assert!(scales_with_density(&det));
    let mut s = FieldSettings::default().for_detector(&det);
    s.grid.tolerance = 0.01;
    let u1 = depletion_voltages(&det, &s, false)
        .unwrap()
        .full_depletion
        .unwrap();
    // The exact searches at scaled densities: U_fd(f) and its error bar, each on its own.
    let factors = [0.85, 0.9, 0.95, 1.0, 1.05, 1.1, 1.15];
    let mut table = Vec::new();
    for &f in &factors {
        let scaled = det.with_impurity_scale(f).unwrap();
        let u = depletion_voltages(&scaled, &s, false)
            .unwrap()
            .full_depletion
            .unwrap();
        eprintln!(
            "f {f}: U_fd {:.3} +- {:.3} V, f U_fd(1) {:.3} +- {:.3} V",
            u.voltage_v,
            u.err_v,
            f * u1.voltage_v,
            f * u1.err_v
        );
        // The scaling law on one grid: to the bisection's width (1e-7 relative, three grids).
        assert!(
            (u.voltage_v - f * u1.voltage_v).abs() <= 1e-5 * u.voltage_v,
            "{f}: {u:?} vs {u1:?}"
        );
        assert!(
            (u.err_v - f * u1.err_v).abs() <= 1e-3 * u.err_v + 1e-3,
            "{f}: {u:?}"
        );
        table.push((f, u.voltage_v, u.err_v));
    }
    // A measurement 4% above the simulated value, 30 V wide: the posterior lies well inside
    // the table's range, which is the prior's.
    let m = Measured {
        voltage_v: 1.04 * u1.voltage_v,
        sigma_v: 30.0,
    };
    let prior = ScalePrior {
        lo: factors[0],
        hi: factors[factors.len() - 1],
    };
    let by_scaling = scale_posterior(m, prior, |f| Ok((f * u1.voltage_v, f * u1.err_v))).unwrap();
    // Brute force: linear interpolation between the exact searches.
    let interp = |f: f64| {
        let k = table
            .windows(2)
            .position(|w| f <= w[1].0)
            .unwrap_or(table.len() - 2);
        let (a, b) = (table[k], table[k + 1]);
        let t = (f - a.0) / (b.0 - a.0);
        Ok((a.1 + t * (b.1 - a.1), a.2 + t * (b.2 - a.2)))
    };
    let brute = scale_posterior(m, prior, interp).unwrap();
    let show = |p: &hpge_inference::depletion::ScalePosterior| {
        format!(
            "median {:.5}, 68% [{:.5}, {:.5}], 95% [{:.5}, {:.5}], sd {:.5}",
            p.median, p.interval_68.0, p.interval_68.1, p.interval_95.0, p.interval_95.1, p.sd
        )
    };
    eprintln!("scaling: {}", show(&by_scaling));
    eprintln!("brute force: {}", show(&brute));
    for (a, b) in [
        (by_scaling.median, brute.median),
        (by_scaling.interval_68.0, brute.interval_68.0),
        (by_scaling.interval_68.1, brute.interval_68.1),
        (by_scaling.interval_95.0, brute.interval_95.0),
        (by_scaling.interval_95.1, brute.interval_95.1),
    ] {
        assert!((a - b).abs() <= 1e-4 * a, "{a} vs {b}");
    }
    // And the answer is the ratio of the voltages, within the posterior's width.
    assert!(
        (by_scaling.median - 1.04).abs() < by_scaling.sd,
        "{}",
        show(&by_scaling)
    );
    assert!(!by_scaling.at_prior_bound);
}

/// The tilt of the density's gradient (issue 64, item 5): the posterior interpolates U_fd
/// between five exact searches at Chebyshev-Lobatto tilts. On coax-closed-end (linear in z,
/// U_fd 2496-2740 V over tilts 0-2), exact searches between the nodes lie on the interpolant
/// within their error bars, and the factor's marginal equals a brute-force one summed over 17
/// exact searches at uniform tilts, with no interpolation.
#[test]
fn the_tilt_posterior_matches_exact_solves_between_its_nodes() {
    use hpge_inference::depletion::tilt::{FACTOR_GRID, interpolate};
    use hpge_inference::depletion::{
        DepletionOptions, Marginal, TiltPrior, depletion, tilt_posterior,
    };
    let det = Detector::from_file(
        &repo_path("detectors/coax-closed-end.toml"),
        &Parameters::new(),
    )
    .unwrap();
    assert!(det.impurity_varies_along_z());
    let s = FieldSettings::default().for_detector(&det);
    let tp = TiltPrior { lo: 0.0, hi: 2.0 };
    let u_exact = |t: f64| {
        depletion_voltages(&det.with_impurity_tilt(t).unwrap(), &s, false)
            .unwrap()
            .full_depletion
            .unwrap()
    };
    let m = Measured {
        voltage_v: 3000.0,
        sigma_v: 50.0,
    };
    let opts = DepletionOptions {
        measured: Some(m),
        tilt: Some(tp),
        pinch_off: false,
        curve: false,
        ..Default::default()
    };
    let r = depletion(&det, &s, &opts, |_| {}).unwrap();
    let t = r.tilt.as_ref().unwrap();
    let xs: Vec<f64> = t.nodes.iter().map(|n| n.tilt).collect();
    let us: Vec<f64> = t.nodes.iter().map(|n| n.u_fd_v).collect();
    let node_err = t.nodes.iter().map(|n| n.err_v).fold(0.0, f64::max);
    for tt in [0.15, 0.6, 1.4, 1.85] {
        let u = u_exact(tt);
        let p = interpolate(&xs, &us, tt);
        eprintln!(
            "tilt {tt}: exact {:.2} +- {:.2} V, interpolated {p:.2} V",
            u.voltage_v, u.err_v
        );
        assert!(
            (p - u.voltage_v).abs() <= u.err_v + node_err,
            "tilt {tt}: {p} vs {u:?}"
        );
    }
    // Brute force: 17 exact searches, the joint density summed over t by the trapezoid.
    let prior = ScalePrior::default();
    let (f0, f1) = (prior.lo.ln(), prior.hi.ln());
    let df = (f1 - f0) / (FACTOR_GRID - 1) as f64;
    let mut w = vec![0.0; FACTOR_GRID];
    for k in 0..17 {
        let tt = 2.0 * k as f64 / 16.0;
        let u = u_exact(tt);
        let c = if k == 0 || k == 16 { 0.5 } else { 1.0 };
        for (i, wi) in w.iter_mut().enumerate() {
            let f = (f0 + i as f64 * df).exp();
            let var = m.sigma_v.powi(2) + (f * u.err_v).powi(2);
            *wi += c * (-0.5 * (m.voltage_v - f * u.voltage_v).powi(2) / var).exp() / var.sqrt();
        }
    }
    let brute = Marginal::from_grid(f0, df, &w, f64::exp).unwrap();
    let (fp, _) = tilt_posterior(m, prior, tp, &t.nodes).unwrap();
    eprintln!(
        "interpolated: median {:.5}, 68% {:?}, 95% {:?}\nbrute force: {brute:?}",
        fp.median, fp.interval_68, fp.interval_95
    );
    let p = r.posterior.as_ref().unwrap();
    assert_eq!(p.median, fp.median);
    for (a, b) in [
        (p.median, brute.median),
        (p.interval_68.0, brute.interval_68.0),
        (p.interval_68.1, brute.interval_68.1),
        (p.interval_95.0, brute.interval_95.0),
        (p.interval_95.1, brute.interval_95.1),
    ] {
        assert!((a - b).abs() <= 2e-3 * b, "{a} vs {b}");
    }
    // The factor's interval is wider than without the tilt: it carries the gradient.
    let one = depletion(&det, &s, &DepletionOptions { tilt: None, ..opts }, |_| {}).unwrap();
    let one = one.posterior.unwrap();
    assert!(p.sd > 1.5 * one.sd, "{} vs {}", p.sd, one.sd);
}
