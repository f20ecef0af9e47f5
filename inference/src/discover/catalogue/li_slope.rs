//! A lithium (n+) layer whose thickness varies linearly along z: d(z) = d_Li + s (t - 1/2), t the
//! relative height along the contact, s the top-minus-bottom difference (mm). Lithium diffusion
//! is not uniform along a crystal; the start model has one d_Li. Outside the surrogate's space:
//! computed with the exact solver, by re-shaping the bias contact's tube.

use hpge_solver::Detector;
use hpge_solver::detector::ContactPotential;
use hpge_solver::geometry::{Primitive, Solid};

use super::{Baseline, Candidate, ExactParameter, Extension, one_more_exact};
use crate::{Error, Result};

/// Domain of s, mm.
pub const SLOPE_RANGE_MM: [f64; 2] = [-4.0, 4.0];
/// Prior sd of s, mm.
pub const SLOPE_PRIOR_SD_MM: f64 = 1.0;
/// The thinnest layer allowed anywhere, mm.
const MIN_THICKNESS_MM: f64 = 0.05;
/// The effect, in words (names it in errors and descriptions).
const LABEL: &str = "a Li thickness slope";

/// The error of a slope that cannot be applied.
fn cannot(message: String) -> Error {
    Error::Extension {
        extension: LABEL.into(),
        message,
    }
}

/// Replaces the bias contact's tube r in [r_in, r_in + d] by a layer of thickness
/// d + s (t - 1/2): the cone with those radii, keeping the tube's rounded ends (within the
/// rounding radius of each end the layer keeps at least the tube's shape). s = 0 leaves the
/// contact unchanged.
fn set_slope(det: &mut Detector, extra: &[f64]) -> Result<()> {
    let s = extra[0];
    let mut found = false;
    for c in det.contacts.iter_mut() {
        if c.potential != ContactPotential::Bias {
            continue;
        }
        let Solid::Primitive(Primitive::Tube {
            r_in_mm,
            r_out_mm,
            z_min_mm,
            z_max_mm,
            round_outer_mm,
        }) = c.geometry.clone()
        else {
            return Err(cannot(format!(
                "contact {} is not a single tube: the Li thickness slope needs a tube-shaped n+ layer",
                c.label()
            )));
        };
        let d = r_out_mm - r_in_mm;
        if d - 0.5 * s.abs() < MIN_THICKNESS_MM {
            return Err(cannot(format!(
                "a slope of {s} mm on a {d} mm layer leaves less than {MIN_THICKNESS_MM} mm"
            )));
        }
        if s == 0.0 {
            found = true;
            continue;
        }
        let cone = Solid::Primitive(Primitive::Cone {
            z_mm: [z_min_mm, z_max_mm],
            r_in_mm: [r_in_mm, r_in_mm],
            r_out_mm: [r_out_mm - 0.5 * s, r_out_mm + 0.5 * s],
        });
        let core = Solid::Intersection(vec![
            cone.clone(),
            Solid::tube(
                r_in_mm,
                r_out_mm + s.abs() + 1.0,
                z_min_mm + round_outer_mm,
                z_max_mm - round_outer_mm,
            ),
        ]);
        let outside = Solid::Difference {
            base: Box::new(Solid::tube(
                r_in_mm,
                r_out_mm + s.abs() + 1.0,
                z_min_mm,
                z_max_mm,
            )),
            minus: vec![cone],
        };
        c.geometry = Solid::Difference {
            base: Box::new(Solid::Union(vec![c.geometry.clone(), core])),
            minus: vec![outside],
        };
        found = true;
    }
    if found {
        Ok(())
    } else {
        Err(cannot(
            "the detector has no contact at the bias potential (the n+ layer)".into(),
        ))
    }
}

/// The catalogue entry.
pub struct LiSlope;

impl Extension for LiSlope {
    fn name(&self) -> &'static str {
        "li-slope"
    }

    fn description(&self) -> &'static str {
        "a lithium (n+) thickness that varies linearly along z (top minus bottom s, mm)"
    }

    fn signature(&self) -> &'static str {
        "residuals near and above full depletion, where c12 is set by the n+ layer's shape; \
         little at low voltage"
    }

    fn build(&self, base: &Baseline) -> Result<Candidate> {
        one_more_exact(
            self,
            base,
            ExactParameter {
                name: "d_li_slope_mm",
                unit: "mm",
                description: "Li thickness at the top minus at the bottom of the n+ layer",
                range: SLOPE_RANGE_MM,
                prior_sd: SLOPE_PRIOR_SD_MM,
                dry_run: 0.1,
            },
            set_slope,
            LABEL,
        )
    }
}
