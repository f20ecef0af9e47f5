//! The TOML description of an impurity model, standalone or as `[semiconductor.impurity]`: the
//! `model` key names one of [`ModelSpec`]'s variants, each a struct of its own keys in its own
//! file; `scale` and `tilt` apply to any model. Densities and y values are numbers or
//! expressions over the detector's parameters ([`Quantity`]), so a parameter space reaches any
//! model through `parameter:NAME`.
//!
//! Adding a model is one file (its keys as a struct implementing [`BuildModel`], and its
//! [`super::ImpurityModel`]) plus one variant of [`ModelSpec`].

use std::path::Path;

use super::model::{ImpurityModel, ScaledModel, TiltedModel};
use crate::error::{Error, Result};
use crate::expr::{Parameters, Quantity};

pub use super::constant::ConstantSpec;
pub use super::linear_z::LinearZSpec;
pub use super::polynomial_z::PolynomialZSpec;
pub use super::rz_spec::RzSpec;
pub use super::z_table::ZTableSpec;

/// The model's own keys, tagged by the TOML `model` key. Unknown keys are rejected by the parser
/// with the list of the model's keys; keys of another model are unknown keys.
#[derive(Debug, Clone, PartialEq, serde::Deserialize, serde::Serialize)]
#[serde(tag = "model", rename_all = "kebab-case")]
pub enum ModelSpec {
    /// `"constant"`: one density everywhere.
    Constant(ConstantSpec),
    /// `"linear-z"`: linear in z between the faces (the manufacturer's, paper Eq. (14)).
    LinearZ(LinearZSpec),
    /// `"rz"`: the paper's zeta_RZ (Eqs. (18)-(21)).
    Rz(RzSpec),
    /// `"z-table"`: piecewise linear in z through a table.
    ZTable(ZTableSpec),
    /// `"polynomial-z"`: quadratic in the height above the bottom face (LEGEND's
    /// `function_pars`).
    PolynomialZ(PolynomialZSpec),
}

/// One model's keys, built into the model.
pub trait BuildModel {
    /// Validates the keys and builds the model; errors name the key through `keys`.
    fn build_model(&self, ctx: &ImpurityContext, keys: Keys<'_>) -> Result<Box<dyn ImpurityModel>>;
}

impl ModelSpec {
    /// The name as written in TOML's `model` key.
    pub fn name(&self) -> &'static str {
        match self {
            ModelSpec::Constant(_) => "constant",
            ModelSpec::LinearZ(_) => "linear-z",
            ModelSpec::Rz(_) => "rz",
            ModelSpec::ZTable(_) => "z-table",
            ModelSpec::PolynomialZ(_) => "polynomial-z",
        }
    }

    fn builder(&self) -> &dyn BuildModel {
        match self {
            ModelSpec::Constant(s) => s,
            ModelSpec::LinearZ(s) => s,
            ModelSpec::Rz(s) => s,
            ModelSpec::ZTable(s) => s,
            ModelSpec::PolynomialZ(s) => s,
        }
    }
}

/// An impurity model as written in TOML: `model` and that model's keys ([`ModelSpec`]), and the
/// modifiers any model takes.
///
/// ```toml
/// model = "rz"
/// knots_mm = [20.0, 28.0, 33.0, 37.5]          # optional if the context has default knots
/// y_bot = [0.7062704, 0.7062704, 0.5, -0.55]   # or zeta_bot_cm3 = [...] in cm^-3
/// y_top = [0.55060154, 0.55060154, 0.4, -0.7]  # or zeta_top_cm3 = [...]; "y1" names a parameter
/// transform = { v = 1000.0, x_l = 14.0, x_u = 17.0, g = 1000.0 }  # optional, these are the defaults
/// ```
///
/// ```
/// use std::path::Path;
/// use hpge_solver::impurity::{ImpurityContext, ImpuritySpec};
/// use hpge_solver::Parameters;
/// let spec = ImpuritySpec::from_toml_str(
///     "model = \"linear-z\"\nbottom_cm3 = \"-1e10 * f\"\ntop_cm3 = -0.5e10\n",
///     Path::new("impurity.toml"),
/// )?;
/// assert_eq!(spec.model.name(), "linear-z");
/// let mut parameters = Parameters::new();
/// parameters.set("f", 2.0);
/// let ctx = ImpurityContext { z_bottom_mm: 0.0, z_top_mm: 10.0, default_knots_mm: None, parameters };
/// let m = spec.build(&ctx, Path::new("impurity.toml"), "")?;
/// assert_eq!(m.density_cm3(0.0, 0.0), -2e10, "the parameter's value");
/// assert!(ImpuritySpec::from_toml_str("model = \"constant\"\nzeta_cm3 = 1.0\nbottom_cm3 = 2.0\n",
///     Path::new("impurity.toml")).is_err(), "a key of another model");
/// # Ok::<(), hpge_solver::Error>(())
/// ```
#[derive(Debug, Clone, PartialEq, serde::Deserialize, serde::Serialize)]
pub struct ImpuritySpec {
    /// Which model, and its keys.
    #[serde(flatten)]
    pub model: ModelSpec,
    /// Any model: a positive factor multiplying its density everywhere (default 1), the impurity
    /// scale factor LEGEND's workflow matches to a measured depletion voltage (`hpge-cv
    /// depletion`, issue 64).
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub scale: Option<f64>,
    /// Any model: a factor on its variation along z about the crystal's mid-height (default 1;
    /// [`TiltedModel`]): zeta(r, z) = zeta(r, z_mid) + tilt (zeta(r, z) - zeta(r, z_mid)),
    /// applied before `scale`. The gradient's uncertainty in `hpge-cv depletion --tilt-range`
    /// (issue 64).
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub tilt: Option<f64>,
}

/// What a model needs from the detector: the crystal's z range, default knots and the values of
/// its parameters.
#[derive(Debug, Clone, PartialEq)]
pub struct ImpurityContext {
    /// z of the crystal's bottom face in mm (where `bottom_cm3` / `y_bot` apply).
    pub z_bottom_mm: f64,
    /// z of the crystal's top face in mm (where `top_cm3` / `y_top` apply).
    pub z_top_mm: f64,
    /// Knots used by `rz` when the spec has no `knots_mm`.
    pub default_knots_mm: Option<Vec<f64>>,
    /// The detector's parameters, which the model's values may name.
    pub parameters: Parameters,
}

impl ImpurityContext {
    /// The z range must be finite and increasing ([`Error::Argument`] otherwise).
    pub fn check_z_range(&self) -> Result<()> {
        let (bottom, top) = (self.z_bottom_mm, self.z_top_mm);
        if bottom.is_finite() && top.is_finite() && top > bottom {
            Ok(())
        } else {
            Err(Error::Argument {
                name: "ImpurityContext".to_string(),
                message: format!("need finite z_bottom_mm < z_top_mm, got {bottom} and {top}"),
            })
        }
    }
}

/// Builds the dotted key paths of error messages and evaluates values.
#[derive(Clone, Copy)]
pub struct Keys<'a> {
    file: &'a Path,
    prefix: &'a str,
    parameters: &'a Parameters,
}

impl Keys<'_> {
    /// The full dotted key of `name`, e.g. `semiconductor.impurity.y_bot[2]`.
    pub fn key(&self, name: &str) -> String {
        if self.prefix.is_empty() {
            name.to_string()
        } else {
            format!("{}.{name}", self.prefix)
        }
    }

    /// An [`Error::Invalid`] naming the file and the key `name`.
    pub fn err(&self, name: &str, message: impl Into<String>) -> Error {
        Error::invalid(self.file, self.key(name), message)
    }

    /// `value` if finite, else an error naming `name`.
    pub fn finite(&self, name: &str, value: f64) -> Result<f64> {
        if value.is_finite() {
            Ok(value)
        } else {
            Err(self.err(name, format!("must be a finite number, got {value}")))
        }
    }

    /// The value of `q` over the detector's parameters: finite, or an error naming `name` and
    /// the failure (an unknown parameter, a syntax error).
    pub fn value(&self, name: &str, q: &Quantity) -> Result<f64> {
        match q.eval(self.parameters) {
            Ok(v) => self.finite(name, v),
            Err(Error::Expression { reason, .. }) => Err(self.err(name, reason)),
            Err(e) => Err(self.err(name, e.to_string())),
        }
    }

    /// The values of a list, each named `name[i]`.
    pub fn values(&self, name: &str, qs: &[Quantity]) -> Result<Vec<f64>> {
        qs.iter()
            .enumerate()
            .map(|(i, q)| self.value(&format!("{name}[{i}]"), q))
            .collect()
    }
}

impl ImpuritySpec {
    /// Reads and parses a standalone impurity file (Io and Parse errors).
    pub fn from_file(path: &Path) -> Result<Self> {
        let text = std::fs::read_to_string(path).map_err(|source| Error::Io {
            file: path.to_path_buf(),
            source,
        })?;
        Self::from_toml_str(&text, path)
    }

    /// Parses TOML text; `file` is only for messages. Syntax errors, unknown keys (with the
    /// model's keys listed), a missing `model` and wrong types are Parse errors.
    pub fn from_toml_str(text: &str, file: &Path) -> Result<Self> {
        toml::from_str(text).map_err(|e| explain(Error::parse(file, &e), Some(text)))
    }

    /// The spec of a TOML table (e.g. a parameter space's `[impurity]` with its values set);
    /// `file` is only for messages.
    pub fn from_table(table: toml::Table, file: &Path) -> Result<Self> {
        toml::Value::Table(table)
            .try_into()
            .map_err(|e: toml::de::Error| explain(Error::parse(file, &e), None))
    }

    /// Validates the spec and builds the model.
    ///
    /// `file` and `key_prefix` (e.g. "" for a standalone file, "semiconductor.impurity" inside a
    /// detector) are only for messages: errors are [`Error::Invalid`] with the full dotted key,
    /// e.g. `semiconductor.impurity.y_bot[2]`. An invalid `ctx` z range is an [`Error::Argument`].
    pub fn build(
        &self,
        ctx: &ImpurityContext,
        file: &Path,
        key_prefix: &str,
    ) -> Result<Box<dyn ImpurityModel>> {
        let keys = Keys {
            file,
            prefix: key_prefix,
            parameters: &ctx.parameters,
        };
        let model = self.model.builder().build_model(ctx, keys)?;
        let model: Box<dyn ImpurityModel> = match self.tilt {
            None => model,
            Some(t) if t.is_finite() => {
                ctx.check_z_range()?;
                Box::new(TiltedModel {
                    inner: model,
                    tilt: t,
                    z_mid_mm: 0.5 * (ctx.z_bottom_mm + ctx.z_top_mm),
                })
            }
            Some(t) => return Err(keys.err("tilt", format!("must be a finite number, got {t}"))),
        };
        match self.scale {
            None => Ok(model),
            Some(f) if f.is_finite() && f > 0.0 => Ok(Box::new(ScaledModel {
                inner: model,
                factor: f,
            })),
            Some(f) => Err(keys.err(
                "scale",
                format!("must be a positive finite factor, got {f}"),
            )),
        }
    }

    /// The rz model's knots where the spec gives them (checked against the crystal's radius by
    /// the detector).
    pub fn knots_mm(&self) -> Option<&[f64]> {
        match &self.model {
            ModelSpec::Rz(rz) => rz.knots_mm.as_deref(),
            _ => None,
        }
    }
}

/// The names of every model, as the `model` key takes them (from the parser's own list).
pub fn model_names() -> Vec<String> {
    let probe = toml::from_str::<ImpuritySpec>("model = \"?\"\n");
    let message = probe.err().map(|e| e.to_string()).unwrap_or_default();
    let list = message.split("expected ").nth(1).unwrap_or("");
    list.split('`')
        .skip(1)
        .step_by(2)
        .map(str::to_string)
        .collect()
}

/// A parse error of an impurity table with what its unknown key means: the models it belongs
/// to and, where the `text` is given, its line. Other errors are returned as they are.
pub(crate) fn explain(err: Error, text: Option<&str>) -> Error {
    let Error::Parse { file, message } = err else {
        return err;
    };
    let Some(key) = message
        .split("unknown field `")
        .nth(1)
        .and_then(|rest| rest.split('`').next())
        .map(str::to_string)
    else {
        return Error::Parse { file, message };
    };
    let accepts = |model: &str| {
        let probe = format!("model = \"{model}\"\n{key} = 0\n");
        match toml::from_str::<ImpuritySpec>(&probe) {
            Ok(_) => true,
            Err(e) => !e.to_string().contains("unknown field"),
        }
    };
    let owners: Vec<String> = model_names()
        .into_iter()
        .filter(|m| accepts(m))
        .map(|m| format!("\"{m}\""))
        .collect();
    let line = text.and_then(|t| {
        t.lines().position(|l| {
            l.trim_start()
                .strip_prefix(key.as_str())
                .is_some_and(|rest| rest.trim_start().starts_with('='))
        })
    });
    let mut hint = format!("`{key}`");
    if let Some(n) = line {
        hint.push_str(&format!(" (line {})", n + 1));
    }
    if owners.is_empty() {
        hint.push_str(" is not a key of any impurity model");
    } else {
        hint.push_str(&format!(
            " is not a key of this model; it belongs to model {}",
            owners.join(", ")
        ));
    }
    Error::Parse {
        file,
        message: format!("{message}\n{hint}"),
    }
}

#[cfg(test)]
#[path = "spec_tests.rs"]
mod tests;
