//! The committed `reports/paper/report.json` (made by `hpge-cv report paper`): no verdict
//! contradicts the numbers of its row, and the full run judged every figure it made.

use hpge_reports::paper::inconsistent_rows;

#[test]
fn committed_paper_report_verdicts_follow_their_criteria() {
    let path = std::path::Path::new(env!("CARGO_MANIFEST_DIR")).join("paper/report.json");
    let json: serde_json::Value =
        serde_json::from_str(&std::fs::read_to_string(&path).unwrap()).unwrap();
    let faults = inconsistent_rows(&json);
    assert!(faults.is_empty(), "{}: {faults:#?}", path.display());
    assert_eq!(json["quick"], false, "the committed report is a full run");
    for r in json["rows"].as_array().unwrap() {
        assert!(
            !r["verdict"].as_str().unwrap_or("").starts_with("not run"),
            "{} was not run",
            r["figure"]
        );
    }
}
