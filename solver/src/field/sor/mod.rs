//! The potential with depletion by red-black projected successive over-relaxation (SOR): the
//! baseline method of SolidStateDetectors.jl and fieldgen, here converging to the same discrete
//! obstacle problem as [`solve_fast`](super::solve_fast) (see `depletion.rs`).
//!
//! The iteration works on the node grid directly. With the 5-point finite-volume stencil of
//! `mesh.rs`, a free node n is updated as
//!
//! x_n <- clamp((1 - omega) x_n + omega (q_n + sum_m w_nm x_m) / sum_m w_nm, l_n, u_n),
//!
//! [l_n, u_n] = [min, max] of the fixed potentials on semiconductor nodes and (-inf, inf) on
//! insulator nodes. Node (i, j) is red when i + j is even: the stencil couples red nodes only to
//! black ones, so each colour is updated in parallel over rows (rayon), red then black. A floating
//! conductor is one unknown: after every red-black pair its potential moves (with the same
//! over-relaxation) to the value that makes its net charge zero, the conductance-weighted mean of
//! its neighbours outside it. Red nodes, black nodes and the floating conductors form a block
//! ordering of the unknowns of an SPD matrix, so projected SOR converges for 0 < omega < 2 (Cryer,
//! SIAM J. Control 9 (1971) 385) to the unique solution of the discrete obstacle problem.
//!
//! Undepleted nodes are read from the KKT conditions after convergence, as the active-set method
//! ends: a semiconductor node is undepleted when its unconstrained Gauss-Seidel target
//! (q_n + sum w x_m) / sum w lies beyond a bound (multiplier lambda_n = f_n - (A x)_n of the
//! bound's sign), not from |x_n - bound| < eps.

mod levels;
mod residual;
mod solve;
pub(crate) mod stencil;
mod sweep;
#[cfg(test)]
mod tests;
mod wgpu;
#[cfg(test)]
mod wgpu_tests;

pub use self::solve::solve_sor_with;
pub use crate::relaxation::{SorSettings, default_omega};
pub use solve::solve_sor;
pub use wgpu::{solve_sor_wgpu, solve_sor_wgpu_with, weighting_potentials_wgpu};
