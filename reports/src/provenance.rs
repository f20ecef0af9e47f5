//! The program name and version that the figures and reports carry.

/// The program whose name the figures and reports carry.
pub const PROGRAM: &str = "hpge-cv";

/// The version the figures and reports carry (the workspace's version, which the command line
/// shares).
pub const VERSION: &str = env!("CARGO_PKG_VERSION");
