//! The exact front equations: one front facing a contact, two fronts of one layer (Newton, else a
//! nested bracketed solve), and the bracketed root search they use.

use super::layers::{End, Fronts};
use crate::error::Result;

impl<'p, 'z> Fronts<'p, 'z> {
    /// Front s (m) facing a contact (r_c, phi_c): root of phi_c - beta + (q/eps) psi_s(r_c) in
    /// [lo, hi] nearest to the estimate s0.
    pub(super) fn front_root(
        &self,
        beta: f64,
        rc: f64,
        phic: f64,
        s0: f64,
        lo: f64,
        hi: f64,
    ) -> Result<Option<f64>> {
        let mc = self.prof.moments(rc)?;
        let f = |s: f64| -> Result<Option<f64>> {
            Ok(Some(
                phic - beta + self.prof.k * self.prof.psi(rc, self.prof.moments(s)?, mc),
            ))
        };
        bracket_root(f, lo, hi, s0, 1e-14 * self.b)
    }

    /// Residuals (V) of a layer between two fronts: (q/eps)(M0(s2) - M0(s1)) and
    /// beta2 - beta1 + (q/eps) psi_{s1}(s2).
    fn pair_residual(&self, s1: f64, s2: f64, b1: f64, b2: f64) -> Result<[f64; 2]> {
        let (m1, m2) = (self.prof.moments(s1)?, self.prof.moments(s2)?);
        let k = self.prof.k;
        Ok([k * (m2.0 - m1.0), b2 - b1 + k * self.prof.psi(s2, m1, m2)])
    }

    /// Two fronts of one layer: Newton, else the nested bracketed solve.
    pub(super) fn front_pair(&self, left: End, right: End) -> Result<Option<(f64, f64)>> {
        // Between conductors at one potential s1 = s2 solves both equations: Newton may fall into
        // that degenerate layer, the nested form excludes it.
        let same = matches!((left, right), (End::Free { beta: b1, .. }, End::Free { beta: b2, .. }) if b1 == b2);
        match self.front_pair_newton(left, right)? {
            Some(x) if !same || x.1 - x.0 > 1e-3 * self.prof.grid.h => Ok(Some(x)),
            _ => self.front_pair_nested(left, right),
        }
    }

    /// Nested form, robust where Newton is not (sub-cell layers across a step of zeta): for each s1
    /// the neutral s2(s1) > s1 (int_{s1}^{s2} zeta t dt = 0, bracketed), then the root in s1 of
    /// beta2 - beta1 + (q/eps) psi_{s1}(s2(s1)) (whose s1-derivative is
    /// -(q/eps) zeta(s1) s1 ln(s2/s1): the s2-derivative vanishes at neutrality).
    fn front_pair_nested(&self, left: End, right: End) -> Result<Option<(f64, f64)>> {
        let (
            End::Free {
                s: e1,
                beta: b1,
                lo: lo1,
                hi: hi1,
                ..
            },
            End::Free {
                s: e2,
                beta: b2,
                lo: lo2,
                hi: hi2,
                ..
            },
        ) = (left, right)
        else {
            return Ok(None);
        };
        let (k, xtol) = (self.prof.k, 1e-14 * self.b);
        let neutral = |s1: f64| -> Result<Option<(f64, (f64, f64))>> {
            let m1 = self.prof.moments(s1)?;
            let lo = lo2.max(s1 + 1e-6 * self.prof.grid.h);
            if lo >= hi2 {
                return Ok(None);
            }
            let h = |s2: f64| -> Result<Option<f64>> { Ok(Some(self.prof.moments(s2)?.0 - m1.0)) };
            Ok(bracket_root(h, lo, hi2, e2, xtol)?.map(|s2| (s2, m1)))
        };
        let outer = |s1: f64| -> Result<Option<f64>> {
            Ok(match neutral(s1)? {
                Some((s2, m1)) => Some(b2 - b1 + k * self.prof.psi(s2, m1, self.prof.moments(s2)?)),
                None => None,
            })
        };
        let Some(s1) = bracket_root(outer, lo1, hi1, e1, xtol)? else {
            return Ok(None);
        };
        Ok(neutral(s1)?.map(|(s2, _)| (s1, s2)))
    }

    /// Two fronts of one layer by damped Newton, each kept in its window. Jacobian:
    /// d/ds1 = (-(q/eps) zeta1 s1, -(q/eps) zeta1 s1 ln(s2/s1)), d/ds2 = ((q/eps) zeta2 s2, R1 / s2).
    fn front_pair_newton(&self, left: End, right: End) -> Result<Option<(f64, f64)>> {
        let (
            End::Free {
                s: mut s1,
                beta: b1,
                lo: lo1,
                hi: hi1,
                ..
            },
            End::Free {
                s: mut s2,
                beta: b2,
                lo: lo2,
                hi: hi2,
                ..
            },
        ) = (left, right)
        else {
            return Ok(None);
        };
        let k = self.prof.k;
        let norm = |r: [f64; 2]| r[0].abs().max(r[1].abs());
        // Newton runs until the residual stops falling (round-off, ~1e-16 vscale); accepted below
        // 1e-13 vscale.
        let tol = 1e-13 * self.vscale;
        let mut res = self.pair_residual(s1, s2, b1, b2)?;
        for _ in 0..100 {
            if norm(res) == 0.0 {
                break;
            }
            let (z1, z2) = (self.prof.zeta_si(s1)?, self.prof.zeta_si(s2)?);
            let j = [
                [-k * z1 * s1, k * z2 * s2],
                [-k * z1 * s1 * (s2 / s1).ln(), res[0] / s2],
            ];
            let det = j[0][0] * j[1][1] - j[0][1] * j[1][0];
            if det == 0.0 || !det.is_finite() {
                return Ok(None);
            }
            let d1 = -(res[0] * j[1][1] - j[0][1] * res[1]) / det;
            let d2 = -(j[0][0] * res[1] - j[1][0] * res[0]) / det;
            let mut t = 1.0;
            let mut accepted = false;
            for _ in 0..40 {
                let (c1, c2) = ((s1 + t * d1).clamp(lo1, hi1), (s2 + t * d2).clamp(lo2, hi2));
                let rc = self.pair_residual(c1, c2, b1, b2)?;
                if norm(rc) < norm(res) {
                    (s1, s2, res) = (c1, c2, rc);
                    accepted = true;
                    break;
                }
                t *= 0.5;
            }
            if !accepted {
                break;
            }
        }
        Ok((norm(res) <= tol && s1 < s2).then_some((s1, s2)))
    }
}

/// A root of `f` in [lo, hi]: the sign change nearest to `s0` among 13 samples (samples where `f`
/// is undefined are skipped), refined by Illinois regula falsi to `xtol`; None without a sign change
/// or where `f` turns undefined inside the bracket.
fn bracket_root<F>(mut f: F, lo: f64, hi: f64, s0: f64, xtol: f64) -> Result<Option<f64>>
where
    F: FnMut(f64) -> Result<Option<f64>>,
{
    const SAMPLES: usize = 12;
    let mut samples = Vec::with_capacity(SAMPLES + 1);
    for j in 0..=SAMPLES {
        let x = lo + (hi - lo) * j as f64 / SAMPLES as f64;
        samples.push((x, f(x)?));
    }
    let mut pts: Vec<(f64, f64)> = samples
        .iter()
        .filter_map(|&(x, v)| v.map(|v| (x, v)))
        .collect();
    // Where f turns undefined between samples, bisect to the edge of its domain: a root may sit
    // between the last sample and that edge (a layer thinner than the sample spacing).
    for w in samples.windows(2) {
        let ((x0, v0), (x1, v1)) = (w[0], w[1]);
        if v0.is_some() == v1.is_some() {
            continue;
        }
        let (mut good, mut bad) = if v0.is_some() { (x0, x1) } else { (x1, x0) };
        let mut edge = None;
        while (bad - good).abs() > xtol {
            let m = 0.5 * (good + bad);
            match f(m)? {
                Some(v) => {
                    good = m;
                    edge = Some((m, v));
                }
                None => bad = m,
            }
        }
        pts.extend(edge);
    }
    pts.sort_by(|p, q| p.0.total_cmp(&q.0));
    // (distance to s0, bracket as two (x, f(x)))
    type Bracket = (f64, (f64, f64), (f64, f64));
    let mut best: Option<Bracket> = None;
    for (j, &(x, v)) in pts.iter().enumerate() {
        let next = pts.get(j + 1).copied();
        let bracket = if v == 0.0 {
            Some(((x, v), (x, v)))
        } else {
            next.filter(|&(_, w)| w != 0.0 && w.signum() != v.signum())
                .map(|n| ((x, v), n))
        };
        if let Some((p, q)) = bracket {
            let d = (0.5 * (p.0 + q.0) - s0).abs();
            if best.is_none_or(|(bd, _, _)| d < bd) {
                best = Some((d, p, q));
            }
        }
    }
    let Some((_, (mut s, mut fs), (mut t, mut ft))) = best else {
        return Ok(None);
    };
    if fs == 0.0 {
        return Ok(Some(s));
    }
    let mut side = 0i8;
    for _ in 0..200 {
        let mut x = (s * ft - t * fs) / (ft - fs);
        if !(x > s.min(t) && x < s.max(t)) {
            x = 0.5 * (s + t);
        }
        let Some(fx) = f(x)? else {
            return Ok(None);
        };
        if fx == 0.0 {
            return Ok(Some(x));
        }
        if fx.signum() == ft.signum() {
            (t, ft) = (x, fx);
            if side == -1 {
                fs *= 0.5;
            }
            side = -1;
        } else {
            (s, fs) = (x, fx);
            if side == 1 {
                ft *= 0.5;
            }
            side = 1;
        }
        if (t - s).abs() <= xtol {
            break;
        }
    }
    Ok(Some(if fs.abs() < ft.abs() { s } else { t }))
}
