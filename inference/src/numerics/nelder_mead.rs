//! A small Nelder-Mead simplex maximiser (Nelder & Mead 1965, with the standard coefficients
//! 1, 2, 1/2, 1/2): the samplers' mode search, and the refinement of a fit's best draw to the
//! global mode. Written by hand: a few hundred evaluations of a cheap function, no bounds (the
//! samplers' unconstrained coordinates).

/// Maximises `f` from `x0` with initial steps `step`; stops after `max_evals` evaluations or when
/// the simplex's values agree within `tol`. Returns (x, f(x)).
///
/// ```
/// use hpge_inference::numerics::nelder_mead;
/// // The maximum of -(x - 1)^2 - 10 (y + 2)^2 at (1, -2).
/// let f = |x: &[f64]| -(x[0] - 1.0).powi(2) - 10.0 * (x[1] + 2.0).powi(2);
/// let (x, fx) = nelder_mead(&f, &[0.0, 0.0], 0.5, 2000, 1e-14);
/// assert!((x[0] - 1.0).abs() < 1e-5 && (x[1] + 2.0).abs() < 1e-5);
/// assert!(fx <= 0.0 && fx > -1e-9);
/// ```
pub fn nelder_mead(
    f: &dyn Fn(&[f64]) -> f64,
    x0: &[f64],
    step: f64,
    max_evals: usize,
    tol: f64,
) -> (Vec<f64>, f64) {
    nelder_mead_until(f, x0, step, max_evals, tol, &|| false)
}

/// As [`nelder_mead`], also stopping (with the best point so far) as soon as `stop()` holds
/// after a step (a time budget; the first simplex is always evaluated).
pub fn nelder_mead_until(
    f: &dyn Fn(&[f64]) -> f64,
    x0: &[f64],
    step: f64,
    max_evals: usize,
    tol: f64,
    stop: &dyn Fn() -> bool,
) -> (Vec<f64>, f64) {
    let d = x0.len();
    // Minimise g = -f; NaN counts as +inf.
    let g = |x: &[f64]| {
        let v = -f(x);
        if v.is_nan() { f64::INFINITY } else { v }
    };
    let mut simplex: Vec<(Vec<f64>, f64)> = Vec::with_capacity(d + 1);
    simplex.push((x0.to_vec(), g(x0)));
    for i in 0..d {
        let mut x = x0.to_vec();
        x[i] += step;
        let v = g(&x);
        simplex.push((x, v));
    }
    let mut evals = d + 1;
    while evals < max_evals && !stop() {
        simplex.sort_by(|a, b| a.1.total_cmp(&b.1));
        if (simplex[d].1 - simplex[0].1).abs() <= tol {
            break;
        }
        let centroid: Vec<f64> = (0..d)
            .map(|j| simplex[..d].iter().map(|p| p.0[j]).sum::<f64>() / d as f64)
            .collect();
        let along = |t: f64| -> Vec<f64> {
            (0..d)
                .map(|j| centroid[j] + t * (simplex[d].0[j] - centroid[j]))
                .collect()
        };
        let xr = along(-1.0);
        let fr = g(&xr);
        evals += 1;
        if fr < simplex[0].1 {
            let xe = along(-2.0);
            let fe = g(&xe);
            evals += 1;
            simplex[d] = if fe < fr { (xe, fe) } else { (xr, fr) };
        } else if fr < simplex[d - 1].1 {
            simplex[d] = (xr, fr);
        } else {
            let xc = if fr < simplex[d].1 {
                along(-0.5)
            } else {
                along(0.5)
            };
            let fc = g(&xc);
            evals += 1;
            if fc < simplex[d].1.min(fr) {
                simplex[d] = (xc, fc);
            } else {
                let best = simplex[0].0.clone();
                for p in simplex.iter_mut().skip(1) {
                    for (x, b) in p.0.iter_mut().zip(&best) {
                        *x = b + 0.5 * (*x - b);
                    }
                    p.1 = g(&p.0);
                    evals += 1;
                }
            }
        }
    }
    simplex.sort_by(|a, b| a.1.total_cmp(&b.1));
    let (x, v) = simplex.swap_remove(0);
    (x, -v)
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn finds_the_maximum_of_a_rosenbrock_valley() {
        let f = |x: &[f64]| -((1.0 - x[0]).powi(2) + 100.0 * (x[1] - x[0] * x[0]).powi(2));
        let (x, v) = nelder_mead(&f, &[-1.2, 1.0], 0.5, 5000, 1e-14);
        assert!(
            (x[0] - 1.0).abs() < 1e-3 && (x[1] - 1.0).abs() < 2e-3,
            "{x:?}"
        );
        assert!(v > -1e-6);
    }
}
