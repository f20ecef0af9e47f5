//! The TOML description of an impurity model, standalone or as `[semiconductor.impurity]`.

use std::path::Path;

use super::model::{
    ConstantModel, ImpurityModel, LinearZModel, ScaledModel, TiltedModel, ZTableModel,
};
use super::rz::RzModel;
use super::transform::LogTransform;
use crate::error::{Error, Result};

/// Which impurity model a spec describes (the TOML `model` key).
#[derive(Debug, Clone, Copy, PartialEq, Eq, Hash, serde::Serialize, serde::Deserialize)]
#[serde(rename_all = "kebab-case")]
pub enum ModelKind {
    /// `"constant"`: [`ConstantModel`], needs `zeta_cm3`.
    Constant,
    /// `"linear-z"`: [`LinearZModel`], needs `bottom_cm3` and `top_cm3`.
    LinearZ,
    /// `"rz"`: [`RzModel`], needs `y_bot` and `y_top` or `zeta_bot_cm3` and `zeta_top_cm3`;
    /// optional `knots_mm` and `transform`.
    Rz,
    /// `"z-table"`: [`ZTableModel`], needs `z_mm` and `values_cm3` (piecewise linear in z,
    /// constant beyond the ends; e.g. a LEGEND record's profile along the axis).
    ZTable,
}

impl ModelKind {
    /// The name as written in TOML.
    pub fn as_str(self) -> &'static str {
        match self {
            ModelKind::Constant => "constant",
            ModelKind::LinearZ => "linear-z",
            ModelKind::Rz => "rz",
            ModelKind::ZTable => "z-table",
        }
    }
}

impl std::fmt::Display for ModelKind {
    fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        f.write_str(self.as_str())
    }
}

/// An impurity model as written in TOML: one flat table whose `model` key says which of the other
/// keys apply. Unknown keys are rejected by the parser (with line and column); keys of another
/// model and physically invalid values are rejected by [`Self::build`].
///
/// ```toml
/// model = "rz"
/// knots_mm = [20.0, 28.0, 33.0, 37.5]          # optional if the context has default knots
/// y_bot = [0.7062704, 0.7062704, 0.5, -0.55]   # or zeta_bot_cm3 = [...] in cm^-3
/// y_top = [0.55060154, 0.55060154, 0.4, -0.7]  # or zeta_top_cm3 = [...]
/// transform = { v = 1000.0, x_l = 14.0, x_u = 17.0, g = 1000.0 }  # optional, these are the defaults
/// ```
#[derive(Debug, Clone, PartialEq, serde::Deserialize, serde::Serialize)]
#[serde(deny_unknown_fields)]
pub struct ImpuritySpec {
    /// Which model.
    pub model: ModelKind,
    /// `constant`: the density in cm^-3.
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub zeta_cm3: Option<f64>,
    /// `linear-z`: the density at the crystal's bottom (z_bottom_mm) in cm^-3.
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub bottom_cm3: Option<f64>,
    /// `linear-z`: the density at the crystal's top (z_top_mm) in cm^-3.
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub top_cm3: Option<f64>,
    /// `rz`: spline knots in mm (non-negative, strictly increasing); default from the context.
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub knots_mm: Option<Vec<f64>>,
    /// `rz`: y at the knots on the bottom face, each in [-1, 1].
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub y_bot: Option<Vec<f64>>,
    /// `rz`: y at the knots on the top face, each in [-1, 1].
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub y_top: Option<Vec<f64>>,
    /// `rz`: densities (cm^-3) at the knots on the bottom face, instead of `y_bot`.
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub zeta_bot_cm3: Option<Vec<f64>>,
    /// `rz`: densities (cm^-3) at the knots on the top face, instead of `y_top`.
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub zeta_top_cm3: Option<Vec<f64>>,
    /// `rz`: override of the transform's parameters (missing ones take the paper's values).
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub transform: Option<LogTransform>,
    /// `rz`: amplitude of a quadratic z term added to y, 4 y_quad t (1 - t) with t the relative
    /// height (zero at both faces; model discovery's `quadratic-z` extension). Default 0.
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub y_quad: Option<f64>,
    /// `z-table`: heights in mm (strictly increasing).
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub z_mm: Option<Vec<f64>>,
    /// `z-table`: the signed density (cm^-3) at each of `z_mm`.
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub values_cm3: Option<Vec<f64>>,
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

/// What a model needs from the detector: the crystal's z range and default knots.
#[derive(Debug, Clone, PartialEq)]
pub struct ImpurityContext {
    /// z of the crystal's bottom face in mm (where `bottom_cm3` / `y_bot` apply).
    pub z_bottom_mm: f64,
    /// z of the crystal's top face in mm (where `top_cm3` / `y_top` apply).
    pub z_top_mm: f64,
    /// Knots used by `rz` when the spec has no `knots_mm`.
    pub default_knots_mm: Option<Vec<f64>>,
}

/// Builds the dotted key paths of error messages.
#[derive(Clone, Copy)]
struct Keys<'a> {
    file: &'a Path,
    prefix: &'a str,
}

impl Keys<'_> {
    fn key(&self, name: &str) -> String {
        if self.prefix.is_empty() {
            name.to_string()
        } else {
            format!("{}.{name}", self.prefix)
        }
    }

    fn err(&self, name: &str, message: impl Into<String>) -> Error {
        Error::invalid(self.file, self.key(name), message)
    }

    fn finite(&self, name: &str, value: f64) -> Result<f64> {
        if value.is_finite() {
            Ok(value)
        } else {
            Err(self.err(name, format!("must be a finite number, got {value}")))
        }
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

    /// Parses TOML text; `file` is only for messages. Syntax errors, unknown keys, a missing
    /// `model` and wrong types are Parse errors with line and column.
    pub fn from_toml_str(text: &str, file: &Path) -> Result<Self> {
        toml::from_str(text).map_err(|e| Error::parse(file, &e))
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
        };
        self.check_foreign_keys(keys)?;
        let model = self.build_unscaled(ctx, keys)?;
        let model: Box<dyn ImpurityModel> = match self.tilt {
            None => model,
            Some(t) if t.is_finite() => {
                check_context(ctx)?;
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

    /// [`Self::build`] without the scale factor.
    fn build_unscaled(
        &self,
        ctx: &ImpurityContext,
        keys: Keys<'_>,
    ) -> Result<Box<dyn ImpurityModel>> {
        let model_key = "model";
        match self.model {
            ModelKind::Constant => {
                let zeta = self
                    .zeta_cm3
                    .ok_or_else(|| keys.err("zeta_cm3", "model \"constant\" needs `zeta_cm3`"))?;
                let zeta = keys.finite("zeta_cm3", zeta)?;
                let model =
                    ConstantModel::new(zeta).map_err(|e| keys.err(model_key, e.to_string()))?;
                Ok(Box::new(model))
            }
            ModelKind::LinearZ => {
                let need = "model \"linear-z\" needs `bottom_cm3` and `top_cm3`";
                let bottom = self
                    .bottom_cm3
                    .ok_or_else(|| keys.err("bottom_cm3", need))?;
                let top = self.top_cm3.ok_or_else(|| keys.err("top_cm3", need))?;
                let bottom = keys.finite("bottom_cm3", bottom)?;
                let top = keys.finite("top_cm3", top)?;
                check_context(ctx)?;
                let model = LinearZModel::new(bottom, top, ctx.z_bottom_mm, ctx.z_top_mm)
                    .map_err(|e| keys.err(model_key, e.to_string()))?;
                Ok(Box::new(model))
            }
            ModelKind::Rz => Ok(Box::new(self.build_rz(ctx, keys)?)),
            ModelKind::ZTable => {
                let need = "model \"z-table\" needs `z_mm` and `values_cm3`";
                let z = self.z_mm.as_ref().ok_or_else(|| keys.err("z_mm", need))?;
                let v = self
                    .values_cm3
                    .as_ref()
                    .ok_or_else(|| keys.err("values_cm3", need))?;
                if z.len() != v.len() || z.is_empty() {
                    return Err(keys.err(
                        "values_cm3",
                        format!(
                            "has {} values for {} heights in `z_mm` (need the same number, at least one)",
                            v.len(),
                            z.len()
                        ),
                    ));
                }
                for (i, &x) in z.iter().enumerate() {
                    keys.finite(&format!("z_mm[{i}]"), x)?;
                    if i > 0 && x <= z[i - 1] {
                        return Err(keys.err(
                            &format!("z_mm[{i}]"),
                            format!("heights must increase: {x} mm after {} mm", z[i - 1]),
                        ));
                    }
                }
                for (i, &x) in v.iter().enumerate() {
                    keys.finite(&format!("values_cm3[{i}]"), x)?;
                }
                Ok(Box::new(ZTableModel {
                    z_mm: z.clone(),
                    values_cm3: v.clone(),
                }))
            }
        }
    }

    /// Rejects keys that belong to a model other than `self.model`.
    fn check_foreign_keys(&self, keys: Keys<'_>) -> Result<()> {
        use ModelKind::{Constant, LinearZ, Rz, ZTable};
        let present = [
            ("zeta_cm3", self.zeta_cm3.is_some(), Constant),
            ("bottom_cm3", self.bottom_cm3.is_some(), LinearZ),
            ("top_cm3", self.top_cm3.is_some(), LinearZ),
            ("knots_mm", self.knots_mm.is_some(), Rz),
            ("y_bot", self.y_bot.is_some(), Rz),
            ("y_top", self.y_top.is_some(), Rz),
            ("zeta_bot_cm3", self.zeta_bot_cm3.is_some(), Rz),
            ("zeta_top_cm3", self.zeta_top_cm3.is_some(), Rz),
            ("transform", self.transform.is_some(), Rz),
            ("y_quad", self.y_quad.is_some(), Rz),
            ("z_mm", self.z_mm.is_some(), ZTable),
            ("values_cm3", self.values_cm3.is_some(), ZTable),
        ];
        for (name, is_some, owner) in present {
            if is_some && owner != self.model {
                return Err(keys.err(
                    name,
                    format!(
                        "`{name}` is not used by model \"{}\" (it belongs to model \"{owner}\")",
                        self.model
                    ),
                ));
            }
        }
        Ok(())
    }

    fn build_rz(&self, ctx: &ImpurityContext, keys: Keys<'_>) -> Result<RzModel> {
        let need = "model \"rz\" needs `y_bot` and `y_top`, or `zeta_bot_cm3` and `zeta_top_cm3`";
        let y_pair = (self.y_bot.as_ref(), self.y_top.as_ref());
        let zeta_pair = (self.zeta_bot_cm3.as_ref(), self.zeta_top_cm3.as_ref());
        let y_given = y_pair.0.is_some() || y_pair.1.is_some();
        let zeta_given = zeta_pair.0.is_some() || zeta_pair.1.is_some();
        if y_given && zeta_given {
            let name = if zeta_pair.0.is_some() {
                "zeta_bot_cm3"
            } else {
                "zeta_top_cm3"
            };
            return Err(keys.err(
                name,
                "give either `y_bot` and `y_top`, or `zeta_bot_cm3` and `zeta_top_cm3`, not both",
            ));
        }
        // Which pair is given (or which key is missing) is reported before anything else.
        let (bot, top, in_y) = match (y_pair, zeta_pair) {
            ((Some(bot), Some(top)), _) => (bot, top, true),
            (_, (Some(bot), Some(top))) => (bot, top, false),
            ((Some(_), None), _) => return Err(keys.err("y_top", need)),
            ((None, Some(_)), _) => return Err(keys.err("y_bot", need)),
            (_, (Some(_), None)) => return Err(keys.err("zeta_top_cm3", need)),
            (_, (None, Some(_))) => return Err(keys.err("zeta_bot_cm3", need)),
            _ => return Err(keys.err("model", need)),
        };
        let transform = self.transform.unwrap_or_default();
        transform
            .validate()
            .map_err(|e| keys.err("transform", e.to_string()))?;
        check_context(ctx)?;
        let knots = self.knots(ctx, keys)?;
        let n = knots.len();
        let (y_bot, y_top) = if in_y {
            (
                ys_from_y(bot, "y_bot", n, keys)?,
                ys_from_y(top, "y_top", n, keys)?,
            )
        } else {
            (
                ys_from_zeta(bot, "zeta_bot_cm3", n, &transform, keys)?,
                ys_from_zeta(top, "zeta_top_cm3", n, &transform, keys)?,
            )
        };
        RzModel::new(
            knots,
            y_bot,
            y_top,
            ctx.z_bottom_mm,
            ctx.z_top_mm,
            transform,
        )
        .and_then(|m| m.with_quadratic(self.y_quad.unwrap_or(0.0)))
        .map_err(|e| keys.err("model", e.to_string()))
    }

    /// The spec's `knots_mm` or the context's default, validated: non-empty, finite,
    /// non-negative, strictly increasing.
    fn knots(&self, ctx: &ImpurityContext, keys: Keys<'_>) -> Result<Vec<f64>> {
        let (knots, origin) = match (&self.knots_mm, &ctx.default_knots_mm) {
            (Some(k), _) => (k.clone(), ""),
            (None, Some(k)) => (k.clone(), " (the default knots)"),
            (None, None) => {
                return Err(keys.err(
                    "knots_mm",
                    "model \"rz\" needs `knots_mm` (no default knots are configured)",
                ));
            }
        };
        if knots.is_empty() {
            return Err(keys.err("knots_mm", format!("needs at least one knot{origin}")));
        }
        for (i, &r) in knots.iter().enumerate() {
            let name = format!("knots_mm[{i}]");
            if !r.is_finite() {
                return Err(keys.err(&name, format!("must be a finite number, got {r}{origin}")));
            }
            if r < 0.0 {
                return Err(keys.err(
                    &name,
                    format!("a radius must not be negative, got {r} mm{origin}"),
                ));
            }
            if i > 0 && r <= knots[i - 1] {
                return Err(keys.err(
                    &name,
                    format!(
                        "knots must be strictly increasing: {r} mm is not greater than \
                         knots_mm[{}] = {} mm{origin}",
                        i - 1,
                        knots[i - 1]
                    ),
                ));
            }
        }
        Ok(knots)
    }
}

/// The context's z range must be finite and increasing.
fn check_context(ctx: &ImpurityContext) -> Result<()> {
    let (bottom, top) = (ctx.z_bottom_mm, ctx.z_top_mm);
    if bottom.is_finite() && top.is_finite() && top > bottom {
        Ok(())
    } else {
        Err(Error::Argument {
            name: "ImpurityContext".to_string(),
            message: format!("need finite z_bottom_mm < z_top_mm, got {bottom} and {top}"),
        })
    }
}

fn check_length(values: &[f64], name: &str, n_knots: usize, keys: Keys<'_>) -> Result<()> {
    if values.len() == n_knots {
        Ok(())
    } else {
        Err(keys.err(
            name,
            format!("has {} values but there are {n_knots} knots", values.len()),
        ))
    }
}

/// y values as given, checked: one per knot, finite, in [-1, 1].
fn ys_from_y(values: &[f64], name: &str, n_knots: usize, keys: Keys<'_>) -> Result<Vec<f64>> {
    check_length(values, name, n_knots, keys)?;
    for (i, &y) in values.iter().enumerate() {
        let indexed = format!("{name}[{i}]");
        keys.finite(&indexed, y)?;
        if y.abs() > 1.0 {
            return Err(keys.err(&indexed, format!("y = {y} is outside [-1, 1]")));
        }
    }
    Ok(values.to_vec())
}

/// y values from densities in cm^-3: one per knot, finite, expressible by the transform.
fn ys_from_zeta(
    values: &[f64],
    name: &str,
    n_knots: usize,
    transform: &LogTransform,
    keys: Keys<'_>,
) -> Result<Vec<f64>> {
    check_length(values, name, n_knots, keys)?;
    values
        .iter()
        .enumerate()
        .map(|(i, &zeta)| {
            let indexed = format!("{name}[{i}]");
            keys.finite(&indexed, zeta)?;
            transform
                .y_of_zeta_cm3(zeta)
                .map_err(|e| keys.err(&indexed, e.to_string()))
        })
        .collect()
}

#[cfg(test)]
#[path = "spec_tests.rs"]
mod tests;
