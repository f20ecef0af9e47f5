//! C-V curves at parameter points near a base point, solved on the base point's grids.
//!
//! A forward difference (c12(p + h e_j) - c12(p)) / h over two adaptive solves differs by
//! whatever the two grids differ by: where one more adaptive pass or a different split happens
//! at p + h, c12 jumps by up to the tolerance (0.1% of c12 at 0.2%), which for h = 1% of a
//! parameter's range can be the size of the derivative itself (`validation/examples/fd_noise.rs`).
//! Here every point of the nearby curve is solved once, without refinement, on the base
//! point's final grid carried along with the geometry ([`Grid::deformed`]: ticks mapped
//! piecewise-linearly between the geometry's boundaries, so a thicker contact moves the nodes
//! near it instead of adding lines), seeded by the base potential node for node. The difference
//! is then that of one discretisation, smooth in the parameter; and each nearby point costs
//! one potential solve and one weighting stage instead of the refinement passes and the two
//! coarsened grids of the error estimate.
//!
//! An undepleted base point's c12 carries the fully depleted reference over to its grid
//! (`field::depleted`); its nearby points take the same shift, part of the base's
//! discretisation like the grid itself, and cost no extra weighting solve.
//!
//! Where the nearby detector's geometry ticks cannot be matched to the base's one for one (two
//! boundaries merge, a feature appears), that point is solved adaptively on its own and counted
//! in [`NearCurves::regridded`].
//!
//! Which potential seeds a nearby solve ([`NearSeeding`]) changes its cost, not its result: on
//! a fixed grid the depletion problem (a convex energy under bounds) has one solution, which
//! the active-set solver reaches from any seed; the seed sets how many active-set steps (each a
//! sparse factorisation) it takes. A forward-difference step is closest to the base point
//! ([`NearSeeding::Base`]); the draws of a posterior are closer to each other than to its mode,
//! most of all where the posterior has two modes (the bottom and top levels swapped: 290
//! steps per 60-point curve from the other mode's seed against 190 near it, in the B_Z fit's
//! exact check), so they are solved along a chain, each seeded by the one before
//! ([`NearSeeding::Chain`], [`SeedChain`]). Either way the curves come out bit for bit the same
//! (measured on the B_Z fit's 300 exact curves).

use std::sync::atomic::{AtomicUsize, Ordering};

use rayon::prelude::*;

use super::curve::{Continuation, CvCurve, curve_keeping};
use super::point::{solve_point, solve_point_on_grid};
use super::settings::FieldSettings;
use crate::detector::Detector;
use crate::error::{Error, Result};
use crate::grid::Grid;

/// A base curve and c12 of nearby detectors at the same voltages.
#[derive(Debug, Clone, PartialEq)]
pub struct NearCurves {
    /// The base detector's curve, solved as [`super::cv_curve_with`] solves it.
    pub base: CvCurve,
    /// c12 (pF) of each nearby detector at the base curve's voltages, solved on the base's
    /// final grids.
    pub near_pf: Vec<Vec<f64>>,
    /// Nearby points solved on their own adaptive grids (geometry ticks not matched).
    pub regridded: usize,
    /// Potential-solve iterations (active-set steps) of the nearby points, summed: the work
    /// counter the seeding changes.
    pub iterations: usize,
}

/// A base curve and, for each nearby detector, its c12 at the same voltages or the error that
/// stopped its solve (one failed nearby detector does not stop the others).
#[derive(Debug)]
pub struct NearEach {
    /// The base detector's curve, solved as [`super::cv_curve_with`] solves it.
    pub base: CvCurve,
    /// c12 (pF) of each nearby detector at the base curve's voltages, solved on the base's
    /// final grids; the first failed point's error where a solve failed.
    pub near_pf: Vec<Result<Vec<f64>>>,
    /// Nearby points solved on their own adaptive grids (geometry ticks not matched).
    pub regridded: usize,
    /// Potential-solve iterations (active-set steps) of the nearby points that solved, summed.
    pub iterations: usize,
}

/// Which potential seeds each nearby point's solve (see the module text).
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum NearSeeding<'a> {
    /// Every nearby detector from the base point's potential at the same voltage (in parallel
    /// over the detectors and the voltages): for forward-difference steps, each a small step
    /// from the base.
    Base,
    /// Along a chain, a permutation of the nearby detectors' indices: at each voltage the
    /// chain's first detector is seeded by the base's potential and each next one by the last
    /// solution at that voltage before it (node for node: every nearby grid is the base grid
    /// deformed). The voltages run in parallel, the chain in order within each.
    Chain(&'a [usize]),
}

/// A greedy nearest-neighbour chain through nearby points, and whether it is worth following.
#[derive(Debug, Clone, PartialEq)]
pub struct SeedChain {
    /// The points' indices in chain order.
    pub order: Vec<usize>,
    /// The chain's length from the start: the sum of the distances between neighbours.
    pub length: f64,
    /// The star's length: the sum of the points' distances from the start (every point seeded
    /// by the start, [`NearSeeding::Base`]).
    pub star: f64,
}

impl SeedChain {
    /// A greedy nearest-neighbour chain through `points` from `start`: the index of the point
    /// nearest `start`, then of the unvisited point nearest that one, and so on, with the
    /// distance d(a, b)^2 = sum_j ((a_j - b_j) / scale_j)^2 (`scale`: each coordinate's range;
    /// a non-positive or non-finite scale drops its coordinate). Ties go to the lower index.
    /// O(n^2) distances.
    pub fn nearest_neighbour(start: &[f64], points: &[Vec<f64>], scale: &[f64]) -> Self {
        let dist = |a: &[f64], b: &[f64]| -> f64 {
            a.iter()
                .zip(b)
                .zip(scale)
                .filter(|(_, s)| s.is_finite() && **s > 0.0)
                .map(|((x, y), s)| ((x - y) / s).powi(2))
                .sum::<f64>()
                .sqrt()
        };
        let mut left: Vec<usize> = (0..points.len()).collect();
        let mut order = Vec::with_capacity(points.len());
        let mut length = 0.0;
        let mut at: &[f64] = start;
        while !left.is_empty() {
            let (pos, d) = left
                .iter()
                .enumerate()
                .map(|(pos, &k)| (pos, dist(at, &points[k])))
                .fold(
                    (0, f64::INFINITY),
                    |best, c| if c.1 < best.1 { c } else { best },
                );
            let k = left.remove(pos);
            order.push(k);
            length += d;
            at = &points[k];
        }
        let star = points.iter().map(|p| dist(start, p)).sum();
        Self {
            order,
            length,
            star,
        }
    }

    /// The shorter way to seed: along the chain where it is shorter than the star (posterior
    /// draws, close to each other), else from the start (forward-difference steps, each a small
    /// step from it).
    pub fn seeding(&self) -> NearSeeding<'_> {
        if self.length < self.star {
            NearSeeding::Chain(&self.order)
        } else {
            NearSeeding::Base
        }
    }
}

/// Solves `det` at `volts` (as [`super::cv_curve_with`] with `continuation`), then every
/// detector of `near` at the same voltages on the base points' final grids, deformed with the
/// geometry (see the module text). The nearby detectors should differ from `det` by a small
/// change of parameters (a forward-difference step): each is solved without refinement, so its
/// c12 carries the base grid's discretisation error, not its own grid's.
///
/// # Errors
/// The base curve's first failure, or the first failure of any nearby detector
/// ([`cv_curves_near_each`] keeps them apart).
pub fn cv_curves_near(
    det: &Detector,
    near: &[Detector],
    volts: &[f64],
    settings: &FieldSettings,
    continuation: Continuation,
) -> Result<NearCurves> {
    let each = cv_curves_near_each(
        det,
        near,
        volts,
        settings,
        (continuation, NearSeeding::Base),
        |_, _| {},
    )?;
    Ok(NearCurves {
        base: each.base,
        near_pf: each.near_pf.into_iter().collect::<Result<_>>()?,
        regridded: each.regridded,
        iterations: each.iterations,
    })
}

/// [`cv_curves_near`] with each nearby detector's outcome on its own: a nearby solve that fails
/// is its entry's error, not the call's; `seeding` says which potential seeds each nearby solve
/// (the results agree to the solver's convergence, the cost differs). `progress(done, total)`
/// counts curves (the base first, then the nearby detectors as they finish), from any thread.
///
/// # Errors
/// The base curve's failure (there are no grids to solve the others on without it); a chain
/// that is not a permutation of the nearby detectors.
pub fn cv_curves_near_each(
    det: &Detector,
    near: &[Detector],
    volts: &[f64],
    settings: &FieldSettings,
    (continuation, seeding): (Continuation, NearSeeding),
    progress: impl Fn(usize, usize) + Sync,
) -> Result<NearEach> {
    if let NearSeeding::Chain(order) = seeding {
        let mut seen = vec![false; near.len()];
        let ok = order.len() == near.len()
            && order
                .iter()
                .all(|&k| k < near.len() && !std::mem::replace(&mut seen[k], true));
        if !ok {
            return Err(Error::Argument {
                name: "seeding".into(),
                message: format!(
                    "a chain must list each of the {} nearby detectors once",
                    near.len()
                ),
            });
        }
    }
    let total = near.len() + 1;
    let (base, kept) = curve_keeping(det, volts, settings, continuation, true, |_, _| {})?;
    progress(1, total);
    let from = det.ticks();
    let ticks: Vec<_> = near.iter().map(Detector::ticks).collect();
    // One nearby point on the base point's grid deformed to the nearby geometry, seeded node
    // for node by `seed` (a potential on a grid of the base's nodes), or adaptively on its own.
    // The base point's shift by the depleted reference (`field::depleted`) goes with its grid:
    // a nearby point differs from the base by the difference on one discretisation.
    let solve = |k: usize, (grid, seed, shift): (&Grid, &[f64], f64), v: f64| -> Result<Solved> {
        let to = &ticks[k];
        match grid.deformed((&from.0, &from.1), (&to.0, &to.1)) {
            Some(g) => {
                let r = solve_point_on_grid(&near[k], v, settings, g.clone(), Some((&g, seed)))?;
                let iterations = r.reports.iter().map(|x| x.iterations).sum();
                Ok(Solved {
                    c12_pf: r.c12_pf + shift,
                    own: false,
                    iterations,
                    phi_v: Some(r.potential.phi_v),
                })
            }
            None => {
                let r = solve_point(&near[k], v, settings, None)?;
                let iterations = r.reports.iter().map(|x| x.iterations).sum();
                Ok(Solved {
                    c12_pf: r.c12_pf,
                    own: true,
                    iterations,
                    phi_v: None,
                })
            }
        }
    };
    // solved[k][j]: nearby detector k at voltage j.
    let solved: Vec<Vec<Result<Solved>>> = match seeding {
        NearSeeding::Base => {
            let done = AtomicUsize::new(1);
            (0..near.len())
                .into_par_iter()
                .map(|k| {
                    let points = kept
                        .par_iter()
                        .zip(base.points.par_iter())
                        .map(|((grid, phi, shift), p)| solve(k, (grid, phi, *shift), p.voltage_v))
                        .map(|r| r.map(|s| Solved { phi_v: None, ..s }))
                        .collect();
                    progress(done.fetch_add(1, Ordering::Relaxed) + 1, total);
                    points
                })
                .collect()
        }
        NearSeeding::Chain(order) => {
            let nv = kept.len();
            let volts_done = AtomicUsize::new(0);
            let by_voltage: Vec<Vec<Option<Result<Solved>>>> = kept
                .par_iter()
                .zip(base.points.par_iter())
                .map(|((grid, phi, shift), p)| {
                    let mut out: Vec<Option<Result<Solved>>> =
                        (0..near.len()).map(|_| None).collect();
                    let mut last: Option<Vec<f64>> = None;
                    for &k in order {
                        let seed = last.as_deref().unwrap_or(phi);
                        let mut r = solve(k, (grid, seed, *shift), p.voltage_v);
                        if let Ok(Solved {
                            phi_v: phi_v @ Some(_),
                            ..
                        }) = &mut r
                        {
                            last = phi_v.take();
                        }
                        out[k] = Some(r);
                    }
                    let d = volts_done.fetch_add(1, Ordering::Relaxed) + 1;
                    progress(1 + d * near.len() / nv.max(1), total);
                    out
                })
                .collect();
            // Transposed to one row per nearby detector.
            let mut rows: Vec<Vec<Result<Solved>>> =
                (0..near.len()).map(|_| Vec::with_capacity(nv)).collect();
            for column in by_voltage {
                for (row, cell) in rows.iter_mut().zip(column) {
                    row.push(cell.expect("the chain visits every nearby detector"));
                }
            }
            rows
        }
    };
    let mut regridded = 0;
    let mut iterations = 0;
    let near_pf = solved
        .into_iter()
        .map(|points| {
            let mut c = Vec::with_capacity(points.len());
            for p in points {
                let s = p?;
                c.push(s.c12_pf);
                regridded += usize::from(s.own);
                iterations += s.iterations;
            }
            Ok(c)
        })
        .collect();
    Ok(NearEach {
        base,
        near_pf,
        regridded,
        iterations,
    })
}

/// One nearby point's outcome.
struct Solved {
    /// c12, pF.
    c12_pf: f64,
    /// Solved on its own adaptive grid (the geometry's ticks did not match).
    own: bool,
    /// Potential-solve iterations.
    iterations: usize,
    /// Its potential on the deformed base grid, where a chain seeds the next solve with it.
    phi_v: Option<Vec<f64>>,
}

#[cfg(test)]
mod tests {
    use std::path::Path;

    use super::*;
    use crate::Parameters;

    #[test]
    fn a_chain_visits_the_nearest_point_next() {
        let pts: Vec<Vec<f64>> = [5.0, 1.0, 9.0, 2.0, 6.0].iter().map(|&x| vec![x]).collect();
        let c = SeedChain::nearest_neighbour(&[0.0], &pts, &[1.0]);
        assert_eq!(c.order, vec![1, 3, 0, 4, 2]);
        assert_eq!(c.length, 9.0);
        assert_eq!(c.star, 23.0);
        // The scale divides: a coordinate ten times wider counts a tenth.
        let pts = vec![vec![0.0, 5.0], vec![1.0, 0.0]];
        let c = SeedChain::nearest_neighbour(&[0.0, 0.0], &pts, &[1.0, 10.0]);
        assert_eq!(c.order, vec![0, 1]);
        // A zero or NaN scale drops its coordinate.
        let c = SeedChain::nearest_neighbour(&[0.0, 0.0], &pts, &[1.0, 0.0]);
        assert_eq!(c.order, vec![0, 1]);
        assert_eq!(c.length, 1.0);
        let c = SeedChain::nearest_neighbour(&[0.0, 0.0], &pts, &[f64::NAN, 1.0]);
        assert_eq!(c.order, vec![1, 0]);
    }

    #[test]
    fn steps_from_the_base_keep_its_seed_and_clustered_draws_follow_the_chain() {
        // Forward-difference steps along each axis: the chain is longer than the star.
        let h = 0.01;
        let steps = vec![vec![h, 0.0, 0.0], vec![0.0, h, 0.0], vec![0.0, 0.0, h]];
        let c = SeedChain::nearest_neighbour(&[0.0; 3], &steps, &[1.0; 3]);
        assert!(c.length > c.star);
        assert_eq!(c.seeding(), NearSeeding::Base);
        // Two clusters, one around the base and one far from it (two modes).
        let mut draws = Vec::new();
        for k in 0..10 {
            let e = 0.001 * f64::from(k);
            draws.push(vec![e, 0.0, 0.0]);
            draws.push(vec![1.0 + e, 1.0, 0.0]);
        }
        let c = SeedChain::nearest_neighbour(&[0.0; 3], &draws, &[1.0; 3]);
        assert!(c.length < c.star / 5.0, "{} vs {}", c.length, c.star);
        assert_eq!(c.seeding(), NearSeeding::Chain(&c.order));
        // Every point once, the near cluster first.
        let mut seen = c.order.clone();
        seen.sort_unstable();
        assert_eq!(seen, (0..20).collect::<Vec<_>>());
        assert!(c.order[..10].iter().all(|k| k % 2 == 0));
    }

    #[test]
    fn a_chain_that_is_not_a_permutation_is_refused_by_name() {
        let p = Path::new(env!("CARGO_MANIFEST_DIR")).join("../detectors/coax-analytic.toml");
        let det = Detector::from_file(&p, &Parameters::new()).unwrap();
        let near = [det.clone(), det.clone()];
        let s = FieldSettings::default();
        for chain in [&[0usize, 0][..], &[0], &[0, 2]] {
            let e = cv_curves_near_each(
                &det,
                &near,
                &[1000.0],
                &s,
                (Continuation::Cold, NearSeeding::Chain(chain)),
                |_, _| {},
            )
            .unwrap_err();
            assert!(e.to_string().contains("seeding"), "{e}");
            assert!(e.to_string().contains("each of the 2"), "{e}");
        }
    }
}
