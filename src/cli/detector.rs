//! `hpge-cv detector`: check a description, summarise it, draw its cross-section.

use std::path::{Path, PathBuf};

use anyhow::{Context, Result};
use hpge_reports::plot;
use hpge_solver::Detector;
use hpge_solver::detector::WorldSide;
use hpge_solver::detector::legend::{self, LegendOptions};
use serde_json::json;

use super::DetectorInput;
use super::args::load_detector;

/// Loads and checks the detector, prints a summary (text or JSON) and writes the plots.
pub fn run(input: &DetectorInput, plots: &[PathBuf], as_json: bool) -> Result<()> {
    for p in plots {
        plot::check_output(p, "--plot")?;
    }
    let outputs: Vec<(&str, &Path)> = plots.iter().map(|p| ("--plot", p.as_path())).collect();
    super::args::check_outputs(&outputs, &super::args::detector_inputs(input))?;
    let det = load_detector(input)?;
    show(&det, plots, as_json)
}

/// `detector --from-legend DIODE.json [--out D.toml]`: converts a LEGEND diode record
/// ([`hpge_solver::detector::legend`]), writes (or prints) the description, then loads, checks,
/// summarises and draws it as [`run`] does a detector file.
pub fn from_legend(
    record: &Path,
    out: Option<&Path>,
    options: &LegendOptions,
    params: &[(String, f64)],
    impurity: Option<&Path>,
    plots: &[PathBuf],
    as_json: bool,
) -> Result<()> {
    for p in plots {
        plot::check_output(p, "--plot")?;
    }
    let mut outputs: Vec<(&str, &Path)> = plots.iter().map(|p| ("--plot", p.as_path())).collect();
    if let Some(o) = out {
        outputs.insert(0, ("--out", o));
    }
    let mut inputs = vec![("--from-legend", record)];
    if let Some(i) = impurity {
        inputs.push(("--impurity", i));
    }
    super::args::check_outputs(&outputs, &inputs)?;
    for (flag, v) in [
        ("--n-plus-thickness", options.n_plus_thickness_mm),
        ("--can-gap", options.can_gap_mm),
    ] {
        if !(v.is_finite() && (0.0..=1000.0).contains(&v)) {
            anyhow::bail!(
                "{flag} {}: must be a number of mm from 0 to 1000",
                super::args::short(v)
            );
        }
    }
    let overrides = super::args::param_overrides(params)?;
    let diode = legend::read_file(record, options)?;
    let text = legend::to_toml(&diode, record, options);
    // The description is checked before it is written or printed: a conversion the detector
    // format refuses (e.g. an n+ layer thicker than the crystal) leaves no file behind and
    // names the flags that shaped it.
    let file = out.map_or_else(|| record.with_extension("toml"), Path::to_path_buf);
    let mut det = Detector::from_toml_str(&text, &file, &overrides).with_context(|| {
        format!(
            "the description converted from {} (with --n-plus-thickness {} mm, --can-gap {} mm){}",
            record.display(),
            super::args::short(options.n_plus_thickness_mm),
            super::args::short(options.can_gap_mm),
            if out.is_some() { ", not written" } else { "" }
        )
    })?;
    let mut staged = hpge_files::Staged::new();
    match out {
        Some(path) => staged
            .write(path, text.as_bytes())
            .with_context(|| format!("--out {}: cannot write the file", path.display()))?,
        None => out!("{text}"),
    }
    for n in &diode.notes {
        eprintln!("note: {n}");
    }
    match diode.depletion_voltage_v {
        Some(u) => eprintln!("the record's characterization: depletion voltage {u} V"),
        None => eprintln!("the record's characterization gives no depletion voltage"),
    }
    if let Some(path) = impurity {
        det.set_impurity_file(path)?;
    }
    if out.is_none() && plots.is_empty() && !as_json {
        return Ok(());
    }
    // Checked and drawn first: the description is written only when every step succeeded.
    hpge_solver::grid::Grid::check_initial_size(&det, &det.grid.clone().unwrap_or_default())?;
    for p in plots {
        plot::cross_section(&det, p)?;
    }
    super::args::commit(staged)?;
    if let Some(path) = out {
        eprintln!("wrote {}", path.display());
    }
    show(&det, &[], as_json)?;
    for p in plots {
        eprintln!("wrote {}", p.display());
    }
    Ok(())
}

fn show(det: &Detector, plots: &[PathBuf], as_json: bool) -> Result<()> {
    // The check every solving command makes: a world too large for any grid is refused here
    // already (at the file's own [grid] settings, else the defaults).
    hpge_solver::grid::Grid::check_initial_size(det, &det.grid.clone().unwrap_or_default())?;
    for p in plots {
        plot::cross_section(det, p)?;
        eprintln!("wrote {}", p.display());
    }
    if as_json {
        outln!("{}", summary_json(det));
    } else {
        print_summary(det)?;
    }
    Ok(())
}

fn print_summary(det: &Detector) -> Result<()> {
    let w = &det.world;
    outln!("detector  {} ({})", det.name, det.file.display());
    if !det.parameters.is_empty() {
        let p: Vec<String> = det
            .parameters
            .iter()
            .map(|(k, v)| format!("{k} = {v}"))
            .collect();
        outln!("parameters  {}", p.join(", "));
    }
    outln!(
        "world  r in [0, {}] mm, z in [{}, {}] mm, medium {} (eps_r {}); r_max {:?}, z_min {:?}, z_max {:?}",
        w.r_max_mm,
        w.z_min_mm,
        w.z_max_mm,
        w.medium.name,
        w.medium.eps_r,
        w.boundary(WorldSide::RMax),
        w.boundary(WorldSide::ZMin),
        w.boundary(WorldSide::ZMax)
    );
    let sc = &det.semiconductor;
    let b = sc.geometry.bbox();
    outln!(
        "semiconductor  {} ({}, eps_r {}), r in [{}, {}] mm, z in [{}, {}] mm",
        sc.name,
        sc.material.name,
        sc.material.eps_r,
        b.r_min_mm,
        b.r_max_mm,
        b.z_min_mm,
        b.z_max_mm
    );
    outln!(
        "impurity  model \"{}\" from {}",
        det.impurity().name(),
        sc.impurity_file().display()
    );
    for c in &det.contacts {
        let b = c.geometry.bbox();
        outln!(
            "contact {}  {}: potential {}, {}, r in [{}, {}] mm, z in [{}, {}] mm",
            c.id,
            c.name,
            c.potential,
            if c.geometry.is_surface_only() {
                "surface"
            } else {
                "volume"
            },
            b.r_min_mm,
            b.r_max_mm,
            b.z_min_mm,
            b.z_max_mm
        );
    }
    for p in &det.passives {
        outln!("passive  {}: {:?}, {}", p.name, p.kind, p.material.name);
    }
    Ok(())
}

fn summary_json(det: &Detector) -> serde_json::Value {
    let sc = &det.semiconductor;
    json!({
        "name": det.name,
        "file": det.file.display().to_string(),
        "parameters": det.parameters.iter().collect::<std::collections::BTreeMap<_, _>>(),
        "world": det.world,
        "semiconductor": {
            "name": sc.name,
            "material": sc.material,
            "bbox_mm": sc.geometry.bbox(),
            "impurity_model": det.impurity().name(),
            "impurity_file": sc.impurity_file().display().to_string(),
        },
        "contacts": det.contacts.iter().map(|c| json!({
            "id": c.id, "name": c.name, "potential": c.potential.to_string(),
            "surface": c.geometry.is_surface_only(), "bbox_mm": c.geometry.bbox(),
        })).collect::<Vec<_>>(),
        "passives": det.passives.iter().map(|p| json!({
            "name": p.name, "kind": p.kind, "material": p.material.name, "bbox_mm": p.geometry.bbox(),
        })).collect::<Vec<_>>(),
        "program": env!("CARGO_PKG_NAME"),
        "version": env!("CARGO_PKG_VERSION"),
    })
}
