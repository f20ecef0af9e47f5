//! The paper's section 9 (Fig. 29: the field strength along r and the n+ pulses for the
//! manufacturer's model and the global modes of both fits) from `paper::section9`, fed with the
//! fits of this run.

use serde_json::Value;

use super::fits::fit_dir;
use super::section9_compute::{Section9Inputs, section9};
use super::{Cmp, Criterion, Ctx, Judgement};
use crate::{Error, Result};

/// The section-9 step of `report paper` (left out of a `--quick` run).
pub fn run(ctx: &mut Ctx) -> Result<()> {
    let stems = [
        ("section9-field-r", "Fig. 29a (sec. 9)"),
        ("section9-pulses-nplus", "Fig. 29b (sec. 9)"),
    ];
    if ctx.quick {
        for (stem, paper) in stems {
            ctx.row(
                stem,
                paper,
                "(section 9 is left out of a --quick run)",
                String::new(),
                Judgement::NotRun("--quick".into()),
            );
        }
        return Ok(());
    }
    let mut inputs = Section9Inputs {
        detector: ctx.inputs.detector.clone(),
        surrogate: ctx.inputs.fit_model.clone(),
        ..Default::default()
    };
    for f in &mut inputs.fits {
        f.3 = fit_dir(ctx, &f.0).join("summary.json");
    }
    let dir = ctx.out.join("section9");
    section9(&dir, &inputs)?;
    ctx.copy_both(&dir, "field-r", "section9-field-r")?;
    ctx.copy_both(&dir, "pulses-nplus", "section9-pulses-nplus")?;
    let path = dir.join("section9.json");
    let v: Value =
        serde_json::from_str(
            &std::fs::read_to_string(&path).map_err(|source| Error::Read {
                file: path.clone(),
                what: "section 9's numbers",
                source,
            })?,
        )?;
    let models = v["models"].as_array().cloned().unwrap_or_default();
    let get = |key: &str| {
        models
            .iter()
            .find(|m| m["key"] == key)
            .cloned()
            .unwrap_or(Value::Null)
    };
    let e_at = |m: &Value, r: f64| {
        m["e_at_radii"]
            .as_array()
            .and_then(|a| a.iter().find(|e| e["r_mm"].as_f64() == Some(r)))
            .and_then(|e| e["e_V_per_cm"].as_f64())
            .unwrap_or(f64::NAN)
    };
    let (m, bz, brz) = (get("manufacturer"), get("b-z"), get("b-rz"));
    let field_txt = [("M*", &m), ("B_Z", &bz), ("B_RZ", &brz)]
        .iter()
        .map(|(n, x)| {
            format!(
                "{n}: |E|(10 mm) {:.0}, |E|(37 mm) {:.0} V/cm",
                e_at(x, 10.0),
                e_at(x, 37.0)
            )
        })
        .collect::<Vec<_>>()
        .join("; ");
    let span = |x: &Value| (e_at(x, 37.0) - e_at(x, 10.0)).abs();
    let field = vec![
        Criterion::new(
            "span of |E| over r = 10-37 mm, B_Z / M*",
            span(&bz) / span(&m),
            Cmp::Lt,
            1.0,
        ),
        Criterion::new(
            "|E|(37 mm, p+ side), B_RZ / B_Z",
            e_at(&brz, 37.0) / e_at(&bz, 37.0),
            Cmp::Lt,
            1.0,
        ),
        Criterion::new(
            "|E|(10 mm, n+ side), B_RZ / B_Z",
            e_at(&brz, 10.0) / e_at(&bz, 10.0),
            Cmp::Gt,
            1.0,
        ),
    ];
    ctx.row(
        stems[0].0,
        stems[0].1,
        "|E| near the contacts differs between the models: B_Z's is less r-dependent than M*'s; B_RZ lowers |E| near the p+ contact (mantle) and raises it near the n+ (borehole).",
        field_txt,
        Judgement::by(
            field,
            "the fields are those of the fits' global modes on the stand-in data (see the B_Z and B_RZ rows)",
        ),
    );
    let rise = |x: &Value| x["nplus_rise_time_10_90_ns"].as_f64().unwrap_or(f64::NAN);
    let coll = |x: &Value| x["collection_time_ns"].as_f64().unwrap_or(f64::NAN);
    let pulse_txt = [("M*", &m), ("B_Z", &bz), ("B_RZ", &brz)]
        .iter()
        .map(|(n, x)| {
            format!(
                "{n}: rise 10-90% {:.0} ns, collection {:.0} ns",
                rise(x),
                coll(x)
            )
        })
        .collect::<Vec<_>>()
        .join("; ");
    ctx.row(
        stems[1].0,
        stems[1].1,
        "The n+ pulses of B_Z and B_RZ are very similar; M*'s differs (B_Z's is faster at the end).",
        pulse_txt,
        Judgement::by(
            vec![Criterion::new(
                "|rise(B_Z) - rise(B_RZ)| / rise(B_Z), 10-90%",
                (rise(&bz) - rise(&brz)).abs() / rise(&bz),
                Cmp::Lt,
                0.1,
            )],
            "the pulses are those of the fits' global modes on the stand-in data",
        ),
    );
    ctx.number("section9", v["models"].clone());
    Ok(())
}
