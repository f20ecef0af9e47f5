//! The keys of `model = "rz"`: the paper's zeta_RZ (Eqs. (18)-(21)), y (or densities) at radial
//! knots on the bottom and top faces.

use super::model::ImpurityModel;
use super::rz::RzModel;
use super::spec::{BuildModel, ImpurityContext, Keys};
use super::transform::LogTransform;
use crate::error::Result;
use crate::expr::Quantity;

/// The keys of `model = "rz"`. Give `y_bot` and `y_top`, or `zeta_bot_cm3` and `zeta_top_cm3`.
#[derive(Debug, Clone, Default, PartialEq, serde::Deserialize, serde::Serialize)]
#[serde(deny_unknown_fields)]
pub struct RzSpec {
    /// Spline knots in mm (non-negative, strictly increasing); default from the context.
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub knots_mm: Option<Vec<f64>>,
    /// y at the knots on the bottom face, each in [-1, 1].
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub y_bot: Option<Vec<Quantity>>,
    /// y at the knots on the top face, each in [-1, 1].
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub y_top: Option<Vec<Quantity>>,
    /// Densities (cm^-3) at the knots on the bottom face, instead of `y_bot`.
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub zeta_bot_cm3: Option<Vec<Quantity>>,
    /// Densities (cm^-3) at the knots on the top face, instead of `y_top`.
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub zeta_top_cm3: Option<Vec<Quantity>>,
    /// Override of the transform's parameters (missing ones take the paper's values).
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub transform: Option<LogTransform>,
    /// Amplitude of a quadratic z term added to y, 4 y_quad t (1 - t) with t the relative height
    /// (zero at both faces; model discovery's `quadratic-z` extension). Default 0.
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub y_quad: Option<Quantity>,
}

impl BuildModel for RzSpec {
    fn build_model(&self, ctx: &ImpurityContext, keys: Keys<'_>) -> Result<Box<dyn ImpurityModel>> {
        Ok(Box::new(self.build_rz(ctx, keys)?))
    }
}

impl RzSpec {
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
        ctx.check_z_range()?;
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
        let y_quad = match &self.y_quad {
            Some(q) => keys.value("y_quad", q)?,
            None => 0.0,
        };
        RzModel::new(
            knots,
            y_bot,
            y_top,
            ctx.z_bottom_mm,
            ctx.z_top_mm,
            transform,
        )
        .and_then(|m| m.with_quadratic(y_quad))
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

fn check_length(values: &[Quantity], name: &str, n_knots: usize, keys: Keys<'_>) -> Result<()> {
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
fn ys_from_y(values: &[Quantity], name: &str, n_knots: usize, keys: Keys<'_>) -> Result<Vec<f64>> {
    check_length(values, name, n_knots, keys)?;
    let ys = keys.values(name, values)?;
    for (i, &y) in ys.iter().enumerate() {
        if y.abs() > 1.0 {
            return Err(keys.err(
                &format!("{name}[{i}]"),
                format!("y = {y} is outside [-1, 1]"),
            ));
        }
    }
    Ok(ys)
}

/// y values from densities in cm^-3: one per knot, finite, expressible by the transform.
fn ys_from_zeta(
    values: &[Quantity],
    name: &str,
    n_knots: usize,
    transform: &LogTransform,
    keys: Keys<'_>,
) -> Result<Vec<f64>> {
    check_length(values, name, n_knots, keys)?;
    let zetas = keys.values(name, values)?;
    zetas
        .iter()
        .enumerate()
        .map(|(i, &zeta)| {
            transform
                .y_of_zeta_cm3(zeta)
                .map_err(|e| keys.err(&format!("{name}[{i}]"), e.to_string()))
        })
        .collect()
}
