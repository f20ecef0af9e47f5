//! Bad detector and impurity files (issue: foundation, item 5): the solver's error names the
//! file, the key and the problem, one test per case. That the command line turns each into one
//! `error:` line and exit code 2, without a panic, is the root `tests/bad_input.rs`.

use std::path::PathBuf;

use hpge_solver::{Detector, Parameters};

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
    let dir = PathBuf::from(env!("CARGO_TARGET_TMPDIR")).join("bad_files");
    std::fs::create_dir_all(&dir).unwrap();
    let path = dir.join(name);
    std::fs::write(&path, text).unwrap();
    path
}

/// The error of loading the detector file `path`.
fn detector_error(path: &std::path::Path) -> String {
    match Detector::from_file(path, &Parameters::new()) {
        Ok(_) => panic!("{} must be rejected", path.display()),
        Err(e) => e.to_string(),
    }
}

/// Checks a detector text that must be rejected; every needle must appear in the message.
fn bad_detector(name: &str, text: &str, needles: &[&str]) {
    let msg = detector_error(&write(name, text));
    assert!(
        msg.contains(name),
        "message must name the file {name}: {msg}"
    );
    for n in needles {
        assert!(msg.contains(n), "message must contain `{n}`: {msg}");
    }
}

/// Checks an impurity file that must be rejected.
fn bad_impurity(name: &str, text: &str, needles: &[&str]) {
    // Tests run in parallel: every test writes its own files.
    let det = write(&format!("detector-for-{name}"), DETECTOR);
    let path = write(name, text);
    let mut det = Detector::from_file(&det, &Parameters::new()).unwrap();
    let msg = match det.set_impurity_file(&path) {
        Ok(()) => panic!("{name} must be rejected"),
        Err(e) => e.to_string(),
    };
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
    let mut det = Detector::from_file(&det, &Parameters::new()).unwrap();
    det.set_impurity_file(&imp).unwrap();
    det.check_bias_contact().unwrap();
}

#[test]
fn syntax_error() {
    let text = DETECTOR.replace("[world.boundary]", "[world.boundary");
    bad_detector("syntax.toml", &text, &["TOML parse error", "line"]);
}

#[test]
fn unknown_key() {
    let text = DETECTOR.replace("name = \"p+\"", "name = \"p+\"\ncolour = \"red\"");
    bad_detector("unknown-key.toml", &text, &["unknown field `colour`"]);
}

#[test]
fn missing_field() {
    let text = DETECTOR.replace("potential = 0.0\n", "");
    bad_detector("missing.toml", &text, &["missing field `potential`"]);
}

#[test]
fn negative_length() {
    let text = DETECTOR.replace("r_max_mm = 40.0", "r_max_mm = -40.0");
    bad_detector(
        "negative.toml",
        &text,
        &["world.r_max_mm", "must be positive"],
    );
}

#[test]
fn zero_length() {
    let text = DETECTOR.replace(
        "z_mm = [0.0, 10.0] } }\n\n[semiconductor.impurity]",
        "z_mm = [10.0, 10.0] } }\n\n[semiconductor.impurity]",
    );
    bad_detector(
        "zero.toml",
        &text,
        &[
            "semiconductor.geometry.tube.z_mm",
            "zero or negative length",
        ],
    );
}

#[test]
fn overlapping_contacts() {
    let text = DETECTOR.replace(
        "geometry = { cylinder_surface = { r_mm = 37.5, z_mm = [0.0, 10.0] } }",
        "geometry = { tube = { r_mm = [5.0, 37.5], z_mm = [0.0, 10.0] } }",
    );
    bad_detector(
        "overlap.toml",
        &text,
        &["contact 1 (n+)", "contact 2 (p+)", "overlap"],
    );
}

#[test]
fn contact_outside_world() {
    let text = DETECTOR.replace(
        "r_mm = 37.5, z_mm = [0.0, 10.0]",
        "r_mm = 37.5, z_mm = [0.0, 12.0]",
    );
    bad_detector(
        "outside.toml",
        &text,
        &["contacts[1].geometry", "outside the world"],
    );
}

#[test]
fn nan_in_detector() {
    let text = DETECTOR.replace("z_max_mm = 10.0", "z_max_mm = nan");
    bad_detector(
        "nan.toml",
        &text,
        &["world.z_max_mm", "not a finite number"],
    );
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
fn knots_not_increasing() {
    bad_impurity(
        "knots.toml",
        &RZ.replace("[20.0, 28.0, 33.0, 37.5]", "[20.0, 28.0, 28.0, 37.5]"),
        &["knots_mm", "increasing"],
    );
}

#[test]
fn y_outside_unit_interval() {
    bad_impurity(
        "y.toml",
        &RZ.replace("[0.60, 0.55, 0.50, 0.30]", "[0.60, 1.5, 0.50, 0.30]"),
        &["y_top[1]"],
    );
}

#[test]
fn density_outside_transform_range() {
    let text = r#"
model = "rz"
zeta_bot_cm3 = [1.3e10, 1.3e10, 1.3e9, -0.44e10]
zeta_top_cm3 = [0.44e10, 2e11, 0.44e9, -1.3e10]
"#;
    bad_impurity("range.toml", text, &["zeta_top_cm3[1]"]);
}

#[test]
fn impurity_unknown_key_and_missing_model() {
    bad_impurity(
        "imp-unknown.toml",
        &format!("{RZ}\nslope = 1.0\n"),
        &["unknown field `slope`"],
    );
    bad_impurity(
        "imp-missing.toml",
        "zeta_cm3 = 1e10\n",
        &["missing field `model`"],
    );
    bad_impurity(
        "imp-wrong-model.toml",
        "model = \"quadratic\"\nzeta_cm3 = 1e10\n",
        &["unknown variant `quadratic`"],
    );
}

#[test]
fn unreadable_files() {
    let msg = detector_error(std::path::Path::new("no/such/detector.toml"));
    assert!(
        msg.contains("no/such/detector.toml") && msg.contains("cannot read"),
        "{msg}"
    );
    let det = write("detector-for-unreadable.toml", DETECTOR);
    let mut det = Detector::from_file(&det, &Parameters::new()).unwrap();
    let msg = det
        .set_impurity_file(std::path::Path::new("no/such/impurity.toml"))
        .unwrap_err()
        .to_string();
    assert!(msg.contains("no/such/impurity.toml"), "{msg}");
}

/// A detector with no contact at the bias: the bias would act on nothing.
#[test]
fn no_bias_contact() {
    let nobias = DETECTOR.replace("potential = \"bias\"", "potential = 5.0");
    let path = write("detector-no-bias.toml", &nobias);
    let det = Detector::from_file(&path, &Parameters::new()).unwrap();
    let msg = det.check_bias_contact().unwrap_err().to_string();
    assert!(
        msg.contains("detector-no-bias.toml") && msg.contains("bias"),
        "{msg}"
    );
}

/// Issue 24: every contact at the bias is refused before a solve (it was reported as an
/// undepleted region, "the impurity density is too high").
#[test]
fn every_contact_at_the_bias() {
    let all = DETECTOR.replace("potential = 0.0", "potential = \"bias\"");
    let path = write("detector-all-bias.toml", &all);
    let det = Detector::from_file(&path, &Parameters::new()).unwrap();
    let msg = det.check_bias_contact().unwrap_err().to_string();
    assert!(
        msg.contains("detector-all-bias.toml")
            && msg.contains("contacts[1].potential")
            && msg.contains("every contact"),
        "{msg}"
    );
}

/// Issue 24: rz knots beyond the crystal (r <= 37.5 mm here), in the detector's default knots or
/// in an impurity file, are refused with their key.
#[test]
fn rz_knots_beyond_the_crystal() {
    bad_detector(
        "knots-beyond.toml",
        &DETECTOR.replace(
            "rz_knots_mm = [6.0, 16.0, 27.0, 37.5]",
            "rz_knots_mm = [6.0, 16.0, 27.0, 45.0]",
        ),
        &["semiconductor.rz_knots_mm[3]", "beyond the crystal"],
    );
    bad_impurity(
        "rz-knots-beyond.toml",
        &RZ.replace("[20.0, 28.0, 33.0, 37.5]", "[20.0, 28.0, 33.0, 39.0]"),
        &["knots_mm[3]", "beyond the crystal"],
    );
}

/// Issue 24: a passive overlapping the crystal names both key paths (it was reported as two
/// *contacts* overlapping).
#[test]
fn passive_overlapping_the_crystal() {
    let text = format!(
        "{DETECTOR}\n[[passives]]\nname = \"ring\"\nkind = \"grounded\"\nmaterial = \"copper\"\n\
         geometry = {{ tube = {{ r_mm = [30.0, 39.0], z_mm = [2.0, 4.0] }} }}\n"
    );
    bad_detector(
        "passive-overlap.toml",
        &text,
        &[
            "`passives[0].geometry` (passive ring)",
            "`semiconductor.geometry` (the semiconductor)",
            "overlap",
        ],
    );
}

/// Issue 18: an unknown key or a bad value in a detector's `[grid]` table names the key.
#[test]
fn bad_grid_table() {
    let with_table = write(
        "detector-with-grid-table.toml",
        &format!("{DETECTOR}\n[grid]\ntolerance = 0.01\nspacing_mm = 0.5\n"),
    );
    let msg = detector_error(&with_table);
    assert!(msg.contains("spacing_mm"), "{msg}");
    let with_bad = write(
        "detector-with-bad-grid.toml",
        &format!("{DETECTOR}\n[grid]\ntolerance = -1.0\n"),
    );
    let msg = detector_error(&with_bad);
    assert!(msg.contains("grid") && msg.contains("tolerance"), "{msg}");
}
