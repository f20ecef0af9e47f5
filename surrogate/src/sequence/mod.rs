//! Low-discrepancy sequences on [0, 1)^d: the golden R_d sequence (the paper's choice) and
//! Owen-scrambled Sobol (sobol_burley), with a start offset and a seed.

use serde::{Deserialize, Serialize};

/// Which sequence (a closed set).
#[derive(Debug, Clone, Copy, PartialEq, Eq, Default, Serialize, Deserialize)]
#[serde(rename_all = "snake_case")]
pub enum SequenceKind {
    /// The golden R_d sequence (Roberts 2018): u_n = frac(s + n alpha), alpha_i = phi_d^-i.
    #[default]
    Golden,
    /// Owen-scrambled Sobol (Burley 2020, the sobol_burley crate): 2^16 points, up to 256
    /// dimensions, f32 resolution.
    Sobol,
}

impl SequenceKind {
    /// Name as on the command line.
    pub fn as_str(self) -> &'static str {
        match self {
            SequenceKind::Golden => "golden",
            SequenceKind::Sobol => "sobol",
        }
    }
}

/// A seeded sequence in d dimensions; point n is a pure function of (kind, d, seed, n), so any
/// index range can be computed anywhere (shards, resumed runs).
#[derive(Debug, Clone, PartialEq)]
pub struct Sequence {
    kind: SequenceKind,
    dim: usize,
    seed: u64,
    alpha: Vec<f64>,
    start: Vec<f64>,
}

/// phi_d: the positive root of x^(d+1) = x + 1 (Newton from 2; phi_1 is the golden ratio).
///
/// ```
/// use hpge_surrogate::sequence::phi_d;
/// assert!((phi_d(1) - (1.0 + 5f64.sqrt()) / 2.0).abs() < 1e-15);
/// let p = phi_d(10);
/// assert!((p.powi(11) - p - 1.0).abs() < 1e-12);
/// ```
pub fn phi_d(d: usize) -> f64 {
    let p = (d + 1) as i32;
    let mut x = 2.0_f64;
    for _ in 0..100 {
        let f = x.powi(p) - x - 1.0;
        let df = p as f64 * x.powi(p - 1) - 1.0;
        let next = x - f / df;
        if (next - x).abs() <= 1e-16 * x {
            return next;
        }
        x = next;
    }
    x
}

/// splitmix64: a well-mixed 64-bit value from a counter.
fn splitmix(mut z: u64) -> u64 {
    z = z.wrapping_add(0x9E37_79B9_7F4A_7C15);
    z = (z ^ (z >> 30)).wrapping_mul(0xBF58_476D_1CE4_E5B9);
    z = (z ^ (z >> 27)).wrapping_mul(0x94D0_49BB_1331_11EB);
    z ^ (z >> 31)
}

impl Sequence {
    /// The sequence of `kind` in `dim` dimensions. Golden: seed 0 starts at s = (0.5, ..., 0.5)
    /// (Roberts' choice); other seeds draw s uniformly from [0, 1)^d. Sobol: the seed selects
    /// the scrambling (its low 32 bits).
    pub fn new(kind: SequenceKind, dim: usize, seed: u64) -> Self {
        let phi = phi_d(dim);
        let alpha = (1..=dim).map(|i| phi.powi(-(i as i32))).collect();
        let start = (0..dim)
            .map(|i| {
                if seed == 0 {
                    0.5
                } else {
                    (splitmix(seed.wrapping_mul(1000).wrapping_add(i as u64)) >> 11) as f64
                        / (1u64 << 53) as f64
                }
            })
            .collect();
        Self {
            kind,
            dim,
            seed,
            alpha,
            start,
        }
    }

    /// Dimensions.
    pub fn dim(&self) -> usize {
        self.dim
    }

    /// Number of points the sequence offers: 2^53 for golden (exact indices in f64), 2^16 for
    /// sobol_burley's scrambled Sobol.
    pub fn max_points(&self) -> u64 {
        match self.kind {
            SequenceKind::Golden => 1 << 53,
            SequenceKind::Sobol => 1 << 16,
        }
    }

    /// The kind.
    pub fn kind(&self) -> SequenceKind {
        self.kind
    }

    /// The seed.
    pub fn seed(&self) -> u64 {
        self.seed
    }

    /// Point n (n < [`Self::max_points`]; callers check the range), every coordinate in [0, 1).
    ///
    /// ```
    /// use hpge_surrogate::{Sequence, SequenceKind};
    /// let s = Sequence::new(SequenceKind::Golden, 3, 0);
    /// // Seed 0 starts at the centre; point n adds n alpha (mod 1).
    /// assert_eq!(s.point(0), vec![0.5, 0.5, 0.5]);
    /// let p = s.point(1000);
    /// assert!(p.iter().all(|x| (0.0..1.0).contains(x)));
    /// assert_eq!(p, s.point(1000), "a point depends on its index alone");
    /// ```
    pub fn point(&self, n: u64) -> Vec<f64> {
        match self.kind {
            SequenceKind::Golden => self
                .alpha
                .iter()
                .zip(&self.start)
                .map(|(&a, &s)| {
                    // frac(s + n a) with n a split so that the product keeps its low bits.
                    let hi = (n >> 26) as f64 * (a * (1u64 << 26) as f64).fract();
                    let lo = (n & ((1 << 26) - 1)) as f64 * a;
                    let v = (s + hi.fract() + lo.fract()).fract();
                    if v >= 1.0 { 0.0 } else { v }
                })
                .collect(),
            SequenceKind::Sobol => (0..self.dim)
                .map(|i| {
                    let v = sobol_burley::sample(n as u32, i as u32, self.seed as u32) as f64;
                    if v >= 1.0 { 0.0 } else { v }
                })
                .collect(),
        }
    }
}

#[cfg(test)]
mod tests;
