use super::*;

fn repo(name: &str) -> PathBuf {
    let root = std::env::temp_dir().join(format!("hpge-numbers-{name}-{}", std::process::id()));
    let _ = std::fs::remove_dir_all(&root);
    std::fs::create_dir_all(root.join("reports/fits")).unwrap();
    std::fs::write(
        root.join("reports/fits/new.json"),
        r#"{"made": {"solver_revision": "now"}, "chi2": 61.26, "rounds": [{"seconds": 100}, {"seconds": 122}]}"#,
    )
    .unwrap();
    std::fs::write(root.join("reports/fits/old.json"), r#"{"chi2": 288.1}"#).unwrap();
    root
}

#[test]
fn a_report_is_filled_and_then_agrees() {
    let root = repo("fill");
    let page = "# Fits\n\n<!-- n-from reports/fits/new.json -->\
                chi^2 <!-- n /chi2 .1f -->61.3<!-- /n --> in \
                <!-- n /rounds/*/seconds sum mmss -->9 min<!-- /n -->.\n";
    std::fs::write(root.join("reports/fits.md"), page).unwrap();
    let filled = fill_repository(&root, "now").unwrap();
    assert_eq!(filled.len(), 1);
    let f = &filled[0];
    assert_eq!((f.file.to_str(), f.numbers), (Some("reports/fits.md"), 2));
    assert_eq!(f.differences.len(), 1, "{:?}", f.differences);
    assert_eq!(f.differences[0].expected, "3 min 42 s");
    assert!(f.older().is_empty());
    std::fs::write(root.join("reports/fits.md"), &f.text).unwrap();
    assert!(
        fill_repository(&root, "now").unwrap()[0]
            .differences
            .is_empty()
    );
    // The same page made from results of another revision gets a banner naming the file.
    let later = fill_repository(&root, "later").unwrap();
    let d = &later[0].differences;
    assert_eq!((d.len(), d[0].what.as_str()), (1, "stale banner"));
    assert!(
        later[0].text.contains("`reports/fits/new.json` (\"now\")"),
        "{}",
        later[0].text
    );
    let _ = std::fs::remove_dir_all(&root);
}

#[test]
fn a_file_without_a_revision_is_older() {
    let root = repo("older");
    let page = "# P\n\nchi^2 <!-- n reports/fits/old.json /chi2 .1f -->288.1<!-- /n -->\n";
    let f = fill_text(&root, "p.md", page, "now").unwrap();
    assert_eq!(f.older(), [("reports/fits/old.json", &Revision::Unknown)]);
    assert!(f.text.contains(stale::BEGIN) && f.text.contains("no revision recorded"));
    let again = fill_text(&root, "p.md", &f.text, "now").unwrap();
    assert!(again.differences.is_empty(), "{:?}", again.differences);
    let _ = std::fs::remove_dir_all(&root);
}

#[test]
fn failures_name_the_report_the_line_and_the_marker() {
    let root = repo("errors");
    for (page, want) in [
        (
            "\n<!-- n reports/fits/none.json /chi2 -->1<!-- /n -->",
            "p.md: line 2: `reports/fits/none.json /chi2`",
        ),
        (
            "<!-- n reports/fits/new.json /nope .1f -->1<!-- /n -->",
            "nothing at /nope",
        ),
        (
            "<!-- n reports/fits/new.json /made .1f -->1<!-- /n -->",
            "is not a number",
        ),
        (
            "<!-- n reports/fits/new.json /chi2 .1z -->1<!-- /n -->",
            "p.md: line 1",
        ),
    ] {
        let e = fill_text(&root, "p.md", page, "now")
            .unwrap_err()
            .to_string();
        assert!(e.contains(want), "{page}: {e}");
    }
    let _ = std::fs::remove_dir_all(&root);
}
