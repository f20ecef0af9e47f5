//! Files shipped in the repository (detectors, spaces, data), found from this crate's folder.

/// Absolute path of a file shipped in the repository (e.g. `detectors/coax-analytic.toml`).
pub fn repo_path(relative: &str) -> std::path::PathBuf {
    std::path::Path::new(env!("CARGO_MANIFEST_DIR"))
        .join("..")
        .join(relative)
}
