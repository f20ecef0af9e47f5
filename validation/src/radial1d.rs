//! A high-precision 1D radial reference: the infinitely long true coax with an arbitrary radial
//! impurity profile zeta(r) (DESIGN.md, "Analytic and reference checks": "the same 1D radial problem
//! for any zeta(r) can be solved to high precision in 1D; the 2D solver on a long coax must match it").
//!
//! # Problem
//!
//! Inner contact r = a at the bias V, outer contact r = b at 0 V, germanium (eps = eps0 eps_r) between:
//!
//! ```text
//! -(1/r) d/dr (r eps dphi/dr) = q zeta(r)          (zeta in m^-3, signed: > 0 n-type)
//! ```
//!
//! where the crystal is depleted. The potential is bounded by [l, u] = [min(0, V), max(0, V)]; where it
//! reaches a bound the crystal is undepleted (free carriers neutralise the space charge): an obstacle
//! problem. Undepleted regions are conductors: attached to a contact they extend it, between depleted
//! layers they float. So the capacitance per unit length is that of cylindrical capacitors in series:
//!
//! ```text
//! 1 / c' = sum over depleted intervals [r_k, r_{k+1}] of ln(r_{k+1} / r_k) / (2 pi eps)
//! ```
//!
//! # Method
//!
//! 1. **Discrete obstacle problem.** Uniform nodes r_0 = a < ... < r_{N-1} = b; finite volumes with
//!    the exact cylindrical conductance 2 pi eps / ln(r_{i+1} / r_i) per unit length and control
//!    volumes [rho_{i-1/2}, rho_{i+1/2}] whose faces are logarithmic means,
//!    rho_{i+1/2}^2 = (r_{i+1}^2 - r_i^2) / (2 ln(r_{i+1} / r_i)): the radius at which the two-point
//!    flux is exact for phi = r^2, so that the scheme reproduces A r^2 + B ln r + C (the
//!    uniform-density solution) exactly. The control-volume charge is the exact integral
//!    2 pi q int zeta(t) t dt (adaptive Gauss-Legendre; steps of zeta anywhere in a cell are resolved
//!    to 1e-13 relative). Dividing by 2 pi eps puts A x = f in volts. min 1/2 x^T A x - f^T x subject
//!    to l <= x <= u is solved by the primal-dual active set method (Hintermueller, Ito, Kunisch
//!    2003), one Thomas solve per step, started from the active set of the same problem on coarser
//!    grids (halving down to 64 nodes). It stops when the active set repeats; at that point the KKT
//!    conditions hold exactly (A x = f on the free nodes; multiplier lambda = f - A x > 0 on nodes
//!    at u, < 0 at l; l <= x <= u), so x is the discrete solution (unique: A is SPD). A settling
//!    failure is returned as an error, never hidden. The multiplier is the neutralised part of a
//!    node's charge (in V, i.e. C/m divided by 2 pi eps).
//! 2. **Fronts from the grid.** The charge of the last node k of an undepleted run that is not
//!    neutralised is the flux towards the depleted side, e = g_k (x_k - x_{k+1}); the front goes
//!    where the depleted part of k's control volume holds that charge (zeta uniform in the cell):
//!    s^2 = rho_{k+1/2}^2 - (e / f_k)(rho_{k+1/2}^2 - rho_{k-1/2}^2). Second order in the distance of
//!    that node to the front (erratic in the node count); reported as `c12_grid_per_mm_pf`.
//! 3. **Exact fronts.** Each depleted layer is an independent two-point problem, because the
//!    conductors around it sit at known potentials. With phi(s) = beta and phi'(s) = 0 at a front s
//!    next to an undepleted region at the bound beta,
//!    ```text
//!    phi(r)    = beta - (q / eps) psi_s(r),    psi_s(r) = int_s^r zeta(t) t ln(r / t) dt,
//!    r phi'(r) = -(q / eps) int_s^r zeta(t) t dt.
//!    ```
//!    A front facing a contact (r_c, phi_c) solves phi_c - beta + (q / eps) psi_s(r_c) = 0 (for a
//!    uniform zeta this is the closed form of [`crate::LongCoax`]); a layer between two fronts
//!    (s1, beta1), (s2, beta2) solves int_{s1}^{s2} zeta t dt = 0 (no net charge: the field vanishes
//!    at both ends) and beta2 - beta1 + (q / eps) psi_{s1}(s2) = 0. The integrals are exact
//!    (cumulative moments int zeta t dt and int zeta t ln(t / a) dt at the nodes plus adaptive
//!    quadrature within one cell). Roots are searched within 3 node spacings of the grid estimate:
//!    bracketed and refined by Illinois regula falsi (one front), by Newton or, where Newton fails
//!    (a layer thinner than a cell across a step of zeta, or the degenerate s1 = s2 between
//!    conductors at one potential), by a nested bracketed solve (two fronts). So the grid only
//!    decides the topology. Sub-cell changes of topology are repaired: a contact whose field would
//!    carry the potential past its bound gets an undepleted layer, a front that leaves the crystal
//!    becomes the contact, an island squeezed to nothing merges its two layers. What cannot be
//!    repaired is flagged (`fronts_exact = false`, the grid estimates are then used): a layer
//!    solution leaving [l, u] at a node, or a cell inside an undepleted region whose zeta has the
//!    sign free carriers cannot neutralise (an unseen depleted layer; more nodes resolve it).
//!
//! # Accuracy (measured; tests/radial1d_vs_closed_form.rs)
//!
//! - Uniform 1e10 cm^-3 (a = 6, b = 37.5 mm) at the ten voltages of the reference table, against
//!   [`crate::LongCoax`]: c' within 3e-13 relative and r_d within 8e-13 mm at 251, 1001 and 4001
//!   nodes; from 1 V to 3501 V (front 1.1 um from the contact) within 1e-11 at 251 to 8001 nodes.
//! - Two-step p-type-mantle profile (junction layer between two fronts, then front to contact)
//!   against its closed form, 1 V to 3000 V: fronts within 5e-13 mm, c' within 1e-12 (and 1e-13
//!   against a 30-digit evaluation at 1000 V); linearly falling profile: 1.1e-12 mm, 9e-13. Between
//!   501 and 8001 nodes the exact-front c' moves by less than 1.1e-12.
//! - The grid estimate alone: within 1.2e-6 of the closed form at the table voltages at the default
//!   4001 nodes (1e-4 at 251), up to 3e-6 on the p-type-mantle profiles.
//! - The discrete potential is second order (2.3e-5 V at 1025 V with 1001 nodes); the exact-front
//!   potential `potential_exact_v` agrees with the closed form to 2e-11 V.
//! - A solve takes 3-4 ms at 4001 nodes (release), 17 ms unoptimised; the cost is linear in nodes,
//!   the active-set iteration takes 2-5 steps on the finest grid (at most 11 seen).

use std::cell::Cell;
use std::f64::consts::PI;

use hpge_solver::constants::{
    CM3_TO_M3, ELEMENTARY_CHARGE_C, EPS_R_GERMANIUM, VACUUM_PERMITTIVITY_F_PER_M,
};

use crate::{Error, Result};

/// Default number of nodes (contacts included): 4001, i.e. 7.9 um on the validation coax. The exact
/// fronts do not need that many; it makes the grid-only estimate agree with them to 1.2e-6 relative
/// at the reference-table voltages (so the two routes cross-check each other below 1e-5) and
/// resolves depleted layers and undepleted islands down to about 10 um. 3-4 ms per solve.
pub const DEFAULT_NODES: usize = 4001;
/// Fewest nodes accepted.
pub const MIN_NODES: usize = 8;

/// Coarse grids of the active-set start stop below this many nodes.
const COARSEST_NODES: usize = 64;
/// Search window of a front around its grid estimate, in node spacings.
const WINDOW_CELLS: f64 = 3.0;
/// Adaptive quadrature: maximal bisection depth and Gauss-Legendre evaluations per call.
const QUAD_MAX_DEPTH: u32 = 60;
const QUAD_BUDGET: usize = 4000;
/// Passes of the topology repair before giving up on exact fronts.
const MAX_PASSES: usize = 8;

/// The long coax with an arbitrary radial density: radii in mm, eps_r dimensionless.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct RadialReference {
    /// Inner (bias) contact radius a, mm.
    pub a_mm: f64,
    /// Outer (0 V) contact radius b, mm.
    pub b_mm: f64,
    /// Relative permittivity (default 16, germanium).
    pub eps_r: f64,
    /// Nodes of the uniform grid, contacts included (default [`DEFAULT_NODES`]; at least
    /// [`MIN_NODES`]). They decide which depleted layers are seen and the accuracy of
    /// `potential_v` and `c12_grid_per_mm_pf`; the exact fronts do not depend on them.
    pub nodes: usize,
}

/// The solution at one bias.
#[derive(Debug, Clone, PartialEq)]
pub struct RadialSolution {
    /// Bias of the inner contact, V.
    pub bias_v: f64,
    /// Capacitance per unit length c' = 2 pi eps / sum ln(r_{k+1} / r_k) over the depleted
    /// intervals, pF/mm, with the exact fronts; `f64::INFINITY` if no depleted layer separates the
    /// contacts (e.g. zero bias with a nonzero density).
    pub c12_per_mm_pf: f64,
    /// The same with the fronts estimated from the discrete solution alone (second order in the
    /// distance of the last undepleted node to the front), pF/mm: a cross-check.
    pub c12_grid_per_mm_pf: f64,
    /// Depleted intervals (mm), sorted.
    pub depleted_mm: Vec<(f64, f64)>,
    /// One depleted interval from a to b.
    pub fully_depleted: bool,
    /// Whether every front was located by the exact equations (false: grid estimates are used).
    pub fronts_exact: bool,
    /// Node radii, mm.
    pub r_mm: Vec<f64>,
    /// Discrete obstacle solution at the nodes, V (second order in the node spacing).
    pub potential_v: Vec<f64>,
    /// Potential of the exact-front solution at the nodes, V (exact up to quadrature where
    /// `fronts_exact`): the layer solutions inside depleted intervals, the bound elsewhere.
    pub potential_exact_v: Vec<f64>,
    /// Multiplier lambda = f - A x of the discrete solution at the nodes (neutralised charge per unit
    /// length divided by 2 pi eps), V: > 0 at nodes held at max(0, V), < 0 at min(0, V), 0 where
    /// depleted and at the contacts.
    pub multiplier_v: Vec<f64>,
    /// Primal-dual active set steps on the finest grid.
    pub active_set_iterations: usize,
}

impl RadialReference {
    /// Radii in mm, eps_r 16, [`DEFAULT_NODES`] nodes.
    pub fn new(a_mm: f64, b_mm: f64) -> Self {
        Self {
            a_mm,
            b_mm,
            eps_r: EPS_R_GERMANIUM,
            nodes: DEFAULT_NODES,
        }
    }

    fn validate(&self, bias_v: f64) -> Result<()> {
        let domain = |quantity: &'static str, value: f64, why: &str| {
            Err(Error::Domain {
                quantity,
                value,
                why: why.into(),
            })
        };
        if !(self.a_mm.is_finite() && self.a_mm > 0.0) {
            return domain("a_mm", self.a_mm, "the inner radius must be finite and > 0");
        }
        if !(self.b_mm.is_finite() && self.b_mm > self.a_mm) {
            return domain("b_mm", self.b_mm, "the outer radius must be finite and > a");
        }
        if !(self.eps_r.is_finite() && self.eps_r > 0.0) {
            return domain("eps_r", self.eps_r, "eps_r must be finite and > 0");
        }
        if self.nodes < MIN_NODES {
            return domain(
                "nodes",
                self.nodes as f64,
                &format!("at least {MIN_NODES} nodes are needed"),
            );
        }
        if !bias_v.is_finite() {
            return domain("bias_v", bias_v, "the bias must be finite");
        }
        Ok(())
    }

    /// Solve at the inner-contact bias `bias_v` (V, any sign) for the density `zeta_cm3(r_mm)`
    /// (cm^-3, signed, evaluated anywhere in [a, b] including the ends; steps are fine).
    /// Errors (`Error::Domain`): a <= 0, b <= a, eps_r <= 0 or any of them non-finite, fewer than
    /// [`MIN_NODES`] nodes, a non-finite bias or density value, or an active-set iteration that does
    /// not settle (never seen; it would be reported, not hidden).
    pub fn solve(&self, zeta_cm3: &dyn Fn(f64) -> f64, bias_v: f64) -> Result<RadialSolution> {
        self.validate(bias_v)?;
        let (a, b) = (self.a_mm * 1e-3, self.b_mm * 1e-3);
        let k = ELEMENTARY_CHARGE_C / (VACUUM_PERMITTIVITY_F_PER_M * self.eps_r);
        let prof = Profile::new(zeta_cm3, a, b, self.nodes, k)?;
        let init = initial_status(a, b, self.nodes, bias_v, &prof)?;
        let disc = solve_obstacle(&prof.grid.g, &prof.f, bias_v, init)?;
        let ctx = Fronts::new(&prof, bias_v, &disc);
        let grid_layers = ctx.initial_layers();
        let (layers, fronts_exact) = ctx.refine(&grid_layers)?;
        let eps = VACUUM_PERMITTIVITY_F_PER_M * self.eps_r;
        let potential_exact_v = ctx.exact_potential(&layers)?;
        // Radii back in mm, the contacts exactly as given.
        let mm = |r: f64| {
            if r == a {
                self.a_mm
            } else if r == b {
                self.b_mm
            } else {
                r * 1e3
            }
        };
        Ok(RadialSolution {
            bias_v,
            c12_per_mm_pf: capacitance_per_mm_pf(eps, &layers),
            c12_grid_per_mm_pf: capacitance_per_mm_pf(eps, &grid_layers),
            depleted_mm: layers
                .iter()
                .map(|l| (mm(l.left.r()), mm(l.right.r())))
                .collect(),
            fully_depleted: layers.len() == 1
                && matches!(layers[0].left, End::Fixed { .. })
                && matches!(layers[0].right, End::Fixed { .. }),
            fronts_exact,
            r_mm: prof.grid.r.iter().map(|&r| mm(r)).collect(),
            potential_v: disc.x,
            potential_exact_v,
            multiplier_v: disc.lam,
            active_set_iterations: disc.iterations,
        })
    }
}

/// c' = 2 pi eps / sum ln(r_{k+1} / r_k) in pF/mm (F/m * 1e12 pF/F * 1e-3 m/mm).
fn capacitance_per_mm_pf(eps: f64, layers: &[Layer]) -> f64 {
    let sum: f64 = layers
        .iter()
        .map(|l| (l.right.r() / l.left.r()).ln().max(0.0))
        .sum();
    if sum > 0.0 {
        2.0 * PI * eps / sum * 1e9
    } else {
        f64::INFINITY
    }
}

// ------------------------------------------------------------------------------------------------
// Grid and density integrals

/// Uniform nodes (m), logarithmic-mean faces (m) and scaled conductances g_i = 1 / ln(r_{i+1}/r_i).
struct Grid {
    r: Vec<f64>,
    face: Vec<f64>,
    g: Vec<f64>,
    h: f64,
}

impl Grid {
    fn uniform(a: f64, b: f64, n: usize) -> Self {
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
struct Profile<'z> {
    zeta: &'z dyn Fn(f64) -> f64,
    grid: Grid,
    a: f64,
    /// q / eps, V m.
    k: f64,
    cum0: Vec<f64>,
    cum1: Vec<f64>,
    /// Absolute tolerance of M0 per cell (M1: times `ln_scale`).
    tol: Vec<f64>,
    ln_scale: f64,
    /// Control-volume charge / (2 pi eps), V (0 at the contacts).
    f: Vec<f64>,
    /// max |zeta| at the nodes, m^-3, at least 1 cm^-3: scale of the quadrature tolerances.
    zref: f64,
    glx: [f64; 5],
    glw: [f64; 5],
    /// Lagrange basis of the five Gauss nodes evaluated at x = +1 (extrapolation to the end).
    glext: [f64; 5],
    /// Smallest and largest zeta (m^-3) seen by the quadrature in each cell.
    zmin: Vec<f64>,
    zmax: Vec<f64>,
    seen: Cell<(f64, f64)>,
}

impl<'z> Profile<'z> {
    fn new(zeta: &'z dyn Fn(f64) -> f64, a: f64, b: f64, n: usize, k: f64) -> Result<Self> {
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
    fn zeta_si(&self, r: f64) -> Result<f64> {
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
    fn moments(&self, r: f64) -> Result<(f64, f64)> {
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
    fn psi(&self, r: f64, ms: (f64, f64), mr: (f64, f64)) -> f64 {
        (r / self.a).ln() * (mr.0 - ms.0) - (mr.1 - ms.1)
    }
}

// ------------------------------------------------------------------------------------------------
// Discrete obstacle problem: primal-dual active set with Thomas solves

/// Where the discrete solution stands at a node.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
enum Status {
    /// Depleted (inactive): A x = f holds there.
    Free,
    /// Held at u = max(0, V), multiplier >= 0.
    Upper,
    /// Held at l = min(0, V), multiplier <= 0.
    Lower,
}

/// The discrete solution: potentials and multipliers at all nodes (contacts included).
struct Obstacle {
    x: Vec<f64>,
    lam: Vec<f64>,
    status: Vec<Status>,
    iterations: usize,
}

/// Interior row i of A x: g_{i-1}(x_i - x_{i-1}) + g_i(x_i - x_{i+1}).
fn apply_row(g: &[f64], x: &[f64], i: usize) -> f64 {
    g[i - 1] * (x[i] - x[i - 1]) + g[i] * (x[i] - x[i + 1])
}

/// Solve A x = f on the free nodes with x fixed at the bounds on the others and at the contacts
/// (x_0 = V, x_{N-1} = 0). Thomas without pivoting: the rows are (weakly) diagonally dominant and
/// every free run touches a fixed value, so the system is irreducibly diagonally dominant.
fn linear_solve(g: &[f64], f: &[f64], bias: f64, status: &[Status], x: &mut [f64]) {
    let n = f.len();
    let (lo, up) = (bias.min(0.0), bias.max(0.0));
    let m = n - 2;
    let (mut cp, mut dp) = (vec![0.0; m], vec![0.0; m]);
    for j in 0..m {
        let i = j + 1;
        let (sub, diag, sup, rhs) = match status[i] {
            Status::Upper => (0.0, 1.0, 0.0, up),
            Status::Lower => (0.0, 1.0, 0.0, lo),
            Status::Free => {
                let (mut sub, mut sup, mut rhs) = (-g[i - 1], -g[i], f[i]);
                if i == 1 {
                    rhs += g[0] * bias;
                    sub = 0.0;
                }
                if i == n - 2 {
                    sup = 0.0;
                }
                (sub, g[i - 1] + g[i], sup, rhs)
            }
        };
        let (cprev, dprev) = if j > 0 {
            (cp[j - 1], dp[j - 1])
        } else {
            (0.0, 0.0)
        };
        let denom = diag - sub * cprev;
        cp[j] = sup / denom;
        dp[j] = (rhs - sub * dprev) / denom;
    }
    x[m] = dp[m - 1];
    for j in (0..m - 1).rev() {
        x[j + 1] = dp[j] - cp[j] * x[j + 2];
    }
    x[0] = bias;
    x[n - 1] = 0.0;
}

/// The active-set rule with c_i = A_ii: upper if lambda + c (x - u) > 0, lower if
/// lambda + c (x - l) < 0 (with a 1e-12 relative dead band against round-off cycling).
fn classify(g: &[f64], f: &[f64], bias: f64, x: &[f64], lam: &[f64]) -> Vec<Status> {
    let n = f.len();
    let (lo, up) = (bias.min(0.0), bias.max(0.0));
    let mut s = vec![Status::Free; n];
    for i in 1..n - 1 {
        let c = g[i - 1] + g[i];
        let tol = 1e-12 * (c * (lo.abs() + up.abs()) + f[i].abs());
        if lam[i] + c * (x[i] - up) > tol {
            s[i] = Status::Upper;
        } else if lam[i] + c * (x[i] - lo) < -tol {
            s[i] = Status::Lower;
        }
    }
    s
}

/// Primal-dual active set iteration for min 1/2 x^T A x - f^T x, l <= x <= u. `init`: a starting
/// active set (else the unconstrained solution decides the first one). Each step solves with the
/// active set fixed, sets lambda = f - A x on it (0 elsewhere) and reclassifies; a repeated set is
/// the KKT point.
fn solve_obstacle(g: &[f64], f: &[f64], bias: f64, init: Option<Vec<Status>>) -> Result<Obstacle> {
    let n = f.len();
    let mut x = vec![0.0; n];
    let mut lam = vec![0.0; n];
    let mut status = match init {
        Some(s) => s,
        None => {
            linear_solve(g, f, bias, &vec![Status::Free; n], &mut x);
            classify(g, f, bias, &x, &lam)
        }
    };
    let max_iter = 2 * n + 50;
    for iterations in 1..=max_iter {
        linear_solve(g, f, bias, &status, &mut x);
        for i in 1..n - 1 {
            lam[i] = if status[i] == Status::Free {
                0.0
            } else {
                f[i] - apply_row(g, &x, i)
            };
        }
        let next = classify(g, f, bias, &x, &lam);
        if next == status {
            return Ok(Obstacle {
                x,
                lam,
                status,
                iterations,
            });
        }
        status = next;
    }
    Err(Error::Domain {
        quantity: "active_set_iterations",
        value: max_iter as f64,
        why: "the primal-dual active set iteration did not settle".into(),
    })
}

/// Active set for the fine grid from the same problem on coarser grids (halving down to
/// `COARSEST_NODES`, point-value charges), interpolated: a fine node takes the status of the coarse
/// cell around it when both its ends agree, else starts free. Saves the one-node-per-step crawl of
/// the active set from a poor start.
fn initial_status(
    a: f64,
    b: f64,
    n: usize,
    bias: f64,
    prof: &Profile<'_>,
) -> Result<Option<Vec<Status>>> {
    let mut sizes = Vec::new();
    let mut m = n;
    while m > COARSEST_NODES {
        m = (m - 1) / 2 + 1;
        sizes.push(m);
    }
    let mut prev: Option<(Grid, Vec<Status>)> = None;
    for &m in sizes.iter().rev() {
        let grid = Grid::uniform(a, b, m);
        let mut f = vec![0.0; m];
        for (i, fi) in f.iter_mut().enumerate().take(m - 1).skip(1) {
            let area = 0.5 * (grid.face[i] * grid.face[i] - grid.face[i - 1] * grid.face[i - 1]);
            *fi = prof.k * prof.zeta_si(grid.r[i])? * area;
        }
        let init = prev.map(|(pg, ps)| interpolate_status(&pg, &ps, &grid.r));
        let sol = solve_obstacle(&grid.g, &f, bias, init)?;
        prev = Some((grid, sol.status));
    }
    Ok(prev.map(|(pg, ps)| interpolate_status(&pg, &ps, &prof.grid.r)))
}

fn interpolate_status(coarse: &Grid, status: &[Status], r: &[f64]) -> Vec<Status> {
    let (m, n) = (coarse.r.len(), r.len());
    let mut out = vec![Status::Free; n];
    for i in 1..n - 1 {
        let t = ((r[i] - coarse.r[0]) / coarse.h).floor();
        let j = if t <= 0.0 { 0 } else { (t as usize).min(m - 2) };
        if status[j] == status[j + 1] {
            out[i] = status[j];
        }
    }
    out
}

// ------------------------------------------------------------------------------------------------
// Depleted layers and their fronts

/// One end of a depleted layer.
#[derive(Debug, Clone, Copy, PartialEq)]
enum End {
    /// A contact at radius r (m) and potential phi (V).
    Fixed { r: f64, phi: f64 },
    /// A depletion front at s (m) next to an undepleted region at the bound beta (V), searched in
    /// [lo, hi]; `contact`: radius of the contact the undepleted region is attached to, if any.
    Free {
        s: f64,
        beta: f64,
        lo: f64,
        hi: f64,
        contact: Option<f64>,
    },
}

impl End {
    fn r(&self) -> f64 {
        match *self {
            End::Fixed { r, .. } => r,
            End::Free { s, .. } => s,
        }
    }

    fn with_s(self, x: f64) -> Self {
        match self {
            End::Free {
                beta,
                lo,
                hi,
                contact,
                ..
            } => End::Free {
                s: x,
                beta,
                lo,
                hi,
                contact,
            },
            fixed => fixed,
        }
    }
}

/// A depleted interval [left, right].
#[derive(Debug, Clone, Copy, PartialEq)]
struct Layer {
    left: End,
    right: End,
    solved: bool,
}

/// The discrete solution seen as layers, and the exact equations of their fronts.
struct Fronts<'p, 'z> {
    prof: &'p Profile<'z>,
    disc: &'p Obstacle,
    bias: f64,
    lo: f64,
    up: f64,
    a: f64,
    b: f64,
    /// Volt scale for tolerances: |V| + (q / eps) max|zeta| b^2.
    vscale: f64,
}

impl<'p, 'z> Fronts<'p, 'z> {
    fn new(prof: &'p Profile<'z>, bias: f64, disc: &'p Obstacle) -> Self {
        let (a, b) = (prof.grid.r[0], prof.grid.r[prof.grid.r.len() - 1]);
        Self {
            prof,
            disc,
            bias,
            lo: bias.min(0.0),
            up: bias.max(0.0),
            a,
            b,
            vscale: bias.abs() + prof.k * prof.zref * b * b,
        }
    }

    fn window(&self, s: f64) -> (f64, f64) {
        let w = WINDOW_CELLS * self.prof.grid.h;
        ((s - w).max(self.a), (s + w).min(self.b))
    }

    /// Conductors (maximal runs of contact or bound nodes at one potential) and the layers between
    /// them, fronts at their grid estimates.
    fn initial_layers(&self) -> Vec<Layer> {
        let (st, n) = (&self.disc.status, self.disc.status.len());
        let potential = |i: usize| -> Option<f64> {
            if i == 0 {
                Some(self.bias)
            } else if i == n - 1 {
                Some(0.0)
            } else {
                match st[i] {
                    Status::Upper => Some(self.up),
                    Status::Lower => Some(self.lo),
                    Status::Free => None,
                }
            }
        };
        // (first, last, potential)
        let mut conductors: Vec<(usize, usize, f64)> = Vec::new();
        for i in 0..n {
            if let Some(p) = potential(i) {
                match conductors.last_mut() {
                    Some(c) if c.1 + 1 == i && c.2 == p => c.1 = i,
                    _ => conductors.push((i, i, p)),
                }
            }
        }
        conductors
            .windows(2)
            .map(|w| {
                let (c, d) = (w[0], w[1]);
                let left = if c.1 == 0 {
                    End::Fixed {
                        r: self.a,
                        phi: self.bias,
                    }
                } else {
                    let s = self.estimate_right_of(c.1);
                    let (lo, hi) = self.window(s);
                    End::Free {
                        s,
                        beta: c.2,
                        lo,
                        hi,
                        contact: (c.0 == 0).then_some(self.a),
                    }
                };
                let right = if d.0 == n - 1 {
                    End::Fixed {
                        r: self.b,
                        phi: 0.0,
                    }
                } else {
                    let s = self.estimate_left_of(d.0);
                    let (lo, hi) = self.window(s);
                    End::Free {
                        s,
                        beta: d.2,
                        lo,
                        hi,
                        contact: (d.1 == n - 1).then_some(self.b),
                    }
                };
                Layer {
                    left,
                    right,
                    solved: false,
                }
            })
            .collect()
    }

    /// Front right of the last node k of an undepleted run: the flux g_k (x_k - x_{k+1}) is the charge
    /// of [s, rho_{k+1/2}].
    fn estimate_right_of(&self, k: usize) -> f64 {
        let (g, x, face) = (&self.prof.grid.g, &self.disc.x, &self.prof.grid.face);
        let theta = fraction(g[k] * (x[k] - x[k + 1]), self.prof.f[k]);
        let (r2, l2) = (face[k] * face[k], face[k - 1] * face[k - 1]);
        (r2 - theta * (r2 - l2)).sqrt()
    }

    /// Front left of the first node j of an undepleted run: g_{j-1}(x_j - x_{j-1}) is the charge of
    /// [rho_{j-1/2}, s].
    fn estimate_left_of(&self, j: usize) -> f64 {
        let (g, x, face) = (&self.prof.grid.g, &self.disc.x, &self.prof.grid.face);
        let theta = fraction(g[j - 1] * (x[j] - x[j - 1]), self.prof.f[j]);
        let (r2, l2) = (face[j] * face[j], face[j - 1] * face[j - 1]);
        (l2 + theta * (r2 - l2)).sqrt()
    }

    /// Exact fronts with topology repair; on failure the grid estimates and `false`.
    fn refine(&self, grid_layers: &[Layer]) -> Result<(Vec<Layer>, bool)> {
        let mut layers = grid_layers.to_vec();
        let mut exact = true;
        for _ in 0..MAX_PASSES {
            let mut changed = false;
            for layer in layers.iter_mut().filter(|l| !l.solved) {
                if self.solve_layer(layer)? {
                    layer.solved = true;
                } else if self.detach_from_contact(layer) {
                    changed = true;
                } else {
                    layer.solved = true;
                    exact = false;
                }
            }
            for layer in &mut layers {
                changed |= self.attach_to_contact(layer)?;
            }
            if let Some(j) =
                (1..layers.len()).find(|&j| layers[j - 1].right.r() >= layers[j].left.r())
            {
                let right = layers.remove(j).right;
                layers[j - 1].right = right;
                layers[j - 1].solved = false;
                changed = true;
            }
            if !changed {
                let consistent = self.within_bounds(&layers)? && self.conductors_hold(&layers);
                return Ok((layers, exact && consistent));
            }
        }
        Ok((grid_layers.to_vec(), false))
    }

    /// Solve one layer's front equations; false if a root was not found in the windows.
    fn solve_layer(&self, layer: &mut Layer) -> Result<bool> {
        match (layer.left, layer.right) {
            (End::Fixed { .. }, End::Fixed { .. }) => Ok(true),
            (
                End::Free {
                    s, beta, lo, hi, ..
                },
                End::Fixed { r, phi },
            ) => Ok(match self.front_root(beta, r, phi, s, lo, hi)? {
                Some(x) => {
                    layer.left = layer.left.with_s(x);
                    true
                }
                None => false,
            }),
            (
                End::Fixed { r, phi },
                End::Free {
                    s, beta, lo, hi, ..
                },
            ) => Ok(match self.front_root(beta, r, phi, s, lo, hi)? {
                Some(x) => {
                    layer.right = layer.right.with_s(x);
                    true
                }
                None => false,
            }),
            (End::Free { .. }, End::Free { .. }) => {
                Ok(match self.front_pair(layer.left, layer.right)? {
                    Some((x1, x2)) => {
                        layer.left = layer.left.with_s(x1);
                        layer.right = layer.right.with_s(x2);
                        true
                    }
                    None => false,
                })
            }
        }
    }

    /// A front with no root near its estimate whose undepleted region is attached to a contact and
    /// whose window reaches it: the region has vanished, the layer reaches the contact.
    fn detach_from_contact(&self, layer: &mut Layer) -> bool {
        let mut changed = false;
        for end in [&mut layer.left, &mut layer.right] {
            if let End::Free {
                beta,
                lo,
                hi,
                contact: Some(rc),
                ..
            } = *end
                && (lo == rc || hi == rc)
            {
                *end = End::Fixed { r: rc, phi: beta };
                changed = true;
            }
        }
        changed
    }

    /// A contact end whose field would carry the potential past the bound just inside: an undepleted
    /// layer (thinner than the grid saw) sits on the contact; its front is searched next to it.
    fn attach_to_contact(&self, layer: &mut Layer) -> Result<bool> {
        let tol = 1e-10 * self.vscale;
        let mut changed = false;
        for left_end in [true, false] {
            let end = if left_end { layer.left } else { layer.right };
            let End::Fixed { r: rc, phi } = end else {
                continue;
            };
            // r phi'(r_c), V; inward derivative sign: +1 at the left end, -1 at the right end.
            let inward = if left_end { 1.0 } else { -1.0 } * self.field(layer, rc)?;
            let above = phi == self.up && inward > tol;
            let below = phi == self.lo && inward < -tol;
            if above || below {
                let w = WINDOW_CELLS * self.prof.grid.h;
                let (lo, hi, s) = if left_end {
                    (rc, (rc + w).min(layer.right.r()), rc)
                } else {
                    ((rc - w).max(layer.left.r()), rc, rc)
                };
                let free = End::Free {
                    s,
                    beta: phi,
                    lo,
                    hi,
                    contact: Some(rc),
                };
                if left_end {
                    layer.left = free;
                } else {
                    layer.right = free;
                }
                layer.solved = false;
                changed = true;
            }
        }
        Ok(changed)
    }

    /// r phi'(r) (V) of a layer's solution.
    fn field(&self, layer: &Layer, r: f64) -> Result<f64> {
        let mr = self.prof.moments(r)?;
        Ok(match (layer.left, layer.right) {
            (End::Free { s, .. }, _) | (_, End::Free { s, .. }) => {
                -self.prof.k * (mr.0 - self.prof.moments(s)?.0)
            }
            (End::Fixed { r: r1, phi: p1 }, End::Fixed { r: r2, phi: p2 }) => {
                let b = self.fixed_slope(r1, p1, r2, p2)?;
                let m1 = self.prof.moments(r1)?;
                b - self.prof.k * (mr.0 - m1.0)
            }
        })
    }

    /// Between two contacts: phi(r) = phi1 + B ln(r / r1) - (q/eps) psi_{r1}(r) with
    /// B = (phi2 - phi1 + (q/eps) psi_{r1}(r2)) / ln(r2 / r1).
    fn fixed_slope(&self, r1: f64, p1: f64, r2: f64, p2: f64) -> Result<f64> {
        let (m1, m2) = (self.prof.moments(r1)?, self.prof.moments(r2)?);
        Ok((p2 - p1 + self.prof.k * self.prof.psi(r2, m1, m2)) / (r2 / r1).ln())
    }

    /// Potential (V) of a layer's solution at r.
    fn layer_potential(&self, layer: &Layer, r: f64) -> Result<f64> {
        let mr = self.prof.moments(r)?;
        Ok(match (layer.left, layer.right) {
            (End::Free { s, beta, .. }, _) | (_, End::Free { s, beta, .. }) => {
                beta - self.prof.k * self.prof.psi(r, self.prof.moments(s)?, mr)
            }
            (End::Fixed { r: r1, phi: p1 }, End::Fixed { r: r2, phi: p2 }) => {
                let b = self.fixed_slope(r1, p1, r2, p2)?;
                p1 + b * (r / r1).ln() - self.prof.k * self.prof.psi(r, self.prof.moments(r1)?, mr)
            }
        })
    }

    /// The exact-front potential at the nodes: layer solutions inside layers, the bound of the
    /// neighbouring undepleted region elsewhere (the discrete value if there are no layers).
    fn exact_potential(&self, layers: &[Layer]) -> Result<Vec<f64>> {
        let r = &self.prof.grid.r;
        if layers.is_empty() {
            return Ok(self.disc.x.clone());
        }
        let end_potential = |e: End| match e {
            End::Fixed { phi, .. } => phi,
            End::Free { beta, .. } => beta,
        };
        let mut out = Vec::with_capacity(r.len());
        let mut j = 0;
        for &ri in r {
            while j < layers.len() && layers[j].right.r() < ri {
                j += 1;
            }
            out.push(if j == layers.len() {
                end_potential(layers[j - 1].right)
            } else if ri < layers[j].left.r() {
                end_potential(layers[j].left)
            } else {
                self.layer_potential(&layers[j], ri)?
            });
        }
        Ok(out)
    }

    /// The layer solutions stay within [l, u] at the nodes inside them (else an island was missed).
    fn within_bounds(&self, layers: &[Layer]) -> Result<bool> {
        let tol = 1e-9 * self.vscale;
        for layer in layers {
            let (l, r) = (layer.left.r(), layer.right.r());
            for &ri in self.prof.grid.r.iter().filter(|&&ri| ri > l && ri < r) {
                let p = self.layer_potential(layer, ri)?;
                if p > self.up + tol || p < self.lo - tol {
                    return Ok(false);
                }
            }
        }
        Ok(true)
    }

    /// Free carriers can neutralise only charge of one sign: an undepleted region at u (> l) holds
    /// zeta >= 0 (n-type), one at l holds zeta <= 0. A cell inside a conductor with the other sign
    /// is a depleted layer the grid did not see (thinner than a node spacing).
    fn conductors_hold(&self, layers: &[Layer]) -> bool {
        if self.up == self.lo {
            return true;
        }
        let potential = |e: End| match e {
            End::Fixed { phi, .. } => phi,
            End::Free { beta, .. } => beta,
        };
        // (from, to, potential) of every undepleted stretch, contacts included.
        let mut regions = Vec::new();
        let mut from = (self.a, self.bias);
        for l in layers {
            regions.push((from.0, l.left.r(), potential(l.left)));
            from = (l.right.r(), potential(l.right));
        }
        regions.push((from.0, self.b, if layers.is_empty() { 0.0 } else { from.1 }));
        let (r, tol) = (&self.prof.grid.r, 1e-12 * self.prof.zref);
        regions.iter().all(|&(x0, x1, p)| {
            (0..r.len() - 1)
                .filter(|&i| r[i] >= x0 && r[i + 1] <= x1)
                .all(|i| {
                    if p == self.up {
                        self.prof.zmin[i] * CM3_TO_M3 >= -tol
                    } else {
                        self.prof.zmax[i] * CM3_TO_M3 <= tol
                    }
                })
        })
    }

    /// Front s (m) facing a contact (r_c, phi_c): root of phi_c - beta + (q/eps) psi_s(r_c) in
    /// [lo, hi] nearest to the estimate s0.
    fn front_root(
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
    fn front_pair(&self, left: End, right: End) -> Result<Option<(f64, f64)>> {
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

/// The charged fraction e / f of a control volume, clamped to [0, 1] (1/2 for an empty one).
fn fraction(e: f64, f: f64) -> f64 {
    if f != 0.0 {
        (e / f).clamp(0.0, 1.0)
    } else {
        0.5
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    fn kq() -> f64 {
        ELEMENTARY_CHARGE_C / (VACUUM_PERMITTIVITY_F_PER_M * EPS_R_GERMANIUM)
    }

    /// The discrete pieces of a solve, for KKT checks.
    fn discrete(n: usize, zeta: &dyn Fn(f64) -> f64, bias: f64) -> (Vec<f64>, Vec<f64>, Obstacle) {
        let (a, b) = (6e-3, 37.5e-3);
        let prof = Profile::new(zeta, a, b, n, kq()).unwrap();
        let init = initial_status(a, b, n, bias, &prof).unwrap();
        let disc = solve_obstacle(&prof.grid.g, &prof.f, bias, init).unwrap();
        (prof.grid.g.clone(), prof.f.clone(), disc)
    }

    /// KKT of the discrete obstacle problem: A x = f on free nodes (relative to the row's terms),
    /// multiplier >= 0 at u and <= 0 at l, l <= x <= u.
    fn assert_kkt(g: &[f64], f: &[f64], bias: f64, d: &Obstacle) {
        let (lo, up) = (bias.min(0.0), bias.max(0.0));
        let n = f.len();
        let (mut worst, mut n_up, mut n_lo) = (0.0f64, 0, 0);
        for i in 1..n - 1 {
            let ax = apply_row(g, &d.x, i);
            let lam = f[i] - ax;
            let scale = f[i].abs()
                + g[i - 1] * (d.x[i].abs() + d.x[i - 1].abs())
                + g[i] * (d.x[i].abs() + d.x[i + 1].abs());
            let slack = 1e-11 * (up - lo).abs().max(1.0);
            assert!(
                d.x[i] <= up + slack && d.x[i] >= lo - slack,
                "bounds at {i}"
            );
            match d.status[i] {
                Status::Free => worst = worst.max(lam.abs() / scale),
                Status::Upper => {
                    n_up += 1;
                    assert_eq!(d.x[i], up);
                    assert!(lam >= 0.0, "upper multiplier {lam} at {i}");
                    assert_eq!(lam, d.lam[i]);
                }
                Status::Lower => {
                    n_lo += 1;
                    assert_eq!(d.x[i], lo);
                    assert!(lam <= 0.0, "lower multiplier {lam} at {i}");
                    assert_eq!(lam, d.lam[i]);
                }
            }
        }
        assert!(worst < 1e-12, "free residual {worst}");
        eprintln!(
            "KKT at {bias} V: free residual {worst:.1e}, {n_up} nodes at u, {n_lo} at l, {} steps",
            d.iterations
        );
    }

    fn p_outer(r: f64) -> f64 {
        if r < 30.0 { 1.0e10 } else { -0.5e10 }
    }

    #[test]
    fn kkt_holds_at_both_bounds() {
        for bias in [-300.0, 10.0, 100.0, 400.0, 1500.0, 3000.0] {
            let (g, f, d) = discrete(2001, &p_outer, bias);
            assert_kkt(&g, &f, bias, &d);
            if (10.0..=100.0).contains(&bias) {
                // Both bounds are active: n core at V, p layer on the mantle at 0 V.
                assert!(d.status.contains(&Status::Upper) && d.status.contains(&Status::Lower));
            }
        }
        let falling = |r: f64| 1.3e10 * (1.0 - 0.6 * (r - 6.0) / 31.5);
        for bias in [25.0, 1000.0, 2000.0] {
            let (g, f, d) = discrete(1001, &falling, bias);
            assert_kkt(&g, &f, bias, &d);
        }
    }

    /// Projected Gauss-Seidel converges to the discrete obstacle solution (a classical result);
    /// the active set method must land on the same point.
    #[test]
    fn active_set_equals_projected_gauss_seidel() {
        let zeta = |r: f64| 1.0e10 * (0.3 - ((r - 6.0) / 31.5 * 7.0).sin());
        for bias in [-200.0, 150.0, 900.0] {
            let (g, f, d) = discrete(41, &zeta, bias);
            let (lo, up) = (bias.min(0.0), bias.max(0.0));
            let mut x = vec![0.0; 41];
            x[0] = bias;
            for _ in 0..200_000 {
                for i in 1..40 {
                    let v = (f[i] + g[i - 1] * x[i - 1] + g[i] * x[i + 1]) / (g[i - 1] + g[i]);
                    x[i] = v.clamp(lo, up);
                }
            }
            for (i, (xi, di)) in x.iter().zip(&d.x).enumerate() {
                assert!((xi - di).abs() < 1e-9 * bias.abs(), "{bias} V node {i}");
            }
        }
    }

    /// The log-mean faces make the scheme exact for a uniform density when fully depleted.
    #[test]
    fn discrete_potential_exact_for_uniform_density_fully_depleted() {
        let (a, b, n0, v) = (6e-3, 37.5e-3, 1.0e10 * CM3_TO_M3, 4000.0);
        let (g, f, d) = discrete(101, &|_| 1.0e10, v);
        assert_kkt(&g, &f, v, &d);
        let k = kq();
        // phi = C1 - k n0 r^2 / 4 + C2 ln r through (a, V), (b, 0).
        let p = |r: f64| -k * n0 * r * r / 4.0;
        let c2 = (0.0 - v - p(b) + p(a)) / (b / a).ln();
        let grid = Grid::uniform(a, b, 101);
        for (i, &r) in grid.r.iter().enumerate() {
            let exact = v + p(r) - p(a) + c2 * (r / a).ln();
            assert!(
                (d.x[i] - exact).abs() < 1e-9 * v,
                "node {i}: {} vs {exact}",
                d.x[i]
            );
        }
    }

    /// Both moments of a step profile, for steps anywhere in a cell (Gauss nodes miss the ends of
    /// an interval: the end check must catch steps there).
    #[test]
    fn quadrature_resolves_a_step() {
        let (a, b) = (6e-3f64, 37.5e-3f64);
        // int t ln(t / a) dt = t^2/2 ln(t / a) - t^2/4
        let i1 = |lo: f64, hi: f64| {
            let g = |t: f64| t * t / 2.0 * (t / a).ln() - t * t / 4.0;
            g(hi) - g(lo)
        };
        for (n, s_mm) in [
            (101, 20.123_456_7),
            (251, 30.0),
            (501, 30.0),
            (1001, 30.0),
            (2001, 30.0),
        ] {
            let step = move |r: f64| if r < s_mm { 2.0 } else { -1.0 };
            let prof = Profile::new(&step, a, b, n, kq()).unwrap();
            let s = s_mm * 1e-3;
            let e0 = 1e6 * 0.5 * (2.0 * (s * s - a * a) - (b * b - s * s));
            let e1 = 1e6 * (2.0 * i1(a, s) - i1(s, b));
            let (m0, m1) = (prof.cum0[n - 1], prof.cum1[n - 1]);
            assert!((m0 / e0 - 1.0).abs() < 1e-13, "{n}: m0 {m0} vs {e0}");
            assert!((m1 / e1 - 1.0).abs() < 1e-13, "{n}: m1 {m1} vs {e1}");
            let mid = prof.moments(s).unwrap();
            let (x0, x1) = (1e6 * (s * s - a * a), 2e6 * i1(a, s));
            assert!((mid.0 / x0 - 1.0).abs() < 1e-13 && (mid.1 / x1 - 1.0).abs() < 1e-13);
        }
    }

    #[test]
    fn invalid_input_is_a_domain_error() {
        let z = |_: f64| 1.0e10;
        let ok = RadialReference {
            nodes: 101,
            ..RadialReference::new(6.0, 37.5)
        };
        let bad = [
            RadialReference { a_mm: 0.0, ..ok },
            RadialReference { a_mm: -1.0, ..ok },
            RadialReference {
                a_mm: f64::NAN,
                ..ok
            },
            RadialReference { b_mm: 6.0, ..ok },
            RadialReference {
                b_mm: f64::INFINITY,
                ..ok
            },
            RadialReference { eps_r: 0.0, ..ok },
            RadialReference { nodes: 3, ..ok },
        ];
        for r in bad {
            assert!(
                matches!(r.solve(&z, 100.0), Err(Error::Domain { .. })),
                "{r:?}"
            );
        }
        assert!(matches!(ok.solve(&z, f64::NAN), Err(Error::Domain { .. })));
        assert!(matches!(
            ok.solve(&z, f64::INFINITY),
            Err(Error::Domain { .. })
        ));
        let holes = |r: f64| if r > 20.0 { f64::NAN } else { 1.0e10 };
        let e = ok.solve(&holes, 100.0).unwrap_err();
        assert!(
            matches!(
                e,
                Error::Domain {
                    quantity: "zeta_cm3",
                    ..
                }
            ),
            "{e}"
        );
        let inf = |r: f64| {
            if (r - 30.0).abs() < 1e-3 {
                f64::INFINITY
            } else {
                1.0e10
            }
        };
        assert!(ok.solve(&inf, 100.0).is_err());
        assert!(ok.solve(&z, 100.0).is_ok());
    }

    #[test]
    fn zero_bias_shorts_the_contacts() {
        let r = RadialReference {
            nodes: 101,
            ..RadialReference::new(6.0, 37.5)
        };
        let s = r.solve(&|_| 1.0e10, 0.0).unwrap();
        assert!(s.c12_per_mm_pf.is_infinite() && s.depleted_mm.is_empty());
        let s = r.solve(&|_| 0.0, 0.0).unwrap();
        assert!(s.fully_depleted && s.c12_per_mm_pf.is_finite());
    }
}
