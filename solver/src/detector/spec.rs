//! The detector file format (TOML), as deserialised before evaluation and checks.
//!
//! See `detectors/README.md` for the user-facing description of every key.

use std::collections::BTreeMap;
use std::fmt;

use serde::de::{self, Visitor};
use serde::{Deserialize, Deserializer, Serialize};

use super::{BoundaryKind, PassiveKind};
use crate::expr::Quantity;
use crate::geometry::SolidSpec;
use crate::impurity::ImpuritySpec;

/// Top level of a detector file.
#[derive(Debug, Clone, Deserialize, Serialize)]
#[serde(deny_unknown_fields)]
pub(crate) struct DetectorSpec {
    pub name: String,
    #[serde(default)]
    pub description: Option<String>,
    /// Named numbers that geometry expressions may use, e.g. `d_li_mm = 1.0`.
    #[serde(default)]
    pub parameters: BTreeMap<String, f64>,
    /// Additional or overriding materials.
    #[serde(default)]
    pub materials: BTreeMap<String, MaterialSpec>,
    pub world: WorldSpec,
    pub semiconductor: SemiconductorSpec,
    pub contacts: Vec<ContactSpec>,
    #[serde(default)]
    pub passives: Vec<PassiveSpec>,
    /// Grid and accuracy settings for this detector (`GridSettings`: keys left out keep their
    /// defaults; unknown keys are errors).
    #[serde(default)]
    pub grid: Option<crate::grid::GridSettings>,
}

#[derive(Debug, Clone, Deserialize, Serialize)]
#[serde(deny_unknown_fields)]
pub(crate) struct MaterialSpec {
    pub eps_r: f64,
    #[serde(default)]
    pub conductor: bool,
    #[serde(default)]
    pub note: Option<String>,
}

#[derive(Debug, Clone, Deserialize, Serialize)]
#[serde(deny_unknown_fields)]
pub(crate) struct WorldSpec {
    pub r_max_mm: Quantity,
    pub z_min_mm: Quantity,
    pub z_max_mm: Quantity,
    #[serde(default = "default_medium")]
    pub medium: String,
    pub boundary: WorldBoundarySpec,
    #[serde(default)]
    pub label: WorldLabelSpec,
}

fn default_medium() -> String {
    "vacuum".to_string()
}

#[derive(Debug, Clone, Deserialize, Serialize)]
#[serde(deny_unknown_fields)]
pub(crate) struct WorldBoundarySpec {
    pub r_max: BoundaryKind,
    pub z_min: BoundaryKind,
    pub z_max: BoundaryKind,
}

#[derive(Debug, Clone, Default, Deserialize, Serialize)]
#[serde(deny_unknown_fields)]
pub(crate) struct WorldLabelSpec {
    #[serde(default)]
    pub r_max: Option<String>,
    #[serde(default)]
    pub z_min: Option<String>,
    #[serde(default)]
    pub z_max: Option<String>,
}

#[derive(Debug, Clone, Deserialize, Serialize)]
#[serde(deny_unknown_fields)]
pub(crate) struct SemiconductorSpec {
    #[serde(default)]
    pub name: Option<String>,
    #[serde(default = "default_semiconductor")]
    pub material: String,
    pub geometry: SolidSpec,
    /// The default impurity model (same keys as a standalone impurity file).
    pub impurity: ImpuritySpec,
    /// Default spline knots (mm) for `model = "rz"` files that give none.
    #[serde(default)]
    pub rz_knots_mm: Option<Vec<f64>>,
    /// z (mm) of the crystal bottom and top used by the z-dependent models; default: the
    /// semiconductor's bounding box.
    #[serde(default)]
    pub z_bottom_mm: Option<Quantity>,
    #[serde(default)]
    pub z_top_mm: Option<Quantity>,
}

fn default_semiconductor() -> String {
    "HPGe".to_string()
}

#[derive(Debug, Clone, Deserialize, Serialize)]
#[serde(deny_unknown_fields)]
pub(crate) struct ContactSpec {
    pub id: u32,
    pub name: String,
    pub potential: PotentialSpec,
    pub geometry: SolidSpec,
}

#[derive(Debug, Clone, Deserialize, Serialize)]
#[serde(deny_unknown_fields)]
pub(crate) struct PassiveSpec {
    pub name: String,
    pub kind: PassiveKind,
    #[serde(default)]
    pub material: Option<String>,
    pub geometry: SolidSpec,
}

/// `potential = "bias"` or `potential = 0.0` (V).
#[derive(Debug, Clone, PartialEq)]
pub(crate) enum PotentialSpec {
    Bias,
    Volts(f64),
}

impl Serialize for PotentialSpec {
    fn serialize<S: serde::Serializer>(&self, s: S) -> Result<S::Ok, S::Error> {
        match self {
            PotentialSpec::Bias => s.serialize_str("bias"),
            PotentialSpec::Volts(v) => s.serialize_f64(*v),
        }
    }
}

impl<'de> Deserialize<'de> for PotentialSpec {
    fn deserialize<D: Deserializer<'de>>(d: D) -> Result<Self, D::Error> {
        struct V;
        impl Visitor<'_> for V {
            type Value = PotentialSpec;
            fn expecting(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
                f.write_str("a potential in V or the string \"bias\"")
            }
            fn visit_f64<E: de::Error>(self, v: f64) -> Result<PotentialSpec, E> {
                Ok(PotentialSpec::Volts(v))
            }
            fn visit_i64<E: de::Error>(self, v: i64) -> Result<PotentialSpec, E> {
                Ok(PotentialSpec::Volts(v as f64))
            }
            fn visit_u64<E: de::Error>(self, v: u64) -> Result<PotentialSpec, E> {
                Ok(PotentialSpec::Volts(v as f64))
            }
            fn visit_str<E: de::Error>(self, v: &str) -> Result<PotentialSpec, E> {
                if v == "bias" {
                    Ok(PotentialSpec::Bias)
                } else {
                    Err(E::invalid_value(de::Unexpected::Str(v), &self))
                }
            }
        }
        d.deserialize_any(V)
    }
}
