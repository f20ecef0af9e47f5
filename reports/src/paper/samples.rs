//! The paper's Fig. 16 (section 7): the distributions of zeta_1^bot and zeta_4^bot over the
//! generated training and test samples (the points of `data/training/train.csv` and `test.csv`).

use hpge_solver::impurity::LogTransform;
use hpge_surrogate::{ParameterSpace, Sequence, SequenceKind};
use serde_json::json;

use super::criterion::{Cmp, Criterion, Judgement};
use super::ctx::Ctx;
use crate::error::{Error, Result};
use crate::plot::{self, Corner, Curve, LineFigure};

/// (column, y range, histogram range in signed log10 zeta, bins, stem, title).
struct Param {
    column: &'static str,
    y_range: (f64, f64),
    range: (f64, f64),
    bins: usize,
    stem: &'static str,
    name: &'static str,
}

const PARAMS: [Param; 2] = [
    Param {
        column: "y1_bot",
        y_range: (0.018566145, 1.0),
        range: (7.9, 11.1),
        bins: 64,
        stem: "samples-zeta1-bot",
        name: "zeta_1^bot",
    },
    Param {
        column: "y4_bot",
        y_range: (-1.0, 1.0),
        range: (-11.1, 11.1),
        bins: 111,
        stem: "samples-zeta4-bot",
        name: "zeta_4^bot",
    },
];

/// The sampled values of dimension `name` at sequence indices `range`: the golden sequence
/// (seed 0) mapped through the space, as `generate` draws them (`data/training/make.sh`: indices
/// 0..47999 train, 48000..59999 test). The CSVs themselves are not shipped (40 min to remake),
/// but the points they were solved at follow from the sequence alone.
fn column(space: &ParameterSpace, name: &str, range: std::ops::Range<u64>) -> Result<Vec<f64>> {
    let Some(k) = space.dimensions.iter().position(|d| d.name == name) else {
        return Err(Error::invalid(format!(
            "the space {} has no dimension `{name}`",
            space.name
        )));
    };
    let seq = Sequence::new(SequenceKind::Golden, space.dim(), 0);
    Ok(range.map(|n| space.from_unit(&seq.point(n))[k]).collect())
}

/// Kolmogorov-Smirnov distance of `v` from the uniform distribution on [lo, hi].
fn ks_uniform(v: &[f64], (lo, hi): (f64, f64)) -> f64 {
    let mut s = v.to_vec();
    s.sort_by(f64::total_cmp);
    let n = s.len() as f64;
    s.iter().enumerate().fold(0.0, |d: f64, (i, &x)| {
        let f = ((x - lo) / (hi - lo)).clamp(0.0, 1.0);
        d.max((f - i as f64 / n).abs())
            .max(((i + 1) as f64 / n - f).abs())
    })
}

/// A step curve of the fraction of samples per bin of sign(zeta) log10(|zeta| / cm^-3).
fn histogram(label: String, slog: &[f64], p: &Param) -> Curve {
    let (lo, hi) = p.range;
    let w = (hi - lo) / p.bins as f64;
    let mut counts = vec![0usize; p.bins];
    for &v in slog {
        let k = ((v - lo) / w).floor();
        if k >= 0.0 && (k as usize) < p.bins {
            counts[k as usize] += 1;
        }
    }
    let n = slog.len().max(1) as f64;
    let mut points = Vec::with_capacity(2 * p.bins);
    for (k, &c) in counts.iter().enumerate() {
        let f = Some(c as f64 / n);
        points.push((lo + k as f64 * w, f));
        points.push((lo + (k + 1) as f64 * w, f));
    }
    Curve { label, points }
}

/// Draws both histograms and adds their README rows.
pub fn run(ctx: &mut Ctx) -> Result<()> {
    let t = LogTransform::default();
    let slog = |y: f64| {
        let z = t.zeta_cm3_of_y(y);
        if z == 0.0 {
            0.0
        } else {
            z.signum() * z.abs().log10().max(0.0)
        }
    };
    let space = ParameterSpace::from_file(&ctx.inputs.space).map_err(|source| Error::Space {
        file: ctx.inputs.space.clone(),
        source,
    })?;
    let sets = [("training", 0..48_000u64), ("test", 48_000..60_000u64)];
    let mut numbers = serde_json::Map::new();
    for p in &PARAMS {
        let mut curves = Vec::new();
        let mut notes = Vec::new();
        let mut worst: f64 = 0.0;
        for (label, range) in &sets {
            let y = column(&space, p.column, range.clone())?;
            let d = ks_uniform(&y, p.y_range);
            worst = worst.max(d);
            let s: Vec<f64> = y.iter().map(|&y| slog(y)).collect();
            curves.push(histogram(label.to_string(), &s, p));
            notes.push(format!(
                "{label}: {} samples, KS distance of {} from U{:?} = {d:.2e}",
                y.len(),
                p.column,
                p.y_range
            ));
            numbers.insert(
                format!("{}_{}", p.column, label.replace(' ', "_")),
                json!({"n": y.len(), "ks_uniform": d}),
            );
        }
        let fig = LineFigure {
            title: format!("distribution of {} over the generated samples", p.name),
            x_desc: format!("sign(zeta) log10(|{}| / cm^-3)", p.name),
            y_desc: "fraction of samples per bin".into(),
            curves,
            y_from_zero: true,
            legend: Corner::MiddleMiddle,
            footnotes: vec![format!(
                "hpge-cv {} report paper: {}, golden sequence seed 0, indices 0..47999 (training), 48000..59999 (test); {}",
                crate::provenance::VERSION,
                ctx.inputs.space.display(),
                notes.join("; ")
            )],
        };
        ctx.both(p.stem, |path| plot::line_figure(&fig, path))?;
        ctx.row(
            p.stem,
            "Fig. 16 (sec. 7)",
            "The generated samples of zeta_1^bot (n-type, 1e8..1e11) and zeta_4^bot (either sign) cover their intervals properly in both sets (golden sequence, uniform in y).",
            notes.join("; "),
            Judgement::by(
                vec![Criterion::new(
                    "largest KS distance of y from uniform, both sets",
                    worst,
                    Cmp::Lt,
                    0.01,
                )],
                "",
            ),
        );
    }
    ctx.number("samples", serde_json::Value::Object(numbers));
    Ok(())
}
