//! Which depressions the grid resolves (issue 64, item 4).
//!
//! A depression of a carrier's landscape is the set of that carrier's material nodes that
//! share one pour point (`flood.rs`). The five-point stencil represents a potential that varies
//! smoothly over a cell; at a convex corner of the crystal (a contact's recess, a groove's edge)
//! the true potential is singular (it goes as rho^(pi/alpha) with alpha the interior angle), and
//! the discrete potential at the corner node can fall below all its conducting neighbours: a
//! "depression" of one node, or of a few nodes along one grid line, that exists only because the
//! grid does not resolve the corner. Such depressions come and go with the bias and vanish on a
//! finer grid: LEGEND's V99000A (`detector --from-legend`) had a one-node hole pocket at the
//! corner of its p+ contact's recess (r 3 mm, z 0) from 2066 V to beyond 6000 V that left c12
//! unchanged to 3e-9 relative and kept the detector "not fully depleted"; icpc-legend at 1850 V
//! had 12 nodes on z = 18 mm and none on the grid with every interval halved.
//!
//! The criterion: a depression is *unresolved* when every node of it lies on the crystal's
//! surface (a neighbour in vacuum or a dielectric), where the corner singularities are, and it
//! is thinner along r or along z than the extrinsic Debye length of its material
//! ([`debye_length_mm`], about 24 um at 10^10 cm^-3 and 78 K). Unresolved depressions are not
//! tied (the solvers leave their nodes bounded by the contacts' potentials only) and do not count
//! in the checks that a solution has no depression (`deepest_depression_v`,
//! `deepest_empty_depression_v`) nor in the full-depletion test. Everything else is resolved.
//!
//! Why a physical thickness and not a count of grid lines: until 2026-12-07 the rule was "on one
//! grid line" (a depression that spans no cell: the grid cannot represent the potential's
//! curvature across it). On V99000A's grid with every interval divided into 4 the corner of the
//! recess (r 3, z 0) has r ticks 3.9 um apart, and the same corner depression covered two of
//! them (4 nodes from z = 0 to 0.047 mm, 0.38 V deep at 3000 V): resolved by that rule, so the
//! detector never depleted on the finer grid (U_fd 1686 V on the default grid, above 3500 V on
//! the 4x one). At a convex corner of a p-type crystal whose faces are nearly free of normal
//! field (germanium's permittivity is 16 times the vacuum's), the potential near the corner is
//! phi_0 + c (x^2 + y^2) + d (x^2 - y^2) with 4 c = -rho / eps > 0, a minimum for holes wherever
//! the applied field's |d| < c: a well of a few um whose size does not shrink with the grid,
//! and which holds no neutral region because it is thinner than the length over which free
//! carriers screen a potential. A bulk pocket is never dropped this way: it has interior nodes.
//!
//! Why the surface condition: a genuine pocket shrinks to a line before it vanishes at full
//! depletion. Dropping such remnants (one grid line) in the bulk moved U_fd of the shipped ICPCs 44-59 V
//! below the value on the grid with every interval divided into 4 (icpc-example 2028.4 +- 38.2 V
//! against 2079.7 V, icpc-legend 2239.5 +- 42.5 against 2283.7, ppc-example 5426.7 +- 56.3
//! against 5485.8; measured 2026-12-06): outside their error bars. With the surface condition
//! every shipped detector kept its U_fd to the bisection's 1e-7. Why not depth: a genuine
//! pocket just past pinch-off is as shallow as a corner well (`validation/tests/
//! physical_pockets.rs` pins both). A genuine pocket that starts as a thin layer on the surface
//! becomes resolved a few volts later; that shift is a grid effect and part of the error bars (the
//! coarsened grids, `field::threshold`).

use std::collections::{HashMap, HashSet};

use serde::{Deserialize, Serialize};

use super::{flood, holds};
use crate::carrier::Carrier;
use crate::field::mesh::{Mesh, NodeKind};

/// Extent of one depression: its r and z ranges (mm), node count, whether every node lies on
/// the crystal's surface, and the largest fixed-charge density among its nodes (m^-3).
#[derive(Debug, Clone, Copy)]
struct Extent {
    r_mm: (f64, f64),
    z_mm: (f64, f64),
    nodes: usize,
    surface: bool,
    density_m3: f64,
}

/// Temperature (K) of the Debye length: the detectors operate near liquid-nitrogen temperature,
/// where [`crate::constants::EPS_R_GERMANIUM`] is given (78 K).
const DEBYE_TEMPERATURE_K: f64 = 78.0;

/// The extrinsic Debye length (mm) of germanium with `density_m3` ionised impurities at 78 K:
/// L_D = sqrt(eps_0 eps_r k T / (q^2 N)), about 24 um at 10^10 cm^-3 (10^16 m^-3). Free carriers
/// screen a potential over L_D, so an undepleted region thinner than it has no neutral core: the
/// depletion approximation that the active set solves does not hold across it. Infinite where
/// there is no charge.
pub(crate) fn debye_length_mm(density_m3: f64) -> f64 {
    use crate::constants::{
        BOLTZMANN_J_PER_K, ELEMENTARY_CHARGE_C, EPS_R_GERMANIUM, VACUUM_PERMITTIVITY_F_PER_M,
    };
    if density_m3 <= 0.0 {
        return f64::INFINITY;
    }
    let kt_over_q_v = BOLTZMANN_J_PER_K * DEBYE_TEMPERATURE_K / ELEMENTARY_CHARGE_C;
    let l2_m2 = VACUUM_PERMITTIVITY_F_PER_M * EPS_R_GERMANIUM * kt_over_q_v
        / (ELEMENTARY_CHARGE_C * density_m3);
    l2_m2.sqrt() * 1e3
}

/// True for a node with a 4-neighbour in an insulator (vacuum, a dielectric): on a bare or
/// passivated surface of the crystal.
fn on_surface(mesh: &Mesh, n: usize) -> bool {
    let (nr, nz) = (mesh.grid.nr(), mesh.grid.nz());
    super::flood::neighbours(nr, nz, n).any(|m| mesh.kind[m] == NodeKind::Insulator)
}

/// The extents of the depressions of `side`'s material in `pour` (the pour point of every
/// node inside a depression), keyed by pour point.
fn extents(mesh: &Mesh, side: Carrier, pour: &[Option<usize>]) -> HashMap<usize, Extent> {
    let nr = mesh.grid.nr();
    let (r, z) = (mesh.grid.r_mm(), mesh.grid.z_mm());
    let mut out: HashMap<usize, Extent> = HashMap::new();
    for (n, p) in pour.iter().enumerate() {
        let Some(s) = *p else { continue };
        if !holds(side, mesh.charge_c[n]) {
            continue;
        }
        let (ri, zj) = (r[n % nr], z[n / nr]);
        let surface = on_surface(mesh, n);
        let density_m3 = if mesh.volume_m3[n] > 0.0 {
            mesh.charge_c[n].abs() / (crate::constants::ELEMENTARY_CHARGE_C * mesh.volume_m3[n])
        } else {
            0.0
        };
        out.entry(s)
            .and_modify(|e| {
                e.r_mm = (e.r_mm.0.min(ri), e.r_mm.1.max(ri));
                e.z_mm = (e.z_mm.0.min(zj), e.z_mm.1.max(zj));
                e.nodes += 1;
                e.surface &= surface;
                e.density_m3 = e.density_m3.max(density_m3);
            })
            .or_insert(Extent {
                r_mm: (ri, ri),
                z_mm: (zj, zj),
                nodes: 1,
                surface,
                density_m3,
            });
    }
    out
}

/// True when a depression is resolved (module docs): it has a node inside the crystal, or it is
/// at least a Debye length thick along both r and z (a depression on one grid line has no
/// thickness at all).
fn is_resolved(e: &Extent) -> bool {
    let l_mm = debye_length_mm(e.density_m3);
    !e.surface || (e.r_mm.1 - e.r_mm.0 >= l_mm && e.z_mm.1 - e.z_mm.0 >= l_mm)
}

/// The pour points of the depressions of `side`'s material that lie on the crystal's surface and
/// are thinner than a Debye length along r or z (module docs): unresolved, never tied.
pub(crate) fn line_depressions(
    mesh: &Mesh,
    side: Carrier,
    pour: &[Option<usize>],
) -> HashSet<usize> {
    extents(mesh, side, pour)
        .into_iter()
        .filter(|(_, e)| !is_resolved(e))
        .map(|(s, _)| s)
        .collect()
}

/// One depression of a carrier's landscape in a potential.
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
pub struct Depression {
    /// The carriers it would trap.
    pub carrier: Carrier,
    /// Its pour point (node index): the spill level is the potential there.
    pub pour_node: usize,
    /// Number of the carrier's material nodes in it.
    pub nodes: usize,
    /// Depth, V: max over its nodes of |F(n) - phi_n| (F the fill level, `flood.rs`).
    pub depth_v: f64,
    /// The deepest node (index).
    pub deepest_node: usize,
    /// Spans at least one grid cell in r and in z, or has a node inside the crystal (module
    /// docs); unresolved ones are ignored by the solvers and the checks.
    pub resolved: bool,
}

/// Every depression of `side`'s landscape in `phi_v` (bounds: the lowest and highest fixed
/// potentials), resolved or not, deepest first. A diagnostic: a solution solved right has none
/// that is resolved and deeper than round-off (pockets sit flat at their spill level).
pub fn depressions(
    mesh: &Mesh,
    phi_v: &[f64],
    side: Carrier,
    bounds_v: (f64, f64),
) -> Vec<Depression> {
    let f = flood(mesh, phi_v, side, bounds_v, None, 0.0);
    let ext = extents(mesh, side, &f.pour);
    let mut deepest: HashMap<usize, (f64, usize)> = HashMap::new();
    for (n, p) in f.pour.iter().enumerate() {
        let Some(s) = *p else { continue };
        if !holds(side, mesh.charge_c[n]) || !f.fill_v[n].is_finite() {
            continue;
        }
        let d = (f.fill_v[n] - phi_v[n]).abs();
        let e = deepest.entry(s).or_insert((d, n));
        if d > e.0 {
            *e = (d, n);
        }
    }
    let mut out: Vec<Depression> = deepest
        .into_iter()
        .map(|(s, (d, n))| Depression {
            carrier: side,
            pour_node: s,
            nodes: ext[&s].nodes,
            depth_v: d,
            deepest_node: n,
            resolved: is_resolved(&ext[&s]),
        })
        .collect();
    out.sort_by(|a, b| {
        b.depth_v
            .total_cmp(&a.depth_v)
            .then(a.pour_node.cmp(&b.pour_node))
    });
    out
}

#[cfg(test)]
mod tests {
    use super::debye_length_mm;

    #[test]
    fn debye_length_is_the_closed_form() {
        // L_D = sqrt(eps0 eps_r kT / (q^2 N)) at 78 K, N = 10^16 m^-3 (10^10 cm^-3): by hand,
        // eps0 eps_r = 1.41667e-10 F/m, kT/q = 6.7215e-3 V, q N = 1.60218e-3 C/m^3, so
        // L_D^2 = 5.9433e-10 m^2 and L_D = 24.379 um.
        let l = debye_length_mm(1e16);
        assert!((l - 0.024_379).abs() < 2e-6, "{l}");
        // It scales as N^-1/2; no charge screens nothing.
        assert!((debye_length_mm(4e16) / l - 0.5).abs() < 1e-12);
        assert_eq!(debye_length_mm(0.0), f64::INFINITY);
    }
}
