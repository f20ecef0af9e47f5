//! Bad input on the command line gets one clear message naming the file, the key and the problem,
//! and exit code 2; never a panic or a backtrace (issue: foundation, item 5). A bad detector and a
//! bad impurity file stand here for every kind of bad file (each `error:` of the libraries exits
//! with 2); the solver's message for each kind, one test per case, is `solver/tests/bad_files.rs`.

use std::path::PathBuf;
use std::process::Command;

const DETECTOR: &str = r#"
name = "test-coax"

[parameters]
inner_mm = 6.0

[world]
r_max_mm = 40.0
z_min_mm = 0.0
z_max_mm = 10.0

[world.boundary]
r_max = "grounded"
z_min = "reflecting"
z_max = "reflecting"

[semiconductor]
rz_knots_mm = [6.0, 16.0, 27.0, 37.5]
geometry = { tube = { r_mm = ["inner_mm", 37.5], z_mm = [0.0, 10.0] } }

[semiconductor.impurity]
model = "constant"
zeta_cm3 = 1.0e10

[[contacts]]
id = 1
name = "n+"
potential = "bias"
geometry = { cylinder_surface = { r_mm = "inner_mm", z_mm = [0.0, 10.0] } }

[[contacts]]
id = 2
name = "p+"
potential = 0.0
geometry = { cylinder_surface = { r_mm = 37.5, z_mm = [0.0, 10.0] } }
"#;

const RZ: &str = r#"
model = "rz"
knots_mm = [20.0, 28.0, 33.0, 37.5]
y_bot = [0.70, 0.66, 0.60, 0.40]
y_top = [0.60, 0.55, 0.50, 0.30]
"#;

fn write(name: &str, text: &str) -> PathBuf {
    let dir = PathBuf::from(env!("CARGO_TARGET_TMPDIR")).join("bad_input");
    std::fs::create_dir_all(&dir).unwrap();
    let path = dir.join(name);
    std::fs::write(&path, text).unwrap();
    path
}

/// Runs hpge-cv, asserts exit code 2 and no panic, returns stderr.
fn fails(args: &[&str]) -> String {
    let out = Command::new(env!("CARGO_BIN_EXE_hpge-cv"))
        .args(args)
        .env("RUST_BACKTRACE", "1")
        .output()
        .unwrap();
    let stderr = String::from_utf8_lossy(&out.stderr).to_string();
    assert_eq!(
        out.status.code(),
        Some(2),
        "args {args:?}\nstderr: {stderr}"
    );
    assert!(!stderr.contains("panicked"), "panic: {stderr}");
    assert!(!stderr.contains("stack backtrace"), "backtrace: {stderr}");
    assert!(
        stderr.starts_with("error:"),
        "message should start with `error:`: {stderr}"
    );
    assert!(out.stdout.is_empty(), "nothing on stdout on error");
    stderr
}

/// Checks a detector text that must be rejected; every needle must appear in the message.
fn bad_detector(name: &str, text: &str, needles: &[&str]) {
    let path = write(name, text);
    let p = path.to_str().unwrap();
    for cmd in [
        vec!["detector", "--detector", p],
        vec!["impurity", "--detector", p, "--at", "20,5"],
    ] {
        let msg = fails(&cmd);
        assert!(
            msg.contains(name),
            "message must name the file {name}: {msg}"
        );
        for n in needles {
            assert!(msg.contains(n), "message must contain `{n}`: {msg}");
        }
    }
}

/// Checks an impurity file that must be rejected.
fn bad_impurity(name: &str, text: &str, needles: &[&str]) {
    // Tests run in parallel: every test writes its own files.
    let det = write(&format!("detector-for-{name}"), DETECTOR);
    let path = write(name, text);
    let msg = fails(&[
        "impurity",
        "--detector",
        det.to_str().unwrap(),
        "--impurity",
        path.to_str().unwrap(),
        "--at",
        "20,5",
        "--json",
    ]);
    assert!(
        msg.contains(name),
        "message must name the file {name}: {msg}"
    );
    for n in needles {
        assert!(msg.contains(n), "message must contain `{n}`: {msg}");
    }
}

#[test]
fn the_base_files_are_good() {
    let det = write("base-detector.toml", DETECTOR);
    let imp = write("base-rz.toml", RZ);
    let out = Command::new(env!("CARGO_BIN_EXE_hpge-cv"))
        .args([
            "impurity",
            "--detector",
            det.to_str().unwrap(),
            "--impurity",
        ])
        .arg(&imp)
        .args(["--at", "20,5", "--json"])
        .output()
        .unwrap();
    assert!(
        out.status.success(),
        "{}",
        String::from_utf8_lossy(&out.stderr)
    );
}

#[test]
fn syntax_error() {
    let text = DETECTOR.replace("[world.boundary]", "[world.boundary");
    bad_detector("syntax.toml", &text, &["TOML parse error", "line"]);
}

#[test]
fn nan_in_impurity() {
    bad_impurity(
        "nan-imp.toml",
        &RZ.replace("0.66, 0.60, 0.40]", "nan, 0.60, 0.40]"),
        &["y_bot[1]"],
    );
}

#[test]
fn unreadable_files() {
    let msg = fails(&["detector", "--detector", "no/such/detector.toml"]);
    assert!(
        msg.contains("no/such/detector.toml") && msg.contains("cannot read"),
        "{msg}"
    );
    let det = write("detector-for-unreadable.toml", DETECTOR);
    let msg = fails(&[
        "impurity",
        "--detector",
        det.to_str().unwrap(),
        "--impurity",
        "no/such/impurity.toml",
        "--at",
        "1,1",
    ]);
    assert!(msg.contains("no/such/impurity.toml"), "{msg}");
}

#[test]
fn bad_arguments() {
    let det = write("detector-for-arguments.toml", DETECTOR);
    let d = det.to_str().unwrap();
    let msg = fails(&["impurity", "--detector", d, "--at", "20"]);
    assert!(msg.contains("--at") && msg.contains("R,Z"), "{msg}");
    let msg = fails(&["impurity", "--detector", d, "--at", "-3,1"]);
    assert!(msg.contains("R must be >= 0"), "{msg}");
    let msg = fails(&[
        "impurity",
        "--detector",
        d,
        "--at",
        "20,5",
        "--param",
        "d_li_mm=2",
    ]);
    assert!(msg.contains("declares no parameter `d_li_mm`"), "{msg}");
    let msg = fails(&["detector", "--detector", d, "--param", "inner_mm=40"]);
    assert!(msg.contains("semiconductor.geometry.tube.r_mm"), "{msg}");
    let msg = fails(&["detector", "--detector", d, "--plot", "x.jpg"]);
    assert!(
        msg.contains("x.jpg") && msg.contains(".svg or .png"),
        "{msg}"
    );
    let msg = fails(&["detector", "--detector", d, "--plot", "no/such/dir/x.png"]);
    assert!(msg.contains("no/such/dir/x.png"), "{msg}");
}

#[test]
fn simulate_bad_voltages_and_options() {
    let det = write("detector-for-simulate.toml", DETECTOR);
    let d = det.to_str().unwrap();
    let msg = fails(&["simulate", "--detector", d, "--voltages", "0,25"]);
    assert!(
        msg.contains("--voltages") && msg.contains("positive"),
        "{msg}"
    );
    let msg = fails(&["simulate", "--detector", d, "--voltages", "-25"]);
    assert!(msg.contains("positive"), "{msg}");
    let msg = fails(&["simulate", "--detector", d, "--voltages", "25:10:5"]);
    assert!(msg.contains("STOP"), "{msg}");
    let msg = fails(&["simulate", "--detector", d]);
    assert!(msg.contains("--voltages"), "{msg}");
    let msg = fails(&[
        "simulate",
        "--detector",
        d,
        "--voltages",
        "25",
        "--field-plot",
        "f.png",
    ]);
    assert!(msg.contains("--field"), "{msg}");
    let msg = fails(&[
        "simulate",
        "--detector",
        d,
        "--voltages",
        "25",
        "--d-li",
        "1",
    ]);
    assert!(msg.contains("d_li_mm"), "{msg}");
    let msg = fails(&["capacitance", "--detector", d, "--voltage", "nan"]);
    assert!(msg.contains("--voltage"), "{msg}");
    let nobias = DETECTOR.replace("potential = \"bias\"", "potential = 5.0");
    let nb = write("detector-no-bias.toml", &nobias);
    let msg = fails(&[
        "simulate",
        "--detector",
        nb.to_str().unwrap(),
        "--voltages",
        "25",
    ]);
    assert!(msg.contains("bias"), "{msg}");
}

/// Issue 18: grid and accuracy options. A tolerance <= 0, NaN or below what any grid can reach,
/// unknown or ill-typed `--grid` keys: errors naming the option or key, exit 2 (a bad key in a
/// detector's `[grid]` table: `solver/tests/bad_files.rs`).
#[test]
fn bad_grid_and_tolerance() {
    let det = write("detector-for-grid.toml", DETECTOR);
    let d = det.to_str().unwrap();
    for t in ["0", "-0.01", "nan", "1e-9", "1"] {
        let msg = fails(&[
            "simulate",
            "--detector",
            d,
            "--voltages",
            "25",
            "--tolerance",
            t,
        ]);
        assert!(
            msg.contains("--tolerance") && msg.contains("tolerance"),
            "{t}: {msg}"
        );
    }
    let msg = fails(&[
        "simulate",
        "--detector",
        d,
        "--voltages",
        "25",
        "--grid",
        "front_spacing=0.1",
    ]);
    assert!(msg.contains("unknown grid key `front_spacing`"), "{msg}");
    let msg = fails(&[
        "capacitance",
        "--detector",
        d,
        "--voltage",
        "25",
        "--grid",
        "adaptive=perhaps",
    ]);
    assert!(msg.contains("`adaptive`"), "{msg}");
    let msg = fails(&[
        "capacitance",
        "--detector",
        d,
        "--voltage",
        "25",
        "--grid",
        "front_spacing_mm",
    ]);
    assert!(msg.contains("KEY=VALUE"), "{msg}");
    let msg = fails(&[
        "simulate",
        "--detector",
        d,
        "--voltages",
        "25",
        "--grid",
        "min_tick_distance_mm=-1",
    ]);
    assert!(msg.contains("min_tick_distance_mm"), "{msg}");
    let msg = fails(&[
        "convergence",
        "--detector",
        d,
        "--voltage",
        "25",
        "--levels",
        "0",
    ]);
    assert!(msg.contains("--levels"), "{msg}");
}

/// `detector --from-legend`: a bad LEGEND diode record is exit code 2 with the file and the key.
#[test]
fn bad_legend_records() {
    let cases: [(&str, &str, &[&str]); 4] = [
        (
            "legend-negative.json",
            r#"{"name": "X", "type": "bege", "geometry": {"height_in_mm": 30, "radius_in_mm": -3}}"#,
            &["`geometry.radius_in_mm`", "-3"],
        ),
        (
            "legend-missing.json",
            r#"{"name": "X", "type": "ppc", "geometry": {"radius_in_mm": 30}}"#,
            &["`geometry.height_in_mm`", "missing"],
        ),
        (
            "legend-type.json",
            r#"{"name": "X", "type": "planar", "geometry": {"height_in_mm": 30, "radius_in_mm": 30}}"#,
            &["`type`", "planar"],
        ),
        (
            "legend-truncated.json",
            r#"{"name": "X", "type": "#,
            &["JSON"],
        ),
    ];
    for (name, text, needles) in cases {
        let path = write(name, text);
        let msg = fails(&["detector", "--from-legend", path.to_str().unwrap()]);
        assert!(msg.contains(name), "{msg}");
        for n in needles {
            assert!(msg.contains(n), "{name}: `{n}` not in {msg}");
        }
    }
}

#[test]
fn bad_lh5_pulse_files() {
    // A truncated HDF5 file (its signature and nothing else) and a text file named .lh5, each
    // with a valid sidecar: given alone or as the only file of a folder, exit 2 naming the file.
    let sidecar = "bias_V = 100.0\nsampling_period_ns = 160.0\ncharge_unit = \"pC\"\n";
    let dir = PathBuf::from(env!("CARGO_TARGET_TMPDIR")).join("bad_input_lh5");
    for (name, bytes) in [
        ("truncated", b"\x89HDF\r\n\x1a\n\0".as_slice()),
        ("text", b"bias,values\n".as_slice()),
    ] {
        let folder = dir.join(name);
        std::fs::create_dir_all(&folder).unwrap();
        let lh5 = folder.join(format!("{name}.lh5"));
        std::fs::write(&lh5, bytes).unwrap();
        std::fs::write(lh5.with_extension("toml"), sidecar).unwrap();
        let out = dir.join(format!("{name}-cv.csv"));
        for raw in [&lh5, &folder] {
            let msg = fails(&[
                "measure",
                "--raw",
                raw.to_str().unwrap(),
                "--out",
                out.to_str().unwrap(),
            ]);
            assert!(msg.contains(lh5.to_str().unwrap()), "{msg}");
            assert!(msg.contains("HDF5"), "{msg}");
            assert!(!msg.contains("HDF5-DIAG"), "{msg}");
        }
    }
}
