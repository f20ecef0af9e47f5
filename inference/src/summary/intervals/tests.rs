//! Tests of the smallest intervals: normal, flat, autocorrelated, bimodal and weighted draws.
use rand::rngs::StdRng;
use rand::{RngExt, SeedableRng};
use rand_distr::{Distribution, Normal};

use super::*;

fn normal_draws(n: usize, mean: f64, sd: f64, rng: &mut StdRng) -> Vec<f64> {
    let g = Normal::new(mean, sd).unwrap();
    (0..n).map(|_| g.sample(rng)).collect()
}

/// Main interval (the one holding 0) within `tol` of `[-edge, edge]`; stray bins allowed
/// only just outside it.
fn check_sigma_interval(found: &[[f64; 2]], edge: f64, tol: f64) {
    let main = found.iter().find(|v| interval_contains(&[**v], 0.0));
    let main = main.unwrap_or_else(|| panic!("no interval holds 0: {found:?}"));
    assert!((main[0] + edge).abs() <= tol, "{found:?}");
    assert!((main[1] - edge).abs() <= tol, "{found:?}");
    assert!(found.len() <= 3, "{found:?}");
    for v in found {
        assert!(v[0] > -edge - 0.2 && v[1] < edge + 0.2, "{found:?}");
    }
}

#[test]
fn standard_normal_intervals_are_one_and_two_sigma() {
    let mut rng = StdRng::seed_from_u64(11);
    let x = normal_draws(200_000, 0.0, 1.0, &mut rng);
    // Bins of 0.05 (about the Freedman-Diaconis width for 200k draws). Counting noise
    // can swap the order of neighbouring bins near the edges, so the result is good to one bin.
    let iv = smallest_intervals(&x, None, None, [-5.0, 5.0], 200, &[0.683, 0.955]);
    assert_eq!(iv.len(), 2);
    check_sigma_interval(&iv[0], 1.0, 0.05 + 1e-9);
    check_sigma_interval(&iv[1], 2.0, 0.05 + 1e-9);
    let mode = marginal_mode(&x, None, [-5.0, 5.0], 50);
    assert!(mode.abs() < 0.11, "mode {mode}");
    assert!(interval_contains(&iv[0], 0.5));
    assert!(!interval_contains(&iv[0], 1.5));
    assert!(interval_contains(&iv[1], 1.5));
}

#[test]
fn a_small_noisy_sample_gives_one_interval_per_level() {
    // 8000 draws in 60 bins, as a fit's marginal figure: the flanks' counting noise must not
    // split off one-bin intervals. Ranked by the raw bin contents, 11 of these 20 seeds gave
    // two intervals at 99.7% or 95.5%; with the smoothed rank alone, 1.
    for seed in 0..20 {
        let mut rng = StdRng::seed_from_u64(seed);
        let x = normal_draws(8000, 0.0, 1.0, &mut rng);
        let iv = smallest_intervals(&x, None, None, [-4.0, 4.0], 60, &[0.683, 0.955, 0.997]);
        for (found, edge) in iv.iter().zip([1.0, 2.0, 3.0]) {
            assert_eq!(found.len(), 1, "seed {seed}, {edge} sigma: {found:?}");
            // Edges within about two bins (0.133 each) plus the tail's sampling spread.
            let tol = 0.1 * edge + 0.15;
            assert!(
                (found[0][0] + edge).abs() <= tol && (found[0][1] - edge).abs() <= tol,
                "seed {seed}: {found:?}"
            );
        }
    }
}

#[test]
fn noise_free_normal_intervals_within_003() {
    // 200k grid points weighted by the normal density: a standard normal "sample" without
    // counting noise, so only the binning (0.025) limits the accuracy.
    let h = 10.0 / 200_000.0;
    let x: Vec<f64> = (0..200_000).map(|i| -5.0 + (i as f64 + 0.5) * h).collect();
    let w: Vec<f64> = x.iter().map(|v| (-0.5 * v * v).exp()).collect();
    let iv = smallest_intervals(&x, Some(&w), None, [-5.0, 5.0], 400, &[0.683, 0.955]);
    for (found, edge) in iv.iter().zip([1.0, 2.0]) {
        assert_eq!(found.len(), 1, "{found:?}");
        check_sigma_interval(found, edge, 0.03);
    }
}

#[test]
fn bimodal_mixture_gives_two_intervals() {
    let mut rng = StdRng::seed_from_u64(12);
    let mut x = normal_draws(50_000, -3.0, 0.5, &mut rng);
    x.extend(normal_draws(50_000, 3.0, 0.5, &mut rng));
    let iv = smallest_intervals(&x, None, None, [-6.0, 6.0], 240, &[0.683]);
    assert_eq!(iv[0].len(), 2, "{:?}", iv[0]);
    let [l, r] = [iv[0][0], iv[0][1]];
    assert!(l[1] < r[0]);
    assert!(
        (l[0] + 3.5).abs() < 0.06 && (l[1] + 2.5).abs() < 0.06,
        "{l:?}"
    );
    assert!(
        (r[0] - 2.5).abs() < 0.06 && (r[1] - 3.5).abs() < 0.06,
        "{r:?}"
    );
    assert!(!interval_contains(&iv[0], 0.0));
    assert!(interval_contains(&iv[0], -3.0) && interval_contains(&iv[0], 3.0));
}

#[test]
fn zero_weights_equal_dropping_draws() {
    let mut rng = StdRng::seed_from_u64(13);
    let x = normal_draws(20_000, 1.0, 2.0, &mut rng);
    let w: Vec<f64> = (0..x.len()).map(|i| (i % 2) as f64).collect();
    let kept: Vec<f64> = x.iter().skip(1).step_by(2).copied().collect();
    let levels = [0.5, 0.683, 0.9, 0.99];
    let weighted = smallest_intervals(&x, Some(&w), None, [-8.0, 10.0], 90, &levels);
    let dropped = smallest_intervals(&kept, None, None, [-8.0, 10.0], 90, &levels);
    assert_eq!(weighted, dropped);
    assert_eq!(
        marginal_mode(&x, Some(&w), [-8.0, 10.0], 90),
        marginal_mode(&kept, None, [-8.0, 10.0], 90)
    );
    // Doubling every weight changes nothing.
    let w2: Vec<f64> = w.iter().map(|v| 2.0 * v).collect();
    assert_eq!(
        smallest_intervals(&x, Some(&w2), None, [-8.0, 10.0], 90, &levels),
        weighted
    );
}

/// Content of the intervals `iv` for draws uniform on `[lo, hi]`.
fn uniform_content(iv: &[[f64; 2]], lo: f64, hi: f64) -> f64 {
    iv.iter().map(|v| v[1].min(hi) - v[0].max(lo)).sum::<f64>() / (hi - lo)
}

#[test]
fn flat_marginal_gives_one_interval_of_the_level() {
    // A parameter the data do not constrain (a point contact's Li depth, uniform prior
    // 0.5-2 mm): 8000 draws in 60 bins. Without the noise test the highest bins were noise
    // picked all over the range (five pieces at 68.3% in such a fit).
    for seed in 0..20 {
        let mut rng = StdRng::seed_from_u64(100 + seed);
        let x: Vec<f64> = (0..8000).map(|_| rng.random_range(0.5..2.0)).collect();
        let iv = smallest_intervals(&x, None, None, [0.5, 2.0], 60, &[0.683, 0.955]);
        for (found, level) in iv.iter().zip([0.683, 0.955]) {
            assert_eq!(found.len(), 1, "seed {seed}, {level}: {found:?}");
            let c = uniform_content(found, 0.5, 2.0);
            assert!(
                (c - level).abs() < 0.03,
                "seed {seed}, {level}: {c} {found:?}"
            );
        }
    }
}

#[test]
fn autocorrelated_flat_draws_need_their_ess() {
    // A Markov chain on [0, 1] (reflected random walk, step sd 0.02): 8000 draws whose ESS
    // is a few hundred. Counted as 8000 independent draws its histogram's wiggles look
    // significant; with the chain's ESS they are noise and the interval is one piece.
    let mut rng = StdRng::seed_from_u64(7);
    let step = Normal::new(0.0, 0.02).unwrap();
    let mut x = Vec::with_capacity(8000);
    let mut v: f64 = 0.5;
    for _ in 0..8000 {
        v += step.sample(&mut rng);
        v = if v < 0.0 {
            -v
        } else if v > 1.0 {
            2.0 - v
        } else {
            v
        };
        x.push(v);
    }
    // ESS of a reflected walk: about n / (1 + 2 tau), tau ~ (range / step)^2 / pi^2 ~ 250.
    let iv = smallest_intervals(&x, None, Some(8000.0 / 500.0), [0.0, 1.0], 50, &[0.683]);
    assert_eq!(iv[0].len(), 1, "{:?}", iv[0]);
}

#[test]
fn a_real_dip_stays_a_gap_at_fit_size() {
    // Two modes at +-2 (sd 0.5) in 8000 draws: the dip at 0 holds almost nothing, far
    // below the noise of the cut, so the 68.3% region keeps two intervals.
    for seed in 0..10 {
        let mut rng = StdRng::seed_from_u64(200 + seed);
        let mut x = normal_draws(4000, -2.0, 0.5, &mut rng);
        x.extend(normal_draws(4000, 2.0, 0.5, &mut rng));
        let iv = smallest_intervals(&x, None, None, [-4.0, 4.0], 60, &[0.683, 0.955]);
        for found in &iv {
            assert_eq!(found.len(), 2, "seed {seed}: {found:?}");
            assert!(!interval_contains(found, 0.0), "seed {seed}: {found:?}");
        }
    }
}

#[test]
fn edge_cases() {
    assert_eq!(
        smallest_intervals(&[], None, None, [0.0, 1.0], 10, &[0.5, 0.9]),
        vec![Vec::<[f64; 2]>::new(); 2]
    );
    assert!(marginal_mode(&[], None, [0.0, 1.0], 10).is_nan());
    assert!(smallest_intervals(&[0.5], None, None, [1.0, 0.0], 10, &[0.5])[0].is_empty());
    // Draws outside the range land in the edge bins.
    // Five draws cannot tell the empty bins between them from noise: one interval. Told
    // that they are worth many effective draws, the empty bins are real gaps.
    let x = [-10.0, -10.0, -10.0, 0.55, 20.0];
    let iv = smallest_intervals(&x, None, None, [0.0, 1.0], 10, &[0.6, 1.0]);
    assert_eq!(iv[0], vec![[0.0, 0.1]]);
    assert_eq!(iv[1], vec![[0.0, 1.0]]);
    let iv = smallest_intervals(&x, None, Some(1e9), [0.0, 1.0], 10, &[0.6, 1.0]);
    assert_eq!(iv[0], vec![[0.0, 0.1]]);
    assert_eq!(iv[1].len(), 3);
    assert!((iv[1][2][0] - 0.9).abs() < 1e-12 && iv[1][2][1] == 1.0);
    assert!((marginal_mode(&x, None, [0.0, 1.0], 10) - 0.05).abs() < 1e-12);
    assert!(smallest_intervals(&x, None, None, [0.0, 1.0], 10, &[0.0])[0].is_empty());
    assert!(!interval_contains(&[[0.0, 1.0]], f64::NAN));
}
