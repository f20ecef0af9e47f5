//! The electric field against the closed form of a uniformly doped true coax.

use std::path::Path;

use super::ElectricField;
use crate::constants::{
    CM3_TO_M3, ELEMENTARY_CHARGE_C, EPS_R_GERMANIUM, VACUUM_PERMITTIVITY_F_PER_M,
};
use crate::detector::Detector;
use crate::expr::Parameters;
use crate::field::{FieldSettings, PointResult, solve_point};
use crate::grid::GridSettings;

/// The long coax of `detectors/coax-analytic.toml`: a = 6 mm, b = 37.5 mm, N = 1e10 cm^-3 n-type,
/// reflecting ends (no z dependence), bias on the inner contact.
pub(super) const A_M: f64 = 6e-3;
pub(super) const B_M: f64 = 37.5e-3;
const N_CM3: f64 = 1e10;

pub(super) fn coax() -> Detector {
    let path = Path::new(env!("CARGO_MANIFEST_DIR")).join("../detectors/coax-analytic.toml");
    Detector::from_file(&path, &Parameters::new()).unwrap()
}

pub(super) fn solve(det: &Detector, bias_v: f64, spacing_mm: f64) -> PointResult {
    let settings = FieldSettings {
        grid: GridSettings {
            max_spacing_semiconductor_mm: spacing_mm,
            ..GridSettings::default()
        },
        ..FieldSettings::default()
    };
    solve_point(det, bias_v, &settings, None).unwrap()
}

/// alpha = q N / (2 eps) in V/m^2.
pub(super) fn alpha_v_per_m2() -> f64 {
    ELEMENTARY_CHARGE_C * N_CM3 * CM3_TO_M3 / (2.0 * EPS_R_GERMANIUM * VACUUM_PERMITTIVITY_F_PER_M)
}

/// The closed-form field of the coax, E_r(r) in V/m. Poisson's equation
/// (1/r) d/dr (r dphi/dr) = -q N / eps gives phi = -alpha r^2 / 2 + A ln r + B and
/// E_r = alpha r - A / r. Fully depleted: phi(a) - phi(b) = U_B fixes
/// A = (U_B - alpha (b^2 - a^2) / 2) / ln(a / b). Partly depleted (depleted for r > r_d):
/// E_r(r_d) = 0 gives A = alpha r_d^2, with U_B = alpha [(b^2 - r_d^2)/2 - r_d^2 ln(b / r_d)]
/// solved for r_d by bisection; `None` for r < r_d.
pub(super) fn closed_form(bias_v: f64) -> impl Fn(f64) -> Option<f64> {
    let al = alpha_v_per_m2();
    let u = |rd: f64| al * ((B_M * B_M - rd * rd) / 2.0 - rd * rd * (B_M / rd).ln());
    let (rd, a) = if bias_v >= u(A_M) {
        (
            A_M,
            (bias_v - al * (B_M * B_M - A_M * A_M) / 2.0) / (A_M / B_M).ln(),
        )
    } else {
        let (mut lo, mut hi) = (A_M, B_M);
        for _ in 0..200 {
            let m = 0.5 * (lo + hi);
            if u(m) > bias_v { lo = m } else { hi = m }
        }
        (lo, al * lo * lo)
    };
    move |r_m: f64| (r_m >= rd).then(|| al * r_m - a / r_m)
}

/// Largest |E - E_closed| over r in [a + 0.5 mm, b - 0.5 mm] relative to max |E_closed|, and
/// the largest |E_z| relative to it, at z = 5 mm, phi = 0.4 rad.
fn errors(field: &ElectricField, bias_v: f64, r_min_mm: f64) -> (f64, f64) {
    let want = closed_form(bias_v);
    let rs: Vec<f64> = (0..=200)
        .map(|k| r_min_mm + (37.0 - r_min_mm) * k as f64 / 200.0)
        .collect();
    let scale = rs.iter().filter_map(|r| want(r * 1e-3)).fold(0.0, f64::max);
    let (mut er, mut ez) = (0.0f64, 0.0f64);
    for &r in &rs {
        let phi = 0.4;
        let e = field.at(r, phi, 5.0).expect("in the depleted crystal");
        let w = want(r * 1e-3).unwrap();
        let e_r = e[0] * phi.cos() + e[1] * phi.sin();
        assert!((e[0] * phi.sin() - e[1] * phi.cos()).abs() < 1e-9 * scale);
        er = er.max((e_r - w).abs() / scale);
        ez = ez.max(e[2].abs() / scale);
    }
    (er, ez)
}

#[test]
fn coax_field_matches_the_closed_form_and_converges() {
    let det = coax();
    let mut last = f64::INFINITY;
    for h_mm in [1.0, 0.5, 0.25] {
        let p = solve(&det, 4000.0, h_mm);
        assert!(p.fully_depleted());
        let field = ElectricField::new(&det, &p);
        let (er, ez) = errors(&field, 4000.0, 6.5);
        eprintln!("coax 4000 V, h = {h_mm} mm: max |dE_r| / max E = {er:.3e}, |E_z| {ez:.1e}");
        // Second order: the error bound scales with h^2.
        assert!(er < 2e-3 * h_mm * h_mm, "h = {h_mm}: {er:e}");
        assert!(ez < 1e-6, "h = {h_mm}: {ez:e}");
        assert!(er < last);
        last = er;
    }
}

#[test]
fn partly_depleted_coax_and_where_there_is_no_field() {
    let det = coax();
    let bias_v = 2000.0;
    let p = solve(&det, bias_v, 0.5);
    assert!(!p.fully_depleted());
    let field = ElectricField::new(&det, &p);
    let want = closed_form(bias_v);
    // Undepleted inside r_d; the front is located to within a cell.
    let rd_mm = (60..375)
        .map(|k| k as f64 * 0.1)
        .find(|r| want(r * 1e-3).is_some())
        .unwrap();
    eprintln!("coax 2000 V: r_d = {rd_mm:.1} mm");
    assert!(field.at(rd_mm - 1.0, 0.0, 5.0).is_none());
    let (er, _) = errors(&field, bias_v, rd_mm + 2.0);
    eprintln!("coax 2000 V, h = 0.5 mm: max |dE_r| / max E = {er:.3e} beyond r_d + 2 mm");
    assert!(er < 2e-3, "{er:e}");
    // Outside the crystal, inside a contact, outside the world.
    assert!(field.at(3.0, 0.0, 5.0).is_none());
    assert!(field.at(38.0, 0.0, 5.0).is_none());
    assert!(field.at(20.0, 0.0, 11.0).is_none());
    assert!(field.at(f64::NAN, 0.0, 5.0).is_none());
    let mags = field.magnitude_along_r(0.5, 5.0, &[3.0, 30.0, 37.499]);
    assert!(mags[0].is_none());
    let m30 = mags[1].unwrap();
    assert!((m30 - want(30e-3).unwrap()).abs() < 2e-3 * m30, "{m30}");
    // At the p+ surface (on it a point belongs to the contact) the field comes from the crystal
    // side only.
    let m_surface = mags[2].unwrap();
    assert!(
        (m_surface - want(37.499e-3).unwrap()).abs() < 5e-3 * m_surface,
        "{m_surface}"
    );
}
