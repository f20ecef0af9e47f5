//! The measurement file formats: pulse files (.npy + sidecar), raw-data directories, C-V curves
//! with covariances, and `load_data`. Round trips, and every kind of bad input giving an error
//! that names the file and the problem.

use std::fmt::Debug;
use std::path::{Path, PathBuf};
use std::sync::atomic::{AtomicUsize, Ordering};

use hpge_measurement::{
    CvData, Data, PulseSet, load_data, read_curve, read_pulses, read_raw_dir, write_curve,
    write_curve_with_comments, write_pulses,
};
use proptest::prelude::*;

// ---------------------------------------------------------------------------------------------
// Helpers
// ---------------------------------------------------------------------------------------------

/// A fresh, empty directory under the system temp dir, unique to this process and call;
/// removed when dropped, unless the test is failing (to keep the evidence).
struct TempDir(PathBuf);

impl std::ops::Deref for TempDir {
    type Target = Path;
    fn deref(&self) -> &Path {
        &self.0
    }
}

impl Drop for TempDir {
    fn drop(&mut self) {
        if !std::thread::panicking() {
            let _ = std::fs::remove_dir_all(&self.0);
        }
    }
}

fn temp_dir(name: &str) -> TempDir {
    static COUNTER: AtomicUsize = AtomicUsize::new(0);
    let k = COUNTER.fetch_add(1, Ordering::Relaxed);
    let dir = std::env::temp_dir().join(format!(
        "hpge-formats-test-{}-{k}-{name}",
        std::process::id()
    ));
    let _ = std::fs::remove_dir_all(&dir);
    std::fs::create_dir_all(&dir).unwrap();
    TempDir(dir)
}

/// The error message of a result that must be an error naming `file` and every one of `needles`.
fn expect_err<T: Debug>(
    result: hpge_measurement::Result<T>,
    file: &Path,
    needles: &[&str],
) -> String {
    let message = match result {
        Ok(value) => panic!("expected an error about {}, got {value:?}", file.display()),
        Err(e) => e.to_string(),
    };
    let name = file.display().to_string();
    assert!(
        message.contains(&name),
        "message does not name {name}: {message}"
    );
    for needle in needles {
        assert!(
            message.contains(needle),
            "message does not mention `{needle}`: {message}"
        );
    }
    message
}

/// A pulse set with distinct, float32-exact values.
fn pulse_set(npy: &Path, bias_v: f64, n_pulses: usize, n_samples: usize) -> PulseSet {
    PulseSet {
        bias_v,
        sampling_period_ns: 4.0,
        n_pulses,
        n_samples,
        charge_pc: (0..n_pulses * n_samples)
            .map(|k| (k as f64) * 0.125 - 3.5 + bias_v * 1e-3)
            .collect(),
        source: npy.to_path_buf(),
    }
}

/// An .npy file (format 1.0) as numpy writes it, from a header's parts and raw data bytes.
fn npy_bytes(descr: &str, fortran: bool, shape: &[usize], data: &[u8]) -> Vec<u8> {
    let shape = match shape {
        [n] => format!("({n},)"),
        _ => format!(
            "({})",
            shape
                .iter()
                .map(|n| n.to_string())
                .collect::<Vec<_>>()
                .join(", ")
        ),
    };
    let fortran = if fortran { "True" } else { "False" };
    let mut dict =
        format!("{{'descr': '{descr}', 'fortran_order': {fortran}, 'shape': {shape}, }}");
    while (10 + dict.len() + 1) % 64 != 0 {
        dict.push(' ');
    }
    dict.push('\n');
    let mut out = b"\x93NUMPY\x01\x00".to_vec();
    out.extend_from_slice(&(dict.len() as u16).to_le_bytes());
    out.extend_from_slice(dict.as_bytes());
    out.extend_from_slice(data);
    out
}

fn f64_bytes(values: &[f64]) -> Vec<u8> {
    values.iter().flat_map(|v| v.to_le_bytes()).collect()
}

/// Writes `<dir>/<stem>.npy` with the given bytes and a valid sidecar; returns the .npy path.
fn write_pair(dir: &Path, stem: &str, npy: &[u8], sidecar: &str) -> PathBuf {
    let path = dir.join(format!("{stem}.npy"));
    std::fs::write(&path, npy).unwrap();
    std::fs::write(dir.join(format!("{stem}.toml")), sidecar).unwrap();
    path
}

const SIDECAR: &str = "bias_V = 1000.0\nsampling_period_ns = 4.0\ncharge_unit = \"pC\"\n";

/// A valid 2 x 3 float64 .npy.
fn good_npy() -> Vec<u8> {
    npy_bytes(
        "<f8",
        false,
        &[2, 3],
        &f64_bytes(&[1.0, 2.0, 3.0, 4.0, 5.0, 6.0]),
    )
}

fn curve(n: usize, covariance: bool) -> CvData {
    let voltage_v: Vec<f64> = (0..n).map(|i| 100.0 + 150.5 * i as f64).collect();
    let c12_pf: Vec<f64> = (0..n).map(|i| 30.0 / (1.0 + 0.1 * i as f64)).collect();
    let sigma_pf: Vec<f64> = (0..n).map(|i| 0.01 + 0.001 * i as f64).collect();
    let covariance_pf2 = covariance.then(|| correlated(&sigma_pf, 0.6));
    CvData {
        voltage_v,
        c12_pf,
        sigma_pf,
        covariance_pf2,
        source: PathBuf::new(),
    }
}

/// sigma_i sigma_j rho^|i-j|: symmetric, positive definite, diagonal exactly sigma^2.
fn correlated(sigma: &[f64], rho: f64) -> Vec<Vec<f64>> {
    let n = sigma.len();
    (0..n)
        .map(|i| {
            (0..n)
                .map(|j| sigma[i] * sigma[j] * rho.powi((i as i32 - j as i32).abs()))
                .collect()
        })
        .collect()
}

// ---------------------------------------------------------------------------------------------
// Pulse files
// ---------------------------------------------------------------------------------------------

#[test]
fn pulses_round_trip_f64() {
    let dir = temp_dir("pulses-f64");
    let npy = dir.join("u1000.npy");
    let mut set = pulse_set(&npy, 1000.0, 5, 7);
    set.charge_pc[3] = 0.1 + 0.2; // not float32-exact
    set.sampling_period_ns = 0.1 + 0.3;
    set.bias_v = 1234.5678901234;
    write_pulses(&npy, &set, false).unwrap();
    let sidecar = std::fs::read_to_string(dir.join("u1000.toml")).unwrap();
    assert!(sidecar.contains("charge_unit = \"pC\""), "{sidecar}");
    assert!(sidecar.contains("pulses = 5"), "{sidecar}");
    assert!(sidecar.contains("samples = 7"), "{sidecar}");
    assert_eq!(read_pulses(&npy).unwrap(), set);
}

#[test]
fn pulses_round_trip_f32() {
    let dir = temp_dir("pulses-f32");
    let npy = dir.join("u500.npy");
    let set = pulse_set(&npy, 500.0, 3, 4);
    write_pulses(&npy, &set, true).unwrap();
    let bytes = std::fs::read(&npy).unwrap();
    assert!(String::from_utf8_lossy(&bytes[..128]).contains("'<f4'"));
    assert_eq!(read_pulses(&npy).unwrap(), set);
}

#[test]
fn write_pulses_rejects_inconsistent_set() {
    let dir = temp_dir("pulses-bad-set");
    let npy = dir.join("x.npy");
    let mut set = pulse_set(&npy, 10.0, 2, 3);
    set.charge_pc.pop();
    expect_err(
        write_pulses(&npy, &set, false),
        &npy,
        &["2 pulses x 3 samples", "5 charges"],
    );
    let mut set = pulse_set(&npy, 10.0, 2, 3);
    set.charge_pc[4] = f64::NAN;
    expect_err(
        write_pulses(&npy, &set, false),
        &npy,
        &["pulse 1, sample 1", "finite"],
    );
    let mut set = pulse_set(&npy, 10.0, 2, 3);
    set.charge_pc[0] = 1e300;
    expect_err(
        write_pulses(&npy, &set, true),
        &npy,
        &["pulse 0, sample 0", "float32"],
    );
    assert!(!npy.exists());
}

#[test]
fn numpy_style_header_and_fc_unit() {
    let dir = temp_dir("numpy-fc");
    let values = [1.0, -2.5, 3.25, 4.0, 5.0, 6.0];
    let npy = write_pair(
        &dir,
        "a",
        &npy_bytes("<f8", false, &[2, 3], &f64_bytes(&values)),
        "bias_V = 300\nsampling_period_ns = 4\ncharge_unit = \"fC\"\npulses = 2\nsamples = 3\n",
    );
    let set = read_pulses(&npy).unwrap();
    assert_eq!((set.n_pulses, set.n_samples), (2, 3));
    assert_eq!(set.bias_v, 300.0);
    assert_eq!(set.sampling_period_ns, 4.0);
    for (q, v) in set.charge_pc.iter().zip(values) {
        assert!((q - v * 1e-3).abs() < 1e-15, "{q} vs {v} fC");
    }
    assert_eq!(set.pulse(1), &set.charge_pc[3..6]);
    assert_eq!(set.source, npy);
}

#[test]
fn format_versions_2_and_3_and_f32() {
    let dir = temp_dir("versions");
    let v1 = npy_bytes(
        "<f4",
        false,
        &[1, 2],
        &[1.5f32, -2.0].map(f32::to_le_bytes).concat(),
    );
    for (major, name) in [(2u8, "v2"), (3u8, "v3")] {
        // Same dictionary, 4-byte header length.
        let header_len = u16::from_le_bytes([v1[8], v1[9]]) as u32;
        let mut bytes = b"\x93NUMPY".to_vec();
        bytes.extend_from_slice(&[major, 0]);
        bytes.extend_from_slice(&header_len.to_le_bytes());
        bytes.extend_from_slice(&v1[10..]);
        let npy = write_pair(&dir, name, &bytes, SIDECAR);
        let set = read_pulses(&npy).unwrap();
        assert_eq!(set.charge_pc, vec![1.5, -2.0]);
    }
}

#[test]
fn empty_npy() {
    let dir = temp_dir("empty-npy");
    let npy = write_pair(&dir, "e", b"", SIDECAR);
    expect_err(read_pulses(&npy), &npy, &["empty"]);
}

#[test]
fn truncated_npy_in_header_and_in_data() {
    let dir = temp_dir("truncated");
    let good = good_npy();
    for cut in [3, 7, 9, 40] {
        let npy = write_pair(&dir, &format!("h{cut}"), &good[..cut], SIDECAR);
        expect_err(read_pulses(&npy), &npy, &["truncated"]);
    }
    let npy = write_pair(&dir, "d", &good[..good.len() - 5], SIDECAR);
    expect_err(
        read_pulses(&npy),
        &npy,
        &["truncated data", "2 x 3", "48 bytes"],
    );
    let mut long = good.clone();
    long.extend_from_slice(&[0; 3]);
    let npy = write_pair(&dir, "x", &long, SIDECAR);
    expect_err(read_pulses(&npy), &npy, &["3 unexpected bytes"]);
}

#[test]
fn wrong_magic_and_version() {
    let dir = temp_dir("magic");
    let mut bytes = good_npy();
    bytes[1] = b'X';
    let npy = write_pair(&dir, "m", &bytes, SIDECAR);
    expect_err(read_pulses(&npy), &npy, &["not an .npy file", "magic"]);
    let npy = write_pair(&dir, "t", b"voltage_V,c12_pF\n1,2\n", SIDECAR);
    expect_err(read_pulses(&npy), &npy, &["not an .npy file"]);
    let mut bytes = good_npy();
    bytes[6] = 9;
    let npy = write_pair(&dir, "v", &bytes, SIDECAR);
    expect_err(
        read_pulses(&npy),
        &npy,
        &["unsupported .npy format version 9.0"],
    );
    let mut bytes = good_npy();
    bytes[12] = b'#';
    let npy = write_pair(&dir, "h", &bytes, SIDECAR);
    expect_err(read_pulses(&npy), &npy, &["malformed .npy header"]);
}

#[test]
fn one_and_three_dimensional_arrays() {
    let dir = temp_dir("ndim");
    let npy = write_pair(
        &dir,
        "one",
        &npy_bytes("<f8", false, &[3], &f64_bytes(&[1.0, 2.0, 3.0])),
        SIDECAR,
    );
    expect_err(
        read_pulses(&npy),
        &npy,
        &["expected a 2-D array", "1-D", "(3,)"],
    );
    let npy = write_pair(
        &dir,
        "three",
        &npy_bytes("<f8", false, &[2, 1, 2], &f64_bytes(&[1.0; 4])),
        SIDECAR,
    );
    expect_err(
        read_pulses(&npy),
        &npy,
        &["expected a 2-D array", "3-D", "(2, 1, 2)"],
    );
    let npy = write_pair(
        &dir,
        "short",
        &npy_bytes("<f8", false, &[4, 1], &f64_bytes(&[1.0; 4])),
        SIDECAR,
    );
    expect_err(
        read_pulses(&npy),
        &npy,
        &["shape", "at least 1 pulse of at least 2 samples"],
    );
    let npy = write_pair(
        &dir,
        "none",
        &npy_bytes("<f8", false, &[0, 5], &[]),
        SIDECAR,
    );
    expect_err(read_pulses(&npy), &npy, &["0 pulses"]);
}

#[test]
fn unsupported_dtypes_and_order() {
    let dir = temp_dir("dtype");
    let ints: Vec<u8> = [1i64, 2, 3, 4]
        .iter()
        .flat_map(|v| v.to_le_bytes())
        .collect();
    let npy = write_pair(
        &dir,
        "i8",
        &npy_bytes("<i8", false, &[2, 2], &ints),
        SIDECAR,
    );
    expect_err(
        read_pulses(&npy),
        &npy,
        &["integer", "'<i8'", "float32 or float64"],
    );
    let npy = write_pair(
        &dir,
        "be",
        &npy_bytes(">f8", false, &[2, 2], &ints),
        SIDECAR,
    );
    expect_err(read_pulses(&npy), &npy, &["big-endian", "'>f8'"]);
    let npy = write_pair(
        &dir,
        "c16",
        &npy_bytes("<c16", false, &[1, 2], &ints),
        SIDECAR,
    );
    expect_err(read_pulses(&npy), &npy, &["unsupported dtype '<c16'"]);
    let npy = write_pair(&dir, "f", &npy_bytes("<f8", true, &[2, 2], &ints), SIDECAR);
    expect_err(read_pulses(&npy), &npy, &["Fortran order"]);
}

#[test]
fn non_finite_sample_names_pulse_and_sample() {
    let dir = temp_dir("nan");
    let mut values = vec![0.5; 8];
    values[6] = f64::NAN;
    let npy = write_pair(
        &dir,
        "nan",
        &npy_bytes("<f8", false, &[2, 4], &f64_bytes(&values)),
        SIDECAR,
    );
    expect_err(
        read_pulses(&npy),
        &npy,
        &["pulse 1, sample 2", "NaN", "finite"],
    );
    let values: Vec<u8> = [1.0f32, f32::INFINITY].map(f32::to_le_bytes).concat();
    let npy = write_pair(
        &dir,
        "inf",
        &npy_bytes("<f4", false, &[1, 2], &values),
        SIDECAR,
    );
    expect_err(read_pulses(&npy), &npy, &["pulse 0, sample 1", "inf"]);
}

#[test]
fn missing_sidecar() {
    let dir = temp_dir("no-sidecar");
    let npy = dir.join("lonely.npy");
    std::fs::write(&npy, good_npy()).unwrap();
    let sidecar = dir.join("lonely.toml").display().to_string();
    expect_err(read_pulses(&npy), &npy, &["missing sidecar", &sidecar]);
}

#[test]
fn missing_npy_is_an_io_error() {
    let dir = temp_dir("no-npy");
    let npy = dir.join("ghost.npy");
    std::fs::write(dir.join("ghost.toml"), SIDECAR).unwrap();
    expect_err(read_pulses(&npy), &npy, &["cannot read"]);
}

#[test]
fn sidecar_problems() {
    let dir = temp_dir("sidecars");
    let cases: [(&str, &str, &[&str]); 8] = [
        (
            "unknown",
            "colour = \"red\"\n",
            &["unknown field", "colour", "line 4"],
        ),
        (
            "pulses",
            "pulses = 3\n",
            &[
                "`pulses`",
                "sidecar says 3 pulses, the array in pulses.npy has 2",
            ],
        ),
        (
            "samples",
            "samples = 4\n",
            &[
                "`samples`",
                "sidecar says 4 samples, the array in samples.npy has 3",
            ],
        ),
        ("zero", "", &["`sampling_period_ns`", "above 0, got 0"]),
        ("negative", "", &["`sampling_period_ns`", "got -4"]),
        ("unit", "", &["`charge_unit`", "\"nC\"", "\"pC\" or \"fC\""]),
        ("nanbias", "", &["`bias_V`", "finite", "NaN"]),
        ("syntax", "bias_V = \n", &["invalid sidecar", "line 4"]),
    ];
    for (stem, extra, needles) in cases {
        let mut text = SIDECAR.to_string();
        match stem {
            "zero" => text = text.replace("= 4.0", "= 0.0"),
            "negative" => text = text.replace("= 4.0", "= -4.0"),
            "unit" => text = text.replace("\"pC\"", "\"nC\""),
            "nanbias" => text = text.replace("1000.0", "nan"),
            _ => {}
        }
        text.push_str(extra);
        let npy = write_pair(&dir, stem, &good_npy(), &text);
        let sidecar = dir.join(format!("{stem}.toml"));
        expect_err(read_pulses(&npy), &sidecar, needles);
    }
    let npy = write_pair(
        &dir,
        "missing",
        &good_npy(),
        "bias_V = 1.0\ncharge_unit = \"pC\"\n",
    );
    expect_err(
        read_pulses(&npy),
        &dir.join("missing.toml"),
        &["sampling_period_ns"],
    );
}

// ---------------------------------------------------------------------------------------------
// Raw-data directories
// ---------------------------------------------------------------------------------------------

/// A directory with good pulse files at 300, 100 and 200 V (in that file-name order).
fn raw_dir(name: &str) -> TempDir {
    let dir = temp_dir(name);
    for (stem, bias) in [("a", 300.0), ("b", 100.0), ("c", 200.0)] {
        let npy = dir.join(format!("{stem}.npy"));
        write_pulses(&npy, &pulse_set(&npy, bias, 2, 5), stem == "b").unwrap();
    }
    dir
}

#[test]
fn raw_dir_reads_good_files_and_lists_problems() {
    let dir = raw_dir("raw-problems");
    let bad = write_pair(
        &dir,
        "bad",
        b"",
        "bias_V = 250.0\nsampling_period_ns = 4.0\ncharge_unit = \"pC\"\n",
    );
    let dup = dir.join("dup.npy");
    write_pulses(&dup, &pulse_set(&dup, 200.0, 1, 2), false).unwrap();
    std::fs::write(dir.join("orphan.toml"), "bias_V = 50\n").unwrap();
    let nosidecar = dir.join("z.npy");
    std::fs::write(&nosidecar, good_npy()).unwrap();
    std::fs::write(dir.join("measurement.toml"), "voltages_V = [100, 200]\n").unwrap();
    std::fs::write(dir.join("notes.txt"), "ignored").unwrap();
    std::fs::create_dir(dir.join("sub.npy")).unwrap();

    let run = read_raw_dir(&dir, None).unwrap();
    assert_eq!(run.dir, *dir);
    let biases: Vec<f64> = run.sets.iter().map(|s| s.bias_v).collect();
    assert_eq!(biases, vec![100.0, 200.0, 300.0]);
    assert_eq!(
        run.sets[1].source,
        dir.join("c.npy"),
        "the first file of a bias is kept"
    );
    let files: Vec<&Path> = run.problems.iter().map(|p| p.file.as_path()).collect();
    assert_eq!(
        files,
        vec![
            bad.as_path(),
            dup.as_path(),
            &dir.join("orphan.toml"),
            nosidecar.as_path()
        ],
        "{:#?}",
        run.problems
    );
    let p = &run.problems;
    assert_eq!(p[0].bias_v, Some(250.0));
    assert!(
        p[0].message.contains("empty") && p[0].message.contains("bad.npy"),
        "{p:?}"
    );
    assert_eq!(p[1].bias_v, Some(200.0));
    assert!(
        p[1].message.contains("c.npy") && p[1].message.contains("ignored"),
        "{p:?}"
    );
    assert_eq!(p[2].bias_v, Some(50.0));
    assert!(p[2].message.contains("sidecar without pulse file"), "{p:?}");
    assert!(p[2].message.contains("orphan.npy"), "{p:?}");
    assert_eq!(p[3].bias_v, None);
    assert!(p[3].message.contains("missing sidecar"), "{p:?}");
}

#[test]
fn raw_dir_missing_expected_voltage() {
    let dir = raw_dir("raw-expected");
    write_pair(
        &dir,
        "broken",
        b"junk",
        "bias_V = 400.0\nsampling_period_ns = 4.0\ncharge_unit = \"pC\"\n",
    );
    let run = read_raw_dir(&dir, Some(&[100.0, 200.0 + 1e-7, 300.0, 400.0, 500.0])).unwrap();
    assert_eq!(run.sets.len(), 3);
    assert_eq!(run.problems.len(), 3, "{:#?}", run.problems);
    assert_eq!(run.problems[0].file, dir.join("broken.npy"));
    let p400 = &run.problems[1];
    assert_eq!((p400.file.as_path(), p400.bias_v), (&*dir, Some(400.0)));
    assert!(
        p400.message.contains("broken.npy could not be used"),
        "{p400:?}"
    );
    let p500 = &run.problems[2];
    assert_eq!((p500.file.as_path(), p500.bias_v), (&*dir, Some(500.0)));
    assert_eq!(p500.message, "no pulse file for this bias");
}

#[test]
fn raw_dir_that_does_not_exist_or_is_a_file() {
    let parent = temp_dir("raw-missing");
    let dir = parent.join("nope");
    expect_err(
        read_raw_dir(&dir, None),
        &dir,
        &["cannot open the raw-data directory"],
    );
    let parent = temp_dir("raw-file");
    let file = parent.join("f.npy");
    std::fs::write(&file, good_npy()).unwrap();
    expect_err(read_raw_dir(&file, None), &file, &["not a directory"]);
}

#[test]
fn raw_dir_without_pulse_files() {
    let dir = temp_dir("raw-empty");
    std::fs::write(dir.join("readme.txt"), "nothing").unwrap();
    std::fs::write(dir.join("measurement.toml"), "voltages_V = [1.0]\n").unwrap();
    expect_err(
        read_raw_dir(&dir, Some(&[1.0])),
        &dir,
        &["no readable pulse file"],
    );
    let bad = write_pair(&dir, "bad", b"\x93NUM", SIDECAR);
    let message = expect_err(
        read_raw_dir(&dir, None),
        &dir,
        &["no readable pulse file", "problems"],
    );
    assert!(
        message.contains(&bad.display().to_string()) && message.contains("truncated"),
        "{message}"
    );
}

// ---------------------------------------------------------------------------------------------
// C-V curves
// ---------------------------------------------------------------------------------------------

#[test]
fn curve_round_trip_without_covariance() {
    let dir = temp_dir("curve-plain");
    let csv = dir.join("cv.csv");
    let mut data = curve(6, false);
    data.c12_pf[2] = 0.1 + 0.2;
    data.sigma_pf[4] = 1e-20;
    data.voltage_v[5] = 1e7 + 0.3;
    data.source = csv.clone();
    write_curve(&csv, &data).unwrap();
    assert!(!dir.join("cv.covariance.csv").exists());
    assert_eq!(read_curve(&csv, None).unwrap(), data);
}

#[test]
fn curve_round_trip_with_covariance_and_comments() {
    let dir = temp_dir("curve-cov");
    let csv = dir.join("cv.csv");
    let mut data = curve(5, true);
    data.source = csv.clone();
    let comments = [
        "produced by a test".to_string(),
        "two\nlines".to_string(),
        String::new(),
    ];
    write_curve_with_comments(&csv, &data, &comments).unwrap();
    let text = std::fs::read_to_string(&csv).unwrap();
    assert!(
        text.starts_with("# produced by a test\n# two\n# lines\n#\nvoltage_V,c12_pF,sigma_pF\n"),
        "{text}"
    );
    assert!(dir.join("cv.covariance.csv").is_file());
    assert_eq!(read_curve(&csv, None).unwrap(), data);
    // An explicit covariance path, elsewhere.
    let other = dir.join("elsewhere.csv");
    std::fs::rename(dir.join("cv.covariance.csv"), &other).unwrap();
    assert_eq!(read_curve(&csv, Some(&other)).unwrap(), data);
    assert_eq!(read_curve(&csv, None).unwrap().covariance_pf2, None);
    // Rewriting without a covariance removes a stale one.
    write_curve(&csv, &data).unwrap();
    data.covariance_pf2 = None;
    write_curve(&csv, &data).unwrap();
    assert!(!dir.join("cv.covariance.csv").exists());
    assert_eq!(read_curve(&csv, None).unwrap(), data);
}

#[test]
fn curve_tolerates_whitespace_comments_and_crlf() {
    let dir = temp_dir("curve-lenient");
    let csv = dir.join("cv.csv");
    std::fs::write(
        &csv,
        "# provenance\r\n  voltage_V , c12_pF,sigma_pF  \r\n\r\n100, 30, 0.1\r\n# mid comment\r\n 200 ,20,0.2\r\n",
    )
    .unwrap();
    let data = read_curve(&csv, None).unwrap();
    assert_eq!(data.voltage_v, vec![100.0, 200.0]);
    assert_eq!(data.c12_pf, vec![30.0, 20.0]);
    assert_eq!(data.sigma_pf, vec![0.1, 0.2]);
    // Line numbers count comment lines.
    std::fs::write(
        &csv,
        "# c\nvoltage_V,c12_pF,sigma_pF\n# c\n100,30,0.1\n200,x,0.1\n",
    )
    .unwrap();
    expect_err(
        read_curve(&csv, None),
        &csv,
        &["line 5, column 2 (c12_pF)", "`x` is not a number"],
    );
}

#[test]
fn curve_bad_inputs() {
    let dir = temp_dir("curve-bad");
    let h = "voltage_V,c12_pF,sigma_pF\n";
    let cases: Vec<(&str, String, Vec<&str>)> = vec![
        ("empty", String::new(), vec!["empty C-V curve"]),
        (
            "comments",
            "# only\n\n".to_string(),
            vec!["empty C-V curve"],
        ),
        (
            "header",
            "V,C,S\n1,2,3\n".to_string(),
            vec![
                "line 1",
                "header is `V,C,S`",
                "expected `voltage_V,c12_pF,sigma_pF`",
            ],
        ),
        ("norows", h.to_string(), vec!["no data rows"]),
        (
            "cell",
            format!("{h}100,30,0.1\n200,30,abc\n"),
            vec!["line 3, column 3 (sigma_pF)", "`abc` is not a number"],
        ),
        (
            "emptycell",
            format!("{h}100,,0.1\n"),
            vec!["line 2, column 2", "`` is not a number"],
        ),
        (
            "nan",
            format!("{h}100,NaN,0.1\n"),
            vec!["`c12_pF`", "line 2, column 2", "not a finite number"],
        ),
        (
            "cells",
            format!("{h}100,30\n"),
            vec!["line 2", "2 cells", "expected 3"],
        ),
        (
            "decreasing",
            format!("{h}100,30,0.1\n300,20,0.1\n200,10,0.1\n"),
            vec![
                "`voltage_V`",
                "line 4",
                "200 V does not exceed the previous voltage 300 V",
                "strictly increasing",
            ],
        ),
        (
            "equal",
            format!("{h}100,30,0.1\n100,20,0.1\n"),
            vec!["line 3", "strictly increasing"],
        ),
        (
            "sigma0",
            format!("{h}100,30,0\n"),
            vec!["`sigma_pF`", "line 2", "sigma = 0 pF, must be above 0"],
        ),
        (
            "sigmaneg",
            format!("{h}100,30,0.1\n200,30,-0.5\n"),
            vec!["`sigma_pF`", "line 3", "-0.5"],
        ),
        (
            "c12",
            format!("{h}100,-1,0.1\n"),
            vec!["`c12_pF`", "must be above 0"],
        ),
    ];
    for (stem, text, needles) in cases {
        let csv = dir.join(format!("{stem}.csv"));
        std::fs::write(&csv, text).unwrap();
        expect_err(read_curve(&csv, None), &csv, &needles);
    }
    let missing = dir.join("missing.csv");
    expect_err(read_curve(&missing, None), &missing, &["cannot read"]);
}

/// Writes a 3-point curve (100, 200, 300 V; sigma 0.1, 0.2, 0.3 pF) and the given covariance
/// text as its sibling; returns (curve, covariance) paths.
fn curve_with_covariance(dir: &Path, stem: &str, covariance: &str) -> (PathBuf, PathBuf) {
    let csv = dir.join(format!("{stem}.csv"));
    std::fs::write(
        &csv,
        "voltage_V,c12_pF,sigma_pF\n100,30,0.1\n200,20,0.2\n300,10,0.3\n",
    )
    .unwrap();
    let cov = dir.join(format!("{stem}.covariance.csv"));
    std::fs::write(&cov, covariance).unwrap();
    (csv, cov)
}

#[test]
fn covariance_bad_inputs() {
    let dir = temp_dir("cov-bad");
    let h = "voltage_V,100,200,300\n";
    let r1 = "100,0.01,0.01,0\n";
    let r2 = "200,0.01,0.04,0\n";
    let r3 = "300,0,0,0.09\n";
    let good = format!("{h}{r1}{r2}{r3}");
    let (csv, _) = curve_with_covariance(&dir, "good", &good);
    let data = read_curve(&csv, None).unwrap();
    assert_eq!(data.covariance_pf2.unwrap()[1], vec![0.01, 0.04, 0.0]);

    let cases: Vec<(&str, String, Vec<&str>)> = vec![
        ("empty", String::new(), vec!["empty covariance"]),
        (
            "size",
            "voltage_V,100,200\n100,0.01,0\n200,0,0.04\n".to_string(),
            vec!["line 1", "the header lists 2 voltages", "size.csv has 3"],
        ),
        ("rows", format!("{h}{r1}{r2}"), vec!["2 matrix rows", "expected 3"]),
        ("cells", format!("{h}{r1}200,0.01,0.04\n{r3}"), vec!["line 3", "3 cells, expected 4"]),
        ("firstcell", format!("V,100,200,300\n{r1}{r2}{r3}"), vec!["line 1", "must start with `voltage_V`"]),
        (
            "headerv",
            format!("voltage_V,100,250,300\n{r1}{r2}{r3}"),
            vec!["`column 3`", "voltage 250 V does not match voltage 2 of the curve", "200 V"],
        ),
        (
            "rowv",
            format!("{h}{r1}{r2}301,0,0,0.09\n"),
            vec!["`voltage_V`", "line 4", "voltage 301 V does not match voltage 3", "300 V"],
        ),
        ("cell", format!("{h}{r1}200,0.01,oops,0\n{r3}"), vec!["line 3, column 3", "`oops` is not a number"]),
        (
            "asym",
            format!("{h}{r1}{r2}300,0,0.001,0.09\n"),
            vec!["`row 2, column 3`", "not symmetric", "0.001"],
        ),
        (
            "diag",
            format!("{h}{r1}200,0.01,0.05,0\n{r3}"),
            vec!["`row 2 (200 V)`", "line 3", "0.05", "sigma^2 = 0.04", "sigma = 0.2 pF"],
        ),
        (
            "notpsd",
            "voltage_V,100,200,300\n100,0.01,0.018,-0.027\n200,0.018,0.04,0.054\n300,-0.027,0.054,0.09\n"
                .to_string(),
            vec!["`covariance`", "not positive semi-definite", "row 3 (300 V)"],
        ),
    ];
    for (stem, text, needles) in cases {
        let (csv, cov) = curve_with_covariance(&dir, stem, &text);
        expect_err(read_curve(&csv, None), &cov, &needles);
    }
    let (csv, _) = curve_with_covariance(&dir, "explicit", &good);
    let missing = dir.join("nowhere.csv");
    expect_err(read_curve(&csv, Some(&missing)), &missing, &["cannot read"]);
}

#[test]
fn covariance_rank_deficient_but_psd_is_accepted() {
    let dir = temp_dir("cov-rank1");
    // Fully correlated: sigma sigma^T, rank 1.
    let (csv, _) = curve_with_covariance(
        &dir,
        "rank1",
        "voltage_V,100,200,300\n100,0.01,0.02,0.03\n200,0.02,0.04,0.06\n300,0.03,0.06,0.09\n",
    );
    assert!(read_curve(&csv, None).unwrap().covariance_pf2.is_some());
}

#[test]
fn write_curve_rejects_inconsistent_data() {
    let dir = temp_dir("curve-write-bad");
    let csv = dir.join("cv.csv");
    let mut data = curve(3, false);
    data.sigma_pf.pop();
    expect_err(write_curve(&csv, &data), &csv, &["3 voltages", "2 sigmas"]);
    let mut data = curve(3, true);
    data.covariance_pf2.as_mut().unwrap()[1].pop();
    expect_err(write_curve(&csv, &data), &csv, &["not 3 x 3"]);
    expect_err(write_curve(&csv, &curve(0, false)), &csv, &["no points"]);
}

proptest! {
    #![proptest_config(ProptestConfig {
        failure_persistence: None,
        ..ProptestConfig::with_cases(64)
    })]

    #[test]
    fn curve_round_trip_is_exact(
        points in prop::collection::vec((1e-3f64..1e3, 1e-3f64..1e4, 1e-9f64..10.0), 1..25),
        start in -1e3f64..1e3,
        rho in prop::option::of(0.0f64..0.95),
    ) {
        let dir = temp_dir("proptest");
        let csv = dir.join("p.csv");
        let mut v = start;
        let voltage_v: Vec<f64> = points.iter().map(|p| { v += p.0; v }).collect();
        let sigma_pf: Vec<f64> = points.iter().map(|p| p.2).collect();
        let data = CvData {
            voltage_v,
            c12_pf: points.iter().map(|p| p.1).collect(),
            covariance_pf2: rho.map(|rho| correlated(&sigma_pf, rho)),
            sigma_pf,
            source: csv.clone(),
        };
        write_curve(&csv, &data).unwrap();
        prop_assert_eq!(read_curve(&csv, None).unwrap(), data);
    }
}

// ---------------------------------------------------------------------------------------------
// load_data
// ---------------------------------------------------------------------------------------------

#[test]
fn load_data_directory_uses_measurement_toml() {
    let dir = raw_dir("load-dir");
    std::fs::write(
        dir.join("measurement.toml"),
        "# settings\nvoltages_V = [100, 200.0, 300, 400]\nother = \"ignored\"\n[circuit]\nr1 = 1\n",
    )
    .unwrap();
    let Data::Raw(run) = load_data(&dir).unwrap() else {
        panic!("a directory must load as raw data");
    };
    assert_eq!(run.sets.len(), 3);
    assert_eq!(run.problems.len(), 1, "{:#?}", run.problems);
    assert_eq!(run.problems[0].bias_v, Some(400.0));
    assert_eq!(run.problems[0].message, "no pulse file for this bias");

    // Without the key (or the file), no voltages are expected.
    std::fs::write(dir.join("measurement.toml"), "other = 1\n").unwrap();
    let Data::Raw(run) = load_data(&dir).unwrap() else {
        panic!()
    };
    assert!(run.problems.is_empty(), "{:#?}", run.problems);

    let settings = dir.join("measurement.toml");
    std::fs::write(&settings, "voltages_V = 100\n").unwrap();
    expect_err(
        load_data(&dir),
        &settings,
        &["`voltages_V`", "array", "integer"],
    );
    std::fs::write(&settings, "voltages_V = [100, \"x\"]\n").unwrap();
    expect_err(
        load_data(&dir),
        &settings,
        &["`voltages_V[1]`", "must be a number"],
    );
    std::fs::write(&settings, "voltages_V = [100\n").unwrap();
    expect_err(load_data(&dir), &settings, &["line"]);
}

#[test]
fn load_data_csv_and_others() {
    let dir = temp_dir("load-csv");
    let csv = dir.join("curve.CSV");
    let mut data = curve(4, true);
    data.source = csv.clone();
    write_curve(&csv, &data).unwrap();
    let Data::Curve(read) = load_data(&csv).unwrap() else {
        panic!("a .csv must load as a curve");
    };
    assert_eq!(read, data);
    assert!(read.covariance_pf2.is_some());

    let txt = dir.join("curve.txt");
    std::fs::write(&txt, "voltage_V,c12_pF,sigma_pF\n1,2,3\n").unwrap();
    expect_err(
        load_data(&txt),
        &txt,
        &["unknown kind of measured data", ".csv"],
    );
    let npy = dir.join("pulses.npy");
    std::fs::write(&npy, good_npy()).unwrap();
    expect_err(load_data(&npy), &npy, &["pass the directory"]);
    let missing = dir.join("missing");
    expect_err(load_data(&missing), &missing, &["cannot open"]);
    let bad = dir.join("bad.csv");
    std::fs::write(&bad, "nope\n").unwrap();
    expect_err(load_data(&bad), &bad, &["header"]);
}
