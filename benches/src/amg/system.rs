//! The solver's field systems as test matrices for the multigrid: the weighting problem of a
//! shipped detector, assembled by the solver itself (`hpge_solver::internals`).

use hpge_solver::Result;
use hpge_solver::detector::Detector;
use hpge_solver::expr::Parameters;
use hpge_solver::field::Mesh;
use hpge_solver::grid::{Grid, GridSettings};
use hpge_solver::internals::{Owner, System, owners, weighting_dofs};

use super::Csr;

/// The weighting system of contact `k` of a detector (fully depleted, no undepleted node) on its
/// initial grid of crystal spacing `h_mm`: the Laplace-type operator of the field problems,
/// its matrix in unknown space and the right-hand side of contact `k` at 1 V.
///
/// # Errors
/// The detector file does not load or its contacts cannot be labelled.
pub fn weighting_system(name: &str, h_mm: f64, k: usize) -> Result<(System, Vec<f64>)> {
    let path = hpge_validation::repo_path(&format!("detectors/{name}"));
    let det = Detector::from_file(&path, &Parameters::new())?;
    let s = GridSettings {
        max_spacing_semiconductor_mm: h_mm,
        max_spacing_mm: (4.0 * h_mm).min(GridSettings::default().max_spacing_mm),
        ..GridSettings::default()
    };
    let mesh = Mesh::new(&det, Grid::initial(&det, &s));
    let none = vec![false; mesh.kind.len()];
    let own = owners(&mesh, &det, &none, 1000.0)?;
    let sys = System::assemble(&mesh, &weighting_dofs(&own), &vec![0.0; mesh.kind.len()]);
    let fixed: Vec<f64> = own
        .iter()
        .map(|o| f64::from(u8::from(*o == Some(Owner::Contact(k)))))
        .collect();
    let rhs = sys.rhs_for_fixed(&mesh, &fixed);
    Ok((sys, rhs))
}

/// The system's matrix with the values `val` (its pattern) as a [`Csr`].
pub fn csr(sys: &System, val: &[f64]) -> Csr {
    Csr::from_symmetric_csc(sys.n, &sys.col_ptr, &sys.row_idx, val)
}

/// max_i |a_i - b_i| / max_i |b_i|.
pub fn max_rel_diff(a: &[f64], b: &[f64]) -> f64 {
    let scale = b.iter().fold(0.0f64, |m, v| m.max(v.abs()));
    a.iter()
        .zip(b)
        .fold(0.0f64, |m, (x, y)| m.max((x - y).abs()))
        / scale
}
