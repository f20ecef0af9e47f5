//! Grid and accuracy options given on top of a detector file (the command line's `--tolerance`
//! and `--grid KEY=VALUE`), declared once here and flattened into every command that solves
//! fields.

use super::GridSettings;
use crate::detector::Detector;
use crate::error::{Error, Result};
use crate::field::FieldSettings;

/// Grid and accuracy options of every command that solves fields. Precedence: the program's
/// defaults, then the detector file's `[grid]` table, then `--grid`, then `--tolerance`.
#[derive(Debug, Clone, Default, PartialEq)]
#[cfg_attr(feature = "clap", derive(clap::Args))]
pub struct GridOverrides {
    /// Target relative error of c12 for the adaptive grid (the detector's `[grid]` table, else
    /// 0.002 = 0.2%; for the exact solver of `fit` and `discover`, else 0.01 = 1%).
    #[cfg_attr(
        feature = "clap",
        arg(long, value_name = "REL", allow_hyphen_values = true)
    )]
    pub tolerance: Option<f64>,
    /// A grid setting as KEY=VALUE, VALUE in TOML syntax (e.g. front_spacing_mm=0.1,
    /// adaptive=false, refinement_limits=[0.2,0.1]); repeatable. The keys are those of the
    /// detector file's `[grid]` table (detectors/README.md).
    #[cfg_attr(
        feature = "clap",
        arg(long = "grid", value_name = "KEY=VALUE", value_parser = parse_grid_setting)
    )]
    pub grid: Vec<(String, String)>,
}

impl GridOverrides {
    /// `base` with the detector's `[grid]` table, then these options, in force.
    ///
    /// # Errors
    /// [`Error::GridOption`] naming the option when the grid settings refuse a key or value;
    /// [`Error::Invalid`] naming the detector's world key when its initial grid would be larger
    /// than [`crate::detector::MAX_GRID_NODES`] at these settings.
    pub fn apply(&self, base: &FieldSettings, det: &Detector) -> Result<FieldSettings> {
        let mut s = base.for_detector(det);
        s.grid = with_overrides(&s.grid, &self.grid)?;
        if let Some(t) = self.tolerance {
            s.grid.tolerance = t;
            s.grid.validate().map_err(|m| Error::GridOption {
                option: format!("--tolerance {t}"),
                message: m.to_string(),
            })?;
        }
        crate::grid::Grid::check_initial_size(det, &s.grid)?;
        Ok(s)
    }
}

fn with_overrides(grid: &GridSettings, items: &[(String, String)]) -> Result<GridSettings> {
    grid.with_overrides(items).map_err(|m| Error::GridOption {
        option: "--grid".into(),
        message: m.to_string(),
    })
}

/// Parses KEY=VALUE as given to `--grid` (both sides non-empty, trimmed).
///
/// # Errors
/// A message saying what was expected (the command line shows it beside the option).
pub fn parse_grid_setting(text: &str) -> std::result::Result<(String, String), Error> {
    let (k, v) = text.split_once('=').ok_or_else(|| Error::Syntax {
        text: text.into(),
        message: format!("expected KEY=VALUE (e.g. front_spacing_mm=0.1), got `{text}`"),
    })?;
    let (k, v) = (k.trim(), v.trim());
    if k.is_empty() || v.is_empty() {
        return Err(Error::Syntax {
            text: text.into(),
            message: format!("expected KEY=VALUE, got `{text}`"),
        });
    }
    Ok((k.to_string(), v.to_string()))
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn grid_settings_parse() {
        assert_eq!(
            parse_grid_setting(" adaptive = false ").unwrap(),
            ("adaptive".to_string(), "false".to_string())
        );
        assert!(parse_grid_setting("adaptive").is_err());
        assert!(parse_grid_setting("=1").is_err());
    }
}
