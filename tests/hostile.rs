//! The bad-input suite (issue 24): every command over a table of hostile inputs,
//! `tests/hostile/cases.toml`. Each case runs the binary under `ulimit -v` (memory bounded) in the
//! repository root and must end with its documented exit code (2 for bad input), name the file,
//! flag or key at fault on stderr, never panic or abort, and leave none of the listed outputs
//! behind. To add a case, add a `[[case]]` to the table: see its header for the fields.
//!
//! The cases of issue 24's groups 8 to 11 have one test each below (`case!`); every other case
//! runs in `the_rest_of_the_table`, several at a time.

use std::collections::BTreeSet;
use std::path::{Path, PathBuf};
use std::process::Command;
use std::sync::Mutex;

use serde::Deserialize;

/// Virtual-memory bound (KiB) of a case unless it sets `memory_kib`: 4 GiB, far above what a
/// refusal needs and far below what an unbounded allocation would take.
const DEFAULT_MEMORY_KIB: u64 = 4 * 1024 * 1024;

#[derive(Debug, Deserialize)]
#[serde(deny_unknown_fields)]
struct Table {
    case: Vec<Case>,
}

#[derive(Debug, Clone, Deserialize)]
#[serde(deny_unknown_fields)]
struct Case {
    name: String,
    /// The group (8, 9, 10, 11), or 0 for the broad set.
    #[serde(default)]
    group: u32,
    args: Vec<String>,
    #[serde(default)]
    files: Vec<FileSpec>,
    #[serde(default)]
    folders: Vec<String>,
    exit: i32,
    #[serde(default)]
    stderr: Vec<String>,
    #[serde(default)]
    stderr_not: Vec<String>,
    #[serde(default)]
    once: Vec<String>,
    #[serde(default)]
    absent: Vec<String>,
    /// Files that must hold the same bytes after the run as before (inputs never overwritten).
    #[serde(default)]
    unchanged: Vec<String>,
    /// Where stdout goes: "full" (`/dev/full`: every write fails with ENOSPC) or "closed" (a
    /// pipe whose reader has gone: every write fails with EPIPE); captured otherwise.
    #[serde(default)]
    stdout: Option<String>,
    /// Hard links (existing, new) made in the case's folder after `files`.
    #[serde(default)]
    link: Vec<[String; 2]>,
    #[serde(default)]
    memory_kib: Option<u64>,
    /// Seconds after which the run is killed (SIGKILL; the case then fails on its exit code):
    /// for a case that would otherwise not end at all on the code before its fix.
    #[serde(default)]
    timeout_s: Option<u64>,
    /// Environment variables removed for the run.
    #[serde(default)]
    unset: Vec<String>,
    /// The case needs the wgpu backend: skipped where no adapter is found (unless
    /// `HPGE_REQUIRE_GPU=1`, as in CI, where Mesa's software Vulkan provides one).
    #[serde(default)]
    needs_gpu: bool,
    #[serde(default)]
    #[allow(dead_code)]
    why: String,
}

/// A file a case writes into its temporary folder before it runs.
#[derive(Debug, Clone, Deserialize)]
#[serde(deny_unknown_fields)]
struct FileSpec {
    path: String,
    /// Literal content.
    #[serde(default)]
    text: Option<String>,
    /// Or a shipped file (relative to the repository root) ...
    #[serde(default)]
    from: Option<String>,
    /// ... cut to its first `head` lines ...
    #[serde(default)]
    head: Option<usize>,
    /// ... with these (old, new) replacements, each of which must match ...
    #[serde(default)]
    replace: Vec<[String; 2]>,
    /// ... and this text in front (e.g. a byte-order mark).
    #[serde(default)]
    prefix: String,
    /// Raw bytes in hex instead of text (binary garbage).
    #[serde(default)]
    hex: Option<String>,
    /// `text` repeated this many times (a long table), `{x}` in it standing for numbers evenly
    /// spaced over `range` (first and last included).
    #[serde(default)]
    repeat: Option<usize>,
    #[serde(default)]
    range: Option<[f64; 2]>,
}

/// The binary the cases run: this build's, or `HPGE_HOSTILE_BIN` (e.g. a build of the code
/// before a fix, to check that a new case fails there).
fn binary() -> String {
    std::env::var("HPGE_HOSTILE_BIN").unwrap_or_else(|_| env!("CARGO_BIN_EXE_hpge-cv").to_string())
}

fn root() -> PathBuf {
    PathBuf::from(env!("CARGO_MANIFEST_DIR"))
}

fn table() -> Vec<Case> {
    let path = root().join("tests/hostile/cases.toml");
    let text = std::fs::read_to_string(&path).unwrap();
    let t: Table = toml::from_str(&text).unwrap_or_else(|e| panic!("{}: {e}", path.display()));
    let mut names = BTreeSet::new();
    for c in &t.case {
        assert!(names.insert(c.name.clone()), "case `{}` twice", c.name);
    }
    t.case
}

fn expand(s: &str, tmp: &Path) -> String {
    s.replace("{tmp}", tmp.to_str().unwrap())
}

fn sh_quote(s: &str) -> String {
    format!("'{}'", s.replace('\'', "'\\''"))
}

fn write_file(f: &FileSpec, tmp: &Path, case: &str) {
    let path = tmp.join(&f.path);
    if let Some(dir) = path.parent() {
        std::fs::create_dir_all(dir).unwrap();
    }
    if let Some(hex) = &f.hex {
        let bytes: Vec<u8> = (0..hex.len())
            .step_by(2)
            .map(|i| u8::from_str_radix(&hex[i..i + 2], 16).unwrap())
            .collect();
        std::fs::write(&path, bytes).unwrap();
        return;
    }
    let mut text = match (&f.text, &f.from) {
        (Some(t), None) => expand(t, tmp),
        (None, Some(from)) => std::fs::read_to_string(root().join(from)).unwrap(),
        _ => panic!("{case}: file {} needs `text` or `from`", f.path),
    };
    if let Some(n) = f.head {
        text = text.lines().take(n).map(|l| format!("{l}\n")).collect();
    }
    if let Some(n) = f.repeat {
        let [a, b] = f.range.unwrap_or([0.0, 0.0]);
        let step = if n > 1 { (b - a) / (n - 1) as f64 } else { 0.0 };
        text = (0..n)
            .map(|i| text.replace("{x}", &(a + step * i as f64).to_string()))
            .collect();
    }
    for [old, new] in &f.replace {
        assert!(
            text.contains(old.as_str()),
            "{case}: `{old}` not in {}",
            f.path
        );
        text = text.replace(old.as_str(), &expand(new, tmp));
    }
    std::fs::write(&path, format!("{}{text}", f.prefix)).unwrap();
}

/// Runs one case; returns the failures (empty: it passed).
fn run_case(c: &Case) -> Vec<String> {
    let tmp = std::env::temp_dir().join(format!("hpge-hostile-{}-{}", std::process::id(), c.name));
    let _ = std::fs::remove_dir_all(&tmp);
    std::fs::create_dir_all(&tmp).unwrap();
    for f in &c.files {
        write_file(f, &tmp, &c.name);
    }
    for d in &c.folders {
        std::fs::create_dir_all(tmp.join(d)).unwrap();
    }
    for [from, to] in &c.link {
        std::fs::hard_link(tmp.join(from), tmp.join(to)).unwrap();
    }
    let args: Vec<String> = c.args.iter().map(|a| sh_quote(&expand(a, &tmp))).collect();
    let script = format!(
        "ulimit -v {}; exec {}{} {}",
        c.memory_kib.unwrap_or(DEFAULT_MEMORY_KIB),
        c.timeout_s
            .map_or(String::new(), |t| format!("timeout --signal=KILL {t} ")),
        sh_quote(&binary()),
        args.join(" ")
    );
    let start = std::time::Instant::now();
    let mut cmd = Command::new("bash");
    cmd.arg("-c")
        .arg(&script)
        .current_dir(root())
        .env("RUST_BACKTRACE", "0");
    for k in &c.unset {
        cmd.env_remove(k);
    }
    let before: Vec<(PathBuf, Option<Vec<u8>>)> = c
        .unchanged
        .iter()
        .map(|f| {
            let p = PathBuf::from(expand(f, &tmp));
            let bytes = std::fs::read(&p).ok();
            (p, bytes)
        })
        .collect();
    let out = match c.stdout.as_deref() {
        None => cmd.output().unwrap(),
        Some("full") => {
            cmd.stdout(std::fs::File::create("/dev/full").unwrap());
            cmd.output().unwrap()
        }
        Some("closed") => {
            cmd.stdout(std::process::Stdio::piped())
                .stderr(std::process::Stdio::piped());
            let mut child = cmd.spawn().unwrap();
            // The only reader of the pipe goes away before the command writes anything.
            drop(child.stdout.take());
            child.wait_with_output().unwrap()
        }
        Some(other) => panic!("{}: stdout = {other:?}: use \"full\" or \"closed\"", c.name),
    };
    let seconds = start.elapsed().as_secs_f64();
    let err = String::from_utf8_lossy(&out.stderr).into_owned();
    let mut fails = Vec::new();
    let code = out.status.code();
    if c.needs_gpu
        && code == Some(2)
        && err.contains("no GPU adapter for the wgpu backend")
        && !std::env::var("HPGE_REQUIRE_GPU").is_ok_and(|v| v == "1")
    {
        eprintln!("{}: skipped, no wgpu adapter here", c.name);
        let _ = std::fs::remove_dir_all(&tmp);
        return fails;
    }
    if code != Some(c.exit) {
        fails.push(format!(
            "exit {:?} (signal or code), expected {}",
            out.status, c.exit
        ));
    }
    if matches!(code, Some(134 | 139)) || code.is_none() {
        fails.push("aborted or killed by a signal".into());
    }
    if err.contains("panicked") {
        fails.push("panicked".into());
    }
    if c.exit == 2 && !err.starts_with("error: ") && !err.contains("\nerror: ") {
        fails.push("no `error:` line".into());
    }
    for n in &c.stderr {
        let n = expand(n, &tmp);
        if !err.contains(&n) {
            fails.push(format!("`{n}` not in stderr"));
        }
    }
    for n in &c.stderr_not {
        if err.contains(&expand(n, &tmp)) {
            fails.push(format!("`{n}` in stderr"));
        }
    }
    for n in &c.once {
        let k = err.matches(n.as_str()).count();
        if k != 1 {
            fails.push(format!("`{n}` {k} times in stderr, expected once"));
        }
    }
    for (p, bytes) in &before {
        if bytes.is_none() {
            fails.push(format!("{}: no such file before the run", p.display()));
        } else if std::fs::read(p).ok() != *bytes {
            fails.push(format!(
                "{} was changed (an input overwritten)",
                p.display()
            ));
        }
    }
    for a in &c.absent {
        let p = PathBuf::from(expand(a, &tmp));
        if p.exists() {
            fails.push(format!("{} was left behind", p.display()));
        }
    }
    if !fails.is_empty() {
        fails.push(format!(
            "args: {:?}\n  stderr: {}",
            c.args,
            err.trim_end().replace('\n', "\n          ")
        ));
    }
    // Everything refused here must be refused before long work starts.
    if seconds > 60.0 {
        fails.push(format!("took {seconds:.0} s"));
    }
    let _ = std::fs::remove_dir_all(&tmp);
    fails
}

fn check(name: &str) {
    let c = table()
        .into_iter()
        .find(|c| c.name == name)
        .unwrap_or_else(|| panic!("no case `{name}` in tests/hostile/cases.toml"));
    let fails = run_case(&c);
    assert!(fails.is_empty(), "{name}:\n  {}", fails.join("\n  "));
}

/// The cases with a test of their own.
const NAMED: &[&str] = &[
    "g8_fit_max_seconds_negative",
    "g8_fit_max_seconds_nan",
    "g8_fit_ess_zero",
    "g8_fit_exact_draws_zero",
    "g8_discover_min_ln_bayes_nan",
    "g8_discover_max_seconds_negative",
    "g9_fit_truth_unknown_name",
    "g9_predict_params_twice",
    "g9_detector_param_twice",
    "g9_simulate_field_without_field_plot",
    "g9_rz_knots_beyond_the_crystal",
    "g9_detector_rz_knots_beyond_the_crystal",
    "g9_train_test_is_data",
    "g9_train_poly3_one_row",
    "g9_generate_space_y_outside",
    "g10_predict_nan_is_not_missing",
    "g10_evaluate_bom",
    "g10_passive_overlaps_the_crystal",
    "g10_both_contacts_at_bias",
    "g10_synthesize_names_flags",
    "g10_os_error_once",
    "g10_detector_plot_to_a_folder",
    "g10_wgpu_run_prints_no_xdg_error",
    "g11_fit_one_row_leaves_nothing",
    "g11_discover_one_row_leaves_nothing_and_names_the_file",
];

macro_rules! case {
    ($($name:ident),* $(,)?) => {
        $(
            #[test]
            fn $name() {
                check(stringify!($name));
            }
        )*
    };
}

case!(
    g8_fit_max_seconds_negative,
    g8_fit_max_seconds_nan,
    g8_fit_ess_zero,
    g8_fit_exact_draws_zero,
    g8_discover_min_ln_bayes_nan,
    g8_discover_max_seconds_negative,
    g9_fit_truth_unknown_name,
    g9_predict_params_twice,
    g9_detector_param_twice,
    g9_simulate_field_without_field_plot,
    g9_rz_knots_beyond_the_crystal,
    g9_detector_rz_knots_beyond_the_crystal,
    g9_train_test_is_data,
    g9_train_poly3_one_row,
    g9_generate_space_y_outside,
    g10_predict_nan_is_not_missing,
    g10_evaluate_bom,
    g10_passive_overlaps_the_crystal,
    g10_both_contacts_at_bias,
    g10_synthesize_names_flags,
    g10_os_error_once,
    g10_detector_plot_to_a_folder,
    g10_wgpu_run_prints_no_xdg_error,
    g11_fit_one_row_leaves_nothing,
    g11_discover_one_row_leaves_nothing_and_names_the_file,
);

#[test]
fn every_group_case_has_its_own_test() {
    let names: BTreeSet<String> = table()
        .iter()
        .filter(|c| c.group != 0)
        .map(|c| c.name.clone())
        .collect();
    let named: BTreeSet<String> = NAMED.iter().map(|s| s.to_string()).collect();
    assert_eq!(names, named, "the group cases and NAMED differ");
}

/// Every case without a test of its own, two at a time (CI has 2 cores).
#[test]
fn the_rest_of_the_table() {
    // `HPGE_HOSTILE_ONLY=PREFIX`: only the cases whose name starts with it.
    let only = std::env::var("HPGE_HOSTILE_ONLY").unwrap_or_default();
    let cases: Vec<Case> = table()
        .into_iter()
        .filter(|c| c.group == 0 && c.name.starts_with(&only))
        .collect();
    assert!(
        !only.is_empty() || cases.len() >= 30,
        "the broad set has {} cases",
        cases.len()
    );
    let next = Mutex::new(cases.iter());
    let failures = Mutex::new(Vec::new());
    std::thread::scope(|s| {
        for _ in 0..2 {
            s.spawn(|| {
                loop {
                    let c = match next.lock().unwrap().next() {
                        Some(c) => c,
                        None => break,
                    };
                    let fails = run_case(c);
                    if !fails.is_empty() {
                        failures.lock().unwrap().push(format!(
                            "{}:\n  {}",
                            c.name,
                            fails.join("\n  ")
                        ));
                    }
                }
            });
        }
    });
    let failures = failures.into_inner().unwrap();
    assert!(
        failures.is_empty(),
        "{} of {} cases failed:\n{}",
        failures.len(),
        cases.len(),
        failures.join("\n")
    );
}
