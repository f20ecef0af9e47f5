//! Trapped-carrier pockets: undepleted regions cut off from their carriers' contact.
//!
//! Holes in p-type material drain downhill in potential to the conductors at the lowest fixed
//! potential, electrons in n-type material uphill to those at the highest. Where the potential of
//! p-type material has a local minimum that no path joins downhill to a drain, holes are trapped
//! (n-type: electrons at a local maximum). Such a *pocket* is undepleted and flat at its own
//! level, and for the weighting potentials a floating conductor. As the bias rises slowly (a C-V
//! measurement) its carriers spill over the lowest barrier towards their contact: the pocket sits
//! at its *spill level*, the potential of its pour point (`flood.rs`), shrinking until it
//! vanishes. The bias at which the first pocket appears is the pinch-off voltage; the detector is
//! fully depleted only when the last one is gone.
//!
//! The discrete model: every semiconductor node n of the carrier's material inside a depression
//! is *tied* to its pour point s(n), with the constraint phi_n >= phi_s(n) for holes (<= for
//! electrons) in place of the contact bound. Nodes where the constraint is active hold trapped
//! carriers (their multiplier is the neutralised part of the space charge); the pour point itself
//! obeys Gauss's law with its full charge. This is the obstacle problem whose obstacle depends on
//! the solution (a quasi-variational inequality): the solvers alternate a solve with fixed ties
//! and a new flood until the ties no longer change, starting every time from the ties of no
//! pocket, so the answer does not depend on the initial guess.

mod flood;

use serde::{Deserialize, Serialize};

use std::collections::HashMap;

use crate::carrier::Carrier;
use crate::field::mesh::{Mesh, NodeKind};
use crate::field::union_find::UnionFind;

mod resolution;

pub(crate) use flood::flood;
pub use flood::{deepest_depression_v, deepest_empty_depression_v};
pub(crate) use resolution::line_depressions;
pub use resolution::{Depression, depressions};

/// True when a node with fixed charge `charge_c` (C) is of the material whose majority carriers
/// are `carrier`: p-type (negative fixed charge) for holes, n-type for electrons.
pub(crate) fn holds(carrier: Carrier, charge_c: f64) -> bool {
    match carrier {
        Carrier::Hole => charge_c < 0.0,
        Carrier::Electron => charge_c > 0.0,
    }
}

/// Both carriers, holes first.
pub(crate) const CARRIERS: [Carrier; 2] = [Carrier::Hole, Carrier::Electron];

/// The deepest (empty, full) depressions of either carrier's landscape in `phi_v`, V (see
/// [`deepest_empty_depression_v`] and [`deepest_depression_v`]): both 0 up to round-off when
/// every pocket is flat at its spill level.
pub(crate) fn depression_depths_v(
    mesh: &Mesh,
    phi_v: &[f64],
    undepleted: &[bool],
    bounds_v: (f64, f64),
) -> (f64, f64) {
    CARRIERS
        .iter()
        .filter(|&&side| mesh.charge_c.iter().any(|&q| holds(side, q)))
        .map(|&side| {
            (
                deepest_empty_depression_v(mesh, phi_v, undepleted, side, bounds_v).0,
                deepest_depression_v(mesh, phi_v, side, bounds_v).0,
            )
        })
        .fold((0.0, 0.0), |a, b| (a.0.max(b.0), a.1.max(b.1)))
}

/// The tie of one semiconductor node: the node whose potential bounds it, and from which side.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub(crate) struct Tie {
    /// The pour point (node index).
    pub saddle: usize,
    /// Holes: phi_n >= phi_saddle; electrons: phi_n <= phi_saddle.
    pub side: Carrier,
}

/// Ties of every node (None: bounded by the contacts' potentials only).
pub(crate) type Ties = Vec<Option<Tie>>;

/// The ties for the potential `phi_v`: every node of a carrier's material inside that carrier's
/// depression is tied to its pour point. `occupied` marks the nodes that held trapped carriers in
/// the solve that produced `phi_v` (so that a pocket at its spill level keeps its tie).
/// A depression on the crystal's surface thinner than a Debye length is not tied
/// (`resolution.rs`: it holds no neutral region; issue 64).
pub(crate) fn ties(
    mesh: &Mesh,
    phi_v: &[f64],
    bounds_v: (f64, f64),
    occupied: &[bool],
    tol_v: f64,
) -> Ties {
    let mut out: Ties = vec![None; phi_v.len()];
    for side in CARRIERS {
        if !mesh.charge_c.iter().any(|&q| holds(side, q)) {
            continue;
        }
        let f = flood(mesh, phi_v, side, bounds_v, Some(occupied), tol_v);
        let pour = merge_touching(mesh, phi_v, side, occupied, &f.pour);
        let lines = line_depressions(mesh, side, &pour);
        for (n, p) in pour.iter().enumerate() {
            if let Some(s) = p
                && holds(side, mesh.charge_c[n])
                && !lines.contains(s)
                && out[n].is_none()
            {
                out[n] = Some(Tie { saddle: *s, side });
            }
        }
    }
    out
}

/// Pour points with touching pockets merged: carriers held in neighbouring nodes (`occupied`,
/// joined along conducting edges) are one pocket at one level, whatever depressions the flood
/// found them in. Each such region takes the lowest spill level among its members' pour points
/// for holes (the highest for electrons): the carriers leave over the lowest barrier. Every node
/// tied to a merged pour point follows it. Without this, neighbouring strips of one undepleted
/// region kept the pour points of the depressions they had started in and sat at different
/// levels (measured on the paper's space: 0.34, 0.41 and 0.78 V side by side at 25 V).
fn merge_touching(
    mesh: &Mesh,
    phi_v: &[f64],
    side: Carrier,
    occupied: &[bool],
    pour: &[Option<usize>],
) -> Vec<Option<usize>> {
    let (nr, nz) = (mesh.grid.nr(), mesh.grid.nz());
    let held = |n: usize| occupied[n] && pour[n].is_some() && holds(side, mesh.charge_c[n]);
    let mut uf = UnionFind::new(phi_v.len());
    for n in (0..phi_v.len()).filter(|&n| held(n)) {
        for m in flood::neighbours(nr, nz, n).filter(|&m| m > n && held(m)) {
            if mesh.edge_conducts(n, m) {
                uf.union(n, m);
            }
        }
    }
    // The best pour point of every region (by the carrier's level, then node index).
    let key = |s: usize| match side {
        Carrier::Hole => phi_v[s],
        Carrier::Electron => -phi_v[s],
    };
    let mut best: HashMap<usize, usize> = HashMap::new();
    for n in (0..phi_v.len()).filter(|&n| held(n)) {
        let (r, s) = (uf.find(n), pour[n].unwrap_or(n));
        best.entry(r)
            .and_modify(|b| {
                if key(s).total_cmp(&key(*b)).then(s.cmp(b)).is_lt() {
                    *b = s;
                }
            })
            .or_insert(s);
    }
    // Old pour point -> the region's best.
    let mut remap: HashMap<usize, usize> = HashMap::new();
    for n in (0..phi_v.len()).filter(|&n| held(n)) {
        let r = uf.find(n);
        if let Some(s) = pour[n] {
            remap.insert(s, best[&r]);
        }
    }
    pour.iter()
        .map(|p| p.map(|s| remap.get(&s).copied().unwrap_or(s)))
        .collect()
}

/// One pocket of trapped carriers in a solution.
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
pub struct Pocket {
    /// The trapped carriers.
    pub carrier: Carrier,
    /// Potential of the pocket (flat: its spill level), V.
    pub level_v: f64,
    /// Semiconductor volume of the pocket (its nodes' control volumes), cm^3.
    pub volume_cm3: f64,
    /// Number of undepleted nodes.
    pub nodes: usize,
    /// Volume-weighted centroid (r, z), mm.
    pub centroid_mm: (f64, f64),
    /// Extent of the pocket's nodes along r, mm.
    pub r_range_mm: (f64, f64),
    /// Extent along z, mm.
    pub z_range_mm: (f64, f64),
}

impl Pocket {
    /// True when the pocket spans at least one grid cell in both r and z: its nodes lie on more
    /// than one r tick and more than one z tick. A depression confined to one grid line is not
    /// resolved by the grid (nothing varies across it): at the convex corner of a contact's
    /// recess or a groove's edge, such lines of a few nodes come and go with the bias and
    /// vanish on a finer grid (icpc-legend at 1850 V: 12 nodes on z = 18 mm, none on the grid
    /// with every interval halved; issue 64). The pinch-off voltage counts resolved pockets
    /// only (`field::pinch_off`).
    pub fn resolved(&self) -> bool {
        self.r_range_mm.1 > self.r_range_mm.0 && self.z_range_mm.1 > self.z_range_mm.0
    }
}

/// The pockets of a solution: connected sets of undepleted semiconductor nodes (joined along
/// conducting edges) that touch no conductor. In order of their first node.
pub fn find_pockets(mesh: &Mesh, phi_v: &[f64], undepleted: &[bool]) -> Vec<Pocket> {
    let (r, z) = (mesh.grid.r_mm(), mesh.grid.z_mm());
    let nr = mesh.grid.nr();
    let mut out = Vec::new();
    for members in pocket_components(mesh, undepleted) {
        let mut vol = 0.0;
        let (mut cr, mut cz, mut level, mut q) = (0.0, 0.0, 0.0, 0.0);
        let (mut rr, mut zr) = (
            (f64::INFINITY, f64::NEG_INFINITY),
            (f64::INFINITY, f64::NEG_INFINITY),
        );
        for &n in &members {
            let (i, j) = (n % nr, n / nr);
            let v = mesh.volume_m3[n];
            vol += v;
            cr += v * r[i];
            cz += v * z[j];
            level += phi_v[n];
            q += mesh.charge_c[n];
            rr = (rr.0.min(r[i]), rr.1.max(r[i]));
            zr = (zr.0.min(z[j]), zr.1.max(z[j]));
        }
        let k = members.len() as f64;
        let w = if vol > 0.0 { vol } else { 1.0 };
        out.push(Pocket {
            carrier: if q < 0.0 {
                Carrier::Hole
            } else {
                Carrier::Electron
            },
            level_v: level / k,
            volume_cm3: vol * 1e6,
            nodes: members.len(),
            centroid_mm: (cr / w, cz / w),
            r_range_mm: rr,
            z_range_mm: zr,
        });
    }
    out
}

/// The nodes of every pocket (see [`find_pockets`]): true for an undepleted semiconductor node
/// whose undepleted region touches no conductor.
pub(crate) fn pocket_nodes(mesh: &Mesh, undepleted: &[bool]) -> Vec<bool> {
    let mut out = vec![false; undepleted.len()];
    for n in pocket_components(mesh, undepleted).into_iter().flatten() {
        out[n] = true;
    }
    out
}

/// Connected sets of undepleted semiconductor nodes (joined along conducting edges) that touch
/// no conductor, in order of their first node.
fn pocket_components(mesh: &Mesh, undepleted: &[bool]) -> Vec<Vec<usize>> {
    let (nr, nz) = (mesh.grid.nr(), mesh.grid.nz());
    let nn = nr * nz;
    let und = |n: usize| undepleted[n] && mesh.kind[n] == NodeKind::Semiconductor;
    let conductor = |n: usize| {
        matches!(
            mesh.kind[n],
            NodeKind::Contact(_) | NodeKind::Grounded | NodeKind::Floating(_)
        )
    };
    let mut seen = vec![false; nn];
    let mut out = Vec::new();
    for start in 0..nn {
        if seen[start] || !und(start) {
            continue;
        }
        let mut stack = vec![start];
        seen[start] = true;
        let mut members = Vec::new();
        let mut touches = false;
        while let Some(n) = stack.pop() {
            members.push(n);
            for m in flood::neighbours(nr, nz, n) {
                if !mesh.edge_conducts(n, m) {
                    continue;
                }
                if conductor(m) {
                    touches = true;
                } else if und(m) && !seen[m] {
                    seen[m] = true;
                    stack.push(m);
                }
            }
        }
        if !touches {
            out.push(members);
        }
    }
    out
}

#[cfg(test)]
mod tests;
