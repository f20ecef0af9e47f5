//! Reading the converged iterate: the unconstrained Gauss-Seidel target of a node (for the KKT
//! readout of undepleted nodes) and the projected residual.

use crate::field::mesh::{Mesh, NodeKind};
use crate::field::system::Dof;

/// (q_n + sum w x_m) / sum w and sum w of node n.
pub(super) fn target(
    mesh: &Mesh,
    phi: &[f64],
    n: usize,
    w: &[f64; 4],
    nb: &[Option<usize>; 4],
) -> (f64, f64) {
    let mut s = mesh.charge_c[n];
    let mut d = 0.0;
    for (m, w) in nb.iter().zip(w) {
        if let Some(m) = m {
            s += w * phi[*m];
            d += w;
        }
    }
    (s / d, d)
}

/// max |x - P(x - g / A_nn)| over the unknowns (free nodes and floating conductors), V: the
/// node-grid form of `depletion::projected_residual`.
pub(super) fn projected_residual(
    mesh: &Mesh,
    dofs: &[Dof],
    phi: &[f64],
    (lo, hi): (f64, f64),
) -> f64 {
    projected_residual_within(mesh, dofs, phi, &vec![(lo, hi); phi.len()])
}

/// [`projected_residual`] with every node's own bounds (`bounds[n]`; semiconductor nodes only).
pub(super) fn projected_residual_within(
    mesh: &Mesh,
    dofs: &[Dof],
    phi: &[f64],
    bounds: &[(f64, f64)],
) -> f64 {
    let nn = phi.len();
    // g / A_nn = x - target for free nodes; for a conductor the sums run over its boundary.
    let kx = mesh.apply(phi);
    let mut diag = vec![0.0; nn];
    mesh.for_each_edge(|p, q, w| {
        diag[p] += w;
        diag[q] += w;
    });
    let mut worst = 0.0_f64;
    let mut groups: Vec<(usize, f64, f64)> = Vec::new();
    for n in 0..nn {
        match dofs[n] {
            Dof::Fixed(_) => {}
            Dof::Free => {
                let g = kx[n] - mesh.charge_c[n];
                let step = phi[n] - g / diag[n];
                let p = if mesh.kind[n] == NodeKind::Semiconductor {
                    step.clamp(bounds[n].0, bounds[n].1)
                } else {
                    step
                };
                worst = worst.max((phi[n] - p).abs());
            }
            Dof::Group(k) => {
                // Internal edges cancel in the sum of (K x) over the group.
                let g = kx[n] - mesh.charge_c[n];
                match groups.iter_mut().find(|e| e.0 == k) {
                    Some(e) => e.1 += g,
                    None => groups.push((k, g, 0.0)),
                }
            }
        }
    }
    if !groups.is_empty() {
        mesh.for_each_edge(|p, q, w| {
            let (gp, gq) = (dofs[p], dofs[q]);
            if gp == gq {
                return;
            }
            for g in [gp, gq] {
                if let Dof::Group(k) = g
                    && let Some(e) = groups.iter_mut().find(|e| e.0 == k)
                {
                    e.2 += w;
                }
            }
        });
        for (_, g, d) in groups {
            worst = worst.max((g / d).abs());
        }
    }
    worst
}
