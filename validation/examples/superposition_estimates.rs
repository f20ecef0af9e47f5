//! fieldgen's depletion and pinch-off *estimates* (superposition from one fully depleted bias)
//! computed from this solver's fields, to set beside this solver's own voltages (from the full
//! nonlinear solutions) and fieldgen's printed estimates (validation/references/fieldgen/).
//!
//! Above full depletion the potential is affine in the bias: phi(U) = phi(U_B) - (U_B - U) W_b,
//! W_b the bias contact's weighting potential. fieldgen extrapolates that below U_B:
//! - depletion estimate: the highest U at which a node next to the point contact (p+) has
//!   phi(U) <= 0 (the field at the contact vanishes there);
//! - bubble threshold: the highest U at which some p-type bulk node is a local minimum of phi(U)
//!   among its grid neighbours (holes trapped); when it is above the depletion estimate, fieldgen
//!   calls the depletion estimate the pinch-off voltage and the threshold the full depletion.
//!
//! Below full depletion the extrapolation ignores the undepleted volume, so the estimates need not
//! equal the voltages of the nonlinear solutions.
//!
//! `cargo run --release -p hpge-validation --example superposition_estimates -- DETECTOR U_B`

use hpge_solver::field::NodeKind;
use hpge_solver::{Detector, FieldSettings, Parameters, solve_point};
use hpge_validation::repo_path;

fn main() -> Result<(), Box<dyn std::error::Error>> {
    let args: Vec<String> = std::env::args().skip(1).collect();
    let file = args
        .first()
        .cloned()
        .unwrap_or("detectors/icpc-example.toml".into());
    let ub: f64 = args.get(1).map_or(Ok(4000.0), |a| a.parse())?;
    let det = Detector::from_file(&repo_path(&file), &Parameters::new())?;
    let p = solve_point(&det, ub, &FieldSettings::default(), None)?;
    if !p.fully_depleted() {
        return Err(format!("{file} is not fully depleted at {ub} V").into());
    }
    let bias = det.bias_contacts()[0];
    let readout = (0..det.contacts.len())
        .find(|&k| k != bias)
        .ok_or("no second contact")?;
    let g = &p.mesh.grid;
    let (nr, nz) = (g.nr(), g.nz());
    let wb = &p.weighting.w[bias];
    let phi = &p.potential.phi_v;
    let semi = |n: usize| p.mesh.kind[n] == NodeKind::Semiconductor;
    let nbrs = |n: usize| {
        let (i, j) = (n % nr, n / nr);
        [
            (i > 0).then(|| n - 1),
            (i + 1 < nr).then_some(n + 1),
            (j > 0).then(|| n - nr),
            (j + 1 < nz).then_some(n + nr),
        ]
        .into_iter()
        .flatten()
    };
    // phi_n(U) = a_n + U b_n.
    let b = |n: usize| wb[n];
    let a = |n: usize| phi[n] - ub * wb[n];
    // Depletion estimate: nodes next to the read-out contact.
    let mut depletion: f64 = f64::NEG_INFINITY;
    for n in (0..nr * nz).filter(|&n| semi(n)) {
        if nbrs(n).any(|m| p.mesh.kind[m] == NodeKind::Contact(readout)) && b(n) > 0.0 {
            depletion = depletion.max(-a(n) / b(n));
        }
    }
    // Bubble threshold: the highest U in [0, U_B] at which a p-type node is below every
    // neighbour: for each neighbour m, a_n + U b_n < a_m + U b_m bounds U from one side.
    let mut bubble: (f64, usize) = (f64::NEG_INFINITY, 0);
    for n in (0..nr * nz).filter(|&n| semi(n) && p.mesh.charge_c[n] < 0.0) {
        let (mut lo, mut hi) = (0.0f64, ub);
        for m in nbrs(n) {
            let (da, db) = (a(n) - a(m), b(m) - b(n));
            if db > 0.0 {
                lo = lo.max(da / db);
            } else if db < 0.0 {
                hi = hi.min(da / db);
            } else if da >= 0.0 {
                hi = f64::NEG_INFINITY;
            }
        }
        if hi > lo && hi > bubble.0 {
            bubble = (hi, n);
        }
    }
    println!("{file}: fully depleted solution at {ub} V on {nr}x{nz} nodes");
    println!("  depletion estimate (field at the read-out contact vanishes): {depletion:.1} V");
    if bubble.0 > depletion {
        let n = bubble.1;
        println!(
            "  bubble threshold (last p-type local minimum): {:.1} V at (r, z) = ({:.2}, {:.2}) mm",
            bubble.0,
            g.r_mm()[n % nr],
            g.z_mm()[n / nr]
        );
        println!(
            "  fieldgen's reading: pinch-off {depletion:.1} V, full depletion {:.1} V",
            bubble.0
        );
    } else {
        println!("  no bubble above the depletion estimate: full depletion {depletion:.1} V");
    }
    Ok(())
}
