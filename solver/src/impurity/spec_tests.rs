//! Tests of [`super::ImpuritySpec`]: parsing, every validation message, the paper's example.

use super::*;
use crate::impurity::LogTransform;
use std::path::PathBuf;

fn ctx() -> ImpurityContext {
    ImpurityContext {
        z_bottom_mm: 0.0,
        z_top_mm: 70.0,
        default_knots_mm: None,
        parameters: crate::Parameters::new(),
    }
}

fn file() -> PathBuf {
    PathBuf::from("impurity.toml")
}

fn rel(a: f64, b: f64) -> f64 {
    (a - b).abs() / a.abs().max(b.abs())
}

fn build(text: &str) -> Result<Box<dyn ImpurityModel>> {
    ImpuritySpec::from_toml_str(text, &file())?.build(&ctx(), &file(), "")
}

/// The (key, message) of an Invalid error from building `text` as a standalone file.
fn invalid(text: &str) -> (String, String) {
    match build(text) {
        Err(Error::Invalid { key, message, .. }) => (key, message),
        other => panic!("expected an Invalid error, got {other:?}"),
    }
}

fn parse_error(text: &str) -> String {
    match ImpuritySpec::from_toml_str(text, &file()) {
        Err(Error::Parse { message, .. }) => message,
        other => panic!("expected a Parse error, got {other:?}"),
    }
}

const RZ_Y: &str = "model = \"rz\"\nknots_mm = [20.0, 28.0, 33.0, 37.5]\n";

#[test]
fn paper_example_through_toml() {
    let text = r#"
        model = "rz"
        knots_mm = [20.0, 28.0, 33.0, 37.5]
        zeta_bot_cm3 = [1.3e10, 1.3e10, 1.3e9, -0.44e10]
        zeta_top_cm3 = [0.44e10, 0.44e10, 0.44e9, -1.3e10]
    "#;
    let m = build(text).unwrap();
    assert_eq!(m.name(), "rz");
    assert!(rel(m.density_cm3(20.0, 0.0), 1.30e10) < 1e-6);
    assert!(rel(m.density_cm3(37.5, 0.0), -0.44e10) < 1e-6);
    assert!(rel(m.density_cm3(20.0, 70.0), 0.44e10) < 1e-6);
    assert!(rel(m.density_cm3(37.5, 70.0), -1.30e10) < 1e-6);
    assert!(m.evaluate(30.0, 10.0).y.is_some());
}

#[test]
fn rz_with_y_default_knots_and_transform() {
    let text = "model = \"rz\"\ny_bot = [0.7062704, 0.7062704]\ny_top = [0.55060154, 0.55060154]\n\
                transform = { g = 1000.0 }\n";
    let spec = ImpuritySpec::from_toml_str(text, &file()).unwrap();
    let ModelSpec::Rz(rz) = &spec.model else {
        panic!("an rz spec")
    };
    assert_eq!(rz.transform, Some(LogTransform::default()));
    let ctx = ImpurityContext {
        default_knots_mm: Some(vec![10.0, 30.0]),
        ..ctx()
    };
    let m = spec.build(&ctx, &file(), "").unwrap();
    assert!(rel(m.density_cm3(5.0, 0.0), 1.3e10) < 1e-6);
    assert!(rel(m.density_cm3(50.0, 70.0), 0.44e10) < 1e-6);
}

#[test]
fn constant_and_linear_z() {
    let m = build("model = \"constant\"\nzeta_cm3 = -2e9\n").unwrap();
    assert_eq!((m.name(), m.density_cm3(3.0, 4.0)), ("constant", -2e9));
    let m = build("model = \"linear-z\"\nbottom_cm3 = 1.3e10\ntop_cm3 = 0.44e10\n").unwrap();
    assert_eq!(m.name(), "linear-z");
    assert_eq!(m.density_cm3(0.0, 0.0), 1.3e10);
    assert!(rel(m.density_cm3(0.0, 70.0), 0.44e10) < 1e-12);
}

#[test]
fn a_tilt_scales_the_gradient_before_the_scale() {
    // 1.3e10 at z = 0 to 0.44e10 at z = 70: mid-height value 0.87e10.
    let m = build(
        "model = \"linear-z\"\nbottom_cm3 = 1.3e10\ntop_cm3 = 0.44e10\ntilt = 2.0\nscale = 0.5\n",
    )
    .unwrap();
    assert!(rel(m.density_cm3(0.0, 35.0), 0.5 * 0.87e10) < 1e-12);
    assert!(rel(m.density_cm3(0.0, 0.0), 0.5 * (0.87e10 + 2.0 * 0.43e10)) < 1e-12);
    let (key, message) = invalid("model = \"constant\"\nzeta_cm3 = 1e10\ntilt = nan\n");
    assert_eq!(key, "tilt");
    assert!(message.contains("finite"), "{message}");
}

#[test]
fn serialisation_round_trip() {
    let text = format!("{RZ_Y}y_bot = [0.5, 0.5, 0.1, -0.2]\ny_top = [0.4, 0.4, 0.1, -0.3]\n");
    let spec = ImpuritySpec::from_toml_str(&text, &file()).unwrap();
    let again = toml::to_string(&spec).unwrap();
    assert_eq!(ImpuritySpec::from_toml_str(&again, &file()).unwrap(), spec);
    assert!(!again.contains("zeta_cm3"), "{again}");
}

#[test]
fn missing_required_keys() {
    let (key, msg) = invalid(RZ_Y);
    assert_eq!(key, "model");
    assert!(
        msg.contains(
            "model \"rz\" needs `y_bot` and `y_top`, or `zeta_bot_cm3` and `zeta_top_cm3`"
        ),
        "{msg}"
    );
    let (key, _) = invalid(&format!("{RZ_Y}y_bot = [0.5, 0.5, 0.5, 0.5]\n"));
    assert_eq!(key, "y_top");
    let (key, _) = invalid(&format!("{RZ_Y}zeta_top_cm3 = [1e10, 1e10, 1e10, 1e10]\n"));
    assert_eq!(key, "zeta_bot_cm3");
    // The missing partner is reported before the missing knots.
    let (key, _) = invalid("model = \"rz\"\ny_bot = [0.5]\n");
    assert_eq!(key, "y_top");
    // A model's required keys are the parser's: the message names the key.
    let msg = parse_error("model = \"constant\"\n");
    assert!(msg.contains("missing field `zeta_cm3`"), "{msg}");
    let msg = parse_error("model = \"linear-z\"\nbottom_cm3 = 1e10\n");
    assert!(msg.contains("missing field `top_cm3`"), "{msg}");
}

#[test]
fn keys_of_another_model() {
    let msg = parse_error(&format!(
        "{RZ_Y}zeta_cm3 = 1e10\ny_bot = [0.5, 0.5, 0.5, 0.5]\ny_top = [0.5, 0.5, 0.5, 0.5]\n"
    ));
    assert!(
        msg.contains(
            "`zeta_cm3` (line 3) is not a key of this model; it belongs to model \"constant\""
        ),
        "{msg}"
    );
    let msg = parse_error("model = \"constant\"\nzeta_cm3 = 1e10\nknots_mm = [1.0]\n");
    assert!(
        msg.contains("`knots_mm` (line 3)") && msg.contains("model \"rz\""),
        "{msg}"
    );
    let msg =
        parse_error("model = \"linear-z\"\nbottom_cm3 = 1.0\ntop_cm3 = 1.0\ntransform = {}\n");
    assert!(msg.contains("`transform` (line 4)"), "{msg}");
    let msg = parse_error("model = \"constant\"\nzeta_cm3 = 1.0\nbottom_cm = 1.0\n");
    assert!(msg.contains("is not a key of any impurity model"), "{msg}");
    assert_eq!(
        model_names(),
        ["constant", "linear-z", "rz", "z-table", "polynomial-z"]
    );
}

#[test]
fn both_y_and_zeta() {
    let (key, msg) = invalid(&format!(
        "{RZ_Y}y_bot = [0.5, 0.5, 0.5, 0.5]\ny_top = [0.5, 0.5, 0.5, 0.5]\n\
         zeta_top_cm3 = [1e10, 1e10, 1e10, 1e10]\n"
    ));
    assert_eq!(key, "zeta_top_cm3");
    assert!(msg.contains("not both"), "{msg}");
}

#[test]
fn non_finite_values() {
    let (key, msg) = invalid("model = \"constant\"\nzeta_cm3 = nan\n");
    assert_eq!(key, "zeta_cm3");
    assert!(msg.contains("finite"), "{msg}");
    let (key, _) = invalid("model = \"linear-z\"\nbottom_cm3 = 1.0\ntop_cm3 = -inf\n");
    assert_eq!(key, "top_cm3");
    let (key, _) = invalid(&format!(
        "{RZ_Y}y_bot = [0.5, 0.5, nan, 0.5]\ny_top = [0.5, 0.5, 0.5, 0.5]\n"
    ));
    assert_eq!(key, "y_bot[2]");
    let (key, _) = invalid(&format!(
        "{RZ_Y}zeta_bot_cm3 = [1e10, 1e10, 1e10, 1e10]\nzeta_top_cm3 = [1e10, inf, 1e10, 1e10]\n"
    ));
    assert_eq!(key, "zeta_top_cm3[1]");
    let (key, _) =
        invalid("model = \"rz\"\nknots_mm = [1.0, inf]\ny_bot = [0.5, 0.5]\ny_top = [0.5, 0.5]\n");
    assert_eq!(key, "knots_mm[1]");
}

#[test]
fn bad_knots() {
    let ys = "y_bot = [0.5, 0.5, 0.5]\ny_top = [0.5, 0.5, 0.5]\n";
    let (key, msg) = invalid(&format!(
        "model = \"rz\"\nknots_mm = [20.0, 28.0, 28.0]\n{ys}"
    ));
    assert_eq!(key, "knots_mm[2]");
    assert!(msg.contains("strictly increasing"), "{msg}");
    let (key, msg) = invalid(&format!(
        "model = \"rz\"\nknots_mm = [-1.0, 28.0, 30.0]\n{ys}"
    ));
    assert_eq!(key, "knots_mm[0]");
    assert!(msg.contains("negative"), "{msg}");
    let (key, msg) = invalid(&format!("model = \"rz\"\n{ys}"));
    assert_eq!(key, "knots_mm");
    assert!(msg.contains("no default knots"), "{msg}");
    let (key, _) = invalid("model = \"rz\"\nknots_mm = []\ny_bot = []\ny_top = []\n");
    assert_eq!(key, "knots_mm");
    // Bad default knots are reported too.
    let spec = ImpuritySpec::from_toml_str(&format!("model = \"rz\"\n{ys}"), &file()).unwrap();
    let ctx = ImpurityContext {
        default_knots_mm: Some(vec![3.0, 2.0, 1.0]),
        ..ctx()
    };
    match spec.build(&ctx, &file(), "") {
        Err(Error::Invalid { key, message, .. }) => {
            assert_eq!(key, "knots_mm[1]");
            assert!(message.contains("default knots"), "{message}");
        }
        other => panic!("{other:?}"),
    }
}

#[test]
fn lengths_not_matching_the_knots() {
    let (key, msg) = invalid(&format!(
        "{RZ_Y}y_bot = [0.5, 0.5, 0.5]\ny_top = [0.5, 0.5, 0.5, 0.5]\n"
    ));
    assert_eq!(key, "y_bot");
    assert!(msg.contains("3 values") && msg.contains("4 knots"), "{msg}");
    let (key, _) = invalid(&format!(
        "{RZ_Y}zeta_bot_cm3 = [1e10, 1e10, 1e10, 1e10]\nzeta_top_cm3 = [1e10, 1e10, 1e10, 1e10, 1e10]\n"
    ));
    assert_eq!(key, "zeta_top_cm3");
}

#[test]
fn y_outside_unit_interval() {
    let (key, msg) = invalid(&format!(
        "{RZ_Y}y_bot = [0.5, 0.5, 0.5, 0.5]\ny_top = [0.5, 0.5, 0.5, -1.01]\n"
    ));
    assert_eq!(key, "y_top[3]");
    assert!(msg.contains("outside [-1, 1]"), "{msg}");
}

#[test]
fn densities_the_transform_cannot_express() {
    let bot = "zeta_bot_cm3 = [1e10, 1e10, 1e10, 1e10]\n";
    let (key, msg) = invalid(&format!(
        "{RZ_Y}{bot}zeta_top_cm3 = [1e10, 1e10, 2e11, 1e10]\n"
    ));
    assert_eq!(key, "zeta_top_cm3[2]");
    assert!(msg.contains("larger than"), "{msg}");
    let (key, msg) = invalid(&format!(
        "{RZ_Y}{bot}zeta_top_cm3 = [1e10, -1e-3, 0.0, 1e10]\n"
    ));
    assert_eq!(key, "zeta_top_cm3[1]");
    assert!(msg.contains("too small"), "{msg}");
    // Zero is fine.
    assert!(
        build(&format!(
            "{RZ_Y}{bot}zeta_top_cm3 = [1e10, 0.0, 0.0, 1e10]\n"
        ))
        .is_ok()
    );
}

#[test]
fn invalid_transform_and_context() {
    let ys = "y_bot = [0.5, 0.5, 0.5, 0.5]\ny_top = [0.5, 0.5, 0.5, 0.5]\n";
    let (key, msg) = invalid(&format!("{RZ_Y}{ys}transform = {{ x_l = 20.0 }}\n"));
    assert_eq!(key, "transform");
    assert!(msg.contains("x_l"), "{msg}");
    let spec = ImpuritySpec::from_toml_str(&format!("{RZ_Y}{ys}"), &file()).unwrap();
    let bad = ImpurityContext {
        z_top_mm: 0.0,
        ..ctx()
    };
    assert!(matches!(
        spec.build(&bad, &file(), ""),
        Err(Error::Argument { .. })
    ));
}

#[test]
fn parse_errors_name_the_key() {
    let msg = parse_error("model = \"constant\"\nzeta_cm3 = 1e10\nfoo = 1\n");
    assert!(msg.contains("`foo` (line 3)"), "{msg}");
    let msg = parse_error("zeta_cm3 = 1e10\n");
    assert!(msg.contains("model"), "{msg}");
    let msg = parse_error("model = \"spline\"\n");
    assert!(msg.contains("spline") && msg.contains("linear-z"), "{msg}");
    let msg = parse_error("model = \"rz\"\ntransform = { w = 1.0 }\n");
    assert!(msg.contains('w'), "{msg}");
    let msg = parse_error("model = \"rz\"\ny_bot = [0.5,\n");
    assert!(msg.contains("line"), "{msg}");
}

#[test]
fn inline_in_a_detector_file() {
    #[derive(serde::Deserialize)]
    struct Detector {
        semiconductor: Semiconductor,
    }
    #[derive(serde::Deserialize)]
    struct Semiconductor {
        impurity: ImpuritySpec,
    }
    let text = "[semiconductor.impurity]\nmodel = \"rz\"\nknots_mm = [20.0, 28.0, 33.0, 37.5]\n\
                y_bot = [0.5, 0.5, 1.5, 0.5]\ny_top = [0.5, 0.5, 0.5, 0.5]\n";
    let det: Detector = toml::from_str(text).unwrap();
    let err = det
        .semiconductor
        .impurity
        .build(&ctx(), Path::new("det.toml"), "semiconductor.impurity")
        .unwrap_err();
    let shown = err.to_string();
    assert!(
        shown.contains("`semiconductor.impurity.y_bot[2]`"),
        "{shown}"
    );
    let bad = toml::from_str::<Detector>(&text.replace("y_top", "y_tpo"))
        .err()
        .unwrap();
    assert!(bad.to_string().contains("y_tpo"), "{bad}");
}

#[test]
fn from_file_reads_and_reports_io_errors() {
    let dir = std::env::temp_dir().join(format!("hpge-impurity-test-{}", std::process::id()));
    std::fs::create_dir_all(&dir).unwrap();
    let path = dir.join("constant.toml");
    std::fs::write(&path, "model = \"constant\"\nzeta_cm3 = 1e10\n").unwrap();
    let spec = ImpuritySpec::from_file(&path).unwrap();
    assert_eq!(
        spec.model,
        ModelSpec::Constant(ConstantSpec {
            zeta_cm3: 1e10.into()
        })
    );
    std::fs::remove_file(&path).unwrap();
    assert!(matches!(
        ImpuritySpec::from_file(&path),
        Err(Error::Io { .. })
    ));
    let _ = std::fs::remove_dir(&dir);
}
