use std::path::Path;

use proptest::prelude::*;

use super::*;

fn shipped() -> ParameterSpace {
    ParameterSpace::from_file(
        &Path::new(env!("CARGO_MANIFEST_DIR")).join("../spaces/super-siegfried-rz.toml"),
    )
    .unwrap()
}

#[test]
fn shipped_space_is_the_papers() {
    let s = shipped();
    assert_eq!(s.dim(), 10);
    let names: Vec<&str> = s.dimensions.iter().map(|d| d.name.as_str()).collect();
    assert_eq!(names[0], "d_li_mm");
    assert_eq!(names[9], "U_B");
    assert_eq!(s.dimensions[0].range, [0.2, 5.0]);
    assert_eq!(s.dimensions[1].range, [0.018566145, 1.0]);
    assert_eq!(s.dimensions[3].range, [-1.0, 1.0]);
    assert_eq!(s.dimensions[9].range, [10.0, 3000.0]);
    assert_eq!(s.targets()[9], Target::Bias);
    assert_eq!(s.targets()[0], Target::Parameter("d_li_mm".into()));
    assert_eq!(s.targets()[8], Target::YTop(3));
}

#[test]
fn bad_spaces_name_the_key() {
    let err = |t: &str| {
        ParameterSpace::from_toml_str(t, Path::new("s.toml"))
            .unwrap_err()
            .to_string()
    };
    let dim = |range: &str, target: &str| {
        format!(
            "name = \"x\"\n[[dimensions]]\nname = \"a\"\nunit = \"1\"\nrange = {range}\ntarget = \"{target}\"\n"
        )
    };
    assert!(err(&dim("[1.0, 0.0]", "bias")).contains("dimensions[0].range"));
    assert!(err(&dim("[0.0, nan]", "bias")).contains("range"));
    assert!(err(&dim("[0.0, 1.0]", "nowhere")).contains("dimensions[0].target"));
    // y outside [-1, 1] is refused up front, not sample by sample (issue 24, group 9).
    let e = err(&dim("[0.0, 1.5]", "y_bot[0]"));
    assert!(
        e.contains("dimensions[0].range") && e.contains("[-1, 1]"),
        "{e}"
    );
    assert!(err(&dim("[-2.0, 0.5]", "y_top[1]")).contains("[-1, 1]"));
    assert!(
        ParameterSpace::from_toml_str(&dim("[-1.0, 1.0]", "y_top[1]"), Path::new("s.toml")).is_ok()
    );
    assert!(err("name = \"x\"\ndimensions = []\n").contains("at least one"));
    assert!(err("name = \"x\"\n[[dimensions]]\nname = \"a\"\n").contains("s.toml"));
}

proptest! {
    #[test]
    fn unit_round_trip(u in proptest::collection::vec(0.0f64..1.0, 10)) {
        let s = shipped();
        let back = s.to_unit(&s.from_unit(&u));
        for (a, b) in u.iter().zip(&back) {
            prop_assert!((a - b).abs() <= 4.0 * f64::EPSILON, "{} vs {}", a, b);
        }
    }

    #[test]
    fn normal_round_trip(u in 1e-300f64..1.0) {
        let z = normal_quantile(u);
        prop_assert!(z.is_finite());
        let back = normal_cdf(z);
        prop_assert!((back - u).abs() <= 1e-14 * u.min(1.0 - u).max(1e-300) + 4.0 * f64::EPSILON * u,
            "u {} z {} back {}", u, z, back);
    }

    #[test]
    fn normal_is_monotone_and_odd(a in -8.0f64..8.0, b in -8.0f64..8.0) {
        prop_assume!(a < b);
        prop_assert!(normal_cdf(a) <= normal_cdf(b));
        prop_assert!((normal_cdf(a) + normal_cdf(-a) - 1.0).abs() < 1e-15);
    }
}
