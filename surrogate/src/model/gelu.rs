//! GELU in its tanh form (Flux's `gelu`, candle's `gelu`), written so that the compiler can
//! vectorise it: tanh through a polynomial exp with exact 2^n scaling.
//!
//! gelu(x) = x/2 (1 + tanh(u)), u = sqrt(2/pi) (x + 0.044715 x^3);
//! gelu'(x) = (1 + tanh u)/2 + x/2 (1 - tanh^2 u) sqrt(2/pi) (1 + 3 0.044715 x^2).

const SQRT_2_OVER_PI: f64 = 0.797_884_560_802_865_4;
const CUBIC: f64 = 0.044_715;

/// e^x for |x| <= 40 to about 2 ulp: x = n ln 2 + r, |r| <= ln 2 / 2, e^r by its Taylor series to
/// r^13 (remainder < 1e-16 relative), times 2^n built from the exponent bits.
#[inline(always)]
pub fn exp_small(x: f64) -> f64 {
    const LN2_HI: f64 = 0.693_147_180_369_123_8;
    const LN2_LO: f64 = 1.908_214_929_270_587_7e-10;
    const MAGIC: f64 = 6_755_399_441_055_744.0; // 1.5 * 2^52: adding it rounds to an integer
    let t = x * std::f64::consts::LOG2_E + MAGIC;
    let n = t - MAGIC;
    let r = (x - n * LN2_HI) - n * LN2_LO;
    // The low bits of t hold n (two's complement): 2^n from integer lanes, no float-to-int
    // conversion, so the loop vectorises with AVX2.
    let n_bits = t.to_bits().wrapping_sub(MAGIC.to_bits());
    let mut p = 1.0 / 6_227_020_800.0;
    p = p * r + 1.0 / 479_001_600.0;
    p = p * r + 1.0 / 39_916_800.0;
    p = p * r + 1.0 / 3_628_800.0;
    p = p * r + 1.0 / 362_880.0;
    p = p * r + 1.0 / 40_320.0;
    p = p * r + 1.0 / 5_040.0;
    p = p * r + 1.0 / 720.0;
    p = p * r + 1.0 / 120.0;
    p = p * r + 1.0 / 24.0;
    p = p * r + 1.0 / 6.0;
    p = p * r + 0.5;
    p = p * r + 1.0;
    p = p * r + 1.0;
    let scale = f64::from_bits(n_bits.wrapping_add(1023) << 52);
    p * scale
}

/// tanh(u) = 1 - 2 / (e^(2u) + 1), with u clamped to [-20, 20] (tanh(20) = 1 - 8e-18).
#[inline(always)]
pub fn tanh_fast(u: f64) -> f64 {
    let u = u.clamp(-20.0, 20.0);
    1.0 - 2.0 / (exp_small(2.0 * u) + 1.0)
}

/// gelu(x) in place over a slice.
#[inline(always)]
pub fn gelu_in_place(x: &mut [f64]) {
    for v in x.iter_mut() {
        let t = tanh_fast(SQRT_2_OVER_PI * (*v + CUBIC * *v * *v * *v));
        *v = 0.5 * *v * (1.0 + t);
    }
}

/// gelu(x) into `x` and gelu'(x) into `d`.
#[inline(always)]
pub fn gelu_and_derivative(x: &mut [f64], d: &mut [f64]) {
    for (v, dv) in x.iter_mut().zip(d.iter_mut()) {
        let x0 = *v;
        let t = tanh_fast(SQRT_2_OVER_PI * (x0 + CUBIC * x0 * x0 * x0));
        *v = 0.5 * x0 * (1.0 + t);
        *dv = 0.5 * (1.0 + t)
            + 0.5 * x0 * (1.0 - t * t) * SQRT_2_OVER_PI * (1.0 + 3.0 * CUBIC * x0 * x0);
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn exp_and_tanh_match_the_standard_library() {
        let mut worst_exp = 0.0_f64;
        let mut worst_tanh = 0.0_f64;
        for k in -4000..=4000 {
            let x = k as f64 * 0.01;
            worst_exp = worst_exp.max((exp_small(x) / x.exp() - 1.0).abs());
            worst_tanh = worst_tanh.max((tanh_fast(x) - x.tanh()).abs());
        }
        assert!(worst_exp < 1e-15, "exp relative error {worst_exp:e}");
        assert!(worst_tanh < 1e-15, "tanh absolute error {worst_tanh:e}");
    }

    #[test]
    fn gelu_derivative_matches_central_differences() {
        let xs: Vec<f64> = (-60..=60).map(|k| k as f64 * 0.1).collect();
        let mut y = xs.clone();
        let mut d = vec![0.0; xs.len()];
        gelu_and_derivative(&mut y, &mut d);
        for (i, &x) in xs.iter().enumerate() {
            let h = 1e-5;
            let mut p = [x + h, x - h];
            gelu_in_place(&mut p);
            let fd = (p[0] - p[1]) / (2.0 * h);
            assert!((fd - d[i]).abs() < 1e-8, "x = {x}: {fd} vs {}", d[i]);
            let exact = 0.5 * x * (1.0 + (SQRT_2_OVER_PI * (x + CUBIC * x.powi(3))).tanh());
            assert!((y[i] - exact).abs() < 1e-14);
        }
    }
}
