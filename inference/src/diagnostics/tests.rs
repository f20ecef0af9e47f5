//! Diagnostics on chains with known answers: independent draws (R-hat 1, ESS ~ draws), AR(1)
//! chains (ESS = M N (1 - phi)/(1 + phi)), chains that disagree in location or only in scale.

use rand::SeedableRng;
use rand::rngs::StdRng;
use rand_distr::{Distribution, Normal};

use super::*;

fn ar1(m: usize, n: usize, phi: f64, seed: u64, shift: &[f64], scale: &[f64]) -> Vec<Vec<f64>> {
    let mut rng = StdRng::seed_from_u64(seed);
    let g = Normal::new(0.0, (1.0 - phi * phi).sqrt()).unwrap();
    (0..m)
        .map(|c| {
            let mut x = Normal::new(0.0, 1.0).unwrap().sample(&mut rng);
            (0..n)
                .map(|_| {
                    x = phi * x + g.sample(&mut rng);
                    shift[c] + scale[c] * x
                })
                .collect()
        })
        .collect()
}

#[test]
fn independent_draws_give_rhat_one_and_full_ess() {
    let ones = [1.0; 4];
    let zeros = [0.0; 4];
    let mut bulk = Vec::new();
    for seed in 0..5 {
        let c = ar1(4, 1000, 0.0, seed, &zeros, &ones);
        let d = Diagnostics::of(&c);
        assert!(d.rhat < 1.01, "seed {seed}: {d:?}");
        assert!(d.ess_tail > 2500.0, "seed {seed}: {d:?}");
        bulk.push(d.ess_bulk);
    }
    let mean = bulk.iter().sum::<f64>() / bulk.len() as f64;
    assert!((mean / 4000.0 - 1.0).abs() < 0.1, "mean bulk ESS {mean}");
}

#[test]
fn ar1_chains_give_the_theoretical_ess() {
    // ESS = M N (1 - phi) / (1 + phi) for an AR(1) process.
    for (phi, seed) in [(0.5, 1), (0.9, 2)] {
        let (m, n) = (4, 20000);
        let c = ar1(m, n, phi, seed, &[0.0; 4], &[1.0; 4]);
        let expected = (m * n) as f64 * (1.0 - phi) / (1.0 + phi);
        let got = ess(&c);
        assert!(
            (got / expected - 1.0).abs() < 0.12,
            "phi {phi}: ESS {got}, expected {expected}"
        );
        let bulk = ess_bulk(&c);
        assert!(
            (bulk / expected - 1.0).abs() < 0.15,
            "phi {phi}: bulk {bulk}, expected {expected}"
        );
        assert!(rank_rhat(&c) < 1.01);
    }
}

#[test]
fn disagreeing_chains_are_flagged() {
    // One chain shifted by half a standard deviation.
    let c = ar1(4, 1000, 0.3, 7, &[0.0, 0.0, 0.0, 0.5], &[1.0; 4]);
    assert!(rank_rhat(&c) > 1.02, "location: {}", rank_rhat(&c));
    // Same location, one chain three times as wide: only the folded R-hat sees it.
    let c = ar1(4, 1000, 0.0, 8, &[0.0; 4], &[1.0, 1.0, 1.0, 3.0]);
    let bulk_only = split_rhat(&rank_normalise(&split_chains(&c)));
    assert!(bulk_only < 1.02, "bulk {bulk_only}");
    assert!(rank_rhat(&c) > 1.05, "scale: {}", rank_rhat(&c));
    // A trend within each chain: split R-hat sees it.
    let trend: Vec<Vec<f64>> = ar1(4, 1000, 0.0, 9, &[0.0; 4], &[1.0; 4])
        .into_iter()
        .map(|c| {
            c.iter()
                .enumerate()
                .map(|(i, x)| x + 2.0 * i as f64 / 1000.0)
                .collect()
        })
        .collect();
    assert!(rank_rhat(&trend) > 1.05, "trend: {}", rank_rhat(&trend));
}

#[test]
fn ranks_are_normal_scores_and_ties_share_a_rank() {
    let c = vec![vec![3.0, 1.0, 2.0], vec![2.0, 5.0, 4.0]];
    let z = rank_normalise(&c);
    // Ranks 1..6 with the two 2.0 sharing 2.5.
    assert_eq!(z[0][2], z[1][0]);
    assert!(z[0][1] < z[0][2] && z[0][2] < z[0][0] && z[1][2] < z[1][1]);
    let s = 6.0;
    let expected = hpge_foundation::normal_quantile((1.0 - 0.375) / (s + 0.25));
    assert!((z[0][1] - expected).abs() < 1e-12);
    assert_eq!(
        split_chains(&[vec![1.0, 2.0, 3.0, 4.0, 5.0]]),
        vec![vec![1.0, 2.0], vec![4.0, 5.0]]
    );
    assert_eq!(
        fold(&[vec![1.0, 3.0], vec![2.0, 6.0]]),
        vec![vec![1.5, 0.5], vec![0.5, 3.5]]
    );
}

#[test]
fn fft_autocovariances_equal_the_direct_sums_at_every_lag() {
    use super::ess::{autocov, autocovariances};
    let mut planner = rustfft::FftPlanner::new();
    // Lengths at, below and above a power of two; an AR(1) chain with long memory and one
    // with a shifted mean.
    for (n, phi, seed) in [(1, 0.0, 1), (7, 0.3, 2), (64, 0.9, 3), (1000, 0.95, 4)] {
        let c = &ar1(1, n, phi, seed, &[3.0], &[2.0])[0];
        let mean = c.iter().sum::<f64>() / n as f64;
        let fast = autocovariances(c, mean, &mut planner);
        assert_eq!(fast.len(), n);
        for (t, a) in fast.iter().enumerate() {
            let direct = autocov(c, mean, t);
            assert!(
                (a - direct).abs() <= 1e-12 * fast[0].abs().max(1e-300) + 1e-15,
                "n {n}, lag {t}: fft {a}, direct {direct}"
            );
        }
    }
}

proptest::proptest! {
    #[test]
    fn fft_autocovariances_match_the_direct_sum(
        c in proptest::collection::vec(-1e3f64..1e3, 2..300),
        lag_frac in 0.0f64..1.0,
    ) {
        let mean = c.iter().sum::<f64>() / c.len() as f64;
        let mut planner = rustfft::FftPlanner::new();
        let fast = super::ess::autocovariances(&c, mean, &mut planner);
        let t = ((c.len() - 1) as f64 * lag_frac) as usize;
        let direct = super::ess::autocov(&c, mean, t);
        proptest::prop_assert!((fast[t] - direct).abs() <= 1e-10 * fast[0].max(1e-12));
    }
}

#[test]
fn diagnostics_of_equal_the_three_functions_apart() {
    let c = ar1(
        4,
        999,
        0.7,
        11,
        &[0.0, 0.1, 0.0, -0.1],
        &[1.0, 1.0, 1.2, 1.0],
    );
    let d = Diagnostics::of(&c);
    assert_eq!(d.rhat, rank_rhat(&c));
    assert_eq!(d.ess_bulk, ess_bulk(&c));
    assert_eq!(d.ess_tail, ess_tail(&c));
}

#[test]
fn worst_takes_the_largest_rhat_and_the_smallest_of_either_ess() {
    let d = |rhat, ess_bulk, ess_tail| Diagnostics {
        rhat,
        ess_bulk,
        ess_tail,
    };
    let all = [
        d(1.002, 900.0, 1200.0),
        d(1.03, 1500.0, 310.0),
        d(f64::NAN, 700.0, 800.0),
    ];
    assert_eq!(Diagnostics::worst(&all), (1.03, 310.0));
    assert_eq!(Diagnostics::worst(&[]), (0.0, f64::INFINITY));
}
