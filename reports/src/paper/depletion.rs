//! The paper's Fig. 11 (section 5): the undepleted volume of Super-Siegfried for the
//! manufacturer's impurity model and d_Li = 1 mm at biases in steps of 250 V (200 V for the last
//! step, to 2975 V), as differently shaded areas of the cross-section.

use hpge_solver::field::solve_potential;
use hpge_solver::{Detector, FieldSettings, Parameters};
use serde_json::json;

use super::criterion::{Cmp, Criterion, Judgement};
use super::ctx::Ctx;
use crate::error::Result;
use crate::plot::{depletion_bands, depletion_map};

/// The figure's stem.
pub const STEM: &str = "depletion-volumes";

/// The paper's lithium thickness for the manufacturer's model (section 5), mm.
const D_LI_MM: f64 = 1.0;

/// The paper's biases: 25 V and then every 250 V to 2775 V, and 2975 V; a quick run keeps
/// every third and the last.
fn biases(quick: bool) -> Vec<f64> {
    let mut v: Vec<f64> = (0..12).map(|k| 25.0 + 250.0 * k as f64).collect();
    v.push(2975.0);
    if quick {
        let last = v[v.len() - 1];
        let mut q: Vec<f64> = v.iter().step_by(3).copied().collect();
        if q.last() != Some(&last) {
            q.push(last);
        }
        q
    } else {
        v
    }
}

/// Draws the figure and adds its README row.
pub fn run(ctx: &mut Ctx) -> Result<()> {
    let mut p = Parameters::new();
    p.set("d_li_mm".to_string(), D_LI_MM);
    let det = Detector::from_file(&ctx.inputs.detector, &p)?;
    let settings = FieldSettings::default();
    let states = biases(ctx.quick)
        .into_iter()
        .map(|u| solve_potential(&det, u, &settings, None))
        .collect::<std::result::Result<Vec<_>, _>>()?;
    ctx.both(STEM, |path| depletion_map(&det, &states, path))?;
    let bands = depletion_bands(&det, &states, 400);
    let n = states.len();
    let (first, last) = (&bands.bias_v[0], &bands.bias_v[n - 1]);
    let v_last = bands.undepleted_cm3[n - 1];
    let rise = bands
        .undepleted_cm3
        .windows(2)
        .map(|w| w[1] - w[0])
        .fold(f64::NEG_INFINITY, f64::max);
    // The band the front sweeps first against the last one it sweeps.
    let swept: Vec<(f64, f64)> = bands
        .bias_v
        .iter()
        .zip(&bands.band_mean_r_mm)
        .filter(|(_, r)| r.is_finite())
        .map(|(u, r)| (*u, *r))
        .collect();
    let (r_first, r_last) = match (swept.first(), swept.last()) {
        (Some(a), Some(b)) => (a.1, b.1),
        _ => (f64::NAN, f64::NAN),
    };
    let ours = format!(
        "undepleted volume {:.0} cm^3 at {first:.0} V, {:.0} cm^3 at {:.0} V, {v_last:.1} cm^3 at {last:.0} V (crystal {:.0} cm^3); mean r of the volume depleted by {first:.0} V {r_first:.1} mm, of the last band swept {r_last:.1} mm",
        bands.undepleted_cm3[0],
        bands.undepleted_cm3[n / 2],
        bands.bias_v[n / 2],
        bands.crystal_cm3,
    );
    ctx.row(
        STEM,
        "Fig. 11 (sec. 5)",
        "For the manufacturer's model (d_Li = 1 mm) the detector depletes from the mantle towards the borehole and is not fully depleted at 2975 V.",
        ours,
        Judgement::by(
            vec![
                Criterion::new(
                    format!("undepleted volume at {last:.0} V (cm^3)"),
                    v_last,
                    Cmp::Gt,
                    0.0,
                ),
                Criterion::new(
                    "largest rise of the undepleted volume from one bias to the next (cm^3)",
                    rise,
                    Cmp::Le,
                    0.0,
                ),
                Criterion::new(
                    "mean r of the first band swept - mean r of the last (mm)",
                    r_first - r_last,
                    Cmp::Gt,
                    0.0,
                ),
            ],
            "",
        ),
    );
    ctx.number(
        "depletion",
        json!({
            "d_li_mm": D_LI_MM,
            "bias_V": bands.bias_v,
            "undepleted_cm3": bands.undepleted_cm3,
            "crystal_cm3": bands.crystal_cm3,
            "band_mean_r_mm": bands.band_mean_r_mm.iter().map(|r| if r.is_finite() { json!(r) } else { serde_json::Value::Null }).collect::<Vec<_>>(),
        }),
    );
    Ok(())
}
