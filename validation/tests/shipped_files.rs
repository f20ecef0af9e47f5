//! The shipped detector and impurity files load and say what their comments claim.

use hpge_solver::detector::{BoundaryKind, ContactPotential, PassiveKind, Region, WorldSide};
use hpge_solver::{Detector, Parameters};
use hpge_validation::repo_path;

fn load(name: &str) -> Detector {
    Detector::from_file(&repo_path(name), &Parameters::new())
        .unwrap_or_else(|e| panic!("{name}: {e}"))
}

fn rel(a: f64, b: f64) -> f64 {
    (a - b).abs() / b.abs()
}

#[test]
fn every_shipped_file_loads() {
    let mut n = 0;
    for entry in std::fs::read_dir(repo_path("detectors")).unwrap() {
        let path = entry.unwrap().path();
        if path.extension().is_some_and(|e| e == "toml") {
            Detector::from_file(&path, &Parameters::new())
                .unwrap_or_else(|e| panic!("{}: {e}", path.display()));
            n += 1;
        }
    }
    assert!(n >= 3, "expected at least three detectors, found {n}");
    let mut det = load("detectors/super-siegfried-k1.toml");
    for entry in std::fs::read_dir(repo_path("detectors/impurities")).unwrap() {
        let path = entry.unwrap().path();
        det.set_impurity_file(&path)
            .unwrap_or_else(|e| panic!("{}: {e}", path.display()));
    }
}

/// Acceptance: the paper's p_zeta,E gives +-1.30e10 and +-0.44e10 at the knot corners (1e-6).
#[test]
fn paper_example_at_the_corners() {
    let mut det = load("detectors/super-siegfried-k1.toml");
    det.set_impurity_file(&repo_path("detectors/impurities/paper-example-rz.toml"))
        .unwrap();
    let m = det.impurity();
    assert_eq!(m.name(), "rz");
    for (r, z, want) in [
        (20.0, 0.0, 1.30e10),
        (37.5, 0.0, -0.44e10),
        (20.0, 70.0, 0.44e10),
        (37.5, 70.0, -1.30e10),
        // Constant inside the first knot, and the third knot's zeta_b/10.
        (10.0, 0.0, 1.30e10),
        (33.0, 0.0, 1.30e9),
    ] {
        let got = m.density_cm3(r, z);
        assert!(rel(got, want) < 1e-6, "({r}, {z}): {got:e} vs {want:e}");
    }
    // Linear in y between the faces: y at mid height is the mean of the faces' y.
    let p0 = m.evaluate(20.0, 0.0);
    let p1 = m.evaluate(20.0, 70.0);
    let pm = m.evaluate(20.0, 35.0);
    let mean = 0.5 * (p0.y.unwrap() + p1.y.unwrap());
    assert!((pm.y.unwrap() - mean).abs() < 1e-14);
}

#[test]
fn super_siegfried_geometry() {
    let det = load("detectors/super-siegfried-k1.toml");
    // Manufacturer model by default: 1.30e10 at the bottom, 0.44e10 at the top.
    assert_eq!(det.impurity().name(), "linear-z");
    assert!(rel(det.impurity().density_cm3(20.0, 0.0), 1.30e10) < 1e-12);
    assert!(rel(det.impurity().density_cm3(20.0, 70.0), 0.44e10) < 1e-12);
    // Borehole and its widening: radius 10 at z = 0, 5 from z = 3 to 67, 10 at z = 70.
    assert_eq!(det.classify(2.0, 35.0), Region::Medium);
    assert_eq!(det.classify(9.0, 0.5), Region::Medium);
    assert_eq!(det.classify(9.0, 69.5), Region::Medium);
    assert_eq!(det.classify(9.0, 35.0), Region::Semiconductor);
    assert_eq!(det.classify(6.0, 0.5), Region::Medium);
    // n+ (Li) tube 1 mm thick on the borehole wall, z in [3, 67], rounded outer edge.
    let n = det
        .contacts
        .iter()
        .position(|c| c.potential == ContactPotential::Bias)
        .unwrap();
    assert_eq!(det.classify(5.5, 35.0), Region::Contact(n));
    assert_eq!(det.classify(6.5, 35.0), Region::Semiconductor);
    assert_eq!(
        det.classify(5.95, 3.05),
        Region::Semiconductor,
        "rounded corner"
    );
    assert_eq!(det.classify(5.05, 3.05), Region::Contact(n));
    // p+ mantle: a surface at r = 37.5 mm.
    let p = det
        .contacts
        .iter()
        .position(|c| c.potential == ContactPotential::Fixed(0.0))
        .unwrap();
    assert_eq!(det.classify(37.5, 35.0), Region::Contact(p));
    assert_eq!(det.classify(37.4, 35.0), Region::Semiconductor);
    // Environment: hat radius 55 mm, inner height 105 mm, everything grounded.
    let w = &det.world;
    assert_eq!(w.r_max_mm, 55.0);
    assert_eq!(w.z_max_mm - w.z_min_mm, 105.0);
    for side in [WorldSide::RMax, WorldSide::ZMin, WorldSide::ZMax] {
        assert_eq!(w.boundary(side), BoundaryKind::Grounded);
    }
    assert!(det.passives.iter().any(|p| p.kind == PassiveKind::Grounded));
    // Grid ticks include every edge, e.g. the widening's ends and the Li thickness.
    let (r, z) = det.ticks();
    for v in [5.0, 6.0, 10.0, 37.5, 55.0] {
        assert!(r.contains(&v), "r tick {v} missing");
    }
    for v in [0.0, 3.0, 4.0, 66.0, 67.0, 70.0] {
        assert!(z.contains(&v), "z tick {v} missing");
    }
}

#[test]
fn d_li_parameter_changes_the_geometry() {
    let mut over = Parameters::new();
    over.set("d_li_mm", 3.0);
    let det = Detector::from_file(&repo_path("detectors/super-siegfried-k1.toml"), &over).unwrap();
    let n = det.bias_contacts()[0];
    let b = det.contacts[n].geometry.bbox();
    assert_eq!((b.r_min_mm, b.r_max_mm), (5.0, 8.0));
    assert_eq!(det.classify(7.5, 35.0), Region::Contact(n));
    assert_eq!(det.parameters.get("d_li_mm"), Some(3.0));
}

#[test]
fn coax_and_ppc() {
    let coax = load("detectors/coax-analytic.toml");
    assert_eq!(
        coax.world.boundary(WorldSide::ZMin),
        BoundaryKind::Reflecting
    );
    assert_eq!(
        coax.world.boundary(WorldSide::ZMax),
        BoundaryKind::Reflecting
    );
    assert_eq!(coax.impurity().density_cm3(20.0, 5.0), 1.0e10);
    assert!(coax.contacts.iter().all(|c| c.geometry.is_surface_only()));
    let b = coax.semiconductor.geometry.bbox();
    assert_eq!(
        (b.r_min_mm, b.r_max_mm, b.z_min_mm, b.z_max_mm),
        (6.0, 37.5, 0.0, 10.0)
    );

    // p-type bulk that reaches the axis.
    let ppc = load("detectors/ppc-example.toml");
    assert!(ppc.impurity().density_cm3(10.0, 20.0) < 0.0);
    assert_eq!(ppc.classify(0.0, 20.0), Region::Semiconductor);
    assert_eq!(ppc.classify(6.0, 1.0), Region::Medium, "groove");
    assert!(matches!(ppc.classify(0.5, 0.2), Region::Contact(_)));
}
