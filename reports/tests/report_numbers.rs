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
