//! Reports made from older results say so at their top (issue 63): a results file records the
//! solver's physics revision it was made with (`made.solver_revision`, or a top-level
//! `solver_revision` in the files that kept one before, or `inputs.solver_revision` in a row file
//! of `hpge-cv depletion --records`); a CSV's is its JSON sidecar's (`<stem>.json`); a report quoting a file of another
//! revision, or of none recorded, carries a banner naming each such file.

use serde_json::Value;

/// The line before the banner.
pub const BEGIN: &str =
    "<!-- stale: begin; made by `cargo run --release -- report numbers --write` -->";
/// The line after it.
pub const END: &str = "<!-- stale: end -->";

/// Which physics a results file's numbers come from.
#[derive(Debug, Clone, PartialEq, Eq)]
pub enum Revision {
    /// The solver's current revision, or numbers that do not depend on the solver (a `made`
    /// record without a solver revision: a measurement).
    Current,
    /// Another revision.
    Other(String),
    /// None recorded (made before results files recorded it).
    Unknown,
}

/// The revision of the results file `v`, against the solver's `current` one. A JSONL or CSV
/// file (an array of records) is as old as its oldest record: another revision where any
/// record has one, none recorded where any record has none, current otherwise.
pub fn revision_of(v: &Value, current: &str) -> Revision {
    if let Value::Array(records) = v {
        let all: Vec<Revision> = records.iter().map(|r| revision_of(r, current)).collect();
        return all
            .iter()
            .find(|r| matches!(r, Revision::Other(_)))
            .or_else(|| all.iter().find(|r| **r == Revision::Unknown))
            .cloned()
            .unwrap_or(Revision::Current);
    }
    let recorded = match v.get(hpge_foundation::MADE_KEY) {
        Some(made) if made.is_object() => match made.get("solver_revision") {
            Some(Value::String(s)) => Some(s.as_str()),
            _ => return Revision::Current,
        },
        _ => v
            .get("solver_revision")
            .or_else(|| v.get("inputs").and_then(|i| i.get("solver_revision")))
            .and_then(Value::as_str),
    };
    match recorded {
        Some(r) if r == current => Revision::Current,
        Some(r) => Revision::Other(r.to_string()),
        None => Revision::Unknown,
    }
}

/// The banner of a report whose `older` results files (with their revisions) predate the
/// `current` revision, out of `total` files it quotes; None when there are none.
pub fn banner(older: &[(String, Revision)], total: usize, current: &str) -> Option<String> {
    if older.is_empty() {
        return None;
    }
    let files = older
        .iter()
        .map(|(f, r)| match r {
            Revision::Other(r) => format!("`{f}` (\"{r}\")"),
            _ => format!("`{f}` (no revision recorded)"),
        })
        .collect::<Vec<_>>()
        .join(", ");
    Some(format!(
        "{BEGIN}\n> **Made from older results.** {} of the {total} results files this page quotes \
         predate the solver's physics revision \"{current}\": {files}. Its numbers are those \
         files' until they are made again.\n{END}",
        older.len()
    ))
}

/// `text` with its banner replaced by `banner` (removed where None), placed after the first
/// line when that is a `# ` heading, else at the top.
pub fn with_banner(text: &str, banner: Option<&str>) -> String {
    let mut t = text.to_string();
    if let (Some(b), Some(e)) = (t.find(BEGIN), t.find(END))
        && e > b
    {
        let mut end = e + END.len();
        if t[end..].starts_with('\n') {
            end += 1;
        }
        let start = if b > 0 && t[..b].ends_with('\n') {
            b - 1
        } else {
            if t[end..].starts_with('\n') {
                end += 1;
            }
            b
        };
        t.replace_range(start..end, "");
    }
    let Some(banner) = banner else { return t };
    match t.find('\n').filter(|_| t.starts_with("# ")) {
        Some(eol) => t.insert_str(eol + 1, &format!("\n{banner}\n")),
        None => t.insert_str(0, &format!("{banner}\n\n")),
    }
    t
}

#[cfg(test)]
mod tests {
    use super::*;
    use serde_json::json;

    #[test]
    fn revisions() {
        let c = "2026 now";
        assert_eq!(
            revision_of(&json!({"made": {"solver_revision": c}}), c),
            Revision::Current
        );
        assert_eq!(
            revision_of(&json!({"made": {"solver_revision": null}}), c),
            Revision::Current
        );
        assert_eq!(
            revision_of(&json!({"solver_revision": "old"}), c),
            Revision::Other("old".into())
        );
        assert_eq!(
            revision_of(&json!({"version": "0.1.0"}), c),
            Revision::Unknown
        );
        assert_eq!(
            revision_of(&json!({"inputs": {"solver_revision": c}, "row": {}}), c),
            Revision::Current
        );
        let now = json!({"made": {"solver_revision": c}});
        let old = json!({"solver_revision": "old"});
        let none = json!({"x": 1});
        assert_eq!(revision_of(&json!([now, now]), c), Revision::Current);
        assert_eq!(revision_of(&json!([now, none]), c), Revision::Unknown);
        assert_eq!(
            revision_of(&json!([none, old, now]), c),
            Revision::Other("old".into())
        );
    }

    #[test]
    fn the_banner_comes_and_goes() {
        let b = banner(&[("a.json".into(), Revision::Unknown)], 2, "now").unwrap();
        assert!(b.contains("1 of the 2") && b.contains("`a.json` (no revision recorded)"));
        for text in ["# Title\n\nBody.\n", "Body.\n\nMore.\n"] {
            let with = with_banner(text, Some(&b));
            assert!(with.contains(&b), "{with}");
            assert_eq!(with_banner(&with, Some(&b)), with, "idempotent");
            assert_eq!(with_banner(&with, None), text, "removed cleanly");
        }
        let with = with_banner("# Title\n\nBody.\n", Some(&b));
        assert!(
            with.starts_with(&format!("# Title\n\n{b}\n\nBody.")),
            "{with}"
        );
        assert!(banner(&[], 2, "now").is_none());
    }
}
