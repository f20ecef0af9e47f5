//! The build needs Rust and a C compiler alone (issue 61): LH5 files are read by an HDF5 reader in
//! Rust (`hdf5-pure`) and the figures' text is drawn with a font embedded in the binary
//! (plotters' `ab_glyph` path), so no crate of the build looks for libhdf5, fontconfig or
//! freetype through pkg-config, and the binary links none of them.

use std::process::Command;

/// Parts of crate names that bind or build HDF5, fontconfig or freetype (hdf5-metno-sys,
/// hdf5-sys, hdf5-src, yeslogic-fontconfig-sys, servo-fontconfig-sys, freetype-sys, font-kit,
/// which loads both).
const FORBIDDEN: [&str; 4] = ["hdf5-metno", "hdf5-s", "fontconfig", "freetype"];

/// Names of the shared libraries that must not be linked.
const FORBIDDEN_LIBRARIES: [&str; 3] = ["libhdf5", "libfontconfig", "libfreetype"];

fn forbidden(name: &str) -> bool {
    FORBIDDEN.iter().any(|f| name.contains(f)) || name == "font-kit"
}

#[test]
fn the_lock_file_holds_no_binding_of_hdf5_fontconfig_or_freetype() {
    let lock = std::fs::read_to_string(concat!(env!("CARGO_MANIFEST_DIR"), "/Cargo.lock")).unwrap();
    let names: Vec<&str> = lock
        .lines()
        .filter_map(|l| l.strip_prefix("name = \""))
        .map(|l| l.trim_end_matches('"'))
        .collect();
    assert!(
        names.contains(&"hdf5-pure"),
        "the LH5 reader is not in Cargo.lock"
    );
    assert!(
        names.contains(&"ab_glyph"),
        "plotters' pure-Rust text path is not in Cargo.lock"
    );
    let bad: Vec<&&str> = names.iter().filter(|n| forbidden(n)).collect();
    assert!(bad.is_empty(), "Cargo.lock holds {bad:?}");
}

/// The crates of the build (this platform, every workspace member, build and dev dependencies
/// too) that depend on `pkg-config`: none of them may be one that looks for HDF5, fontconfig or
/// freetype.
#[test]
fn no_crate_of_the_build_asks_pkg_config_for_hdf5_fontconfig_or_freetype() {
    let out = Command::new(env!("CARGO"))
        .current_dir(env!("CARGO_MANIFEST_DIR"))
        .args([
            "tree",
            "--workspace",
            "--offline",
            "--locked",
            "--edges",
            "normal,build,dev",
            "--prefix",
            "none",
            "--invert",
            "pkg-config",
        ])
        .output()
        .unwrap();
    let stdout = String::from_utf8_lossy(&out.stdout);
    let stderr = String::from_utf8_lossy(&out.stderr);
    // No crate of the build needs pkg-config at all: cargo says the spec matches nothing.
    if !out.status.success() {
        assert!(
            stderr.contains("did not match any packages"),
            "cargo tree failed: {stderr}"
        );
        return;
    }
    let bad: Vec<&str> = stdout
        .lines()
        .filter(|l| forbidden(l.split_whitespace().next().unwrap_or("")))
        .collect();
    assert!(bad.is_empty(), "pkg-config is used by {bad:?}:\n{stdout}");
}

/// The binary these tests run links none of the libraries (Linux: `ldd`; skipped where there is
/// no `ldd`).
#[test]
fn the_binary_links_no_hdf5_fontconfig_or_freetype() {
    let Ok(out) = Command::new("ldd")
        .arg(env!("CARGO_BIN_EXE_hpge-cv"))
        .output()
    else {
        eprintln!("no ldd here: the linked libraries are not checked");
        return;
    };
    let text = String::from_utf8_lossy(&out.stdout);
    let bad: Vec<&str> = text
        .lines()
        .filter(|l| FORBIDDEN_LIBRARIES.iter().any(|f| l.contains(f)))
        .collect();
    assert!(bad.is_empty(), "hpge-cv links {bad:?}:\n{text}");
}
