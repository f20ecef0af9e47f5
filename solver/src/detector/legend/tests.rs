use super::*;

fn icpc() -> Value {
    serde_json::json!({
        "name": "T1", "type": "icpc",
        "geometry": {
            "height_in_mm": 80, "radius_in_mm": 40,
            "borehole": {"radius_in_mm": 5, "depth_in_mm": 50},
            "groove": {"depth_in_mm": 2, "radius_in_mm": {"outer": 13, "inner": 10}},
            "pp_contact": {"radius_in_mm": 3, "depth_in_mm": 0},
            "taper": {"top": {"angle_in_deg": 45, "height_in_mm": 2},
                      "bottom": {"angle_in_deg": 0, "height_in_mm": 0},
                      "borehole": {"angle_in_deg": 0, "height_in_mm": 0}}
        },
        "production": {"impcc": {"function_pars": {"z0": 1.0, "gradient": 0.01}}}
    })
}

#[test]
fn icpc_outline_and_toml_load() {
    let o = LegendOptions::default();
    let d = diode(&icpc(), Path::new("T1.json"), &o).unwrap();
    assert_eq!(d.outline_mm[0], [0.0, 0.0]);
    assert!(d.outline_mm.contains(&[38.0, 80.0]));
    assert!(d.outline_mm.contains(&[5.0, 30.0]));
    assert_eq!(d.outline_mm.len(), d.surfaces.len() + 1);
    let text = to_toml(&d, Path::new("T1.json"), &o);
    let det =
        crate::Detector::from_toml_str(&text, Path::new("T1.toml"), &crate::Parameters::new())
            .unwrap();
    // The linear profile: -1e9 at the contact, -(1 + 0.8) e9 at the top.
    let m = det.semiconductor.impurity();
    assert!((m.density_cm3(20.0, 0.0) + 1.0e9).abs() < 1.0);
    assert!((m.density_cm3(20.0, 80.0) + 1.8e9).abs() < 1.0);
}

/// The density (cm^-3) of a record with `impcc` at r = 20 mm, z = `z_mm`, and the source line.
fn density_of(impcc: Value, z_mm: &[f64]) -> (Vec<f64>, String) {
    let o = LegendOptions::default();
    let mut v = icpc();
    v["production"]["impcc"] = impcc;
    let d = diode(&v, Path::new("T1.json"), &o).unwrap();
    let text = to_toml(&d, Path::new("T1.json"), &o);
    let det =
        crate::Detector::from_toml_str(&text, Path::new("T1.toml"), &crate::Parameters::new())
            .unwrap();
    let m = det.semiconductor.impurity();
    (
        z_mm.iter().map(|&z| m.density_cm3(20.0, z)).collect(),
        d.impurity_toml.1,
    )
}

#[test]
fn legend_impcc_keys_carry_their_units() {
    // legend-testdata's layout: `array` in 1e9 cm^-3 (taken first), `function_pars` in
    // 1e10 cm^-3 with the distance in cm.
    let (n, src) = density_of(
        serde_json::json!({
            "array": {"dist_from_contact_in_mm": [0.0, 80.0], "value_in_1e9e/cm3": [11.0, 8.0]},
            "function_pars": {"z0_in_1e10e/cm3": 5.0, "gradient_in_1e10e/cm4": 0.0}
        }),
        &[0.0, 40.0, 80.0],
    );
    assert_eq!(src, "production.impcc.array tables");
    for (got, want) in n.iter().zip([-11.0e9, -9.5e9, -8.0e9]) {
        assert!((got - want).abs() < 1.0, "{got} {want}");
    }
    let (n, src) = density_of(
        serde_json::json!({
            "function_pars": {"z0_in_1e10e/cm3": 1.2, "gradient_in_1e10e/cm4": -0.1,
                              "quadratic_in_1e10e/cm5": 0.01}
        }),
        &[0.0, 40.0, 80.0],
    );
    assert!(src.starts_with("production.impcc.function_pars"), "{src}");
    // 1.2 - 0.1 d + 0.01 d^2 (1e10 cm^-3, d in cm): 1.2, 0.96, 1.04 at 0, 4, 8 cm.
    for (got, want) in n.iter().zip([-1.2e10, -0.96e10, -1.04e10]) {
        assert!((got - want).abs() < 1e-3 * want.abs(), "{got} {want}");
    }
}

#[test]
fn zero_profiles_are_placeholders() {
    // V99000A in legend-testdata: zeros everywhere, distances [0, 0].
    let (n, src) = density_of(
        serde_json::json!({
            "array": {"value_in_1e9e/cm3": [0.0, 0.0], "dist_from_contact_in_mm": [0.0, 0.0]},
            "function_pars": {"z0_in_1e10e/cm3": 0, "gradient_in_1e10e/cm4": 0,
                              "quadratic_in_1e10e/cm5": 0}
        }),
        &[0.0, 80.0],
    );
    assert_eq!(n, vec![-1.0e10, -1.0e10]);
    assert!(
        src.contains("placeholder")
            && src.contains("production.impcc.array and production.impcc.function_pars"),
        "{src}"
    );
    let o = LegendOptions::default();
    let mut v = icpc();
    v["production"]["impcc"] = serde_json::json!({"comment": "nothing"});
    let e = diode(&v, Path::new("D.json"), &o).unwrap_err().to_string();
    assert!(e.contains("production.impcc") && e.contains("array"), "{e}");
}

#[test]
fn bad_records_name_the_key() {
    let o = LegendOptions::default();
    let f = Path::new("D.json");
    let mut v = icpc();
    v["geometry"]["radius_in_mm"] = serde_json::json!(-3);
    let e = diode(&v, f, &o).unwrap_err().to_string();
    assert!(
        e.contains("geometry.radius_in_mm") && e.contains("-3"),
        "{e}"
    );
    let mut v = icpc();
    v["geometry"]["borehole"]
        .as_object_mut()
        .unwrap()
        .remove("depth_in_mm");
    let e = diode(&v, f, &o).unwrap_err().to_string();
    assert!(
        e.contains("geometry.borehole.depth_in_mm") && e.contains("missing"),
        "{e}"
    );
    let mut v = icpc();
    v["type"] = serde_json::json!("semi-planar");
    let e = diode(&v, f, &o).unwrap_err().to_string();
    assert!(e.contains("`type`") && e.contains("semi-planar"), "{e}");
    let mut v = icpc();
    v["geometry"]["borehole"]["depth_in_mm"] = serde_json::json!(90);
    let e = diode(&v, f, &o).unwrap_err().to_string();
    assert!(e.contains("do not fit together"), "{e}");
    let e = read_json("{", f, &o).unwrap_err().to_string();
    assert!(e.contains("D.json") && e.contains("JSON"), "{e}");
}

#[test]
fn a_zero_depletion_voltage_is_a_placeholder() {
    // legend-testdata's P99000A: `l200_site` 0 V (placeholder), `manufacturer` 3000 V. The
    // site's measurement comes first when it is a value.
    let o = LegendOptions::default();
    let mut v = icpc();
    v["characterization"] = serde_json::json!({
        "l200_site": {"depletion_voltage_in_V": 0},
        "manufacturer": {"depletion_voltage_in_V": 3000.0},
    });
    let d = diode(&v, Path::new("D.json"), &o).unwrap();
    assert_eq!(d.depletion_voltage_v, Some(3000.0));
    v["characterization"]["l200_site"]["depletion_voltage_in_V"] = serde_json::json!(3500);
    let d = diode(&v, Path::new("D.json"), &o).unwrap();
    assert_eq!(d.depletion_voltage_v, Some(3500.0));
    v["characterization"] = serde_json::json!({"l200_site": {"depletion_voltage_in_V": 0}});
    let d = diode(&v, Path::new("D.json"), &o).unwrap();
    assert_eq!(d.depletion_voltage_v, None);
}
