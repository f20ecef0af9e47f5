//! Contact charges of a nonlinear solution and the quasi-static capacitance dQ/dU.
//!
//! Discrete Gauss's law at every node n of the finite-volume mesh: the flux out of its control
//! volume, sum over its edges of w_nm (phi_n - phi_m), equals the charge inside it. On depleted
//! nodes that is the fixed space charge q_n (`Mesh::charge_c`); the rest,
//!
//!   r_n = sum_m w_nm (phi_n - phi_m) - q_n,
//!
//! is free charge: the surface charge of a conductor node, the majority carriers neutralising an
//! undepleted node. The charge a contact has taken from its wire is its own nodes' r_n plus the
//! free carriers it supplied to the crystal: every undepleted node whose majority carriers drain to
//! it (holes, in p-type material, to a contact at the lowest contact potential; electrons, in
//! n-type, to one at the highest), pockets included, whose carriers came from that contact and go
//! back to it when they spill.
//!
//! Varying the bias slowly (every solution in equilibrium, pockets at their spill levels) the
//! read-out contact's charge Q_k(U) is continuous in U, and
//!
//!   C_qs(U) = -dQ_k/dU_B
//!
//! is the quasi-static (slow-ramp) mutual capacitance: carriers that spill from a pocket during
//! the ramp are counted. The weighting-potential c12 of [`super::solve_point`] is the small-signal
//! response with every pocket floating (its carriers cannot come back over the barrier within a
//! pulse or an AC period); below pinch-off and above full depletion the two agree, in the pinch-off
//! window they differ (reports/pockets/).

use super::active_set::{PotentialSolution, solve_fast};
use super::mesh::{Mesh, NodeKind};
use crate::detector::Detector;
use crate::error::{Error, Result};

/// Free charge r_n (C) of every node of `sol` on `mesh` (see the module text).
pub(crate) fn free_charges_c(mesh: &Mesh, sol: &PotentialSolution) -> Vec<f64> {
    let phi = &sol.phi_v;
    let mut r: Vec<f64> = mesh.charge_c.iter().map(|q| -q).collect();
    mesh.for_each_edge(|p, q, w| {
        let f = w * (phi[p] - phi[q]);
        r[p] += f;
        r[q] -= f;
    });
    r
}

/// Charge (C) contact `contact` has taken from its wire in the solution `sol` at `bias_v`: its
/// nodes' free charge plus that of every undepleted node whose majority carriers drain to it
/// (module text).
pub fn contact_charge_c(
    mesh: &Mesh,
    det: &Detector,
    bias_v: f64,
    sol: &PotentialSolution,
    contact: usize,
) -> Result<f64> {
    if contact >= det.contacts.len() {
        return Err(Error::Argument {
            name: "contact".into(),
            message: format!(
                "index {contact}, but the detector has {} contacts",
                det.contacts.len()
            ),
        });
    }
    let (lo, hi) = sol.bounds_v;
    let v = det.contacts[contact].potential_v(bias_v);
    let tol = 1e-9 * (hi - lo).abs().max(1.0);
    let (drains_holes, drains_electrons) = ((v - lo).abs() <= tol, (v - hi).abs() <= tol);
    let r = free_charges_c(mesh, sol);
    let mut total = 0.0;
    for (n, kind) in mesh.kind.iter().enumerate() {
        let owned = match *kind {
            NodeKind::Contact(c) => c == contact,
            NodeKind::Semiconductor if sol.undepleted[n] => {
                // Acceptors (p-type) carry negative fixed charge.
                let p_type = mesh.charge_c[n] < 0.0;
                (p_type && drains_holes) || (!p_type && drains_electrons)
            }
            _ => false,
        };
        if owned {
            total += r[n];
        }
    }
    Ok(total)
}

/// The quasi-static mutual capacitance (pF) between the bias contact and `readout` at `bias_v`
/// on a fixed `mesh`: C_qs = -(Q(U + dU) - Q(U - dU)) / (2 dU), Q the read-out contact's charge
/// ([`contact_charge_c`]) of the nonlinear solutions ([`solve_fast`]) at U +- dU.
pub fn quasi_static_c12_pf(
    mesh: &Mesh,
    det: &Detector,
    bias_v: f64,
    du_v: f64,
    readout: usize,
) -> Result<f64> {
    if !(du_v.is_finite() && du_v > 0.0 && du_v < bias_v.abs()) {
        return Err(Error::Argument {
            name: "du_v".into(),
            message: format!("{du_v} V: must be positive and below the bias {bias_v} V"),
        });
    }
    let q = |u: f64| -> Result<f64> {
        let s = solve_fast(mesh, det, u, None)?;
        contact_charge_c(mesh, det, u, &s, readout)
    };
    Ok(-(q(bias_v + du_v)? - q(bias_v - du_v)?) / (2.0 * du_v) * 1e12)
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::expr::Parameters;
    use crate::field::{FieldSettings, solve_point};

    fn detector(file: &str) -> Detector {
        let path = std::path::Path::new(env!("CARGO_MANIFEST_DIR"))
            .join("..")
            .join(file);
        Detector::from_file(&path, &Parameters::new()).unwrap()
    }

    /// Gauss's law over the whole mesh: the free charges add up to minus the fixed charges
    /// (the world's boundary nodes are grounded nodes of the mesh, no flux leaves it).
    #[test]
    fn free_charges_balance_the_fixed_charges() {
        let det = detector("detectors/planar-pn.toml");
        let p = solve_point(&det, 100.0, &FieldSettings::default(), None).unwrap();
        let r = free_charges_c(&p.mesh, &p.potential);
        let fixed: f64 = p.mesh.charge_c.iter().sum();
        let free: f64 = r.iter().sum();
        assert!(
            (free + fixed).abs() <= 1e-9 * fixed.abs(),
            "{free} vs {fixed}"
        );
    }

    /// Fully depleted, the solution is affine in the bias on a fixed mesh: dQ/dU is the vacuum
    /// mutual capacitance of the weighting potentials, on the same mesh, to round-off.
    #[test]
    fn depleted_quasi_static_equals_the_weighting_c12() {
        let det = detector("detectors/planar-pn.toml");
        let mut s = FieldSettings::default();
        s.grid.adaptive = false;
        let p = solve_point(&det, 1000.0, &s, None).unwrap();
        assert!(p.fully_depleted());
        let readout = (0..det.contacts.len())
            .find(|&k| !det.bias_contacts().contains(&k))
            .unwrap();
        let c = quasi_static_c12_pf(&p.mesh, &det, 1000.0, 50.0, readout).unwrap();
        assert!((c / p.c12_pf - 1.0).abs() < 1e-6, "{c} vs {} pF", p.c12_pf);
    }

    #[test]
    fn bad_step_and_contact_are_errors() {
        let det = detector("detectors/planar-pn.toml");
        let p = solve_point(&det, 100.0, &FieldSettings::default(), None).unwrap();
        assert!(quasi_static_c12_pf(&p.mesh, &det, 100.0, 0.0, 0).is_err());
        assert!(quasi_static_c12_pf(&p.mesh, &det, 100.0, 200.0, 0).is_err());
        assert!(contact_charge_c(&p.mesh, &det, 100.0, &p.potential, 9).is_err());
    }
}
