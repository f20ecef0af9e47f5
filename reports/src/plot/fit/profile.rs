//! The impurity-density profiles at a fit's global mode that the `zeta-z` and `zeta-r` figures
//! draw.

/// zeta (cm^-3) along one line through the detector at the global mode.
#[derive(Debug, Clone, PartialEq)]
pub struct ZetaProfile {
    /// Legend entry, e.g. "r = 20 mm".
    pub label: String,
    /// Position along the line (z or r), mm.
    pub x_mm: Vec<f64>,
    /// Net impurity density at those positions, cm^-3.
    pub zeta_cm3: Vec<f64>,
}

/// zeta(z) at several radii and zeta(r) at several heights.
#[derive(Debug, Clone, PartialEq, Default)]
pub struct ZetaAtMode {
    /// Profiles along z (one per radius); `zeta-z` is skipped when empty.
    pub along_z: Vec<ZetaProfile>,
    /// Profiles along r (one per height); `zeta-r` is skipped when empty.
    pub along_r: Vec<ZetaProfile>,
}
