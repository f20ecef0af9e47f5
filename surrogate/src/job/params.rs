//! Parameter lists as a user writes them (`hpge-cv predict --params`): NAME=VALUE pairs in any
//! order, or bare values in the model's order, comma-separated over one or more items.

use crate::model::Surrogate;
use crate::{Error, Result};

fn refuse(message: String) -> Error {
    Error::Parameters { message }
}

/// Parses NAME=VALUE pairs (any order, every name of the model once) or bare values in the
/// model's order into the model's parameter vector; refuses unknown or missing names, a wrong
/// count, a mix of both forms and values that are not finite numbers ([`Error::Parameters`]).
pub fn parse_params(model: &Surrogate, items: &[String]) -> Result<Vec<f64>> {
    let names = model.parameter_names();
    let parts: Vec<&str> = items
        .iter()
        .flat_map(|s| s.split(','))
        .map(str::trim)
        .filter(|s| !s.is_empty())
        .collect();
    let mut values = vec![f64::NAN; names.len()];
    let mut given = vec![false; names.len()];
    let named = parts.iter().any(|p| p.contains('='));
    if named {
        for p in &parts {
            let Some((n, v)) = p.split_once('=') else {
                return Err(refuse(format!(
                    "`{p}` is not NAME=VALUE (do not mix names and bare values)"
                )));
            };
            let Some(k) = names.iter().position(|&x| x == n.trim()) else {
                return Err(refuse(format!(
                    "unknown parameter `{}`; the model takes {}",
                    n.trim(),
                    names.join(", ")
                )));
            };
            if given[k] {
                return Err(refuse(format!(
                    "`{}` is given twice; give each parameter once",
                    names[k]
                )));
            }
            given[k] = true;
            values[k] = v
                .trim()
                .parse()
                .map_err(|_| refuse(format!("`{v}` (for {n}) is not a number")))?;
            if !values[k].is_finite() {
                return Err(refuse(format!(
                    "`{}` = {} is not a finite number",
                    names[k], values[k]
                )));
            }
        }
        if let Some(k) = given.iter().position(|g| !g) {
            return Err(refuse(format!(
                "no value for `{}`; the model takes {}",
                names[k],
                names.join(", ")
            )));
        }
    } else {
        if parts.len() != names.len() {
            return Err(refuse(format!(
                "{} values given, the model takes {} ({})",
                parts.len(),
                names.len(),
                names.join(", ")
            )));
        }
        for (k, p) in parts.iter().enumerate() {
            values[k] = p
                .parse()
                .map_err(|_| refuse(format!("`{p}` (for {}) is not a number", names[k])))?;
        }
    }
    if let Some(k) = values.iter().position(|v| !v.is_finite()) {
        return Err(refuse(format!(
            "`{}` = {} is not a finite number",
            names[k], values[k]
        )));
    }
    Ok(values)
}
