//! The exact field solver as a [`CvModel`] (slow: about a second per 60-point curve on two
//! cores; used to check a surrogate posterior, never to sample one).

use hpge_solver::Detector;
use hpge_solver::field::{Continuation, SeedChain, cv_curves_near_each};
use hpge_surrogate::ExactSolver;

use super::{CurvesNear, CvModel};
use crate::{Error, Result};

/// The exact solver at the points of a parameter space, bound to the measured voltages.
#[derive(Debug, Clone)]
pub struct ExactModel {
    /// The solver set up on the space and detector.
    pub solver: ExactSolver,
    volts: Vec<f64>,
    domain: Vec<[f64; 2]>,
    names: Vec<String>,
}

impl ExactModel {
    /// The solver's space without its bias dimension defines the inputs and their domain.
    pub fn new(solver: ExactSolver, volts: &[f64]) -> Result<Self> {
        let order = hpge_surrogate::network_order(&solver.space)?;
        let dims: Vec<_> = order[..order.len() - 1]
            .iter()
            .map(|&j| solver.space.dimensions[j].clone())
            .collect();
        if volts
            .windows(2)
            .any(|w| w[1].partial_cmp(&w[0]) != Some(std::cmp::Ordering::Greater))
        {
            return Err(Error::Argument {
                name: "voltages".into(),
                message: "the exact model needs strictly increasing voltages".into(),
            });
        }
        Ok(Self {
            volts: volts.to_vec(),
            domain: dims.iter().map(|d| d.range).collect(),
            names: dims.iter().map(|d| d.name.clone()).collect(),
            solver,
        })
    }
}

/// An error naming the first input of `x` outside its `domain` interval (NaN included).
pub(crate) fn check_domain(names: &[String], domain: &[[f64; 2]], x: &[f64]) -> Result<()> {
    for (k, (&v, r)) in x.iter().zip(domain).enumerate() {
        if !(v >= r[0] && v <= r[1]) {
            return Err(Error::Surrogate(hpge_surrogate::Error::OutsideDomain {
                name: names[k].clone(),
                value: v,
                lo: r[0],
                hi: r[1],
            }));
        }
    }
    Ok(())
}

impl CvModel for ExactModel {
    fn inputs(&self) -> Vec<String> {
        self.names.clone()
    }

    fn domain(&self) -> Vec<[f64; 2]> {
        self.domain.clone()
    }

    fn voltages(&self) -> &[f64] {
        &self.volts
    }

    fn sigma_rel(&self) -> f64 {
        0.0
    }

    fn curve(&self, x: &[f64], c_pf: &mut [f64]) -> Result<()> {
        check_domain(&self.names, &self.domain, x)?;
        let c = self.solver.curve(x, &self.volts)?;
        c_pf.copy_from_slice(&c);
        Ok(())
    }

    fn has_jacobian(&self) -> bool {
        false
    }

    fn curve_jacobian(&self, _x: &[f64], _c_pf: &mut [f64], _jac: &mut [f64]) -> Result<()> {
        Err(Error::Argument {
            name: "model".into(),
            message: "the exact solver gives no Jacobian; use a gradient-free sampler".into(),
        })
    }

    fn describe(&self) -> String {
        format!("exact solver ({})", self.solver.detector_file.display())
    }

    /// The nearby curves on `x`'s grids (`near_curves`).
    fn curves_near(
        &self,
        x: &[f64],
        near: &[Vec<f64>],
        progress: &(dyn Fn(usize, usize) + Sync),
    ) -> Result<CurvesNear> {
        let detector = |x: &[f64]| Ok(self.solver.detector(x)?);
        near_curves(
            self,
            (&self.names, &self.domain),
            x,
            near,
            &detector,
            progress,
        )
    }
}

/// c12 along `model`'s voltages of the detector at `x` and of those at every point of `near` on
/// its grids (`hpge_solver::field::cv_curves_near_each`, seeded continuation as
/// [`ExactSolver::curve`]); `detector` builds a detector from inputs, which must lie in
/// `domain` (named `names`). A nearby point outside the domain, or whose detector cannot be
/// built, is its own entry's error. The nearby points are solved along a nearest-neighbour
/// chain from `x` where it is shorter than the star from `x` (distances in units of each
/// input's domain width; `SeedChain::seeding`): the same curves, in fewer active-set steps
/// where the points lie closer to each other than to `x` (posterior draws); forward-difference
/// steps stay seeded by `x`.
pub(crate) fn near_curves(
    model: &ExactModel,
    (names, domain): (&[String], &[[f64; 2]]),
    x: &[f64],
    near: &[Vec<f64>],
    detector: &dyn Fn(&[f64]) -> Result<Detector>,
    progress: &(dyn Fn(usize, usize) + Sync),
) -> Result<CurvesNear> {
    check_domain(names, domain, x)?;
    let det = detector(x)?;
    // The detectors to solve, and in each entry's place the error that stops it.
    let mut dets = Vec::with_capacity(near.len());
    let mut placed = Vec::with_capacity(near.len());
    let slots: Vec<Option<Error>> = near
        .iter()
        .map(
            |xn| match check_domain(names, domain, xn).and_then(|()| detector(xn)) {
                Ok(d) => {
                    dets.push(d);
                    placed.push(xn.clone());
                    None
                }
                Err(e) => Some(e),
            },
        )
        .collect();
    let total = near.len() + 1;
    let skipped = near.len() - dets.len();
    let widths: Vec<f64> = domain.iter().map(|r| r[1] - r[0]).collect();
    let chain = SeedChain::nearest_neighbour(x, &placed, &widths);
    let nc = cv_curves_near_each(
        &det,
        &dets,
        &model.volts,
        &model.solver.settings,
        (Continuation::Seeded, chain.seeding()),
        |done, _| progress(done + skipped, total),
    )
    .map_err(|e| Error::Surrogate(e.into()))?;
    if nc.base.points.len() != model.volts.len() {
        return Err(Error::Argument {
            name: "voltages".into(),
            message: "the voltages must be positive, increasing and distinct".into(),
        });
    }
    let mut solved = nc.near_pf.into_iter();
    let others = slots
        .into_iter()
        .map(|slot| match slot {
            None => solved
                .next()
                .expect("one solved curve per detector")
                .map_err(|e| Error::Surrogate(e.into())),
            Some(e) => Err(e),
        })
        .collect();
    Ok((nc.base.points.iter().map(|p| p.c12_pf).collect(), others))
}
