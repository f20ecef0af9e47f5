//! Detector descriptions: the TOML format, its evaluation and checks, and the resulting model.

mod build;
mod initial_grid;
pub use initial_grid::MAX_GRID_NODES;
pub mod legend;
mod model;
mod spec;

use std::path::Path;

pub use model::{
    BoundaryKind, Contact, ContactPotential, Detector, Passive, PassiveKind, Region, Semiconductor,
    World, WorldSide,
};

use crate::error::{Error, Result};
use crate::expr::Parameters;
use crate::impurity::ImpuritySpec;

impl Detector {
    /// Reads, evaluates and checks a detector file; `overrides` replace values of its
    /// `[parameters]` (each must be declared there).
    pub fn from_file(path: &Path, overrides: &Parameters) -> Result<Self> {
        let text = std::fs::read_to_string(path).map_err(|source| Error::Io {
            file: path.to_path_buf(),
            source,
        })?;
        Self::from_toml_str(&text, path, overrides)
    }

    /// As [`Detector::from_file`] for text already in memory; `file` is used in messages.
    pub fn from_toml_str(text: &str, file: &Path, overrides: &Parameters) -> Result<Self> {
        let spec: spec::DetectorSpec = toml::from_str(text).map_err(|e| {
            let err = Error::parse(file, &e);
            // An unknown key of the impurity table: say which model it belongs to.
            if e.to_string().contains("impurity") {
                crate::impurity::explain(err, None)
            } else {
                err
            }
        })?;
        build::build(&spec, file, overrides)
    }

    /// Replaces the impurity model by the one in an impurity file.
    pub fn set_impurity_file(&mut self, path: &Path) -> Result<()> {
        let spec = ImpuritySpec::from_file(path)?;
        self.set_impurity(&spec, path)
    }

    /// Replaces the impurity model by `spec`; `file` is where it came from (for messages).
    pub fn set_impurity(&mut self, spec: &ImpuritySpec, file: &Path) -> Result<()> {
        build::set_impurity(self, spec, file)
    }

    /// The detector with its impurity density multiplied by `factor` everywhere (the model's
    /// `scale` key times `factor`): zeta'(r, z) = factor * zeta(r, z).
    ///
    /// # Errors
    /// A factor that is not positive and finite ([`Error::Invalid`] naming `scale`).
    pub fn with_impurity_scale(&self, factor: f64) -> Result<Self> {
        let mut spec = self.semiconductor.impurity_spec().clone();
        spec.scale = Some(spec.scale.unwrap_or(1.0) * factor);
        let file = self.semiconductor.impurity_file().to_path_buf();
        let mut det = self.clone();
        det.set_impurity(&spec, &file)?;
        Ok(det)
    }

    /// The detector with its impurity density's variation along z multiplied by `tilt` about
    /// the crystal's mid-height (the model's `tilt` key times `tilt`; tilts about one pivot
    /// compose by multiplication): zeta'(r, z) = zeta(r, z_mid) + tilt (zeta(r, z) -
    /// zeta(r, z_mid)).
    ///
    /// # Errors
    /// A tilt that is not finite ([`Error::Invalid`] naming `tilt`).
    pub fn with_impurity_tilt(&self, tilt: f64) -> Result<Self> {
        let mut spec = self.semiconductor.impurity_spec().clone();
        spec.tilt = Some(spec.tilt.unwrap_or(1.0) * tilt);
        let file = self.semiconductor.impurity_file().to_path_buf();
        let mut det = self.clone();
        det.set_impurity(&spec, &file)?;
        Ok(det)
    }

    /// Whether the impurity density varies along z anywhere in the crystal's bounding box
    /// (sampled on a 17 x 33 lattice of (r, z), relative change above 1e-9): what a tilt
    /// ([`Detector::with_impurity_tilt`]) changes.
    pub fn impurity_varies_along_z(&self) -> bool {
        let b = self.semiconductor.geometry.bbox();
        let ctx = &self.semiconductor.impurity_context;
        let model = self.impurity();
        let (z0, z1) = (ctx.z_bottom_mm, ctx.z_top_mm);
        (0..17).any(|i| {
            let r = b.r_min_mm + (b.r_max_mm - b.r_min_mm) * i as f64 / 16.0;
            let first = model.density_cm3(r, z0);
            (1..33).any(|k| {
                let z = z0 + (z1 - z0) * k as f64 / 32.0;
                let d = model.density_cm3(r, z);
                (d - first).abs() > 1e-9 * d.abs().max(first.abs())
            })
        })
    }
}
