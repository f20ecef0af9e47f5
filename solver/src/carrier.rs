//! The charge carriers of a semiconductor: electrons and holes (used by the drift and by the
//! field's pockets, which one carrier type fills).

/// The two kinds of charge carrier (a closed set).
#[derive(Debug, Clone, Copy, PartialEq, Eq, Hash, serde::Serialize, serde::Deserialize)]
#[serde(rename_all = "snake_case")]
pub enum Carrier {
    /// Conduction electron, charge -q: drifts against the field.
    Electron,
    /// Hole, charge +q: drifts along the field.
    Hole,
}

impl Carrier {
    /// Charge in units of the elementary charge: -1 for electrons, +1 for holes.
    pub fn charge_e(self) -> f64 {
        match self {
            Carrier::Electron => -1.0,
            Carrier::Hole => 1.0,
        }
    }

    /// Name for messages.
    pub fn as_str(self) -> &'static str {
        match self {
            Carrier::Electron => "electron",
            Carrier::Hole => "hole",
        }
    }
}
