//! The command line as a user runs it: help, JSON output, plots.

use std::process::Command;

fn hpge_cv(args: &[&str]) -> std::process::Output {
    Command::new(env!("CARGO_BIN_EXE_hpge-cv"))
        .current_dir(env!("CARGO_MANIFEST_DIR"))
        .args(args)
        .output()
        .unwrap()
}

#[test]
fn help_lists_the_subcommands() {
    let out = hpge_cv(&["--help"]);
    assert!(out.status.success());
    let text = String::from_utf8_lossy(&out.stdout);
    for sub in ["impurity", "detector"] {
        assert!(text.contains(sub), "{text}");
    }
}

/// Acceptance: the paper's p_zeta,E at the four corners, exactly one JSON object on stdout.
#[test]
fn impurity_json_paper_example() {
    let out = hpge_cv(&[
        "impurity",
        "--detector",
        "detectors/super-siegfried-k1.toml",
        "--impurity",
        "detectors/impurities/paper-example-rz.toml",
        "--at",
        "20,0",
        "--at",
        "37.5,0",
        "--at",
        "20,70",
        "--at",
        "37.5,70",
        "--json",
    ]);
    assert!(
        out.status.success(),
        "{}",
        String::from_utf8_lossy(&out.stderr)
    );
    let v: serde_json::Value = serde_json::from_slice(&out.stdout).expect("one JSON object");
    let pts = v["points"].as_array().unwrap();
    let want = [1.30e10, -0.44e10, 0.44e10, -1.30e10];
    assert_eq!(pts.len(), 4);
    for (p, w) in pts.iter().zip(want) {
        let z = p["zeta_cm3"].as_f64().unwrap();
        assert!(((z - w) / w).abs() < 1e-6, "{z} vs {w}");
        assert!(p["y"].as_f64().unwrap().abs() <= 1.0);
        assert!(p["x"].is_number());
        assert!(p["r_mm"].is_number() && p["z_mm"].is_number());
    }
    assert_eq!(v["version"], env!("CARGO_PKG_VERSION"));
}

#[test]
fn impurity_json_has_null_y_for_models_without_one() {
    let out = hpge_cv(&[
        "impurity",
        "--detector",
        "detectors/super-siegfried-k1.toml",
        "--at",
        "20,0",
        "--json",
    ]);
    assert!(out.status.success());
    let v: serde_json::Value = serde_json::from_slice(&out.stdout).unwrap();
    assert!(v["points"][0]["y"].is_null() && v["points"][0]["x"].is_null());
    assert_eq!(v["points"][0]["zeta_cm3"].as_f64().unwrap(), 1.30e10);
}

#[test]
fn detector_plots_and_summary() {
    let dir = std::path::PathBuf::from(env!("CARGO_TARGET_TMPDIR")).join("cli_plots");
    std::fs::create_dir_all(&dir).unwrap();
    let png = dir.join("ppc.png");
    let svg = dir.join("ppc.svg");
    let out = hpge_cv(&[
        "detector",
        "--detector",
        "detectors/ppc-example.toml",
        "--plot",
        png.to_str().unwrap(),
        "--plot",
        svg.to_str().unwrap(),
        "--json",
    ]);
    assert!(
        out.status.success(),
        "{}",
        String::from_utf8_lossy(&out.stderr)
    );
    let v: serde_json::Value = serde_json::from_slice(&out.stdout).unwrap();
    assert_eq!(v["name"], "ppc-example");
    assert_eq!(v["contacts"].as_array().unwrap().len(), 2);
    let bytes = std::fs::read(&png).unwrap();
    assert_eq!(&bytes[..4], b"\x89PNG");
    let text = std::fs::read_to_string(&svg).unwrap();
    assert!(text.starts_with("<svg") && text.contains("impurity density"));
}

/// `simulate` on the validation coax: one JSON object with the documented fields.
#[test]
fn simulate_coax_json_csv_and_plots() {
    let dir = std::path::PathBuf::from(env!("CARGO_TARGET_TMPDIR")).join("cli_simulate");
    std::fs::create_dir_all(&dir).unwrap();
    let csv = dir.join("cv.csv");
    let png = dir.join("cv.png");
    let field = dir.join("field.svg");
    let out = hpge_cv(&[
        "simulate",
        "--detector",
        "detectors/coax-analytic.toml",
        "--voltages",
        "3600,25,1025,25",
        "--json",
        "--out",
        csv.to_str().unwrap(),
        "--plot",
        png.to_str().unwrap(),
        "--field",
        "1025",
        "--field-plot",
        field.to_str().unwrap(),
    ]);
    assert!(
        out.status.success(),
        "{}",
        String::from_utf8_lossy(&out.stderr)
    );
    let v: serde_json::Value = serde_json::from_slice(&out.stdout).expect("one JSON object");
    let volts: Vec<f64> = v["voltage_V"]
        .as_array()
        .unwrap()
        .iter()
        .map(|x| x.as_f64().unwrap())
        .collect();
    assert_eq!(volts, vec![25.0, 1025.0, 3600.0], "sorted and deduplicated");
    let c: Vec<f64> = v["c12_pF"]
        .as_array()
        .unwrap()
        .iter()
        .map(|x| x.as_f64().unwrap())
        .collect();
    assert!(c[0] > c[1] && c[1] > c[2]);
    assert_eq!(v["fully_depleted"][2], true);
    assert_eq!(v["fully_depleted"][0], false);
    // Closed form of coax-analytic.toml: 3501.1 V (validation/tests/depletion_voltage.rs).
    let vd = v["depletion_voltage_V"].as_f64().unwrap();
    assert!((vd - 3501.1).abs() < 0.003 * 3501.1, "{vd}");
    // Issue 64: U_fd with its error bar, which bounds the closed form.
    let vd_err = v["depletion_voltage_err_V"].as_f64().unwrap();
    assert!(
        (vd - 3501.1).abs() <= vd_err && vd_err < 0.01 * vd,
        "{vd} +- {vd_err}"
    );
    assert!(v["pinch_off_voltage_V"].is_null() && v["pinch_off_voltage_err_V"].is_null());
    assert_eq!(v["method"], "fast");
    assert!(v["grid"]["nr"].as_u64().unwrap() > 10 && v["seconds"].as_f64().unwrap() > 0.0);
    // Issue 18: every c12 with its estimated error, within the default tolerance (0.2%).
    for (k, c) in c.iter().enumerate() {
        let e = v["c12_err_pF"][k].as_f64().unwrap();
        assert!(e >= 0.0 && e <= 0.002 * c, "{k}: {c} +- {e}");
        assert_eq!(v["tolerance_reached"][k], true);
    }
    assert_eq!(v["tolerance"], 0.002);
    let text = std::fs::read_to_string(&csv).unwrap();
    assert!(text.starts_with(
        "voltage_V,c12_pF,fully_depleted,c12_err_pF,tolerance_reached,depletion_voltage_V,depletion_voltage_err_V,pinch_off_voltage_V,pinch_off_voltage_err_V\n25,"
    ));
    // The curve's voltages repeat on every row; no pinch-off: empty cells.
    let row: Vec<&str> = text.lines().nth(1).unwrap().split(',').collect();
    assert_eq!(row.len(), 9, "{row:?}");
    assert_eq!(row[4], "true");
    assert_eq!(row[5].parse::<f64>().unwrap(), vd);
    assert_eq!((row[7], row[8]), ("", ""));
    assert_eq!(&std::fs::read(&png).unwrap()[..4], b"\x89PNG");
    assert!(std::fs::read_to_string(&field).unwrap().starts_with("<svg"));
}

/// Issue 64: a curve none of whose points reaches the tolerance still gives its values, each
/// flagged `tolerance_reached: false` with its estimate, and says so on stderr (exit 0, not 2).
#[test]
fn simulate_returns_values_flagged_where_no_bias_reaches_the_tolerance() {
    let out = hpge_cv(&[
        "simulate",
        "--detector",
        "detectors/coax-analytic.toml",
        "--voltages",
        "1025,2000",
        "--tolerance",
        "1e-6",
        "--grid",
        "max_adaptive_passes=2",
        "--json",
    ]);
    let stderr = String::from_utf8_lossy(&out.stderr);
    assert!(out.status.success(), "{stderr}");
    assert!(stderr.contains("no bias reached it"), "{stderr}");
    let v: serde_json::Value = serde_json::from_slice(&out.stdout).expect("one JSON object");
    for k in 0..2 {
        assert_eq!(v["tolerance_reached"][k], false);
        let (c, e) = (
            v["c12_pF"][k].as_f64().unwrap(),
            v["c12_err_pF"][k].as_f64().unwrap(),
        );
        assert!(c > 0.0 && e > 1e-6 * c, "{k}: {c} +- {e}");
    }
}

#[test]
fn capacitance_matrix_json() {
    let out = hpge_cv(&[
        "capacitance",
        "--detector",
        "detectors/coax-analytic.toml",
        "--voltage",
        "3600",
        "--json",
    ]);
    assert!(
        out.status.success(),
        "{}",
        String::from_utf8_lossy(&out.stderr)
    );
    let v: serde_json::Value = serde_json::from_slice(&out.stdout).unwrap();
    let m = v["maxwell_pF"].as_array().unwrap();
    let c12 = -m[0][1].as_f64().unwrap();
    assert!((c12 / v["c12_pF"].as_f64().unwrap() - 1.0).abs() < 1e-12);
    // Fully depleted coax, 10 mm: 2 pi eps0 16 / ln(37.5 / 6) * 10 mm.
    assert!((c12 - 4.857_19).abs() < 1e-4, "{c12}");
}

/// The sensitivity scan: one JSON object, flat (fully depleted) at low density, rising above; a bad
/// range is a clear error with exit code 2.
#[test]
fn sensitivity_scan_json_and_bad_range() {
    let out = hpge_cv(&[
        "sensitivity",
        "--detector",
        "detectors/coax-analytic.toml",
        "--voltage",
        "25",
        "--zeta-range",
        "1e6:1e11:3",
        "--json",
    ]);
    assert!(
        out.status.success(),
        "{}",
        String::from_utf8_lossy(&out.stderr)
    );
    let v: serde_json::Value = serde_json::from_slice(&out.stdout).expect("one JSON object");
    let c: Vec<f64> = v["c12_pF"]
        .as_array()
        .unwrap()
        .iter()
        .map(|x| x.as_f64().unwrap())
        .collect();
    assert_eq!(c.len(), 3);
    assert!(c[0] < c[1] && c[1] < c[2], "{c:?}");
    assert_eq!(v["fully_depleted"][0], true);
    assert_eq!(v["fully_depleted"][2], false);
    assert_eq!(v["backend"], "cpu");
    assert_eq!(v["method"], "fast");
    let bad = hpge_cv(&[
        "sensitivity",
        "--detector",
        "detectors/coax-analytic.toml",
        "--zeta-range",
        "1e9:1e8:4",
    ]);
    assert_eq!(bad.status.code(), Some(2));
    assert!(String::from_utf8_lossy(&bad.stderr).contains("0 < MIN < MAX"));
}

/// The paper's weighting mode is selectable and recorded in the JSON.
#[test]
fn simulate_paper_weighting_mode() {
    let out = hpge_cv(&[
        "simulate",
        "--detector",
        "detectors/coax-analytic.toml",
        "--voltages",
        "1025",
        "--weighting",
        "paper-epsilon",
        "--json",
    ]);
    assert!(
        out.status.success(),
        "{}",
        String::from_utf8_lossy(&out.stderr)
    );
    let v: serde_json::Value = serde_json::from_slice(&out.stdout).expect("one JSON object");
    assert_eq!(v["weighting"], "paper-epsilon");
    let c = v["c12_pF"][0].as_f64().unwrap();
    // Closed form 18.120 pF for the 10 mm coax; the paper mode with the front on
    // nodes is within 0.5% here (validation/tests/weighting_modes.rs).
    assert!((c / 18.12 - 1.0).abs() < 5e-3, "{c}");
}

/// `simulate` on the coax with an impurity model under which the crystal stays undepleted
/// between the contacts (1e16 cm^-3), with `extra` arguments; the output and the scratch folder.
fn simulate_shorted_coax(tag: &str, extra: &[&str]) -> (std::process::Output, std::path::PathBuf) {
    let dir = std::env::temp_dir().join(format!("hpge-cv-{tag}-{}", std::process::id()));
    std::fs::create_dir_all(&dir).unwrap();
    let model = dir.join("dense.toml");
    std::fs::write(&model, "model = \"constant\"\nzeta_cm3 = 1e16\n").unwrap();
    let mut args = vec![
        "simulate",
        "--detector",
        "detectors/coax-analytic.toml",
        "--impurity",
        model.to_str().unwrap(),
    ];
    args.extend_from_slice(extra);
    (hpge_cv(&args), dir)
}

/// An impurity model under which the crystal stays undepleted between the contacts at every
/// listed voltage: a clear error naming the bias and the contacts, exit code 2.
#[test]
fn simulate_undepleted_crystal_is_a_clear_error() {
    let (out, _) = simulate_shorted_coax("undepleted", &["--voltages", "25,75"]);
    assert_eq!(out.status.code(), Some(2));
    let err = String::from_utf8_lossy(&out.stderr);
    assert!(err.contains("undepleted region connects"), "{err}");
    assert!(!err.contains("panicked"), "{err}");
}

/// Issue 18: a bridge error still draws the failing state with `--field-plot`, marks where the
/// region joins the contacts, and says so.
#[test]
fn simulate_bridge_error_draws_the_field() {
    let png = std::env::temp_dir().join(format!("hpge-cv-bridge-{}.png", std::process::id()));
    let (out, _) = simulate_shorted_coax(
        "bridge-plot",
        &[
            "--voltages",
            "25",
            "--field",
            "25",
            "--field-plot",
            png.to_str().unwrap(),
        ],
    );
    assert_eq!(out.status.code(), Some(2));
    let err = String::from_utf8_lossy(&out.stderr);
    assert!(err.contains("undepleted region connects"), "{err}");
    assert!(err.contains("is drawn in"), "{err}");
    let bytes = std::fs::read(&png).expect("the field plot of the failing state");
    assert!(
        bytes.starts_with(b"\x89PNG") && bytes.len() > 10_000,
        "{} bytes",
        bytes.len()
    );
}

/// GPU issue: `--backend wgpu` gives the CPU's c12 and says in the JSON where it ran.
#[test]
fn simulate_on_wgpu_matches_cpu_json() {
    if !hpge_solver::gpu::gpu_test_gate() {
        return;
    }
    let run = |backend: &str| {
        let out = hpge_cv(&[
            "simulate",
            "--detector",
            "detectors/coax-analytic.toml",
            "--voltages",
            "25,1025",
            "--method",
            "sor",
            "--backend",
            backend,
            "--json",
        ]);
        assert!(
            out.status.success(),
            "{}",
            String::from_utf8_lossy(&out.stderr)
        );
        serde_json::from_slice::<serde_json::Value>(&out.stdout).unwrap()
    };
    let (cpu, gpu) = (run("cpu"), run("wgpu"));
    assert_eq!(cpu["backend"], "cpu");
    assert!(cpu["device"].is_null());
    assert_eq!(gpu["backend"], "wgpu");
    assert_eq!(gpu["method"], "sor");
    assert!(
        gpu["device"]["adapter"]
            .as_str()
            .is_some_and(|a| !a.is_empty())
    );
    assert!(["f32", "f64"].contains(&gpu["device"]["precision"].as_str().unwrap()));
    for k in 0..2 {
        let (a, b) = (
            cpu["c12_pF"][k].as_f64().unwrap(),
            gpu["c12_pF"][k].as_f64().unwrap(),
        );
        assert!((a / b - 1.0).abs() < 1e-4, "{a} vs {b}");
    }
}

/// No adapter (here: none matches WGPU_ADAPTER_NAME) is a clear error with exit code 2 that
/// says what was tried and how to get a software adapter; so is the fast method on wgpu.
#[test]
fn wgpu_without_adapter_is_a_clear_error() {
    let out = Command::new(env!("CARGO_BIN_EXE_hpge-cv"))
        .current_dir(env!("CARGO_MANIFEST_DIR"))
        .env("WGPU_ADAPTER_NAME", "no-such-adapter-anywhere")
        .args([
            "capacitance",
            "--detector",
            "detectors/coax-analytic.toml",
            "--voltage",
            "25",
            "--backend",
            "wgpu",
        ])
        .output()
        .unwrap();
    assert_eq!(out.status.code(), Some(2));
    let err = String::from_utf8_lossy(&out.stderr);
    for want in [
        "no GPU adapter",
        "adapters found",
        "mesa-vulkan-drivers",
        "--backend cpu",
    ] {
        assert!(err.contains(want), "{want} missing in: {err}");
    }
    let out = hpge_cv(&[
        "simulate",
        "--detector",
        "detectors/coax-analytic.toml",
        "--voltages",
        "25",
        "--backend",
        "wgpu",
        "--method",
        "fast",
    ]);
    assert_eq!(out.status.code(), Some(2));
    let err = String::from_utf8_lossy(&out.stderr);
    assert!(err.contains("wgpu backend runs the sor method"), "{err}");
}

fn temp_dir(name: &str) -> std::path::PathBuf {
    let d = std::env::temp_dir().join(format!("hpge-cv-cli-{name}-{}", std::process::id()));
    let _ = std::fs::remove_dir_all(&d);
    std::fs::create_dir_all(&d).unwrap();
    d
}

fn curve_rows(path: &std::path::Path) -> Vec<(f64, f64, f64)> {
    std::fs::read_to_string(path)
        .unwrap()
        .lines()
        .filter(|l| !l.starts_with('#'))
        .skip(1)
        .map(|l| {
            let v: Vec<f64> = l.split(',').map(|x| x.trim().parse().unwrap()).collect();
            (v[0], v[1], v[2])
        })
        .collect()
}

/// Measurement issue: the shipped raw data measure back to the shipped curve exactly (the
/// data set is reproducible), within 0.1% of its truth times the calibration factor drawn for
/// the run (`raw/truth.json`), with covariance, report and figures.
#[test]
fn measure_reproduces_the_shipped_curve() {
    let dir = temp_dir("shipped");
    let out = dir.join("cv.csv");
    let figs = dir.join("figs");
    let o = hpge_cv(&[
        "measure",
        "--raw",
        "data/super-siegfried-k1/raw",
        "--out",
        out.to_str().unwrap(),
        "--plot",
        figs.to_str().unwrap(),
        "--json",
    ]);
    assert!(o.status.success(), "{}", String::from_utf8_lossy(&o.stderr));
    let report: serde_json::Value = serde_json::from_slice(&o.stdout).unwrap();
    assert!(report["problems"].as_array().unwrap().is_empty());
    let ufd = report["depletion_voltage_V"].as_f64().unwrap();
    assert!((2400.0..2800.0).contains(&ufd), "{ufd}");
    let ours = curve_rows(&out);
    let shipped = curve_rows(std::path::Path::new("data/super-siegfried-k1/cv.csv"));
    assert_eq!(ours, shipped);
    let truth: Vec<(f64, f64)> = std::fs::read_to_string("data/super-siegfried-k1/truth-cv.csv")
        .unwrap()
        .lines()
        .skip(1)
        .map(|l| {
            let v: Vec<&str> = l.split(',').collect();
            (v[0].parse().unwrap(), v[1].parse().unwrap())
        })
        .collect();
    assert_eq!(truth.len(), 60);
    let drawn: serde_json::Value = serde_json::from_str(
        &std::fs::read_to_string("data/super-siegfried-k1/raw/truth.json").unwrap(),
    )
    .unwrap();
    let f = drawn["calibration"]["c12_factor"].as_f64().unwrap();
    for ((u, c, s), (ut, ct)) in ours.iter().zip(&truth) {
        assert_eq!(u, ut);
        assert!(
            (c / (f * ct) - 1.0).abs() < 1e-3,
            "{u} V: {c} vs {f} x {ct}"
        );
        assert!((s / c - 0.0596).abs() < 1e-3, "{u} V: sigma {s}");
    }
    assert!(dir.join("cv.covariance.csv").is_file());
    assert!(dir.join("cv.measure.json").is_file());
    for f in ["pulses", "spectra", "peak-fits", "cv", "slope"] {
        for ext in ["svg", "png"] {
            assert!(figs.join(format!("{f}.{ext}")).is_file(), "{f}.{ext}");
        }
    }
    let _ = std::fs::remove_dir_all(&dir);
}

/// synthesize -> measure round trip; a truncated pulse file is reported (named, exit 0) and the
/// other biases still give points; a missing raw directory is a clear error with exit code 2.
#[test]
fn synthesize_then_measure_with_a_broken_file() {
    let dir = temp_dir("synth");
    let truth = dir.join("truth.csv");
    std::fs::write(
        &truth,
        "voltage_V,c12_pF,fully_depleted\n100,300,false\n500,120,false\n900,60,false\n1300,50,true\n1700,50,true\n",
    )
    .unwrap();
    let raw = dir.join("raw");
    let o = hpge_cv(&[
        "synthesize",
        "--curve",
        truth.to_str().unwrap(),
        "--out",
        raw.to_str().unwrap(),
        "--pulses",
        "40",
        "--decimate",
        "40",
        "--seed",
        "3",
    ]);
    assert!(o.status.success(), "{}", String::from_utf8_lossy(&o.stderr));
    let broken = raw.join("U0500V.npy");
    let bytes = std::fs::read(&broken).unwrap();
    std::fs::write(&broken, &bytes[..bytes.len() / 2]).unwrap();
    let out = dir.join("cv.csv");
    let o = hpge_cv(&[
        "measure",
        "--raw",
        raw.to_str().unwrap(),
        "--out",
        out.to_str().unwrap(),
    ]);
    assert!(o.status.success(), "{}", String::from_utf8_lossy(&o.stderr));
    let err = String::from_utf8_lossy(&o.stderr);
    assert!(
        err.contains("U0500V.npy") && err.contains("truncated"),
        "{err}"
    );
    let rows = curve_rows(&out);
    assert_eq!(
        rows.iter().map(|r| r.0).collect::<Vec<_>>(),
        vec![100.0, 900.0, 1300.0, 1700.0]
    );
    for (u, c, _) in &rows {
        let want = match *u as i64 {
            100 => 300.0,
            900 => 60.0,
            _ => 50.0,
        };
        assert!((c / want - 1.0).abs() < 5e-3, "{u} V: {c}");
    }
    let o = hpge_cv(&[
        "measure",
        "--raw",
        dir.join("nowhere").to_str().unwrap(),
        "--out",
        out.to_str().unwrap(),
    ]);
    assert_eq!(o.status.code(), Some(2));
    assert!(String::from_utf8_lossy(&o.stderr).contains("nowhere"));
    let _ = std::fs::remove_dir_all(&dir);
}

/// Issue 18: `convergence` prints c12 against the resolution with the estimates and draws it;
/// `--tolerance` and `--grid` reach the solver (a tighter tolerance: a smaller estimate).
#[test]
fn convergence_and_tolerance_options() {
    let dir = std::path::PathBuf::from(env!("CARGO_TARGET_TMPDIR")).join("cli_convergence");
    std::fs::create_dir_all(&dir).unwrap();
    let png = dir.join("convergence.png");
    let out = hpge_cv(&[
        "convergence",
        "--detector",
        "detectors/coax-analytic.toml",
        "--voltage",
        "1025",
        "--levels",
        "3",
        "--json",
        "--plot",
        png.to_str().unwrap(),
    ]);
    assert!(
        out.status.success(),
        "{}",
        String::from_utf8_lossy(&out.stderr)
    );
    let v: serde_json::Value = serde_json::from_slice(&out.stdout).expect("one JSON object");
    let rows = v["rows"].as_array().unwrap();
    assert_eq!(rows.len(), 4);
    let nodes: Vec<u64> = rows[..3]
        .iter()
        .map(|r| r["nodes"].as_u64().unwrap())
        .collect();
    assert!(nodes[0] < nodes[1] && nodes[1] < nodes[2], "{nodes:?}");
    assert_eq!(rows[3]["adaptive"], true);
    assert_eq!(&std::fs::read(&png).unwrap()[..4], b"\x89PNG");
    let c12 = |extra: &[&str]| -> (f64, f64) {
        let mut args = vec![
            "capacitance",
            "--detector",
            "detectors/coax-analytic.toml",
            "--voltage",
            "25",
            "--json",
        ];
        args.extend_from_slice(extra);
        let out = hpge_cv(&args);
        assert!(
            out.status.success(),
            "{}",
            String::from_utf8_lossy(&out.stderr)
        );
        let v: serde_json::Value = serde_json::from_slice(&out.stdout).unwrap();
        (
            v["c12_pF"].as_f64().unwrap(),
            v["c12_err_pF"].as_f64().unwrap(),
        )
    };
    let (c_loose, e_loose) = c12(&["--tolerance", "0.02", "--grid", "front_spacing_mm=1.0"]);
    let (c_tight, e_tight) = c12(&["--tolerance", "0.0005"]);
    assert!(
        e_tight / c_tight <= 0.0005 && e_tight < e_loose,
        "{e_tight} vs {e_loose}"
    );
    assert!((c_loose / c_tight - 1.0).abs() <= 0.02);
}
