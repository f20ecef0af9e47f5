use proptest::prelude::*;
use rand::{RngExt, SeedableRng};

use super::*;

/// Hickernell's wrap-around L2 discrepancy of points in [0, 1)^d (shift-invariant, the natural
/// measure for Kronecker sequences such as R_d).
fn wrap_around(points: &[Vec<f64>]) -> f64 {
    let n = points.len() as f64;
    let d = points[0].len() as i32;
    let mut c = 0.0;
    for p in points {
        for q in points {
            c += p
                .iter()
                .zip(q)
                .map(|(x, y)| {
                    let t = (x - y).abs();
                    1.5 - t * (1.0 - t)
                })
                .product::<f64>();
        }
    }
    (c / (n * n) - (4.0f64 / 3.0).powi(d)).max(0.0).sqrt()
}

#[test]
fn phi_d_values() {
    assert!((phi_d(1) - (1.0 + 5f64.sqrt()) / 2.0).abs() < 1e-15);
    // The plastic number for d = 2.
    assert!((phi_d(2) - 1.324_717_957_244_746).abs() < 1e-15);
    let p = phi_d(10);
    assert!((p.powi(11) - p - 1.0).abs() < 1e-13);
}

#[test]
fn golden_seed_zero_is_roberts_sequence() {
    let s = Sequence::new(SequenceKind::Golden, 2, 0);
    let g = phi_d(2);
    for n in [0u64, 1, 7, 1000, 123_456_789] {
        let p = s.point(n);
        let want = [
            (0.5 + n as f64 / g).fract(),
            (0.5 + n as f64 / (g * g)).fract(),
        ];
        for (a, b) in p.iter().zip(want) {
            // The plain product loses ~log2(n) bits; the split product does not.
            assert!(
                (a - b).abs() < 1e-15 * (n as f64).max(1.0),
                "{n}: {a} vs {b}"
            );
        }
    }
}

/// Both sequences fill [0, 1)^10 more evenly than pseudo-random points at equal n.
#[test]
fn lower_discrepancy_than_pseudo_random() {
    let n = 512;
    let mut rng = rand::rngs::StdRng::seed_from_u64(1);
    let mut random_d = 0.0;
    for _ in 0..5 {
        let pts: Vec<Vec<f64>> = (0..n)
            .map(|_| (0..10).map(|_| rng.random::<f64>()).collect())
            .collect();
        random_d += wrap_around(&pts) / 5.0;
    }
    for kind in [SequenceKind::Golden, SequenceKind::Sobol] {
        let s = Sequence::new(kind, 10, 3);
        let pts: Vec<Vec<f64>> = (0..n).map(|i| s.point(i as u64)).collect();
        let d = wrap_around(&pts);
        eprintln!(
            "{}: wrap-around L2 {d:.3e}, pseudo-random {random_d:.3e}",
            kind.as_str()
        );
        assert!(d < 0.8 * random_d, "{kind:?}: {d} vs {random_d}");
    }
}

proptest! {
    #[test]
    fn every_coordinate_in_the_unit_interval(n in 0u64..u64::from(u32::MAX), seed in 0u64..1000) {
        for kind in [SequenceKind::Golden, SequenceKind::Sobol] {
            let s = Sequence::new(kind, 10, seed);
            let n = n % s.max_points();
            for u in s.point(n) {
                prop_assert!((0.0..1.0).contains(&u), "{:?} {} {}", kind, n, u);
            }
        }
    }

    #[test]
    fn points_are_pure_functions_of_the_index(n in 0u64..1_000_000, seed in 0u64..100) {
        let a = Sequence::new(SequenceKind::Golden, 10, seed);
        let b = Sequence::new(SequenceKind::Golden, 10, seed);
        prop_assert_eq!(a.point(n), b.point(n));
    }
}
