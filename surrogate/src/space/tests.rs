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
    assert_eq!(
        s.targets()[8],
        Target::Impurity {
            key: "y_top".into(),
            index: Some(3)
        }
    );
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

#[test]
fn the_bz_slice_keeps_the_full_spaces_columns_and_ties_each_face() {
    let full = shipped();
    let slice = ParameterSpace::from_file(
        &Path::new(env!("CARGO_MANIFEST_DIR")).join("../spaces/super-siegfried-bz-slice.toml"),
    )
    .unwrap();
    assert_eq!((slice.dim(), slice.sampled_dim()), (10, 4));
    assert_eq!(full.sampled_dim(), 10);
    let names = |s: &ParameterSpace| -> Vec<String> {
        s.dimensions.iter().map(|d| d.name.clone()).collect()
    };
    assert_eq!(names(&slice), names(&full));
    assert_eq!(slice.targets(), full.targets());
    let (u, x) = slice.from_sampled_unit(&[0.25, 0.5, 0.75, 0.1]);
    assert_eq!(x[0], 0.2 + 0.25 * 4.8);
    for k in 1..5 {
        assert_eq!(x[k], x[1], "bottom knot {k}");
        assert_eq!(x[k + 4], x[5], "top knot {k}");
    }
    assert_eq!(x[9], 10.0 + 0.1 * 2990.0);
    // The unit coordinates are those of the full space at the same physical point.
    let u_full = full.to_unit(&x);
    for (a, b) in u.iter().zip(&u_full) {
        assert!((a - b).abs() < 1e-15, "{a} vs {b}");
    }
    // Without ties, the sampled map is from_unit.
    let v = [0.1, 0.2, 0.3, 0.4, 0.5, 0.6, 0.7, 0.8, 0.9, 0.05];
    assert_eq!(full.from_sampled_unit(&v), (v.to_vec(), full.from_unit(&v)));
}

#[test]
fn same_as_errors_name_the_key() {
    let two = |extra: &str, range_b: &str, target_b: &str| {
        format!(
            "name = \"x\"\n[[dimensions]]\nname = \"a\"\nunit = \"1\"\nrange = [0.1, 0.5]\ntarget = \"y_bot[0]\"\n\
             [[dimensions]]\nname = \"b\"\nunit = \"1\"\nrange = {range_b}\ntarget = \"{target_b}\"\n{extra}"
        )
    };
    let err = |t: String| {
        ParameterSpace::from_toml_str(&t, Path::new("s.toml"))
            .unwrap_err()
            .to_string()
    };
    let e = err(two("same_as = \"c\"\n", "[0, 1]", "y_bot[1]"));
    assert!(
        e.contains("dimensions[1].same_as") && e.contains("`c`"),
        "{e}"
    );
    let e = err(two("same_as = \"a\"\n", "[0.2, 1]", "y_bot[1]"));
    assert!(
        e.contains("dimensions[1].range") && e.contains("`a`"),
        "{e}"
    );
    let e = err(two("same_as = \"a\"\n", "[10, 100]", "bias"));
    assert!(
        e.contains("dimensions[1].same_as") && e.contains("bias"),
        "{e}"
    );
    assert!(
        ParameterSpace::from_toml_str(
            &two("same_as = \"a\"\n", "[0, 1]", "y_bot[1]"),
            Path::new("s.toml")
        )
        .is_ok()
    );
}

#[test]
fn impurity_targets_parse() {
    let t = |s: &str| Target::parse(s);
    assert_eq!(
        t("impurity:z0_cm3"),
        Some(Target::Impurity {
            key: "z0_cm3".into(),
            index: None
        })
    );
    assert_eq!(
        t("impurity:values_cm3[4]"),
        Some(Target::Impurity {
            key: "values_cm3".into(),
            index: Some(4)
        })
    );
    assert_eq!(t("y_bot[2]"), t("impurity:y_bot[2]"));
    assert!(t("y_bot[2]").unwrap().is_rz_y());
    assert!(!t("impurity:z0_cm3").unwrap().is_rz_y());
    for bad in [
        "impurity:",
        "impurity:1x",
        "impurity:a[",
        "impurity:a[x]",
        "impurity:a b",
    ] {
        assert_eq!(t(bad), None, "{bad}");
    }
}
