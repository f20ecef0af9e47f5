//! The Maxwell capacitance matrix from weighting potentials (paper Eq. (5)).
//!
//! C*_ij = eps0 int grad W_i . eps_r grad W_j dV becomes, on the mesh, the energy form
//! W_i^T K W_j = sum_edges w (W_i,p - W_i,q)(W_j,p - W_j,q); the charge form
//! Q_j(W_i) = sum over the nodes of contact j (with its undepleted extension) of (K W_i)_n. The
//! discrete Green identity makes them equal when the solves are exact: a built-in cross-check.

use serde::Serialize;

use super::Mesh;
use super::weighting::WeightingPotentials;

/// Maxwell capacitance matrix in pF (Q = C* U), computed two ways.
#[derive(Debug, Clone, PartialEq, Serialize)]
pub struct CapacitanceMatrix {
    /// Contact names, in detector order.
    pub contacts: Vec<String>,
    /// From the energy form, pF.
    pub energy_pf: Vec<Vec<f64>>,
    /// From the charges on the contacts, pF.
    pub charge_pf: Vec<Vec<f64>>,
}

impl CapacitanceMatrix {
    /// Computes both forms from the weighting potentials.
    pub fn from_weighting(mesh: &Mesh, wp: &WeightingPotentials, names: Vec<String>) -> Self {
        let nc = wp.w.len();
        let mut energy_pf = vec![vec![0.0; nc]; nc];
        let mut charge_pf = vec![vec![0.0; nc]; nc];
        for i in 0..nc {
            let kw = mesh.apply(&wp.w[i]);
            for j in 0..nc {
                energy_pf[i][j] = mesh.energy(&wp.w[i], &wp.w[j]) * 1e12;
                charge_pf[j][i] = kw
                    .iter()
                    .zip(&wp.owned[j])
                    .filter(|(_, o)| **o)
                    .map(|(q, _)| q)
                    .sum::<f64>()
                    * 1e12;
            }
        }
        Self {
            contacts: names,
            energy_pf,
            charge_pf,
        }
    }

    /// Mutual capacitance c_ij = -C*_ij (pF) from the energy form.
    pub fn mutual_pf(&self, i: usize, j: usize) -> f64 {
        -self.energy_pf[i][j]
    }
}
