//! LH5 pulse files: a file written with the layout of legend-pydataobj reads back as the same
//! pulses as the `.npy` file, and every bad file is an error naming the file and the dataset
//! (never a panic, nothing printed by the HDF5 library). The files here are written by
//! `hdf5-pure` (the reader's crate, in Rust) and, in `tests/data/lh5/`, by legend-pydataobj's
//! writer itself (libhdf5 through h5py: chunked, shuffle + gzip, LZF, contiguous, zstd); the
//! comparison of a whole run written by legend-pydataobj is `python/tests/test_lh5.py`.

use std::path::{Path, PathBuf};

use hdf5_pure::{AttrValue, FileBuilder, GroupBuilder};
use hpge_measurement::{Error, PulseSet, read_pulse_file, read_raw_dir, write_pulses};

fn dir(name: &str) -> PathBuf {
    let d = PathBuf::from(env!("CARGO_TARGET_TMPDIR"))
        .join("lh5")
        .join(name);
    let _ = std::fs::remove_dir_all(&d);
    std::fs::create_dir_all(&d).unwrap();
    d
}

fn set(bias_v: f64) -> PulseSet {
    let (n_pulses, n_samples) = (3, 5);
    PulseSet {
        bias_v,
        sampling_period_ns: 4.0,
        n_pulses,
        n_samples,
        charge_pc: (0..n_pulses * n_samples)
            .map(|k| 0.1 * k as f64 + bias_v * 1e-3)
            .collect(),
        source: PathBuf::new(),
    }
}

fn sidecar(lh5: &Path, bias_v: f64) {
    std::fs::write(
        lh5.with_extension("toml"),
        format!("bias_V = {bias_v:?}\nsampling_period_ns = 4.0\ncharge_unit = \"pC\"\n"),
    )
    .unwrap();
}

fn units(unit: &str) -> AttrValue {
    AttrValue::VarLenString(unit.to_string())
}

/// Writes a file of one or more tables: each a group path (`ch000/raw/waveform`, its groups
/// nested) and the function that fills the innermost group.
type Table<'a> = (&'a str, &'a dyn Fn(&mut GroupBuilder));

fn write_file(path: &Path, tables: &[Table]) {
    let mut file = FileBuilder::new();
    for (group_path, fill) in tables {
        let names: Vec<&str> = group_path.split('/').collect();
        let top = file.create_group(names[0]);
        let finished = nest(top, &names[1..], *fill);
        file.add_group(finished);
    }
    file.write(path).unwrap();
}

fn nest(
    mut group: GroupBuilder,
    rest: &[&str],
    fill: &dyn Fn(&mut GroupBuilder),
) -> hdf5_pure::FinishedGroup {
    if rest.is_empty() {
        fill(&mut group);
    } else {
        let child = group.create_group(rest[0]);
        let finished = nest(child, &rest[1..], fill);
        group.add_group(finished);
    }
    group.finish()
}

/// Writes `set` as legend-pydataobj lays out a waveform table: `ch000/raw/waveform/{t0,dt,values}`
/// with `units` attributes (dt in `dt_unit`, scaled accordingly).
fn write_lh5(path: &Path, set: &PulseSet, dt_unit: &str, ns_per_unit: f64) {
    write_file(
        path,
        &[("ch000/raw/waveform", &|table| {
            waveform(table, set, dt_unit, ns_per_unit)
        })],
    );
}

fn waveform(table: &mut GroupBuilder, set: &PulseSet, dt_unit: &str, ns_per_unit: f64) {
    let values: Vec<f32> = set.charge_pc.iter().map(|&q| q as f32).collect();
    table
        .create_dataset("values")
        .with_f32_data(&values)
        .with_shape(&[set.n_pulses as u64, set.n_samples as u64])
        .set_attr("units", units("pC"));
    let dt = vec![set.sampling_period_ns / ns_per_unit; set.n_pulses];
    table
        .create_dataset("dt")
        .with_f64_data(&dt)
        .set_attr("units", units(dt_unit));
    table
        .create_dataset("t0")
        .with_f64_data(&vec![0.0_f64; set.n_pulses]);
}

#[test]
fn lh5_reads_the_same_pulses_as_npy() {
    let d = dir("same");
    let s = set(100.0);
    let npy = d.join("u100.npy");
    write_pulses(&npy, &s, true).unwrap();
    let lh5 = d.join("u100.lh5");
    write_lh5(&lh5, &s, "us", 1e3);
    sidecar(&lh5, 100.0);
    let a = read_pulse_file(&npy).unwrap();
    let b = read_pulse_file(&lh5).unwrap();
    assert_eq!(a.charge_pc, b.charge_pc);
    assert_eq!((b.n_pulses, b.n_samples), (3, 5));
    assert_eq!(b.bias_v, 100.0);
    assert_eq!(b.sampling_period_ns, 4.0);

    // A folder of .lh5 files, and one .lh5 file given instead of a folder.
    let only = dir("folder");
    for u in [50.0, 200.0] {
        let f = only.join(format!("u{u}.lh5"));
        write_lh5(&f, &set(u), "ns", 1.0);
        sidecar(&f, u);
    }
    let run = read_raw_dir(&only, None).unwrap();
    assert_eq!(
        run.sets.iter().map(|s| s.bias_v).collect::<Vec<_>>(),
        [50.0, 200.0]
    );
    assert!(run.problems.is_empty(), "{:?}", run.problems);
    let one = read_raw_dir(&only.join("u50.lh5"), None).unwrap();
    assert_eq!(one.sets.len(), 1);
}

fn expect_lh5_error(path: &Path, dataset_part: &str, reason_part: &str) {
    let err = read_pulse_file(path).unwrap_err();
    let message = err.to_string();
    assert!(
        message.contains(&path.display().to_string()),
        "message does not name the file: {message}"
    );
    match &err {
        Error::Lh5 {
            file,
            dataset,
            reason,
        } => {
            assert_eq!(file, path);
            assert!(dataset.contains(dataset_part), "{message}");
            assert!(reason.contains(reason_part), "{message}");
        }
        other => panic!("expected Error::Lh5, got {other:?}"),
    }
    // The run as a whole: one .lh5 file given as --raw is the error itself.
    assert!(read_raw_dir(path, None).is_err());
}

#[test]
fn truncated_and_non_hdf5_files_are_errors_naming_the_file() {
    let d = dir("truncated");
    // The HDF5 signature and nothing else.
    let cut = d.join("cut.lh5");
    std::fs::write(&cut, b"\x89HDF\r\n\x1a\n\0\0").unwrap();
    sidecar(&cut, 10.0);
    // A valid file cut in half.
    let half = d.join("half.lh5");
    write_lh5(&half, &set(20.0), "ns", 1.0);
    let bytes = std::fs::read(&half).unwrap();
    std::fs::write(&half, &bytes[..bytes.len() / 2]).unwrap();
    sidecar(&half, 20.0);
    // Not HDF5 at all.
    let text = d.join("text.lh5");
    std::fs::write(&text, "bias,values\n").unwrap();
    sidecar(&text, 30.0);
    for path in [&cut, &half, &text] {
        let err = read_pulse_file(path).unwrap_err();
        let message = err.to_string();
        assert!(
            matches!(err, Error::Hdf5Open { .. } | Error::Lh5 { .. }),
            "{message}"
        );
        assert!(message.contains(&path.display().to_string()), "{message}");
        assert!(read_raw_dir(path, None).is_err());
    }
    assert!(matches!(read_pulse_file(&cut), Err(Error::Hdf5Open { .. })));
    // A folder of nothing but bad files: an error listing each.
    let err = read_raw_dir(&d, None).unwrap_err().to_string();
    for path in [&cut, &half, &text] {
        assert!(err.contains(&path.display().to_string()), "{err}");
    }
}

#[test]
fn a_file_without_the_waveform_table_is_an_error_naming_it() {
    let d = dir("layout");

    let empty = d.join("no_table.lh5");
    write_file(
        &empty,
        &[("ch000/raw", &|raw| {
            raw.create_dataset("energy").with_f64_data(&[1.0, 2.0]);
        })],
    );
    sidecar(&empty, 10.0);
    expect_lh5_error(&empty, "waveform", "no waveform table");

    let no_dt = d.join("no_dt.lh5");
    write_file(
        &no_dt,
        &[("raw/waveform", &|table| {
            table
                .create_dataset("values")
                .with_f64_data(&[0.0; 8])
                .with_shape(&[2, 4]);
        })],
    );
    sidecar(&no_dt, 10.0);
    expect_lh5_error(&no_dt, "/raw/waveform/dt", "missing dataset");

    let rank = d.join("rank.lh5");
    write_file(
        &rank,
        &[("raw/waveform", &|table| {
            table
                .create_dataset("values")
                .with_f64_data(&[1.0, 2.0, 3.0]);
        })],
    );
    sidecar(&rank, 10.0);
    expect_lh5_error(&rank, "/raw/waveform/values", "2-D");

    let ints = d.join("ints.lh5");
    write_file(
        &ints,
        &[("raw/waveform", &|table| {
            table
                .create_dataset("values")
                .with_u16_data(&[0; 8])
                .with_shape(&[2, 4]);
        })],
    );
    sidecar(&ints, 10.0);
    expect_lh5_error(&ints, "/raw/waveform/values", "float32 or float64");

    let two = d.join("two_channels.lh5");
    let s10 = set(10.0);
    write_file(
        &two,
        &[
            ("ch000/raw/waveform", &|table| {
                waveform(table, &s10, "ns", 1.0)
            }),
            ("ch001/raw/waveform", &|table| {
                table
                    .create_dataset("values")
                    .with_f64_data(&[0.0; 8])
                    .with_shape(&[2, 4]);
            }),
        ],
    );
    sidecar(&two, 10.0);
    expect_lh5_error(&two, "waveform", "2 waveform tables");

    let unit = d.join("wrong_unit.lh5");
    let mut s = set(10.0);
    s.sampling_period_ns = 8.0;
    write_lh5(&unit, &s, "ns", 1.0);
    sidecar(&unit, 10.0);
    expect_lh5_error(&unit, "/ch000/raw/waveform/dt", "sampling_period_ns");
}

/// The fixtures of `tests/data/lh5/`, written by legend-pydataobj's writer (`make_fixtures.py`).
fn fixture(name: &str) -> PathBuf {
    Path::new(env!("CARGO_MANIFEST_DIR"))
        .join("tests/data/lh5")
        .join(name)
}

#[test]
fn files_written_by_legend_pydataobj_read_as_written() {
    // Sample k (row-major) = 0.1 k + 0.1 pC, stored as float32 or float64.
    let exact: Vec<f64> = (0..15).map(|k| 0.1 * k as f64 + 100.0 * 1e-3).collect();
    let as_f32: Vec<f64> = exact.iter().map(|&q| f64::from(q as f32)).collect();
    for (name, expected) in [
        // The writer's default: chunked, shuffle + gzip.
        ("gzip_f32.lh5", &as_f32),
        // dt in us (4e-3).
        ("gzip_f64_us.lh5", &exact),
        ("lzf_f32.lh5", &as_f32),
        ("contiguous_f64.lh5", &exact),
    ] {
        let set = read_pulse_file(&fixture(name)).unwrap_or_else(|e| panic!("{name}: {e}"));
        assert_eq!((set.n_pulses, set.n_samples), (3, 5), "{name}");
        assert_eq!(&set.charge_pc, expected, "{name}");
        assert_eq!(set.bias_v, 100.0, "{name}");
        assert_eq!(set.sampling_period_ns, 4.0, "{name}");
    }
    // A plugin filter (zstd through hdf5plugin) is an error naming the filter's id.
    expect_lh5_error(
        &fixture("zstd_f32.lh5"),
        "/ch000/raw/waveform/values",
        "32015",
    );
    // LEGEND's encoded waveforms: an error naming the codec.
    expect_lh5_error(
        &fixture("encoded_uleb128.lh5"),
        "/ch000/raw/waveform/values",
        "uleb128_zigzag_diff",
    );
}
