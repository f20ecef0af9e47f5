//! Files shipped in the repository (detectors, spaces, data), found from this crate's folder.

/// Absolute path of a file shipped in the repository (e.g. `detectors/coax-analytic.toml`).
pub fn repo_path(relative: &str) -> std::path::PathBuf {
    std::path::Path::new(env!("CARGO_MANIFEST_DIR"))
        .join("..")
        .join(relative)
}

/// The main job's shipped inputs (data, surrogate, prior, detector) as absolute paths: what the
/// probes of a fit (`examples/refine_probe.rs`, `refine_replay.rs`, `exact_check_timing.rs`)
/// build their job from.
pub fn shipped_fit_files() -> hpge_inference::fit::FitFiles {
    use hpge_inference::fit::{DEFAULT_DATA, DEFAULT_DETECTOR, DEFAULT_MODEL, DEFAULT_PRIOR};
    hpge_inference::fit::FitFiles {
        data: repo_path(DEFAULT_DATA),
        model: repo_path(DEFAULT_MODEL),
        prior: repo_path(DEFAULT_PRIOR),
        detector: repo_path(DEFAULT_DETECTOR),
    }
}

/// A LEGEND diode record shipped in the repository (JSON or YAML, e.g.
/// `validation/references/legend-testdata/yaml/P99000A.yaml`) converted with the default
/// options, as `hpge-cv detector --from-legend` converts it.
///
/// # Errors
/// An unreadable or malformed record, or a conversion the detector loader refuses.
pub fn legend_detector(relative: &str) -> crate::Result<hpge_solver::Detector> {
    use hpge_solver::detector::legend::{LegendOptions, read_file, to_toml};
    let file = repo_path(relative);
    let o = LegendOptions::default();
    let toml = to_toml(&read_file(&file, &o)?, &file, &o);
    Ok(hpge_solver::Detector::from_toml_str(
        &toml,
        &file,
        &hpge_solver::Parameters::new(),
    )?)
}
