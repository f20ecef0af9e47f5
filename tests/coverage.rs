//! `hpge-cv validate coverage` loses nothing when killed: each truth is written as it finishes,
//! and the same command again takes them back and ends with the numbers of a run that was never
//! interrupted; shards of one study share its folder. (The study's statistics, extension and the
//! full pipeline on exact-model data at library level: `validation/tests/coverage_resume.rs`.)

mod common;

use common::{kill_when, ok, run, temp};

/// B_Z's parameters with narrow uniform priors around the manufacturer's levels: one mode, so
/// each truth's fit converges in a few seconds (the shipped B_Z prior has two, and its fits take
/// up to the study's minute).
const NARROW: &str = "name = \"narrow\"\ndescription = \"B_Z near the manufacturer's levels\"\n\
[[parameters]]\nname = \"d_li_mm\"\ninputs = [\"d_li_mm\"]\nprior = { distribution = \"uniform\", lo = 0.9, hi = 1.1 }\n\
[[parameters]]\nname = \"y_bot\"\ninputs = [\"y1_bot\", \"y2_bot\", \"y3_bot\", \"y4_bot\"]\nprior = { distribution = \"uniform\", lo = 0.69, hi = 0.72 }\n\
[[parameters]]\nname = \"y_top\"\ninputs = [\"y1_top\", \"y2_top\", \"y3_top\", \"y4_top\"]\nprior = { distribution = \"uniform\", lo = 0.54, hi = 0.56 }\n";

fn args(prior: &str, out: &str, extra: &[&str]) -> Vec<String> {
    let mut a: Vec<String> = [
        "validate",
        "coverage",
        "--prior",
        prior,
        "--truths",
        "4",
        "--ess",
        "60",
        "--ranks",
        "9",
        "--mode-starts",
        "2",
        "--json",
        "--out",
        out,
    ]
    .iter()
    .map(|s| s.to_string())
    .collect();
    a.extend(extra.iter().map(|s| s.to_string()));
    a
}

fn json(args: &[String]) -> serde_json::Value {
    let a: Vec<&str> = args.iter().map(String::as_str).collect();
    serde_json::from_str(ok(&run(&a)).trim()).expect("one JSON object")
}

#[test]
fn a_killed_study_resumes_and_shards_share_a_folder() {
    let d = temp("coverage");
    let prior = d.join("narrow.toml");
    std::fs::write(&prior, NARROW).unwrap();
    let p = prior.to_str().unwrap();
    let reference = json(&args(p, d.join("whole").to_str().unwrap(), &[]));
    assert_eq!(reference["n_truths"], 4);
    assert_eq!(reference["resumed"], 0);
    // Killed (SIGKILL) as soon as its first truth is written, then started again.
    let killed = d.join("killed");
    let a = args(p, killed.to_str().unwrap(), &[]);
    let truths = killed.join("truths");
    kill_when(
        &a.iter().map(String::as_str).collect::<Vec<_>>(),
        "the first truth",
        || {
            std::fs::read_dir(&truths).is_ok_and(|r| {
                r.filter_map(|e| e.ok())
                    .any(|e| e.path().extension().is_some_and(|x| x == "json"))
            })
        },
    );
    let again = json(&a);
    let resumed = again["resumed"].as_u64().unwrap();
    assert!((1..4).contains(&resumed), "{again}");
    assert_eq!(again["parameters"], reference["parameters"]);
    // Two shards into one folder: the first reports what is missing, the second the study.
    let shards = d.join("shards");
    let s = shards.to_str().unwrap();
    let first = args(p, s, &["--shard", "1/2"]);
    let out = ok(&run(&first.iter().map(String::as_str).collect::<Vec<_>>()));
    assert!(out.contains("2 of 4 truths"), "{out}");
    // A look at the half-done study (--progress) runs nothing and changes nothing.
    let files = || {
        let mut f: Vec<_> = std::fs::read_dir(shards.join("truths"))
            .unwrap()
            .filter_map(|e| e.ok().map(|e| e.path()))
            .collect();
        f.sort();
        f
    };
    let before = files();
    let peek = json(&args(p, s, &["--progress"]));
    assert_eq!(
        (
            &peek["partial"],
            &peek["done"],
            &peek["total"],
            &peek["n_truths"]
        ),
        (&true.into(), &2.into(), &4.into(), &2.into()),
        "{peek}"
    );
    assert_eq!(files(), before);
    let joined = json(&args(p, s, &["--shard", "0/2"]));
    assert_eq!(joined["parameters"], reference["parameters"]);
    // Once every truth is done, the look gives the study's own statistics.
    let peek = json(&args(p, s, &["--progress"]));
    assert_eq!((&peek["done"], &peek["pass"]), (&4.into(), &joined["pass"]));
    assert_eq!(peek["parameters"], reference["parameters"]);
    // A folder without a study has none done, and is not made.
    let none = json(&args(p, d.join("none").to_str().unwrap(), &["--progress"]));
    assert_eq!((&none["done"], &none["partial"]), (&0.into(), &true.into()));
    assert!(!d.join("none").exists());
    let _ = std::fs::remove_dir_all(&d);
}
