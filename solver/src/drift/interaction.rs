//! Where an interaction point lies at a solved bias: in depleted semiconductor (where the field
//! is defined and a drift can start), undepleted semiconductor, a contact, or outside the crystal.

use super::field::ElectricField;
use crate::detector::{Detector, Region};
use crate::error::{Error, Result};
use crate::field::PointResult;

/// Where a point (r, z) lies at a solved bias: what [`ElectricField::at`] needs to give a field.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum PointStatus {
    /// Depleted semiconductor: the field is defined.
    Depleted,
    /// Undepleted semiconductor (no field).
    Undepleted,
    /// Inside contact `Detector::contacts[i]`.
    Contact(usize),
    /// Outside the crystal (world medium, a passive, or off the grid).
    Outside,
}

impl PointStatus {
    /// One word for JSON and tables.
    pub fn as_str(self) -> &'static str {
        match self {
            PointStatus::Depleted => "depleted",
            PointStatus::Undepleted => "undepleted",
            PointStatus::Contact(_) => "contact",
            PointStatus::Outside => "outside",
        }
    }
}

/// Classifies (r, z) in mm: contact, outside the crystal, undepleted or depleted at the bias of
/// `field` (a point the field's interpolation cannot reach counts as outside).
pub fn point_status(det: &Detector, field: &ElectricField, r_mm: f64, z_mm: f64) -> PointStatus {
    match det.classify(r_mm, z_mm) {
        Region::Contact(i) => PointStatus::Contact(i),
        Region::Semiconductor if field.undepleted_at(r_mm, z_mm) => PointStatus::Undepleted,
        Region::Semiconductor if field.at_rz(r_mm, z_mm).is_some() => PointStatus::Depleted,
        _ => PointStatus::Outside,
    }
}

/// Refuses an interaction point (r, z) in mm that is not in depleted semiconductor at the bias
/// of `point` (whose field is `field`): [`Error::InteractionInContact`],
/// [`Error::InteractionUndepleted`] or [`Error::InteractionOutside`], saying where it is.
pub fn check_interaction_point(
    det: &Detector,
    point: &PointResult,
    field: &ElectricField,
    (r_mm, z_mm): (f64, f64),
) -> Result<()> {
    match point_status(det, field, r_mm, z_mm) {
        PointStatus::Depleted => Ok(()),
        PointStatus::Contact(i) => Err(Error::InteractionInContact {
            r_mm,
            z_mm,
            contact: det.contacts[i].name.clone(),
        }),
        PointStatus::Undepleted => Err(Error::InteractionUndepleted {
            r_mm,
            z_mm,
            bias_v: point.bias_v,
        }),
        PointStatus::Outside => {
            let b = det.semiconductor.geometry.bbox();
            Err(Error::InteractionOutside {
                r_mm,
                z_mm,
                crystal: det.semiconductor.name.clone(),
                r_min_mm: b.r_min_mm,
                r_max_mm: b.r_max_mm,
                z_min_mm: b.z_min_mm,
                z_max_mm: b.z_max_mm,
            })
        }
    }
}

/// |E| along r at one (phi, z) with the status of every radius.
#[derive(Debug, Clone, PartialEq)]
pub struct FieldLine {
    /// Radii, mm.
    pub r_mm: Vec<f64>,
    /// |E| in V/m; `None` where there is no field.
    pub e_v_per_m: Vec<Option<f64>>,
    /// Where each radius lies.
    pub status: Vec<PointStatus>,
}

/// |E| (V/m) at the radii `r_mm` for azimuth `phi_rad` and height `z_mm` in the field of one
/// bias point, with each radius's [`PointStatus`].
pub fn field_line(
    det: &Detector,
    field: &ElectricField,
    phi_rad: f64,
    z_mm: f64,
    r_mm: &[f64],
) -> FieldLine {
    FieldLine {
        r_mm: r_mm.to_vec(),
        e_v_per_m: field.magnitude_along_r(phi_rad, z_mm, r_mm),
        status: r_mm
            .iter()
            .map(|&r| point_status(det, field, r, z_mm))
            .collect(),
    }
}

#[cfg(test)]
mod tests {
    use super::super::field_tests::{coax, solve};
    use super::*;

    /// The coax of `detectors/coax-analytic.toml` (annulus 6 - 37.5 mm, bias on the inner
    /// contact) at 1000 V, below its full depletion at about 3500 V: depleted from the outer
    /// contact inwards, undepleted by the inner one.
    #[test]
    fn statuses_and_refusals_in_the_partly_depleted_coax() {
        let det = coax();
        let point = solve(&det, 1000.0, 0.5);
        let field = ElectricField::new(&det, &point);
        let r_mm = [3.0, 6.0, 10.0, 30.0, 37.5, 39.0];
        let line = field_line(&det, &field, 0.3, 5.0, &r_mm);
        assert_eq!(
            line.status,
            [
                PointStatus::Outside,
                PointStatus::Contact(0),
                PointStatus::Undepleted,
                PointStatus::Depleted,
                PointStatus::Contact(1),
                PointStatus::Outside,
            ]
        );
        assert_eq!(line.r_mm, r_mm);
        assert!(line.e_v_per_m[3].is_some_and(|e| e > 0.0));
        assert_eq!(line.e_v_per_m[2], None);
        assert_eq!(PointStatus::Contact(1).as_str(), "contact");

        assert!(check_interaction_point(&det, &point, &field, (30.0, 5.0)).is_ok());
        let message = |rz| {
            check_interaction_point(&det, &point, &field, rz)
                .unwrap_err()
                .to_string()
        };
        assert_eq!(
            message((6.0, 5.0)),
            "(r, z) = (6, 5) mm is inside the contact `n+ (inner surface)`; an interaction must \
             be in the depleted crystal"
        );
        assert_eq!(
            message((10.0, 5.0)),
            "(r, z) = (10, 5) mm is in undepleted volume at U_B = 1000 V (no field there); raise \
             --voltage or choose a point in the depleted crystal"
        );
        assert_eq!(
            message((39.0, 5.0)),
            "(r, z) = (39, 5) mm is outside the crystal `HPGe annulus` (r in [6, 37.5] mm, z in \
             [0, 10] mm, less any borehole)"
        );
    }
}
