//! `pulse`, `field` and the paper's section 9 from the command line: the issue's JSON fields,
//! end charges, normalisation, figures and bad input (exit code 2 naming the flag).

mod common;

use common::{bad, ok, run, temp};

const DET: &str = "detectors/super-siegfried-k1.toml";

fn json(args: &[&str]) -> serde_json::Value {
    let out = run(args);
    serde_json::from_str(&ok(&out)).expect("exactly one JSON object on stdout")
}

fn last(v: &serde_json::Value) -> f64 {
    v.as_array().unwrap().last().unwrap().as_f64().unwrap()
}

#[test]
fn pulse_json_has_the_issue_fields_and_full_collection() {
    let v = json(&[
        "pulse",
        "--detector",
        DET,
        "--param",
        "d_li_mm=3",
        "--voltage",
        "3000",
        "--at",
        "37,30,35",
        "--json",
    ]);
    let t = v["t_ns"].as_array().unwrap();
    let contacts = v["contacts"].as_array().unwrap();
    assert_eq!(contacts.len(), 2);
    let tc = v["collection_time_ns"].as_f64().unwrap();
    assert!(tc > 10.0 && tc < 2000.0, "{tc}");
    assert!(t.last().unwrap().as_f64().unwrap() >= tc);
    for c in contacts {
        assert!(c["name"].is_string());
        assert_eq!(c["signal"].as_array().unwrap().len(), t.len());
    }
    // The electron ends on n+ (bias, +1), the hole on p+ (-1).
    assert!((last(&contacts[0]["signal"]) - 1.0).abs() < 1e-3, "{v}");
    assert!((last(&contacts[1]["signal"]) + 1.0).abs() < 1e-3, "{v}");
    assert_eq!(v["electron"]["stop"], "contact");
    assert_eq!(v["hole"]["contact"], "p+ (mantle)");
    assert_eq!(v["version"], env!("CARGO_PKG_VERSION"));
    assert_eq!(v["at"]["phi_deg"], 30.0);
}

#[test]
fn pulse_normalise_plot_and_csv() {
    let dir = temp("pulse");
    let (svg, png, csv) = (dir.join("p.svg"), dir.join("p.png"), dir.join("p.csv"));
    // The manufacturer's d_Li = 1 mm leaves undepleted volume by the borehole at 3000 V: the
    // electron stops there and counts as collected on n+.
    let v = json(&[
        "pulse",
        "--detector",
        DET,
        "--voltage",
        "3000",
        "--at",
        "37,30,35",
        "--normalise",
        "--json",
        "--plot",
        svg.to_str().unwrap(),
        "--out",
        csv.to_str().unwrap(),
    ]);
    assert!((last(&v["contacts"][0]["signal"]) - 1.0).abs() < 1e-12);
    assert_eq!(v["normalised"], true);
    assert!(v["electron"]["collected"].as_bool().unwrap());
    assert!(std::fs::read_to_string(&svg).unwrap().contains("<svg"));
    let text = std::fs::read_to_string(&csv).unwrap();
    let mut lines = text.lines();
    // A plain table (issue 22): the header first, the provenance in the sidecar p.json.
    assert_eq!(lines.next().unwrap(), "t_ns,q1,q2");
    let side = std::fs::read_to_string(csv.with_extension("json")).unwrap();
    assert!(
        side.contains(DET) && side.contains(env!("CARGO_PKG_VERSION")),
        "{side}"
    );
    assert_eq!(
        lines.count(),
        v["t_ns"].as_array().unwrap().len(),
        "one row per sample"
    );
    // Text summary and a PNG.
    let out = run(&[
        "pulse",
        "--detector",
        DET,
        "--voltage",
        "3000",
        "--at",
        "30,0,40",
        "--plot",
        png.to_str().unwrap(),
    ]);
    let text = ok(&out);
    assert!(
        text.contains("collection time") && text.contains("end charges"),
        "{text}"
    );
    assert!(std::fs::metadata(&png).unwrap().len() > 1000);
}

#[test]
fn pulse_bad_input_exits_2_naming_the_flag() {
    let p = |extra: &[&str]| {
        let mut a = vec!["pulse", "--detector", DET];
        a.extend_from_slice(extra);
        run(&a)
    };
    bad(
        &p(&["--voltage", "3000", "--at", "40,0,35"]),
        &["--at", "outside the crystal"],
    );
    bad(
        &p(&["--voltage", "3000", "--at", "6,0,35"]),
        &["--at", "inside the contact"],
    );
    bad(
        &p(&["--voltage", "3000", "--at", "7,0,10"]),
        &["--at", "undepleted"],
    );
    bad(
        &p(&["--voltage", "3000", "--at", "37,30"]),
        &["--at", "R,PHI,Z"],
    );
    bad(
        &p(&["--voltage", "3000", "--at", "37,x,35"]),
        &["--at", "PHI"],
    );
    bad(
        &p(&["--voltage", "-5", "--at", "30,0,35"]),
        &["--voltage", "positive"],
    );
    bad(
        &p(&["--voltage", "0", "--at", "30,0,35"]),
        &["--voltage", "positive"],
    );
    bad(
        &p(&[
            "--voltage",
            "3000",
            "--at",
            "30,0,35",
            "--drift-parameters",
            "no-such.toml",
        ]),
        &["--drift-parameters", "no-such.toml"],
    );
    bad(
        &p(&["--voltage", "3000", "--at", "30,0,35", "--plot", "p.pdf"]),
        &["--plot", "unknown file type"],
    );
    let dir = temp("pulse-bad");
    let adl = dir.join("adl.toml");
    std::fs::write(
        &adl,
        "[e100]\nmu0_cm2_per_vs = -1\nbeta = 1\ne0_v_per_cm = 500\n",
    )
    .unwrap();
    bad(
        &p(&[
            "--voltage",
            "3000",
            "--at",
            "30,0,35",
            "--drift-parameters",
            adl.to_str().unwrap(),
        ]),
        &["--drift-parameters", "e100.mu0_cm2_per_vs"],
    );
    bad(
        &run(&[
            "pulse",
            "--detector",
            "no-such.toml",
            "--voltage",
            "3000",
            "--at",
            "30,0,35",
        ]),
        &["no-such.toml"],
    );
}

#[test]
fn field_along_r_with_nulls_outside() {
    let v = json(&[
        "field",
        "--detector",
        DET,
        "--voltage",
        "3000",
        "--phi",
        "30",
        "--z",
        "35",
        "--r-range",
        "0:37.5:6",
        "--json",
    ]);
    let e = v["e_V_per_cm"].as_array().unwrap();
    assert_eq!(e.len(), 6);
    // r = 0 is in the borehole, r = 37.5 on the p+ surface; in between the field is depleted.
    assert!(e[0].is_null() && e[5].is_null());
    assert_eq!(v["status"][0], "outside");
    for x in &e[1..5] {
        let x = x.as_f64().unwrap();
        assert!(x > 10.0 && x < 1e5, "{x} V/cm");
    }
    // The field grows towards the p+ junction for the manufacturer's model.
    assert!(e[4].as_f64().unwrap() > e[1].as_f64().unwrap());
    let dir = temp("field");
    let png = dir.join("e.png");
    ok(&run(&[
        "field",
        "--detector",
        DET,
        "--voltage",
        "3000",
        "--phi",
        "30",
        "--z",
        "35",
        "--plot",
        png.to_str().unwrap(),
    ]));
    assert!(std::fs::metadata(&png).unwrap().len() > 1000);
    let f = |extra: &[&str]| {
        let mut a = vec![
            "field",
            "--detector",
            DET,
            "--voltage",
            "3000",
            "--phi",
            "30",
        ];
        a.extend_from_slice(extra);
        run(&a)
    };
    bad(&f(&["--z", "100"]), &["--z", "crystal spans"]);
    bad(
        &f(&["--z", "35", "--r-range", "5:1:10"]),
        &["--r-range", "LO < HI"],
    );
}

/// The paper's section 9 (hidden command until `report paper` calls it): files, provenance and
/// the numbers' sanity.
#[test]
fn paper_section9_outputs() {
    let dir = temp("section9");
    ok(&run(&["paper-section9", "--out", dir.to_str().unwrap()]));
    for f in [
        "field-r.svg",
        "field-r.png",
        "pulses-nplus.svg",
        "pulses-nplus.png",
        "field-r.csv",
        "pulses-nplus.csv",
        "section9.csv",
    ] {
        assert!(dir.join(f).is_file(), "{f}");
        // Plain tables (issue 22): the header first, no comment line, rows of equal length.
        if f.ends_with(".csv") {
            let text = std::fs::read_to_string(dir.join(f)).unwrap();
            let n: Vec<usize> = text.lines().map(|l| l.split(',').count()).collect();
            assert!(
                !text.starts_with('#') && n.iter().all(|&k| k == n[0]),
                "{f}"
            );
        }
    }
    let v: serde_json::Value =
        serde_json::from_str(&std::fs::read_to_string(dir.join("section9.json")).unwrap()).unwrap();
    assert_eq!(v["version"], env!("CARGO_PKG_VERSION"));
    let models = v["models"].as_array().unwrap();
    let keys: Vec<&str> = models.iter().map(|m| m["key"].as_str().unwrap()).collect();
    assert_eq!(keys, ["manufacturer", "b-z", "b-rz"]);
    assert_eq!(models[0]["d_li_mm"], 3.0);
    for m in models {
        let tc = m["collection_time_ns"].as_f64().unwrap();
        let rise = m["nplus_rise_time_10_90_ns"].as_f64().unwrap();
        assert!(tc > 50.0 && tc < 2000.0 && rise > 0.0 && rise < tc, "{m}");
        assert!(m["electron"]["collected"].as_bool().unwrap(), "{m}");
        for e in m["e_at_radii"].as_array().unwrap() {
            assert!(e["e_V_per_cm"].as_f64().unwrap() > 0.0, "{m}");
        }
    }
}
