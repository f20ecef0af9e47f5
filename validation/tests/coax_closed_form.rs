//! The closed-form long coax against the independent reference table in
//! ../shared/reference/coax-1d-reference.md (computed outside this project).

use hpge_validation::LongCoax;

/// (U_B in V, r_d in mm, c' in pF/mm): the independent reference table.
const REFERENCE: [(f64, f64, f64); 10] = hpge_validation::COAX_REFERENCE_TABLE;

#[test]
fn matches_reference_table() {
    let c = LongCoax::validation();
    assert!(
        (c.full_depletion_v() - 3501.1).abs() < 0.05,
        "{}",
        c.full_depletion_v()
    );
    for (v, rd, cp) in REFERENCE {
        let rd_here = c.front_mm(v).unwrap();
        let cp_here = c.c12_per_mm_pf(v).unwrap();
        // The table is rounded to 4 decimals (r_d) and 5 decimals (c'): agree to half a unit.
        assert!(
            (rd_here - rd).abs() <= 0.51e-4,
            "r_d at {v} V: {rd_here} vs {rd}"
        );
        assert!(
            (cp_here - cp).abs() <= 0.51e-5,
            "c' at {v} V: {cp_here} vs {cp}"
        );
    }
}

#[test]
fn fully_depleted_is_the_geometric_capacitance() {
    let c = LongCoax::validation();
    let geometric =
        2.0 * std::f64::consts::PI * 8.8541878128e-12 * 16.0 / (37.5f64 / 6.0).ln() * 1e9;
    let v = c.full_depletion_v();
    assert!((c.c12_per_mm_pf(v + 1.0).unwrap() / geometric - 1.0).abs() < 1e-14);
    assert!(c.c12_per_mm_pf(v - 1.0).unwrap() > geometric);
}
