//! Issue 22, item 4: every CSV the commands write is a plain table (no comment line, one header
//! row, the same number of fields on every row) that pandas and numpy load without options; the
//! provenance is in the JSON sidecar. Readers still accept the files written before, with their
//! leading `#` lines. Small sizes: a few voltages, few pulses, short radius lists.

mod common;

use std::path::Path;

use common::{ok, run, temp};

const SS: &str = "detectors/super-siegfried-k1.toml";
const COAX: &str = "detectors/coax-analytic.toml";

/// Checks `csv` is a plain table: no comment line, a header whose names are `columns` (when
/// given), at least `min_rows` rows, every row with the header's field count; returns the rows.
fn plain_table(csv: &Path, columns: Option<&[&str]>, min_rows: usize) -> Vec<Vec<String>> {
    let text = std::fs::read_to_string(csv).unwrap();
    assert!(text.ends_with('\n'), "{}", csv.display());
    let mut lines = text.lines();
    let header: Vec<&str> = lines.next().unwrap().split(',').collect();
    if let Some(c) = columns {
        assert_eq!(header, c, "{}", csv.display());
    }
    let rows: Vec<Vec<String>> = lines
        .map(|l| l.split(',').map(str::to_string).collect())
        .collect();
    assert!(
        !text
            .lines()
            .any(|l| l.trim_start().starts_with('#') || l.contains('#')),
        "{}: a comment",
        csv.display()
    );
    assert!(
        rows.len() >= min_rows,
        "{}: {} rows",
        csv.display(),
        rows.len()
    );
    for (k, r) in rows.iter().enumerate() {
        assert_eq!(r.len(), header.len(), "{} row {}", csv.display(), k + 2);
    }
    rows
}

fn sidecar(path: &Path) -> serde_json::Value {
    serde_json::from_str(&std::fs::read_to_string(path).unwrap()).unwrap()
}

#[test]
fn simulate_sensitivity_field_and_pulse_write_plain_tables() {
    let d = temp("csv-tables");
    let s = |p: &Path| p.to_str().unwrap().to_string();
    let cv = d.join("cv.csv");
    ok(&run(&[
        "simulate",
        "--detector",
        COAX,
        "--voltages",
        "500,1500",
        "--out",
        &s(&cv),
    ]));
    plain_table(
        &cv,
        // Issue 64 added the flags and the depletion voltages with their error bars after the
        // first four columns (unchanged).
        Some(&[
            "voltage_V",
            "c12_pF",
            "fully_depleted",
            "c12_err_pF",
            "tolerance_reached",
            "depletion_voltage_V",
            "depletion_voltage_err_V",
            "pinch_off_voltage_V",
            "pinch_off_voltage_err_V",
        ]),
        2,
    );
    let scan = d.join("scan.csv");
    ok(&run(&[
        "sensitivity",
        "--detector",
        COAX,
        "--voltage",
        "500",
        "--zeta-range",
        "1e9:1e10:2",
        "--out",
        &s(&scan),
    ]));
    plain_table(&scan, Some(&["zeta_cm3", "c12_pF", "fully_depleted"]), 2);

    let e = d.join("e.csv");
    ok(&run(&[
        "field",
        "--detector",
        SS,
        "--voltage",
        "3000",
        "--phi",
        "30",
        "--z",
        "35",
        "--r-range",
        "5:38:12",
        "--out",
        &s(&e),
    ]));
    let rows = plain_table(&e, Some(&["r_mm", "e_V_per_cm", "status"]), 12);
    assert_eq!(rows.len(), 12);
    let v = sidecar(&d.join("e.json"));
    assert_eq!(v["version"], env!("CARGO_PKG_VERSION"));
    assert_eq!(v["detector"], SS);
    assert_eq!(v["voltage_V"], 3000.0);
    assert_eq!(v["phi_deg"], 30.0);
    assert_eq!(v["csv"], "e.csv");
    // What made it, as every results file records it (hpge_foundation::sidecar).
    assert!(v["made"]["solver_revision"].is_string(), "{v}");
    assert!(
        v["command"]
            .as_array()
            .unwrap()
            .iter()
            .any(|a| a == "field")
    );

    let p = d.join("p.csv");
    ok(&run(&[
        "pulse",
        "--detector",
        SS,
        "--param",
        "d_li_mm=3",
        "--voltage",
        "3000",
        "--at",
        "37,30,35",
        "--normalise",
        "--out",
        &s(&p),
    ]));
    plain_table(&p, Some(&["t_ns", "q1", "q2"]), 10);
    let v = sidecar(&d.join("p.json"));
    assert_eq!(v["version"], env!("CARGO_PKG_VERSION"));
    assert_eq!(v["normalised"], true);
    assert_eq!(v["made"]["program"], "hpge-cv");
    assert_eq!(v["at"]["z_mm"], 35.0);
    assert_eq!(v["parameters"]["d_li_mm"], 3.0);
    assert!(v["columns"]["q1"].is_string(), "{v}");
    let _ = std::fs::remove_dir_all(&d);
}

/// synthesize reads a truth curve written the old way (leading `#` lines); measure writes cv.csv
/// and cv.covariance.csv as plain tables, the provenance in cv.measure.json.
#[test]
fn synthesize_reads_old_curves_and_measure_writes_plain_tables() {
    let d = temp("csv-measure");
    let truth = d.join("truth.csv");
    std::fs::write(
        &truth,
        "# hpge-cv 0.1.0 simulate --detector x.toml\n# settings: old provenance\n\
         voltage_V,c12_pF,fully_depleted\n100,300,false\n900,60,false\n1300,50,true\n1700,50,true\n",
    )
    .unwrap();
    let raw = d.join("raw");
    ok(&run(&[
        "synthesize",
        "--curve",
        truth.to_str().unwrap(),
        "--out",
        raw.to_str().unwrap(),
        "--pulses",
        "20",
        "--decimate",
        "40",
        "--seed",
        "1",
    ]));
    let cv = d.join("cv.csv");
    ok(&run(&[
        "measure",
        "--raw",
        raw.to_str().unwrap(),
        "--out",
        cv.to_str().unwrap(),
    ]));
    let rows = plain_table(&cv, Some(&["voltage_V", "c12_pF", "sigma_pF"]), 4);
    assert_eq!(rows.len(), 4);
    let cov = plain_table(
        &d.join("cv.covariance.csv"),
        Some(&["voltage_V", "100", "900", "1300", "1700"]),
        3,
    );
    assert_eq!(cov.len(), 4);
    let v = sidecar(&d.join("cv.measure.json"));
    assert_eq!(v["version"], env!("CARGO_PKG_VERSION"));
    assert_eq!(v["program"], "hpge-cv");
    assert!(v["uncertainties"].is_object(), "{v}");
    assert_eq!(v["covariance_file"], "cv.covariance.csv");
    assert!(
        v["command"]
            .as_array()
            .unwrap()
            .iter()
            .any(|a| a == "measure")
    );
    let _ = std::fs::remove_dir_all(&d);
}

/// A curve in the format written before issue 22 (leading `#` provenance lines, as the shipped
/// curve had until it was regenerated with a drawn calibration) still reads: the library reader
/// skips them. The shipped curve is now a plain table.
#[test]
fn an_old_format_curve_still_reads() {
    let path = Path::new(env!("CARGO_MANIFEST_DIR")).join("data/super-siegfried-k1/cv.csv");
    let text = std::fs::read_to_string(&path).unwrap();
    assert!(
        text.starts_with("voltage_V,"),
        "the shipped curve is a plain table"
    );
    let d = temp("old-format");
    let old = d.join("cv.csv");
    std::fs::write(
        &old,
        format!("# hpge-cv 0.1.0 measure --raw raw\n# settings: raw/measurement.toml\n{text}"),
    )
    .unwrap();
    let c = hpge_measurement::read_curve(&old, None).unwrap();
    assert_eq!(c.voltage_v.len(), 60);
    let shipped = hpge_measurement::read_curve(&path, None).unwrap();
    assert_eq!(c.c12_pf, shipped.c12_pf);
    let _ = std::fs::remove_dir_all(&d);
}
