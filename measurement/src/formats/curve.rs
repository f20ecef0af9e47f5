//! C-V curves: `voltage_V,c12_pF,sigma_pF` CSV files with an optional covariance
//! `<stem>.covariance.csv` (pF^2).

use std::ffi::OsString;
use std::path::{Path, PathBuf};

use super::files::{VOLTAGE_TOLERANCE_V, read_text, write_file};
use crate::error::{Error, Result};
use crate::types::CvData;

/// The header of a curve file.
const HEADER: [&str; 3] = ["voltage_V", "c12_pF", "sigma_pF"];

/// `x` as written by `{}`, or in exponent form where that would be long (1e300, not 300 digits).
fn short(x: f64) -> String {
    if x != 0.0 && !(1e-4..1e15).contains(&x.abs()) {
        format!("{x:e}")
    } else {
        format!("{x}")
    }
}

/// The largest capacitance or uncertainty (pF) a measured curve may hold: 1 uF, far beyond any
/// detector, far below where squares overflow (issue 66).
pub(crate) const MAX_PF: f64 = 1e6;

/// Relative tolerance of the covariance symmetry, against sqrt(c_ii c_jj).
const SYMMETRY_TOLERANCE: f64 = 1e-9;

/// Relative tolerance between the covariance diagonal and sigma^2.
const DIAGONAL_TOLERANCE: f64 = 1e-6;

/// Relative jitter added to the diagonal before the Cholesky test of semi-definiteness.
const CHOLESKY_JITTER: f64 = 1e-12;

/// One non-comment, non-blank CSV record: its line in the file and its trimmed cells.
struct Row {
    line: u64,
    cells: Vec<String>,
}

impl Row {
    fn text(&self) -> String {
        self.cells.join(",")
    }
}

/// Reads a C-V curve and its covariance, if any.
///
/// The CSV has the header `voltage_V,c12_pF,sigma_pF` (whitespace around cells and lines is
/// tolerated; lines starting with `#` are comments, anywhere) and at least one row; every cell
/// is a finite number, the voltages (V) strictly increase, c12 and sigma (pF) are above 0.
///
/// The covariance (pF^2) is read from `covariance` if given, otherwise from the sibling
/// `<stem>.covariance.csv` when it exists. Its header is `voltage_V,<v_1>,...,<v_N>` and its N
/// rows `v_i,cov_i1,...,cov_iN`; the voltages must match the curve's within 1e-6 V, the matrix
/// must be symmetric (within 1e-9 relative to sqrt(c_ii c_jj)), its diagonal must equal sigma^2
/// within 1e-6 relative, and it must be positive semi-definite (a Cholesky factorisation with a
/// relative jitter of 1e-12 on the diagonal must succeed).
pub fn read_curve(csv: &Path, covariance: Option<&Path>) -> Result<CvData> {
    let (header, body) = header_and_rows(
        csv,
        format!(
            "empty C-V curve: no header `{}` (the file holds only comments or blank lines)",
            HEADER.join(",")
        ),
    )?;
    if header.cells != HEADER {
        return Err(Error::format(
            csv,
            format!(
                "line {}: the header is `{}`, expected `{}`",
                header.line,
                header.text(),
                HEADER.join(",")
            ),
        ));
    }
    if body.is_empty() {
        return Err(Error::format(
            csv,
            "no data rows after the header: a C-V curve needs at least one point",
        ));
    }
    let (mut voltage_v, mut c12_pf, mut sigma_pf) = (vec![], vec![], vec![]);
    for row in body {
        if row.cells.len() != HEADER.len() {
            return Err(Error::format(
                csv,
                format!(
                    "line {}: {} cells (`{}`), expected 3 ({})",
                    row.line,
                    row.cells.len(),
                    row.text(),
                    HEADER.join(",")
                ),
            ));
        }
        let mut values = [0.0; 3];
        for (col, value) in values.iter_mut().enumerate() {
            *value = number(csv, row.line, col, HEADER[col], &row.cells[col])?;
        }
        let [v, c, s] = values;
        if let Some(&prev) = voltage_v.last()
            && v <= prev
        {
            return Err(Error::invalid(
                csv,
                "voltage_V",
                format!(
                    "line {}: {v} V does not exceed the previous voltage {prev} V; voltages must \
                     be strictly increasing",
                    row.line
                ),
            ));
        }
        if c <= 0.0 || c > MAX_PF {
            return Err(Error::invalid(
                csv,
                "c12_pF",
                format!(
                    "line {}: c12 = {} pF, must be above 0 and at most {MAX_PF:e} pF (beyond \
                     any detector's capacitance; a fit's likelihood would overflow)",
                    row.line,
                    short(c)
                ),
            ));
        }
        if s <= 0.0 || s > MAX_PF {
            return Err(Error::invalid(
                csv,
                "sigma_pF",
                format!(
                    "line {}: sigma = {} pF, must be above 0 and at most {MAX_PF:e} pF",
                    row.line,
                    short(s)
                ),
            ));
        }
        voltage_v.push(v);
        c12_pf.push(c);
        sigma_pf.push(s);
    }
    let covariance_file = match covariance {
        Some(path) => Some(path.to_path_buf()),
        None => Some(covariance_path(csv)).filter(|p| p.is_file()),
    };
    let covariance_pf2 = covariance_file
        .map(|file| read_covariance(&file, csv, &voltage_v, &sigma_pf))
        .transpose()?;
    Ok(CvData {
        voltage_v,
        c12_pf,
        sigma_pf,
        covariance_pf2,
        source: csv.to_path_buf(),
    })
}

/// Writes a C-V curve (and `<stem>.covariance.csv` when it has a covariance), numbers in
/// shortest round-trip form so that [`read_curve`] gives back exactly `data` (but `source`).
///
/// Without a covariance, a stale `<stem>.covariance.csv` is removed, so that [`read_curve`]
/// does not pair the new curve with an old covariance.
pub fn write_curve(csv: &Path, data: &CvData) -> Result<()> {
    write_curve_with_comments(csv, data, &[])
}

/// As [`write_curve`], with a leading comment block: each line of each comment written as
/// `# <line>` (e.g. provenance); [`read_curve`] skips them. The command line no longer uses it
/// (its CSVs are plain tables, their provenance in a JSON sidecar, so that `pandas.read_csv`
/// loads them without `comment='#'`); it stays for library users and old-format tests.
pub fn write_curve_with_comments(csv: &Path, data: &CvData, comments: &[String]) -> Result<()> {
    let (table, covariance) = curve_texts(csv, data, comments)?;
    write_file(csv, table.as_bytes())?;
    let cov_file = covariance_path(csv);
    match covariance {
        Some(text) => write_file(&cov_file, text.as_bytes()),
        None if cov_file.is_file() => std::fs::remove_file(&cov_file).map_err(|source| Error::Io {
            file: cov_file,
            action: "cannot remove the stale covariance of the curve",
            source,
        }),
        None => Ok(()),
    }
}

/// The texts [`write_curve_with_comments`] writes for the curve file `csv` (named in errors
/// only): the curve table and, where the curve has one, its covariance table
/// ([`covariance_path`]); for a caller that puts them in place itself (together with other
/// outputs).
///
/// # Errors
/// A curve with no points or with columns (or a covariance) of other lengths.
pub fn curve_texts(
    csv: &Path,
    data: &CvData,
    comments: &[String],
) -> Result<(String, Option<String>)> {
    let n = data.voltage_v.len();
    let argument = |message: String| Error::Argument {
        name: "data".to_string(),
        message: format!("cannot write {}: {message}", csv.display()),
    };
    if n == 0 {
        return Err(argument("the curve has no points".to_string()));
    }
    if data.c12_pf.len() != n || data.sigma_pf.len() != n {
        return Err(argument(format!(
            "{n} voltages, {} c12 values, {} sigmas",
            data.c12_pf.len(),
            data.sigma_pf.len()
        )));
    }
    if let Some(cov) = &data.covariance_pf2
        && (cov.len() != n || cov.iter().any(|row| row.len() != n))
    {
        return Err(argument(format!(
            "the covariance is not {n} x {n} like the curve"
        )));
    }
    let mut out = String::new();
    for line in comments.iter().flat_map(|c| c.split('\n')) {
        let line = line.trim_end_matches('\r');
        if line.is_empty() {
            out.push_str("#\n");
        } else {
            out.push_str(&format!("# {line}\n"));
        }
    }
    out.push_str(&HEADER.join(","));
    out.push('\n');
    for i in 0..n {
        out.push_str(&format!(
            "{},{},{}\n",
            data.voltage_v[i], data.c12_pf[i], data.sigma_pf[i]
        ));
    }
    let covariance = data.covariance_pf2.as_ref().map(|cov| {
        let mut out = String::from("voltage_V");
        for v in &data.voltage_v {
            out.push_str(&format!(",{v}"));
        }
        out.push('\n');
        for (v, row) in data.voltage_v.iter().zip(cov) {
            out.push_str(&v.to_string());
            for c in row {
                out.push_str(&format!(",{c}"));
            }
            out.push('\n');
        }
        out
    });
    Ok((out, covariance))
}

/// The sibling covariance file of a curve: `<stem>.covariance.csv`.
pub fn covariance_path(csv: &Path) -> PathBuf {
    let mut name = csv
        .file_stem()
        .map_or_else(OsString::new, |s| s.to_os_string());
    name.push(".covariance.csv");
    csv.with_file_name(name)
}

/// The non-comment, non-blank records of a CSV text, cells trimmed.
/// The header row and the data rows of the table in `file` ([`records`]); a file with no row at
/// all is the error `empty` (naming the file).
fn header_and_rows(file: &Path, empty: impl Into<String>) -> Result<(Row, Vec<Row>)> {
    let text = read_text(file)?;
    let mut rows = records(file, &text)?.into_iter();
    let header = rows.next().ok_or_else(|| Error::format(file, empty))?;
    Ok((header, rows.collect()))
}

fn records(file: &Path, text: &str) -> Result<Vec<Row>> {
    let text = text.strip_prefix('\u{feff}').unwrap_or(text);
    let mut reader = csv::ReaderBuilder::new()
        .has_headers(false)
        .flexible(true)
        .trim(csv::Trim::All)
        .comment(Some(b'#'))
        .from_reader(text.as_bytes());
    let mut rows = Vec::new();
    for record in reader.records() {
        let record = record.map_err(|e| Error::format(file, format!("malformed CSV: {e}")))?;
        let line = record.position().map_or(0, csv::Position::line);
        let cells: Vec<String> = record.iter().map(str::to_string).collect();
        if cells.iter().all(String::is_empty) {
            continue;
        }
        rows.push(Row { line, cells });
    }
    Ok(rows)
}

/// Reads a model curve without uncertainties: the columns `voltage_V` and `c12_pF` of a CSV,
/// found by name (others, as `simulate --out`'s `fully_depleted` and `c12_err_pF`, are ignored;
/// `#` lines are comments). At least 2 rows; every voltage (V) above 0 (a reverse bias) and
/// strictly increasing, every c12 (pF) above 0.
///
/// # Errors
/// An unreadable file, a missing column, or a cell that breaks these rules, naming the file,
/// the line and the column.
pub fn read_model_curve(csv: &Path) -> Result<(Vec<f64>, Vec<f64>)> {
    let (header, body) = header_and_rows(csv, "empty: no header with voltage_V and c12_pF")?;
    let col = |name: &str| {
        header
            .cells
            .iter()
            .position(|h| h == name)
            .ok_or_else(|| Error::format(csv, format!("no column `{name}`")))
    };
    let (cu, cc) = (col("voltage_V")?, col("c12_pF")?);
    let (mut u, mut c) = (Vec::new(), Vec::new());
    for row in body {
        let cell = |k: usize| row.cells.get(k).map_or("", String::as_str);
        let volts = number(csv, row.line, cu, "voltage_V", cell(cu))?;
        if volts <= 0.0 {
            return Err(Error::invalid(
                csv,
                "voltage_V",
                format!(
                    "line {}: {volts} V: the bias U_B must be above 0 V",
                    row.line
                ),
            ));
        }
        u.push(volts);
        c.push(number(csv, row.line, cc, "c12_pF", cell(cc))?);
    }
    if u.len() < 2 || u.windows(2).any(|w| w[1] <= w[0]) || c.iter().any(|x| *x <= 0.0) {
        return Err(Error::format(
            csv,
            "need at least 2 rows, strictly increasing voltages and c12 > 0",
        ));
    }
    Ok((u, c))
}

/// Parses one cell as a finite number; `col` is 0-based, messages give it 1-based with its name.
fn number(file: &Path, line: u64, col: usize, name: &str, cell: &str) -> Result<f64> {
    let value: f64 = cell.parse().map_err(|_| {
        Error::format(
            file,
            format!(
                "line {line}, column {} ({name}): `{cell}` is not a number",
                col + 1
            ),
        )
    })?;
    if !value.is_finite() {
        return Err(Error::invalid(
            file,
            name,
            format!(
                "line {line}, column {}: `{cell}` is not a finite number",
                col + 1
            ),
        ));
    }
    Ok(value)
}

/// Reads and validates a covariance file against the curve's voltages and sigmas.
fn read_covariance(
    file: &Path,
    curve: &Path,
    voltage_v: &[f64],
    sigma_pf: &[f64],
) -> Result<Vec<Vec<f64>>> {
    let n = voltage_v.len();
    let (header, body) = header_and_rows(
        file,
        "empty covariance: no header `voltage_V,<v_1>,...,<v_N>`",
    )?;
    if header.cells[0] != "voltage_V" {
        return Err(Error::format(
            file,
            format!(
                "line {}: the header must start with `voltage_V`, got `{}`",
                header.line,
                header.text()
            ),
        ));
    }
    if header.cells.len() != n + 1 {
        return Err(Error::format(
            file,
            format!(
                "line {}: the header lists {} voltages, the curve {} has {n}",
                header.line,
                header.cells.len() - 1,
                curve.display()
            ),
        ));
    }
    for (k, cell) in header.cells[1..].iter().enumerate() {
        let name = format!("voltage {}", k + 1);
        let h = number(file, header.line, k + 1, &name, cell)?;
        check_voltage(
            file,
            header.line,
            &format!("column {}", k + 2),
            h,
            k,
            curve,
            voltage_v,
        )?;
    }
    if body.len() != n {
        return Err(Error::format(
            file,
            format!(
                "{} matrix rows after the header, expected {n} (one per voltage of the curve {})",
                body.len(),
                curve.display()
            ),
        ));
    }
    let mut cov = Vec::with_capacity(n);
    for (i, row) in body.iter().enumerate() {
        if row.cells.len() != n + 1 {
            return Err(Error::format(
                file,
                format!(
                    "line {}: {} cells, expected {} (the voltage and {n} covariances)",
                    row.line,
                    row.cells.len(),
                    n + 1
                ),
            ));
        }
        let v = number(file, row.line, 0, "voltage_V", &row.cells[0])?;
        check_voltage(file, row.line, "voltage_V", v, i, curve, voltage_v)?;
        let values = row.cells[1..]
            .iter()
            .enumerate()
            .map(|(j, cell)| number(file, row.line, j + 1, &format!("{} V", voltage_v[j]), cell))
            .collect::<Result<Vec<f64>>>()?;
        cov.push(values);
    }
    for i in 0..n {
        let s2 = sigma_pf[i] * sigma_pf[i];
        if (cov[i][i] - s2).abs() > DIAGONAL_TOLERANCE * s2 {
            return Err(Error::invalid(
                file,
                format!("row {} ({} V)", i + 1, voltage_v[i]),
                format!(
                    "line {}: the diagonal element {} pF^2 differs from sigma^2 = {s2} pF^2 \
                     (sigma = {} pF in {}) by more than {DIAGONAL_TOLERANCE:e} relative",
                    body[i].line,
                    cov[i][i],
                    sigma_pf[i],
                    curve.display()
                ),
            ));
        }
    }
    for i in 0..n {
        for j in i + 1..n {
            let scale = (cov[i][i] * cov[j][j]).sqrt();
            if (cov[i][j] - cov[j][i]).abs() > SYMMETRY_TOLERANCE * scale {
                return Err(Error::invalid(
                    file,
                    format!("row {}, column {}", i + 1, j + 1),
                    format!(
                        "not symmetric: element ({}, {}) = {} pF^2 (line {}) but element ({}, \
                         {}) = {} pF^2 (line {})",
                        i + 1,
                        j + 1,
                        cov[i][j],
                        body[i].line,
                        j + 1,
                        i + 1,
                        cov[j][i],
                        body[j].line
                    ),
                ));
            }
        }
    }
    if let Some((k, pivot)) = cholesky_failure(&cov) {
        return Err(Error::invalid(
            file,
            "covariance",
            format!(
                "not positive semi-definite: the Cholesky factorisation of the correlation \
                 matrix (jitter {CHOLESKY_JITTER:e} on the diagonal) fails at row {} ({} V) \
                 with pivot {pivot:.3e}",
                k + 1,
                voltage_v[k]
            ),
        ));
    }
    Ok(cov)
}

/// Checks a covariance file's voltage against the curve's voltage `index` (0-based).
fn check_voltage(
    file: &Path,
    line: u64,
    key: &str,
    v: f64,
    index: usize,
    curve: &Path,
    voltage_v: &[f64],
) -> Result<()> {
    let expected = voltage_v[index];
    if (v - expected).abs() > VOLTAGE_TOLERANCE_V {
        return Err(Error::invalid(
            file,
            key,
            format!(
                "line {line}: voltage {v} V does not match voltage {} of the curve {}, {expected} V",
                index + 1,
                curve.display()
            ),
        ));
    }
    Ok(())
}

/// Tries a Cholesky factorisation of the correlation matrix of `cov` (positive diagonal,
/// symmetric) with a relative jitter on the diagonal; returns the 0-based row where a pivot is
/// not positive, and that pivot, or `None` if it succeeds (the matrix is positive semi-definite
/// to that tolerance).
fn cholesky_failure(cov: &[Vec<f64>]) -> Option<(usize, f64)> {
    let n = cov.len();
    let d: Vec<f64> = (0..n).map(|i| cov[i][i].sqrt()).collect();
    let mut l = vec![vec![0.0; n]; n];
    for j in 0..n {
        let pivot = 1.0 + CHOLESKY_JITTER - l[j][..j].iter().map(|x| x * x).sum::<f64>();
        if !(pivot > 0.0 && pivot.is_finite()) {
            return Some((j, pivot));
        }
        let ljj = pivot.sqrt();
        l[j][j] = ljj;
        for i in j + 1..n {
            let r = 0.5 * (cov[i][j] + cov[j][i]) / (d[i] * d[j]);
            let dot: f64 = l[i][..j].iter().zip(&l[j][..j]).map(|(a, b)| a * b).sum();
            l[i][j] = (r - dot) / ljj;
        }
    }
    None
}
