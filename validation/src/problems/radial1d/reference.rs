//! The reference problem (radii, permittivity, nodes), its solution at one bias, and the solve
//! that chains the steps of the method (module documentation).

use std::f64::consts::PI;

use hpge_solver::constants::{ELEMENTARY_CHARGE_C, EPS_R_GERMANIUM, VACUUM_PERMITTIVITY_F_PER_M};

use super::layers::{End, Fronts, Layer};
use super::obstacle::{initial_status, solve_obstacle};
use super::profile::Profile;
use crate::error::{Error, Result};

/// Default number of nodes (contacts included): 4001, i.e. 7.9 um on the validation coax. The exact
/// fronts do not need that many; it makes the grid-only estimate agree with them to 1.2e-6 relative
/// at the reference-table voltages (so the two routes cross-check each other below 1e-5) and
/// resolves depleted layers and undepleted islands down to about 10 um. 3-4 ms per solve.
pub const DEFAULT_NODES: usize = 4001;
/// Fewest nodes accepted.
pub const MIN_NODES: usize = 8;

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
