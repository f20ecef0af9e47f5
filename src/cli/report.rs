//! `hpge-cv report paper`: every figure of the paper this project can produce, made in one run
//! with this project's numbers ([`hpge_reports::paper::run_paper`]), and a README that sets each
//! beside the paper's statement about it.

use anyhow::Result;
use hpge_reports::paper::PaperOptions;

/// `report`: reports made of several commands' results.
#[derive(Debug, clap::Args)]
pub struct ReportArgs {
    #[command(subcommand)]
    what: ReportKind,
}

#[derive(Debug, clap::Subcommand)]
enum ReportKind {
    /// Every paper figure the project can produce, with its own numbers, and README.md listing
    /// each beside the paper's statement and whether this project agrees (about 10 min on 2 cores).
    Paper(PaperOptions),
    /// The status table of the README, derived from the shipped results files (fits, coverage
    /// studies, the default surrogate's held-out figures, the solver's accuracy).
    Status(StatusArgs),
    /// Draws a coverage study's figures again from its coverage.json (the study is not run).
    Coverage(CoverageArgs),
    /// Checks every number that the repository's reports quote against its results file
    /// (README.md and the markdown under docs/, reports/, models/, data/; the markers of
    /// `hpge_reports::numbers`) and the banner of each report made from results older than the
    /// solver's physics revision; with --write, fills them. Exit 1 where a report differs and
    /// --write is not given.
    Numbers(NumbersArgs),
}

/// `report numbers`.
#[derive(Debug, clap::Args)]
struct NumbersArgs {
    /// The repository whose reports and results files are read.
    #[arg(long, default_value = ".")]
    root: std::path::PathBuf,
    /// Write the numbers and banners into the reports (only the reports that differ change).
    #[arg(long)]
    write: bool,
    /// Only these reports (paths relative to --root); all of them when none is given.
    files: Vec<String>,
}

/// `report coverage`.
#[derive(Debug, clap::Args)]
struct CoverageArgs {
    /// The study's folder (holding coverage.json), e.g. reports/coverage/b-rz.
    dir: std::path::PathBuf,
}

/// `report status`.
#[derive(Debug, clap::Args)]
struct StatusArgs {
    /// The repository whose results files are read.
    #[arg(long, default_value = ".")]
    root: std::path::PathBuf,
    /// Also write the table into this file, between its status markers (e.g. README.md).
    #[arg(long)]
    write: Option<std::path::PathBuf>,
}

/// Runs `report`.
pub fn run(a: &ReportArgs) -> Result<()> {
    match &a.what {
        ReportKind::Paper(p) => paper(p),
        ReportKind::Status(s) => status(s),
        ReportKind::Numbers(n) => numbers(n),
        ReportKind::Coverage(c) => {
            let files = hpge_reports::plot::redraw_coverage(&c.dir)?;
            for f in files {
                outln!("{}", f.display());
            }
            Ok(())
        }
    }
}

/// Runs `report numbers`: a line per report, one per difference; with `--write` the reports
/// that differ are written.
fn numbers(a: &NumbersArgs) -> Result<()> {
    let current = hpge_solver::field::PHYSICS_REVISION;
    let filled: Vec<_> = hpge_reports::numbers::fill_repository(&a.root, current)?
        .into_iter()
        .filter(|f| a.files.is_empty() || a.files.iter().any(|x| f.file == std::path::Path::new(x)))
        .collect();
    let (mut differing, mut quoted, mut older) = (0, 0, 0);
    for f in &filled {
        quoted += f.numbers;
        let old = f.older().len();
        if old > 0 {
            older += 1;
        }
        outln!(
            "{}: {} number(s) from {} results file(s){}{}",
            f.file.display(),
            f.numbers,
            f.sources.len(),
            if old > 0 {
                format!(", {old} older than the solver's revision")
            } else {
                String::new()
            },
            if f.differences.is_empty() {
                ""
            } else {
                ", differs:"
            }
        );
        for d in &f.differences {
            outln!(
                "  line {}: {}: \"{}\" -> \"{}\"",
                d.line,
                d.what,
                d.found,
                d.expected
            );
        }
        if !f.differences.is_empty() {
            differing += 1;
            if a.write {
                let path = a.root.join(&f.file);
                hpge_files::write(&path, &f.text)
                    .map_err(|e| anyhow::anyhow!("{}: cannot write: {e}", path.display()))?;
            }
        }
    }
    outln!(
        "{} report(s), {quoted} number(s); {older} made from older results; {differing} {}",
        filled.len(),
        if a.write { "written" } else { "differ" }
    );
    if differing > 0 && !a.write {
        return Err(super::StudyFailed(format!(
            "report numbers: {differing} report(s) differ from their results files (`hpge-cv report numbers --write` fills them)"
        ))
        .into());
    }
    Ok(())
}

/// Runs `report status`: prints the table and, with `--write`, puts it into the file.
fn status(a: &StatusArgs) -> Result<()> {
    use hpge_reports::status::{status_rows, status_table, with_table};
    let rows = status_rows(&a.root, hpge_inference::fit::DEFAULT_MODEL)?;
    let table = status_table(&rows);
    // A file without the markers is refused before anything is printed.
    let written = match &a.write {
        Some(file) => {
            let text = std::fs::read_to_string(file)
                .map_err(|e| anyhow::anyhow!("{}: cannot read: {e}", file.display()))?;
            Some((file, with_table(&text, &table, file)?))
        }
        None => None,
    };
    out!("{table}");
    if let Some((file, new)) = written {
        hpge_files::write(file, new)
            .map_err(|e| anyhow::anyhow!("{}: cannot write: {e}", file.display()))?;
        eprintln!("status table written into {}", file.display());
    }
    Ok(())
}

/// Runs `report paper` with progress on stderr and the fits' summaries on stdout. A folder
/// holding a report of another run (other `--quick` or `--exact-check`) is refused unless
/// `--force`.
pub fn paper(a: &PaperOptions) -> Result<()> {
    let record = serde_json::json!({ "quick": a.quick, "exact_check": a.exact_check });
    let describe = |v: &serde_json::Value| {
        format!(
            "report paper{}{}",
            if v["quick"] == true { " --quick" } else { "" },
            if v["exact_check"] == true {
                " --exact-check"
            } else {
                ""
            }
        )
    };
    if let Some(w) = hpge_reports::replace::check_replace(
        &a.out.join("report.json"),
        &record,
        &describe,
        a.force,
    )? {
        eprintln!("warning: {w}");
    }
    eprintln!("report paper: the report's folder is {}", a.out.display());
    let r = hpge_reports::paper::run_paper(
        a.out.clone(),
        a.quick,
        a.exact_check,
        Box::new(crate::cli::fit::ReportDisplay::new()),
        &|name, k, n, seconds| eprintln!("[report {seconds:6.1} s] step {k}/{n}: {name}"),
    )?;
    eprintln!(
        "[report {:6.1} s] {} figure files in {}; {}",
        r.seconds,
        r.files,
        r.figures_dir.display(),
        r.readme.display()
    );
    outln!(
        "report paper: {} figures ({} files) in {:.1} s; see {}",
        r.figures,
        r.files,
        r.seconds,
        r.readme.display()
    );
    Ok(())
}
