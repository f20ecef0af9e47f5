//! Grid and density integrals: the uniform grid with logarithmic-mean faces, and the exact
//! (adaptive Gauss-Legendre) moments of the density and control-volume charges.

use std::cell::Cell;

use hpge_solver::constants::CM3_TO_M3;

use crate::error::{Error, Result};

/// Adaptive quadrature: maximal bisection depth and Gauss-Legendre evaluations per call.
const QUAD_MAX_DEPTH: u32 = 60;
const QUAD_BUDGET: usize = 4000;

/// Uniform nodes (m), logarithmic-mean faces (m) and scaled conductances g_i = 1 / ln(r_{i+1}/r_i).
pub(super) struct Grid {
    pub(super) r: Vec<f64>,
    pub(super) face: Vec<f64>,
    pub(super) g: Vec<f64>,
    pub(super) h: f64,
}

impl Grid {
    pub(super) fn uniform(a: f64, b: f64, n: usize) -> Self {
        let h = (b - a) / (n - 1) as f64;
        let r: Vec<f64> = (0..n)
            .map(|i| if i == n - 1 { b } else { a + i as f64 * h })
            .collect();
        let (mut face, mut g) = (Vec::with_capacity(n - 1), Vec::with_capacity(n - 1));
        for w in r.windows(2) {
            let ln = ((w[1] - w[0]) / w[0]).ln_1p();
            g.push(1.0 / ln);
            face.push(((w[1] - w[0]) * (w[1] + w[0]) / (2.0 * ln)).sqrt());
        }
        Self { r, face, g, h }
    }
}

/// The density with its exact integrals: cumulative moments M0(r) = int_a^r zeta t dt and
/// M1(r) = int_a^r zeta t ln(t / a) dt (zeta in m^-3, t in m), and the control-volume charges.
pub(super) struct Profile<'z> {
    zeta: &'z dyn Fn(f64) -> f64,
    pub(super) grid: Grid,
    a: f64,
    /// q / eps, V m.
    pub(super) k: f64,
    pub(super) cum0: Vec<f64>,
    pub(super) cum1: Vec<f64>,
    /// Absolute tolerance of M0 per cell (M1: times `ln_scale`).
    tol: Vec<f64>,
    ln_scale: f64,
    /// Control-volume charge / (2 pi eps), V (0 at the contacts).
    pub(super) f: Vec<f64>,
    /// max |zeta| at the nodes, m^-3, at least 1 cm^-3: scale of the quadrature tolerances.
    pub(super) zref: f64,
    glx: [f64; 5],
    glw: [f64; 5],
    /// Lagrange basis of the five Gauss nodes evaluated at x = +1 (extrapolation to the end).
    glext: [f64; 5],
    /// Smallest and largest zeta (m^-3) seen by the quadrature in each cell.
    pub(super) zmin: Vec<f64>,
    pub(super) zmax: Vec<f64>,
    seen: Cell<(f64, f64)>,
}

impl<'z> Profile<'z> {
    pub(super) fn new(
        zeta: &'z dyn Fn(f64) -> f64,
        a: f64,
        b: f64,
        n: usize,
        k: f64,
    ) -> Result<Self> {
        let grid = Grid::uniform(a, b, n);
        let (x1, x2) = (
            (5.0 - 2.0 * (10.0f64 / 7.0).sqrt()).sqrt() / 3.0,
            (5.0 + 2.0 * (10.0f64 / 7.0).sqrt()).sqrt() / 3.0,
        );
        let (w0, w1, w2) = (
            128.0 / 225.0,
            (322.0 + 13.0 * 70.0f64.sqrt()) / 900.0,
            (322.0 - 13.0 * 70.0f64.sqrt()) / 900.0,
        );
        let mut p = Self {
            zeta,
            a,
            k,
            cum0: vec![0.0; n],
            cum1: vec![0.0; n],
            tol: vec![0.0; n - 1],
            ln_scale: (b / a).ln().max(1.0),
            f: vec![0.0; n],
            zref: 0.0,
            glx: [-x2, -x1, 0.0, x1, x2],
            glw: [w2, w1, w0, w1, w2],
            glext: [0.0; 5],
            zmin: vec![0.0; n - 1],
            zmax: vec![0.0; n - 1],
            seen: Cell::new((f64::INFINITY, f64::NEG_INFINITY)),
            grid,
        };
        for j in 0..5 {
            p.glext[j] = (0..5)
                .filter(|&m| m != j)
                .map(|m| (1.0 - p.glx[m]) / (p.glx[j] - p.glx[m]))
                .product();
        }
        let mut zmax: f64 = 0.0;
        for &r in &p.grid.r {
            zmax = zmax.max(p.zeta_si(r)?.abs());
        }
        // 1 cm^-3 floor: keeps the tolerances positive for a zero density.
        p.zref = zmax.max(CM3_TO_M3);
        for i in 0..n - 1 {
            let (r0, r1, rho) = (p.grid.r[i], p.grid.r[i + 1], p.grid.face[i]);
            p.tol[i] = 1e-14 * p.zref * r1 * p.grid.h;
            p.seen.set((f64::INFINITY, f64::NEG_INFINITY));
            let left = p.integrate(r0, rho, p.tol[i])?;
            let right = p.integrate(rho, r1, p.tol[i])?;
            (p.zmin[i], p.zmax[i]) = p.seen.get();
            p.cum0[i + 1] = p.cum0[i] + left.0 + right.0;
            p.cum1[i + 1] = p.cum1[i] + left.1 + right.1;
            p.f[i] += k * left.0;
            p.f[i + 1] += k * right.0;
        }
        p.f[0] = 0.0;
        p.f[n - 1] = 0.0;
        Ok(p)
    }

    /// zeta in m^-3 at r in m; a non-finite value is a domain error.
    pub(super) fn zeta_si(&self, r: f64) -> Result<f64> {
        let z = (self.zeta)(r * 1e3);
        let (lo, hi) = self.seen.get();
        self.seen.set((lo.min(z), hi.max(z)));
        if !z.is_finite() {
            return Err(Error::Domain {
                quantity: "zeta_cm3",
                value: z,
                why: format!("the impurity density at r = {} mm must be finite", r * 1e3),
            });
        }
        Ok(z * CM3_TO_M3)
    }

    /// Five-point Gauss-Legendre (exact to degree 9) of (zeta t, zeta t ln(t / a)) on [lo, hi], and
    /// an end check: how far zeta at lo and hi is from the polynomial through the five nodes
    /// (times hi (hi - lo), in the units of the first moment). Gauss nodes miss the outer 5% of an
    /// interval; a step there is invisible to the halves-versus-whole comparison but not to this.
    fn gl5(&self, lo: f64, hi: f64) -> Result<(f64, f64, f64)> {
        let (mid, half) = (0.5 * (lo + hi), 0.5 * (hi - lo));
        let (mut s0, mut s1, mut p_lo, mut p_hi) = (0.0, 0.0, 0.0, 0.0);
        for j in 0..5 {
            let t = mid + half * self.glx[j];
            let z = self.zeta_si(t)?;
            s0 += self.glw[j] * z * t;
            s1 += self.glw[j] * z * t * (t / self.a).ln();
            p_hi += self.glext[j] * z;
            p_lo += self.glext[4 - j] * z;
        }
        let ends = (self.zeta_si(lo)? - p_lo)
            .abs()
            .max((self.zeta_si(hi)? - p_hi).abs());
        Ok((half * s0, half * s1, ends * hi * (hi - lo)))
    }

    /// Adaptive bisection of `gl5` until halves and whole agree to `tol` (absolute, per call) and
    /// the end checks pass.
    fn integrate(&self, lo: f64, hi: f64, tol: f64) -> Result<(f64, f64)> {
        if hi == lo {
            return Ok((0.0, 0.0));
        }
        let mut stack = vec![(lo, hi, self.gl5(lo, hi)?, 0u32)];
        let (mut sum, mut evals) = ((0.0, 0.0), 1usize);
        while let Some((l, h, whole, depth)) = stack.pop() {
            let m = 0.5 * (l + h);
            let (left, right) = (self.gl5(l, m)?, self.gl5(m, h)?);
            evals += 2;
            let halves = (left.0 + right.0, left.1 + right.1);
            let settled = (halves.0 - whole.0).abs() <= tol
                && (halves.1 - whole.1).abs() <= tol * self.ln_scale
                && whole.2.max(left.2).max(right.2) <= tol;
            if settled || depth >= QUAD_MAX_DEPTH || evals > QUAD_BUDGET {
                sum.0 += halves.0;
                sum.1 += halves.1;
            } else {
                stack.push((l, m, left, depth + 1));
                stack.push((m, h, right, depth + 1));
            }
        }
        Ok(sum)
    }

    /// (M0(r), M1(r)) for r in [a, b]: cumulative value at the nearer node of r's cell plus the rest.
    pub(super) fn moments(&self, r: f64) -> Result<(f64, f64)> {
        let n = self.grid.r.len();
        let t = ((r - self.a) / self.grid.h).floor();
        let i = if t <= 0.0 { 0 } else { (t as usize).min(n - 2) };
        let (r0, r1) = (self.grid.r[i], self.grid.r[i + 1]);
        if r - r0 <= r1 - r {
            let p = self.integrate(r0, r, self.tol[i])?;
            Ok((self.cum0[i] + p.0, self.cum1[i] + p.1))
        } else {
            let p = self.integrate(r, r1, self.tol[i])?;
            Ok((self.cum0[i + 1] - p.0, self.cum1[i + 1] - p.1))
        }
    }

    /// psi_s(r) = int_s^r zeta t ln(r / t) dt = ln(r / a)(M0(r) - M0(s)) - (M1(r) - M1(s)), m^-1.
    pub(super) fn psi(&self, r: f64, ms: (f64, f64), mr: (f64, f64)) -> f64 {
        (r / self.a).ln() * (mr.0 - ms.0) - (mr.1 - ms.1)
    }
}
