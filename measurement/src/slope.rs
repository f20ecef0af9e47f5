//! The full-depletion voltage of a C-V curve (paper, section 4): the bias where
//! -dc12/dU_B falls to a threshold (1e-3 pF/V; the paper's Super-Siegfried: about 2600 V).

/// -Delta c12 / Delta U_B between neighbouring points, pF/V, at the midpoints (V).
pub fn negative_slopes(voltage_v: &[f64], c12_pf: &[f64]) -> Vec<(f64, f64)> {
    voltage_v
        .windows(2)
        .zip(c12_pf.windows(2))
        .map(|(u, c)| (0.5 * (u[0] + u[1]), -(c[1] - c[0]) / (u[1] - u[0])))
        .collect()
}

/// The first bias at which -dc12/dU_B falls to `threshold_pf_per_v` and stays there for the
/// rest of the curve: the last crossing from above, interpolated linearly in log(slope)
/// between the two midpoints around it (linearly in the slope where one is <= 0). `None` when
/// the slope never falls that low (not fully depleted within the curve), or is already below
/// it at the first midpoint (the crossing lies before the curve; the first voltage is then an
/// upper bound, reported by the caller).
///
/// ```
/// use hpge_measurement::depletion_voltage;
/// // c12 falls by 1 pF/V up to 100 V and by 1e-4 pF/V after: the paper's 1e-3 pF/V is
/// // crossed between the midpoints 95 V and 105 V.
/// let u: Vec<f64> = (0..=20).map(|k| 10.0 * k as f64).collect();
/// let c: Vec<f64> = u.iter().map(|&x| if x <= 100.0 { 200.0 - x } else { 100.0 - 1e-4 * (x - 100.0) }).collect();
/// let u_fd = depletion_voltage(&u, &c, 1e-3).expect("crossed inside the curve");
/// assert!(u_fd > 95.0 && u_fd < 105.0, "{u_fd}");
/// // Never flat enough: no depletion voltage.
/// let steep: Vec<f64> = u.iter().map(|&x| 300.0 - x).collect();
/// assert_eq!(depletion_voltage(&u, &steep, 1e-3), None);
/// ```
pub fn depletion_voltage(
    voltage_v: &[f64],
    c12_pf: &[f64],
    threshold_pf_per_v: f64,
) -> Option<f64> {
    let s = negative_slopes(voltage_v, c12_pf);
    let last_above = s.iter().rposition(|&(_, d)| d > threshold_pf_per_v)?;
    if last_above + 1 >= s.len() {
        return None;
    }
    let (u0, d0) = s[last_above];
    let (u1, d1) = s[last_above + 1];
    let f = if d1 > 0.0 {
        (threshold_pf_per_v.ln() - d0.ln()) / (d1.ln() - d0.ln())
    } else {
        (threshold_pf_per_v - d0) / (d1 - d0)
    };
    Some(u0 + f.clamp(0.0, 1.0) * (u1 - u0))
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn exponential_approach_crosses_where_expected() {
        // c = 30 + 100 exp(-U / 300): -dc/dU = (1/3) exp(-U / 300) = 1e-3 at U = 300 ln(333.3).
        let u: Vec<f64> = (0..60).map(|k| 25.0 + 50.0 * k as f64).collect();
        let c: Vec<f64> = u
            .iter()
            .map(|x| 30.0 + 100.0 * (-x / 300.0).exp())
            .collect();
        let got = depletion_voltage(&u, &c, 1e-3).unwrap();
        // Finite differences shift the slope by sinh(h/2L)/(h/2L): tiny at h = 50, L = 300.
        let want = 300.0 * (1.0 / 3e-3_f64).ln();
        assert!((got - want).abs() < 5.0, "{got} vs {want}");
        // Never flat enough: None.
        let steep: Vec<f64> = u.iter().map(|x| 1000.0 - 0.1 * x).collect();
        assert_eq!(depletion_voltage(&u, &steep, 1e-3), None);
    }
}
