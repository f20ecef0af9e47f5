//! Curve mode: rows equal point-mode solves at the same x, the bias strata, resume after a
//! cut-off write.

use std::path::PathBuf;

use hpge_solver::FieldSettings;

use super::{Generator, Shard, run};
use crate::sequence::SequenceKind;
use crate::space::ParameterSpace;

fn repo(p: &str) -> PathBuf {
    PathBuf::from(env!("CARGO_MANIFEST_DIR")).join("..").join(p)
}

/// Super-Siegfried's space on the default grid without adaptive refinement (fast), `n` rows of
/// `k` per point.
fn generator(n: u64, k: u64) -> Generator {
    let space = ParameterSpace::from_file(&repo("spaces/super-siegfried-rz.toml")).unwrap();
    let mut settings = FieldSettings::default();
    settings.grid.adaptive = false;
    Generator::new(
        space,
        &repo("detectors/super-siegfried-k1.toml"),
        settings,
        SequenceKind::Golden,
        0,
        0,
        n,
        Shard::WHOLE,
    )
    .unwrap()
    .with_curve_points(k)
    .unwrap()
}

#[test]
fn curve_rows_are_point_solves_on_bias_strata() {
    let k = 3;
    let g = generator(3, k);
    let rows = g.unit(1);
    assert_eq!(rows.len(), 3);
    let b = g.space.dim() - 1; // U_B is the last column of this space
    let (lo, hi) = (
        g.space.dimensions[b].range[0],
        g.space.dimensions[b].range[1],
    );
    for (j, r) in rows.iter().enumerate() {
        assert_eq!(r.index, k + j as u64);
        assert_eq!(r.status, "ok");
        // Row j's bias lies in stratum j of the range; the other coordinates are the point's.
        let u_b = r.u[b];
        assert!(u_b >= j as f64 / k as f64 && u_b < (j + 1) as f64 / k as f64);
        assert!((r.x[b] - (lo + u_b * (hi - lo))).abs() < 1e-9 * hi);
        assert_eq!(r.u[..b], rows[0].u[..b]);
        // The same number as point mode at this x (cold continuation), and the same error
        // estimate: finite, non-negative, written to the row.
        let (c, err) = g.exact.solve_with_error(&r.x).unwrap();
        assert_eq!(
            c.to_bits(),
            r.c12_pf.to_bits(),
            "row {j}: {c} vs {}",
            r.c12_pf
        );
        assert_eq!(err.to_bits(), r.c12_err_pf.to_bits(), "row {j}");
        assert!(
            err.is_finite() && err >= 0.0,
            "row {j}: error estimate {err}"
        );
        assert!(super::format_row(r).contains(&format!(",ok,{err},")));
        // The regime is the point solve's pockets, written between the error and the time.
        let (_, _, regime) = g.exact.solve_labelled(&r.x).unwrap();
        assert_eq!(r.regime.map(|x| x.pockets), Some(regime.pockets));
        assert!(
            super::format_row(r)
                .contains(&format!(",ok,{err},{},", super::Regime::csv(Some(&regime))))
        );
    }
    // The three strata's shift is the point's own quasi-random bias coordinate.
    let shift = rows[0].u[b] * k as f64;
    for (j, r) in rows.iter().enumerate() {
        assert!((r.u[b] * k as f64 - j as f64 - shift).abs() < 1e-12);
    }
}

#[test]
fn counts_must_be_multiples_and_the_fingerprint_records_k() {
    let space = ParameterSpace::from_file(&repo("spaces/super-siegfried-rz.toml")).unwrap();
    let g = |n| {
        Generator::new(
            space.clone(),
            &repo("detectors/super-siegfried-k1.toml"),
            FieldSettings::default(),
            SequenceKind::Golden,
            0,
            0,
            n,
            Shard::WHOLE,
        )
        .unwrap()
    };
    let err = g(7).with_curve_points(3).unwrap_err().to_string();
    assert!(
        err.contains("--curve-points") && err.contains("multiples of 3"),
        "{err}"
    );
    assert!(g(6).with_curve_points(0).is_err());
    assert_eq!(
        g(6).with_curve_points(3).unwrap().fingerprint.curve_points,
        3
    );
    // Point mode leaves the fingerprint's JSON as it was before curve mode.
    let json = serde_json::to_string(&g(6).fingerprint).unwrap();
    assert!(!json.contains("curve_points"), "{json}");
}

#[test]
fn a_point_cut_off_mid_curve_is_solved_again_without_duplicates() {
    let dir = std::env::temp_dir().join(format!("hpge-curve-resume-{}", std::process::id()));
    let _ = std::fs::remove_dir_all(&dir);
    let g = generator(4, 2);
    let first = run(&g, &dir, Some(1), |_, _| {}).unwrap();
    assert_eq!((first.written, first.total), (4, 4));
    let rows_path = dir.join("rows.csv");
    let full = std::fs::read_to_string(&rows_path).unwrap();
    let sorted = |t: &str| {
        let mut v: Vec<String> = t
            .lines()
            .skip(1)
            .map(|l| l[..l.rfind(',').unwrap()].to_string())
            .collect();
        v.sort();
        v
    };
    // Drop the last row: its point keeps one of its two rows.
    let cut: Vec<&str> = full.lines().collect();
    std::fs::write(&rows_path, cut[..cut.len() - 1].join("\n") + "\n").unwrap();
    let again = run(&g, &dir, Some(1), |_, _| {}).unwrap();
    assert!(again.repaired);
    assert_eq!((again.resumed, again.written, again.total), (2, 2, 4));
    let now = std::fs::read_to_string(&rows_path).unwrap();
    assert_eq!(sorted(&now), sorted(&full));
    let _ = std::fs::remove_dir_all(&dir);
}

#[test]
fn retry_failed_solves_failed_rows_again_and_keeps_the_others() {
    let dir = std::env::temp_dir().join(format!("hpge-retry-failed-{}", std::process::id()));
    let _ = std::fs::remove_dir_all(&dir);
    let g = generator(3, 1);
    run(&g, &dir, Some(1), |_, _| {}).unwrap();
    let rows_path = dir.join("rows.csv");
    let full = std::fs::read_to_string(&rows_path).unwrap();
    // Row 1 as a failed solve would have written it: NaN c12, error and regime, and the
    // reason (columns found by name).
    let header: Vec<&str> = full.lines().next().unwrap().split(',').collect();
    let col = |name: &str| header.iter().position(|h| *h == name).unwrap();
    let failed_line = |l: &str| {
        let mut g: Vec<String> = l.split(',').map(|s| s.to_string()).collect();
        for name in [
            "c12_pF",
            "c12_err_pF",
            "pockets",
            "pocket_level_V",
            "pocket_cm3",
        ] {
            g[col(name)] = "NaN".into();
        }
        g[col("status")] = "failed: the fast solver did not converge".into();
        g.join(",")
    };
    let hurt: Vec<String> = full
        .lines()
        .map(|l| {
            if l.starts_with("1,") {
                failed_line(l)
            } else {
                l.to_string()
            }
        })
        .collect();
    std::fs::write(&rows_path, hurt.join("\n") + "\n").unwrap();
    // A plain resume keeps the failed row.
    let plain = run(&g, &dir, Some(1), |_, _| {}).unwrap();
    assert_eq!((plain.written, plain.retried), (0, 0));
    // With the retry, row 1 is solved again; the others are untouched.
    let retry = run(&g.with_retry_failed(true), &dir, Some(1), |_, _| {}).unwrap();
    assert_eq!((retry.resumed, retry.written, retry.retried), (2, 1, 1));
    assert!(!retry.repaired);
    let now = std::fs::read_to_string(&rows_path).unwrap();
    let without_seconds = |t: &str| {
        let mut v: Vec<String> = t
            .lines()
            .map(|l| l[..l.rfind(',').unwrap()].to_string())
            .collect();
        v.sort();
        v
    };
    assert_eq!(without_seconds(&now), without_seconds(&full));
    let _ = std::fs::remove_dir_all(&dir);
}

#[test]
fn rows_carry_the_regime_columns_and_a_run_from_before_them_resumes_in_its_own_format() {
    let g = generator(3, 1);
    assert!(
        g.header()
            .ends_with(",c12_pF,status,c12_err_pF,pockets,pocket_level_V,pocket_cm3,seconds")
    );
    let dir = std::env::temp_dir().join(format!("hpge-regime-cols-{}", std::process::id()));
    let _ = std::fs::remove_dir_all(&dir);
    let new = run(&g, &dir, Some(1), |_, _| {}).unwrap();
    assert_eq!(new.written, 3);
    let text = std::fs::read_to_string(dir.join("rows.csv")).unwrap();
    let header: Vec<&str> = text.lines().next().unwrap().split(',').collect();
    let pockets = header.iter().position(|h| *h == "pockets").unwrap();
    for line in text.lines().skip(1) {
        let f: Vec<&str> = line.split(',').collect();
        assert_eq!(f.len(), header.len());
        let r = super::Regime::parse(f[pockets], f[pockets + 1], f[pockets + 2]);
        assert!(r.is_some(), "{line}");
    }
    // A run started before the columns existed: its generate.json and rows have the old
    // header. Resuming it keeps that format (no mixed rows), and its rows are the new rows
    // less the three regime fields.
    let old_dir = dir.with_extension("old");
    let _ = std::fs::remove_dir_all(&old_dir);
    std::fs::create_dir_all(&old_dir).unwrap();
    let info_text = std::fs::read_to_string(dir.join("generate.json")).unwrap();
    let mut info: super::RunInfo = serde_json::from_str(&info_text).unwrap();
    info.header = g.header_with(false);
    std::fs::write(
        old_dir.join("generate.json"),
        serde_json::to_string_pretty(&info).unwrap(),
    )
    .unwrap();
    let strip = |line: &str| {
        let mut f: Vec<&str> = line.split(',').collect();
        f.drain(pockets..pockets + 3);
        f.join(",")
    };
    let first_two: Vec<String> = text.lines().skip(1).take(2).map(strip).collect();
    std::fs::write(
        old_dir.join("rows.csv"),
        format!("{}\n{}\n", info.header, first_two.join("\n")),
    )
    .unwrap();
    let resumed = run(&g, &old_dir, Some(1), |_, _| {}).unwrap();
    assert_eq!((resumed.resumed, resumed.written), (2, 1));
    let old_text = std::fs::read_to_string(old_dir.join("rows.csv")).unwrap();
    let n_old = info.header.split(',').count();
    assert!(old_text.lines().all(|l| l.split(',').count() == n_old));
    let no_time = |l: &str| l[..l.rfind(',').unwrap()].to_string();
    let last_new = strip(text.lines().nth(3).unwrap());
    assert_eq!(
        no_time(old_text.lines().nth(3).unwrap()),
        no_time(&last_new)
    );
    let _ = std::fs::remove_dir_all(&dir);
    let _ = std::fs::remove_dir_all(&old_dir);
}

#[test]
fn a_run_of_another_solver_revision_is_never_resumed() {
    let g = generator(2, 1);
    let dir = std::env::temp_dir().join(format!("hpge-revision-{}", std::process::id()));
    let _ = std::fs::remove_dir_all(&dir);
    // One row of the run, as a run cut off after it would leave.
    let one = generator(1, 1);
    run(&one, &dir, Some(1), |_, _| {}).unwrap();
    let info_path = dir.join("generate.json");
    let mut info: super::RunInfo =
        serde_json::from_str(&std::fs::read_to_string(&info_path).unwrap()).unwrap();
    assert_eq!(
        info.solver_revision.as_deref(),
        Some(hpge_solver::field::PHYSICS_REVISION)
    );
    info.fingerprint = g.fingerprint.clone();
    let write = |info: &super::RunInfo| {
        std::fs::write(&info_path, serde_json::to_string_pretty(info).unwrap()).unwrap()
    };
    info.solver_revision = Some("1999-01-01 another physics".into());
    write(&info);
    let e = run(&g, &dir, Some(1), |_, _| {}).unwrap_err().to_string();
    assert!(
        e.contains("1999-01-01 another physics")
            && e.contains(hpge_solver::field::PHYSICS_REVISION)
            && e.contains("another folder"),
        "{e}"
    );
    // A run from before the revision was recorded resumes as it did.
    info.solver_revision = None;
    write(&info);
    let resumed = run(&g, &dir, Some(1), |_, _| {}).unwrap();
    assert_eq!((resumed.resumed, resumed.written), (1, 1));
    let _ = std::fs::remove_dir_all(&dir);
}
