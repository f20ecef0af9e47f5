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
//!    uniform zeta this is the closed form of [`LongCoax`](crate::problems::coax::LongCoax)); a layer between two fronts
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
//!   [`LongCoax`](crate::problems::coax::LongCoax): c' within 3e-13 relative and r_d within 8e-13 mm at 251, 1001 and 4001
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

mod front_equations;
mod layer_solution;
mod layers;
mod obstacle;
mod profile;
mod reference;
mod refine;
#[cfg(test)]
mod tests;

pub use reference::{DEFAULT_NODES, MIN_NODES, RadialReference, RadialSolution};
