//! The README's status table is the one the shipped results files give (`hpge-cv report status
//! --write README.md` remakes it): a result that changes without the README fails here.

use std::path::Path;

use hpge_reports::status::{MAX_CELL_CHARS, status_rows, status_table, table_in};

#[test]
fn readme_status_table_agrees_with_the_results_files() {
    let root = Path::new(env!("CARGO_MANIFEST_DIR")).join("..");
    let rows = status_rows(&root, hpge_inference::fit::DEFAULT_MODEL).unwrap();
    let want = status_table(&rows);
    let readme = std::fs::read_to_string(root.join("README.md")).unwrap();
    let have = table_in(&readme).expect("README.md has no status table between the markers");
    assert_eq!(
        have.trim(),
        want.trim(),
        "README.md's status table is out of date: cargo run --release -- report status --write README.md"
    );
    // Both fits of the main job's acceptance (issue 21) show their wall time against its target.
    for fit in ["main job (B_RZ fit)", "B_Z fit"] {
        assert!(
            rows.iter()
                .any(|r| r.what == format!("{fit}: wall time on 2 cores")),
            "no wall-time row for {fit}"
        );
    }
    // Every row's source exists.
    for r in &rows {
        assert!(root.join(&r.source).exists(), "{} is missing", r.source);
    }
    // The README fits one screen (issue 61): at most 70 lines, no table cell over the limit.
    let lines = readme.lines().count();
    assert!(lines <= 70, "README.md has {lines} lines, more than 70");
    for line in have.lines() {
        for cell in line.trim_matches('|').split(" | ") {
            let n = cell.trim().chars().count();
            assert!(
                n <= MAX_CELL_CHARS,
                "a status cell of {n} characters: {cell}"
            );
        }
    }
}
