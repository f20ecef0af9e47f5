//! Reading a diode record's fields with messages that name the file and the key.

use std::path::Path;

use serde_json::Value;

use crate::error::{Error, Result};

/// Reads a record's fields with messages naming the file and the key.
pub(super) struct Reader<'a> {
    pub(super) file: &'a Path,
}

impl Reader<'_> {
    pub(super) fn err(&self, key: &str, message: impl Into<String>) -> Error {
        Error::Invalid {
            file: self.file.to_path_buf(),
            key: key.to_string(),
            message: message.into(),
        }
    }

    pub(super) fn get<'v>(&self, v: &'v Value, key: &str) -> Option<&'v Value> {
        let mut cur = v;
        for part in key.split('.') {
            cur = cur.get(part)?;
        }
        Some(cur)
    }

    /// A number `>= 0` (`> 0` when `positive`), required.
    pub(super) fn length(&self, v: &Value, key: &str, positive: bool) -> Result<f64> {
        let x = self
            .get(v, key)
            .ok_or_else(|| self.err(key, "missing (a length in mm)"))?;
        self.check_length(x, key, positive)
    }

    pub(super) fn check_length(&self, x: &Value, key: &str, positive: bool) -> Result<f64> {
        let x = x
            .as_f64()
            .ok_or_else(|| self.err(key, format!("must be a number (mm), got {x}")))?;
        if !x.is_finite() || x < 0.0 || (positive && x == 0.0) {
            return Err(self.err(
                key,
                format!(
                    "must be a {} number of mm, got {x}",
                    if positive { "positive" } else { "non-negative" }
                ),
            ));
        }
        Ok(x)
    }

    /// An optional length (0 when absent).
    pub(super) fn opt_length(&self, v: &Value, key: &str) -> Result<f64> {
        match self.get(v, key) {
            None | Some(Value::Null) => Ok(0.0),
            Some(x) => self.check_length(x, key, false),
        }
    }

    /// An optional angle in degrees in [0, 90).
    pub(super) fn opt_angle(&self, v: &Value, key: &str) -> Result<f64> {
        match self.get(v, key) {
            None | Some(Value::Null) => Ok(0.0),
            Some(x) => {
                let a = x
                    .as_f64()
                    .ok_or_else(|| self.err(key, format!("must be a number (degrees), got {x}")))?;
                if !(0.0..90.0).contains(&a) {
                    return Err(self.err(key, format!("must be in [0, 90) degrees, got {a}")));
                }
                Ok(a)
            }
        }
    }

    /// A taper (`geometry.taper.<which>`): the radial step (mm) it cuts and its height (mm).
    pub(super) fn taper(&self, g: &Value, which: &str) -> Result<(f64, f64)> {
        let h = self.opt_length(g, &format!("taper.{which}.height_in_mm"))?;
        let a = self.opt_angle(g, &format!("taper.{which}.angle_in_deg"))?;
        Ok((h * a.to_radians().tan(), h))
    }
}
