//! A diverging colour map for signed impurity densities.
//!
//! The density is mapped to t in [-1, 1] on a symmetric log scale over the decades the C-V
//! measurement is sensitive to (paper, section 6: zeta_l = 1e8 to zeta_u = 1e11 cm^-3):
//! t = sign(zeta) * clamp(log10(|zeta| / 1e8) / 3, 0, 1). n-type (t > 0) runs from light grey
//! through orange to dark red, p-type (t < 0) through light to dark blue.

use plotters::style::RGBColor;

/// Lower end of the log scale, cm^-3 (densities below map to t = 0).
pub const ZETA_LOW_CM3: f64 = 1e8;
/// Decades shown (1e8 .. 1e11 cm^-3).
pub const DECADES: f64 = 3.0;

/// t = sign(zeta) * clamp(log10(|zeta| / 1e8) / 3, 0, 1).
pub fn density_to_t(zeta_cm3: f64) -> f64 {
    if !zeta_cm3.is_finite() || zeta_cm3.abs() <= ZETA_LOW_CM3 {
        return 0.0;
    }
    zeta_cm3.signum() * ((zeta_cm3.abs() / ZETA_LOW_CM3).log10() / DECADES).clamp(0.0, 1.0)
}

const N_TYPE: [(f64, [u8; 3]); 5] = [
    (0.0, [240, 240, 240]),
    (0.25, [253, 219, 199]),
    (0.5, [244, 165, 130]),
    (0.75, [214, 96, 77]),
    (1.0, [103, 0, 31]),
];
const P_TYPE: [(f64, [u8; 3]); 5] = [
    (0.0, [240, 240, 240]),
    (0.25, [209, 229, 240]),
    (0.5, [146, 197, 222]),
    (0.75, [67, 147, 195]),
    (1.0, [5, 48, 97]),
];

/// Colour of t in [-1, 1], quantised to `levels` steps per sign (0: no quantisation).
pub fn t_color(t: f64, levels: usize) -> RGBColor {
    let mut a = t.abs().clamp(0.0, 1.0);
    if levels > 0 {
        a = (a * levels as f64).round() / levels as f64;
    }
    let table = if t >= 0.0 { &N_TYPE } else { &P_TYPE };
    let i = table
        .windows(2)
        .position(|w| a <= w[1].0)
        .unwrap_or(table.len() - 2);
    let (t0, c0) = table[i];
    let (t1, c1) = table[i + 1];
    let f = ((a - t0) / (t1 - t0)).clamp(0.0, 1.0);
    let mix = |k: usize| (c0[k] as f64 + f * (c1[k] as f64 - c0[k] as f64)).round() as u8;
    RGBColor(mix(0), mix(1), mix(2))
}

/// Colour of a density in cm^-3 (quantised to `levels` steps per sign).
pub fn density_color(zeta_cm3: f64, levels: usize) -> RGBColor {
    t_color(density_to_t(zeta_cm3), levels)
}

/// A perceptually ordered map (viridis anchors) for t in [0, 1].
pub(super) fn viridis(t: f64) -> RGBColor {
    const A: [(f64, [u8; 3]); 5] = [
        (0.0, [68, 1, 84]),
        (0.25, [59, 82, 139]),
        (0.5, [33, 145, 140]),
        (0.75, [94, 201, 98]),
        (1.0, [253, 231, 37]),
    ];
    let t = t.clamp(0.0, 1.0);
    let i = A
        .windows(2)
        .position(|w| t <= w[1].0)
        .unwrap_or(A.len() - 2);
    let (t0, c0) = A[i];
    let (t1, c1) = A[i + 1];
    let f = (t - t0) / (t1 - t0);
    let m = |k: usize| (c0[k] as f64 + f * (c1[k] as f64 - c0[k] as f64)).round() as u8;
    RGBColor(m(0), m(1), m(2))
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn scale() {
        assert_eq!(density_to_t(0.0), 0.0);
        assert_eq!(density_to_t(1e8), 0.0);
        assert!((density_to_t(1e11) - 1.0).abs() < 1e-12);
        assert!((density_to_t(-1e10) + 2.0 / 3.0).abs() < 1e-12);
        assert_eq!(density_to_t(1e13), 1.0);
        assert_eq!(density_to_t(f64::NAN), 0.0);
        // The manufacturer's top and bottom values get visibly different colours.
        assert_ne!(density_color(0.44e10, 48), density_color(1.3e10, 48));
        assert_eq!(t_color(1.0, 0), RGBColor(103, 0, 31));
        assert_eq!(t_color(-1.0, 0), RGBColor(5, 48, 97));
    }
}
