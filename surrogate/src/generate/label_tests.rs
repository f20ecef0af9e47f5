//! `hpge-cv label`: old-format rows get the labels `generate` writes for them; an interrupted
//! run resumes; another input in the same folder is refused.

use super::*;
use crate::generate::{Generator, Shard, run};
use crate::sequence::SequenceKind;
use crate::space::ParameterSpace;
use hpge_solver::FieldSettings;

fn repo(p: &str) -> PathBuf {
    PathBuf::from(env!("CARGO_MANIFEST_DIR")).join("..").join(p)
}

#[test]
fn old_rows_get_the_labels_generate_writes_and_a_resume_finishes_them() {
    let space = ParameterSpace::from_file(&repo("spaces/super-siegfried-rz.toml")).unwrap();
    let mut settings = FieldSettings::default();
    settings.grid.adaptive = false;
    let g = Generator::new(
        space,
        &repo("detectors/super-siegfried-k1.toml"),
        settings,
        SequenceKind::Golden,
        0,
        40,
        4,
        Shard::WHOLE,
    )
    .unwrap();
    let base = std::env::temp_dir().join(format!("hpge-label-{}", std::process::id()));
    let _ = std::fs::remove_dir_all(&base);
    let gen_dir = base.join("gen");
    run(&g, &gen_dir, Some(1), |_, _| {}).unwrap();
    let new_text = std::fs::read_to_string(gen_dir.join("rows.csv")).unwrap();
    let header: Vec<&str> = new_text.lines().next().unwrap().split(',').collect();
    let col = |n: &str| header.iter().position(|h| *h == n).unwrap();
    let (pockets, status) = (col("pockets"), col("status"));
    let mut new_rows: Vec<Vec<&str>> = new_text
        .lines()
        .skip(1)
        .map(|l| l.split(',').collect())
        .collect();
    new_rows.sort_by_key(|f| f[0].parse::<u64>().unwrap());
    // The same rows in the old format (..., c12_pF, status, seconds), row 41 failed.
    let mut old = header[..=status].join(",") + ",seconds\n";
    for f in &new_rows {
        let mut head: Vec<&str> = f[..=status].to_vec();
        if f[0] == "41" {
            head[status - 1] = "NaN";
            head[status] = "failed: a test";
        }
        old.push_str(&format!("{},1.0\n", head.join(",")));
    }
    let old_path = base.join("old.csv");
    std::fs::write(&old_path, &old).unwrap();
    let out = base.join("labelled");
    // Interrupted after two rows: the run resumes and finishes, sorted.
    let first = label(&g.exact, &old_path, &out, Some(1), |_, _| {}).unwrap();
    assert_eq!((first.solved, first.copied, first.total), (3, 1, 4));
    assert!(first.sorted);
    let done = std::fs::read_to_string(out.join("rows.csv")).unwrap();
    let cut: Vec<&str> = done.lines().take(3).collect();
    std::fs::write(out.join("rows.csv"), cut.join("\n") + "\n").unwrap();
    let again = label(&g.exact, &old_path, &out, Some(1), |_, _| {}).unwrap();
    assert_eq!((again.resumed, again.solved, again.copied), (2, 2, 0));
    let text = std::fs::read_to_string(out.join("rows.csv")).unwrap();
    let lh: Vec<&str> = text.lines().next().unwrap().split(',').collect();
    let lcol = |n: &str| lh.iter().position(|h| *h == n).unwrap();
    let rows: Vec<Vec<&str>> = text
        .lines()
        .skip(1)
        .map(|l| l.split(',').collect())
        .collect();
    assert_eq!(rows.len(), 4);
    for (f, n) in rows.iter().zip(&new_rows) {
        assert_eq!(f[0], n[0], "sorted by index");
        if f[0] == "41" {
            assert_eq!(f[lcol("pockets")], "NaN");
            continue;
        }
        // The labels and the label solve's c12 are what `generate` wrote for the row.
        for (k, name) in REGIME_COLUMNS.iter().enumerate() {
            assert_eq!(f[lcol(name)], n[pockets + k], "{name} of row {}", f[0]);
        }
        assert_eq!(f[lcol(LABEL_C12_COLUMN)], n[col("c12_pF")]);
        assert_eq!(f[lcol("c12_err_pF")], n[col("c12_err_pF")]);
    }
    // Another input in the same folder is refused, naming both.
    std::fs::write(&old_path, old.replace(",1.0\n", ",2.0\n")).unwrap();
    let err = label(&g.exact, &old_path, &out, Some(1), |_, _| {})
        .unwrap_err()
        .to_string();
    assert!(
        err.contains("another run") && err.contains("--out"),
        "{err}"
    );
    let _ = std::fs::remove_dir_all(&base);
}

/// Held-out row 100036 (437.9 V, no pocket) lies 11 V below a pinch-off: c12 falls by 8%
/// between 448 and 451 V, where a pocket forms (solved at 3 V steps, default settings). The
/// label's switch, bisected on the row's final mesh, lands between them.
#[test]
fn the_switch_of_a_row_below_pinch_off_is_where_the_pocket_forms_and_c12_jumps() {
    let space = ParameterSpace::from_file(&repo("spaces/super-siegfried-rz.toml")).unwrap();
    let g = Generator::new(
        space,
        &repo("detectors/super-siegfried-k1.toml"),
        FieldSettings::default(),
        SequenceKind::Golden,
        0,
        100_036,
        1,
        Shard::WHOLE,
    )
    .unwrap();
    let (_, x) = g.space.from_sampled_unit(&g.sequence.point(100_036));
    let b = x.len() - 1;
    assert!((x[b] - 437.89).abs() < 0.01, "bias {}", x[b]);
    let (_, _, regime, switch) = g.exact.solve_labelled_switch(&x, SWITCH_WINDOW_V).unwrap();
    assert_eq!(regime.pockets, 0);
    assert!(switch > 448.0 && switch < 451.0, "switch at {switch} V");
    let at = |u: f64| {
        let mut y = x.clone();
        y[b] = u;
        g.exact.solve_labelled(&y).unwrap()
    };
    let (below, _, r_below) = at(448.0);
    let (above, _, r_above) = at(451.0);
    assert_eq!((r_below.pockets, r_above.pockets), (0, 1));
    assert!(above < 0.95 * below, "c12 {below} -> {above} pF");
}
