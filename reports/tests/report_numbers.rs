//! Every number the committed reports quote from a results file is what that file gives today,
//! and every report made from results older than the solver's physics revision says so at its
//! top (issue 63; `hpge-cv report numbers --write` fills them).

use std::path::Path;

#[test]
fn the_committed_reports_quote_their_results_files() {
    let root = Path::new(env!("CARGO_MANIFEST_DIR")).join("..");
    let filled =
        hpge_reports::numbers::fill_repository(&root, hpge_solver::field::PHYSICS_REVISION)
            .unwrap_or_else(|e| panic!("{e}"));
    let mut wrong = Vec::new();
    for f in &filled {
        for d in &f.differences {
            wrong.push(format!(
                "{}:{}: {}: the report has \"{}\", its results file gives \"{}\"",
                f.file.display(),
                d.line,
                d.what,
                d.found,
                d.expected
            ));
        }
    }
    assert!(
        wrong.is_empty(),
        "reports that differ from their results files (`cargo run --release -- report numbers --write` fills them):\n{}",
        wrong.join("\n")
    );
    let numbers: usize = filled.iter().map(|f| f.numbers).sum();
    assert!(
        numbers >= 20,
        "only {numbers} numbers are tied to results files"
    );
}

/// A results file a report quotes is committed: a clean clone has it (a file under an ignored
/// folder exists only where it was made). Checked where the repository is a git checkout.
#[test]
fn every_quoted_results_file_is_committed() {
    let root = Path::new(env!("CARGO_MANIFEST_DIR")).join("..");
    let filled =
        hpge_reports::numbers::fill_repository(&root, hpge_solver::field::PHYSICS_REVISION)
            .unwrap_or_else(|e| panic!("{e}"));
    let sources: std::collections::BTreeSet<String> = filled
        .iter()
        .flat_map(|f| f.sources.keys().cloned())
        .collect();
    let Ok(out) = std::process::Command::new("git")
        .arg("-C")
        .arg(&root)
        .args(["ls-files", "--"])
        .args(&sources)
        .output()
    else {
        return; // no git: nothing to compare with
    };
    if !out.status.success() {
        return; // not a checkout (a source archive)
    }
    let tracked: std::collections::BTreeSet<String> = String::from_utf8_lossy(&out.stdout)
        .lines()
        .map(str::to_string)
        .collect();
    let missing: Vec<&String> = sources.difference(&tracked).collect();
    assert!(
        missing.is_empty(),
        "results files quoted by the reports but not committed: {missing:?}"
    );
}
