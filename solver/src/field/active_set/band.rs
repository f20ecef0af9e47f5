//! Front moves between active-set factorisations: projected over-relaxation in a band of unknowns
//! around the depletion front.
//!
//! From an active set that is too large (a cold start overshoots: the unconstrained potential
//! exceeds the contact potential over more than the true undepleted region), the primal-dual
//! active-set method frees one layer of nodes per iteration. Inside the undepleted region every
//! node's multiplier is its own charge, lambda_u = f_u, whatever the front does; only the layer
//! next to a free node can change sign. Measured on Super-Siegfried at 1025 V: 1556 -> 1027 active
//! unknowns in 9 iterations of about 70 (one grid layer) each, every one a full sparse
//! factorisation. The front thus crosses the grid one layer per factorisation, and a cold solve
//! costs O(N^0.5) factorisations.
//!
//! Here the front's neighbourhood is solved locally in between: projected SOR (Gauss-Seidel with
//! over-relaxation and the projection onto [l, u], the classical method for obstacle problems,
//! Cryer 1971) over the unknowns within `depth` graph edges of the front, the rest held at the
//! present iterate. The band's bounds decide the next active set there. The exact answer is
//! unchanged: it is still the factorised solve of an active set that a plain active-set step
//! leaves unchanged (the KKT conditions, whose solution is unique for an M-matrix); the band only
//! proposes active sets, which the caller stops doing after a few iterations, so the plain
//! method's finite convergence still holds.

use crate::field::system::System;

/// State of a bounded unknown.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub(crate) enum Bound {
    Free,
    Upper,
    Lower,
}

/// Bounded unknowns within `depth` edges (in the matrix graph) of a `seed` unknown, excluding
/// unknowns that are not `bounded` (insulators, floating conductors: a floating conductor's
/// unknown couples to all of its surface) and the seeds' far side beyond `depth`.
pub(crate) fn band(sys: &System, seeds: &[usize], bounded: &[bool], depth: usize) -> Vec<usize> {
    let mut dist = vec![usize::MAX; sys.n];
    let mut frontier: Vec<usize> = Vec::with_capacity(seeds.len());
    for &s in seeds {
        if bounded[s] && dist[s] == usize::MAX {
            dist[s] = 0;
            frontier.push(s);
        }
    }
    let mut out = frontier.clone();
    for d in 1..=depth {
        let mut next = Vec::with_capacity(frontier.len());
        for &u in &frontier {
            for e in sys.col_ptr[u]..sys.col_ptr[u + 1] {
                let v = sys.row_idx[e];
                if bounded[v] && dist[v] == usize::MAX {
                    dist[v] = d;
                    next.push(v);
                }
            }
        }
        out.extend_from_slice(&next);
        frontier = next;
    }
    out
}

/// Relaxation factor of the band sweeps: over-relaxation speeds the smooth error across a band of
/// a few tens of nodes (omega_opt = 2 / (1 + sin(pi h)) for a strip of 1/h nodes, 1.7-1.8 for
/// 12-20 nodes).
pub(crate) const BAND_OMEGA: f64 = 1.7;

/// Projected SOR on the unknowns of `band`, all others held at `x`: for each u in turn,
/// x_u <- P_[l_u, h_u]( x_u + omega ((f_u - sum_{v != u} A_uv x_v) / A_uu - x_u) ), symmetric
/// sweeps (forward, then backward) until the largest change in a sweep is below `tol_v` or
/// `max_sweeps` sweeps are done. `bounds(u)` is (l_u, h_u) in V. Returns the sweeps done.
pub(crate) fn relax(
    sys: &System,
    x: &mut [f64],
    band: &[usize],
    bounds: impl Fn(usize) -> (f64, f64),
    tol_v: f64,
    max_sweeps: usize,
) -> usize {
    let update = |x: &mut [f64], u: usize| -> f64 {
        let (lo, hi) = bounds(u);
        let mut s = sys.rhs[u];
        let mut diag = 0.0;
        for e in sys.col_ptr[u]..sys.col_ptr[u + 1] {
            let v = sys.row_idx[e];
            if v == u {
                diag = sys.val[e];
            } else {
                s -= sys.val[e] * x[v];
            }
        }
        let old = x[u];
        let new = (old + BAND_OMEGA * (s / diag - old)).clamp(lo, hi);
        x[u] = new;
        (new - old).abs()
    };
    for sweep in 1..=max_sweeps {
        let mut worst: f64 = 0.0;
        if sweep % 2 == 1 {
            for &u in band {
                worst = worst.max(update(x, u));
            }
        } else {
            for &u in band.iter().rev() {
                worst = worst.max(update(x, u));
            }
        }
        if worst <= tol_v {
            return sweep;
        }
    }
    max_sweeps
}

/// Active-set iterations of a round (from its first) whose next active set comes from the
/// band relaxation (this file) rather than the plain step; a seeded solve also moves its
/// guess's front once before the first factorisation. A bound keeps the plain method's finite
/// convergence. Measured on Super-Siegfried at 1025 V, cold, uniform grids
/// (`validation/examples/solver_scaling.rs`): with 6, the front outran the band above 2e5 nodes
/// (19, 45, 84 iterations at 2.1e5, 4.2e5, 8.5e5 nodes); with 40, 10, 13, 17.
pub(crate) const BAND_STEPS: usize = 40;

/// Graph distance (edges) from the front that the band relaxation covers.
pub(crate) const BAND_DEPTH: usize = 8;

/// Largest number of sweeps of one band relaxation.
pub(crate) const BAND_SWEEPS: usize = 64;

/// The active set proposed by a projected relaxation around the front of `next` (an active
/// set), starting from the potential `x` (unknown space, V; the relaxation above); `bounds(u)` gives each
/// bounded unknown's [l, u] (V).
pub(crate) fn band_state(
    sys: &System,
    bounded: &[bool],
    bounds: impl Fn(usize) -> (f64, f64),
    x: &[f64],
    next: &[Bound],
) -> Vec<Bound> {
    // Front: bounded unknowns with a bounded neighbour in another state.
    let seeds: Vec<usize> = (0..sys.n)
        .filter(|&u| {
            bounded[u]
                && (sys.col_ptr[u]..sys.col_ptr[u + 1]).any(|e| {
                    let v = sys.row_idx[e];
                    bounded[v] && next[v] != next[u]
                })
        })
        .collect();
    let mut members = band(sys, &seeds, bounded, BAND_DEPTH);
    // A tied unknown whose pocket level lies beyond the contact potentials has l > h (and a
    // level may be NaN after a singular levels' system): no interval to project on, so the
    // plain step's state stands there.
    members.retain(|&u| {
        let (l, h) = bounds(u);
        l <= h && l.is_finite() && h.is_finite() && x[u].is_finite()
    });
    let mut xt: Vec<f64> = x.to_vec();
    let mut span: f64 = 1.0;
    for &u in &members {
        let (l, h) = bounds(u);
        span = span.max((h - l).abs());
        xt[u] = xt[u].clamp(l, h);
    }
    relax(sys, &mut xt, &members, &bounds, 1e-6 * span, BAND_SWEEPS);
    let mut out = next.to_vec();
    for &u in &members {
        let (l, h) = bounds(u);
        out[u] = if xt[u] >= h {
            Bound::Upper
        } else if xt[u] <= l {
            Bound::Lower
        } else {
            Bound::Free
        };
    }
    out
}

#[cfg(test)]
mod tests {
    use std::path::Path;

    use super::BAND_STEPS;
    use crate::detector::Detector;
    use crate::expr::Parameters;
    use crate::field::active_set::band::Bound;
    use crate::field::active_set::depletion::{FastSeed, solve_with_band_steps};
    use crate::field::mesh::Mesh;
    use crate::grid::{Grid, GridSettings};

    fn detector(file: &str) -> Detector {
        let p = Path::new(env!("CARGO_MANIFEST_DIR"))
            .join("../detectors")
            .join(file);
        Detector::from_file(&p, &Parameters::new()).unwrap()
    }

    fn mesh(det: &Detector, h_mm: f64) -> Mesh {
        let gs = GridSettings {
            max_spacing_semiconductor_mm: h_mm,
            max_spacing_mm: 2.5 * h_mm,
            ..GridSettings::default()
        };
        Mesh::new(det, Grid::initial(det, &gs))
    }

    /// Cold and seeded solves with band steps reach the plain active-set method's solution
    /// (the same final active set, so the same factorised potential, bit for bit) in fewer
    /// factorisations (work counters pinned): on a coaxial detector partly depleted, on the
    /// ICPC in its pinch-off window (pocket rounds with ties), a BEGe and the planar wafer.
    #[test]
    fn band_steps_reach_the_plain_solution_in_fewer_iterations() {
        let cases = [
            ("super-siegfried-k1.toml", 1025.0, 1.0),
            ("icpc-example.toml", 1750.0, 2.0),
            ("planar-pn.toml", 50.0, 0.25),
            ("bege.toml", 750.0, 1.0),
        ];
        let mut totals = [(0, 0); 2];
        for (file, bias_v, h_mm) in cases {
            let det = detector(file);
            let coarse = mesh(&det, 2.0 * h_mm);
            let fine = mesh(&det, h_mm);
            let c = solve_with_band_steps(&coarse, &det, bias_v, &FastSeed::default(), 0).unwrap();
            let guess = coarse.grid.interpolate_to(&c.phi_v, &fine.grid);
            for phi_v in [None, Some(guess.as_slice())] {
                let seed = FastSeed {
                    phi_v,
                    ..FastSeed::default()
                };
                let plain = solve_with_band_steps(&fine, &det, bias_v, &seed, 0).unwrap();
                let band = solve_with_band_steps(&fine, &det, bias_v, &seed, BAND_STEPS).unwrap();
                assert_eq!(plain.phi_v, band.phi_v, "{file} at {bias_v} V");
                assert_eq!(plain.undepleted, band.undepleted, "{file} at {bias_v} V");
                assert_eq!(plain.pockets.len(), band.pockets.len(), "{file}");
                let (p, b) = (plain.report.iterations, band.report.iterations);
                eprintln!(
                    "{file} {bias_v} V, seeded {}: {p} plain iterations, {b} with band steps",
                    phi_v.is_some()
                );
                assert!(b <= p, "{file}: {b} band iterations > {p} plain");
                totals[usize::from(phi_v.is_some())].0 += p;
                totals[usize::from(phi_v.is_some())].1 += b;
            }
        }
        // A cold start crosses the grid layer by layer without them: at least 40% fewer.
        let [(cold_p, cold_b), (seeded_p, seeded_b)] = totals;
        assert!(
            10 * cold_b <= 6 * cold_p,
            "cold: {cold_b} band vs {cold_p} plain"
        );
        assert!(
            seeded_b < seeded_p,
            "seeded: {seeded_b} band vs {seeded_p} plain"
        );
    }

    /// Bounds without an interval (a tied level beyond the contact potentials: l > h; a NaN
    /// level) leave the plain step's state in place instead of panicking in a projection
    /// (found by `tests/surrogate.rs`: a p-n junction pocket of a tiny training space).
    #[test]
    fn empty_or_nan_bounds_keep_the_plain_state() {
        let det = detector("planar-pn.toml");
        let m = mesh(&det, 0.25);
        let (dofs, (lo, hi)) = crate::field::active_set::potential_dofs(&m, &det, 50.0);
        let sys = super::System::assemble(&m, &dofs, &m.charge_c);
        let bounded = vec![true; sys.n];
        // A front in the middle: the first half active at the upper bound.
        let next: Vec<Bound> = (0..sys.n)
            .map(|u| {
                if u < sys.n / 2 {
                    Bound::Upper
                } else {
                    Bound::Free
                }
            })
            .collect();
        let x: Vec<f64> = (0..sys.n)
            .map(|u| if u < sys.n / 2 { hi } else { 0.5 * (lo + hi) })
            .collect();
        let bounds = |u: usize| match u % 3 {
            0 => (hi + 1.0, hi),
            1 => (f64::NAN, hi),
            _ => (lo, hi),
        };
        let out = super::band_state(&sys, &bounded, bounds, &x, &next);
        for u in 0..sys.n {
            if u % 3 != 2 {
                assert_eq!(out[u], next[u], "unknown {u}");
            }
        }
    }

    /// The band is the seeds' graph neighbourhood: the seed alone at depth 0, the seed and its
    /// matrix neighbours at depth 1, and a non-bounded unknown is never entered.
    #[test]
    fn band_is_the_graph_neighbourhood_of_the_seeds() {
        let det = detector("planar-pn.toml");
        let m = mesh(&det, 0.25);
        let (dofs, _) = crate::field::active_set::potential_dofs(&m, &det, 50.0);
        let sys = super::System::assemble(&m, &dofs, &m.charge_c);
        let bounded = vec![true; sys.n];
        let mid = sys.n / 2;
        let b1 = super::band(&sys, &[mid], &bounded, 0);
        assert_eq!(b1, vec![mid]);
        let b2 = super::band(&sys, &[mid], &bounded, 1);
        let neighbours = sys.col_ptr[mid + 1] - sys.col_ptr[mid] - 1;
        assert_eq!(b2.len(), 1 + neighbours);
        let mut none = vec![true; sys.n];
        for &u in &b2[1..] {
            none[u] = false;
        }
        let b3 = super::band(&sys, &[mid], &none, 3);
        assert_eq!(b3, vec![mid], "a non-bounded unknown stops the band");
    }
}
