//! Priority flood (depression filling) of the potential landscape seen by one kind of carrier.
//!
//! Holes move downhill in potential and are collected by the conductors at the lowest fixed
//! potential (the drains); electrons move uphill to the conductors at the highest. For holes the
//! *fill level* of a semiconductor node n is the lowest barrier a hole at n must cross to reach a
//! drain,
//!
//!   F(n) = min over conducting paths n -> drain of max_{m on the path} phi_m  (>= phi_n),
//!
//! the classic depression-filling level of terrain analysis (Barnes, Lehman, Mulla, Comput. Geosci.
//! 62 (2014) 117: priority flood). A node with F(n) > phi_n lies in a *depression*: a hole there
//! is trapped. Electrons see the mirrored landscape (-phi, drains at the highest potential).
//!
//! The flood walks only along edges that conduct (`Mesh::edge_conducts`: through semiconductor
//! or conductor material), so a barrier of dielectric or vacuum is never crossed. Nodes that no
//! conducting path joins to a drain keep F = infinity (no spill level exists).
//!
//! Besides the levels, the flood records each depression node's *pour point*: the last node
//! outside the depression on its filling path, whose potential is the spill level. A pocket of
//! trapped carriers at its spill level is tied to that node (`pockets::Ties`).

use std::cmp::{Ordering, Reverse};
use std::collections::BinaryHeap;

use crate::carrier::Carrier;
use crate::field::mesh::{Mesh, NodeKind};

/// A level with a total order (for the heap); ties broken by node index (deterministic).
#[derive(Debug, Clone, Copy, PartialEq)]
struct Entry {
    level: f64,
    node: usize,
    from: usize,
}

impl Eq for Entry {}

impl PartialOrd for Entry {
    fn partial_cmp(&self, other: &Self) -> Option<Ordering> {
        Some(self.cmp(other))
    }
}

impl Ord for Entry {
    fn cmp(&self, other: &Self) -> Ordering {
        self.level
            .total_cmp(&other.level)
            .then(self.node.cmp(&other.node))
            .then(self.from.cmp(&other.from))
    }
}

/// The result of one flood, in the carrier's orientation (v = phi for holes, -phi for electrons).
#[derive(Debug, Clone)]
pub(crate) struct Flood {
    /// Fill level of every node in V, real orientation (holes: >= phi, electrons: <= phi);
    /// NaN for nodes that are not semiconductor, infinite where no drain is reachable.
    pub fill_v: Vec<f64>,
    /// Pour point (a node index) of every node inside a depression; None elsewhere.
    pub pour: Vec<Option<usize>>,
}

/// The four grid neighbours of node `n` (those that exist).
pub(crate) fn neighbours(nr: usize, nz: usize, n: usize) -> impl Iterator<Item = usize> {
    let (i, j) = (n % nr, n / nr);
    [
        (i > 0).then(|| n - 1),
        (i + 1 < nr).then_some(n + 1),
        (j > 0).then(|| n - nr),
        (j + 1 < nz).then_some(n + nr),
    ]
    .into_iter()
    .flatten()
}

/// True for the conductor nodes that collect `side`'s carriers: contacts and grounded parts at the
/// drain potential (the lowest fixed potential for holes, the highest for electrons).
fn is_drain(mesh: &Mesh, phi_v: &[f64], n: usize, drain_v: f64, tol_v: f64) -> bool {
    matches!(mesh.kind[n], NodeKind::Contact(_) | NodeKind::Grounded)
        && (phi_v[n] - drain_v).abs() <= tol_v
}

/// Floods the landscape of `side`'s carriers.
///
/// `bounds_v` are the lowest and highest fixed potentials (the drains' levels); `occupied`
/// (optional) marks nodes where the last solve held trapped carriers: such a node counts as in a
/// depression even when it is reached at exactly its own level (a pocket that sits at its spill
/// level is flat), so that a pocket keeps its tie. `tol_v` is the depth below which a node is not
/// in a depression.
pub(crate) fn flood(
    mesh: &Mesh,
    phi_v: &[f64],
    side: Carrier,
    bounds_v: (f64, f64),
    occupied: Option<&[bool]>,
    tol_v: f64,
) -> Flood {
    let (nr, nz) = (mesh.grid.nr(), mesh.grid.nz());
    let nn = nr * nz;
    let sign = match side {
        Carrier::Hole => 1.0,
        Carrier::Electron => -1.0,
    };
    let drain_v = match side {
        Carrier::Hole => bounds_v.0,
        Carrier::Electron => bounds_v.1,
    };
    let v = |n: usize| sign * phi_v[n];
    let semi = |n: usize| mesh.kind[n] == NodeKind::Semiconductor;
    let mut fill = vec![f64::INFINITY; nn];
    let mut done = vec![false; nn];
    let mut in_depression = vec![false; nn];
    let mut pour = vec![None; nn];
    let mut heap = BinaryHeap::new();
    // The smallest entry pushed so far for each node not yet done (level, from): a larger one
    // can never be the first popped for that node, so it is not pushed. The same entries pop
    // first as without the filter (the answer is unchanged); the heap holds about one entry
    // per node instead of up to four (`BinaryHeap::pop` was 9% of a pocket point, `perf`).
    let mut pending: Vec<(f64, usize)> = vec![(f64::INFINITY, usize::MAX); nn];
    let mut push = |heap: &mut BinaryHeap<Reverse<Entry>>, e: Entry| {
        let best = &mut pending[e.node];
        if e.level.total_cmp(&best.0).then(e.from.cmp(&best.1)) == Ordering::Less {
            *best = (e.level, e.from);
            heap.push(Reverse(e));
        }
    };
    for d in (0..nn).filter(|&d| is_drain(mesh, phi_v, d, drain_v, tol_v)) {
        for m in neighbours(nr, nz, d) {
            if semi(m) && mesh.edge_conducts(d, m) {
                push(
                    &mut heap,
                    Entry {
                        level: v(d).max(v(m)),
                        node: m,
                        from: d,
                    },
                );
            }
        }
    }
    while let Some(Reverse(Entry { level, node, from })) = heap.pop() {
        if done[node] {
            continue;
        }
        done[node] = true;
        fill[node] = level;
        let held = occupied.is_some_and(|o| o[node]);
        if level > v(node) + tol_v || (held && level >= v(node) - tol_v) {
            in_depression[node] = true;
            pour[node] = Some(if in_depression[from] {
                pour[from].unwrap_or(from)
            } else {
                from
            });
        }
        for m in neighbours(nr, nz, node) {
            if !done[m] && semi(m) && mesh.edge_conducts(node, m) {
                push(
                    &mut heap,
                    Entry {
                        level: level.max(v(m)),
                        node: m,
                        from: node,
                    },
                );
            }
        }
    }
    let fill_v = (0..nn)
        .map(|n| if semi(n) { sign * fill[n] } else { f64::NAN })
        .collect();
    Flood { fill_v, pour }
}

/// The deepest depression of `side`'s landscape among nodes whose fixed charge has the sign of
/// that carrier's material (p-type for holes, n-type for electrons), V: max over those nodes of
/// |F(n) - phi_n|, 0 when there is none, with the deepest node. Depressions the grid does not
/// resolve (on the surface and thinner than a Debye length, `resolution.rs`) do not count. A potential with depletion and
/// pockets solved right has none deeper than round-off: every trapped-carrier pocket is flat at
/// its spill level. Independent of the solvers (used by tests and reports as a check).
pub fn deepest_depression_v(
    mesh: &Mesh,
    phi_v: &[f64],
    side: Carrier,
    bounds_v: (f64, f64),
) -> (f64, Option<usize>) {
    super::depressions(mesh, phi_v, side, bounds_v)
        .into_iter()
        .find(|d| d.resolved)
        .map_or((0.0, None), |d| (d.depth_v, Some(d.deepest_node)))
}

/// The deepest *empty well* of `side`'s carriers, V: a depleted node (`undepleted[n]` false) of
/// that carrier's material inside a depression (fill level F(n) > phi_n: carriers there cannot
/// drain) that the carriers of an undepleted region can flow into. For holes, those of an
/// undepleted p-type node s at phi_s reach every node joined to s by a conducting path on which
/// phi <= phi_s; with W(n) the highest such phi_s, the basin at n fills to min(F(n), W(n)), and
/// the well's depth is min(F(n), W(n)) - phi_n (electrons: mirrored). Wells in depressions the
/// grid does not resolve (`resolution.rs`) do not count. None may remain in any solution. It differs
/// from [`deepest_depression_v`] only where a basin is not filled to its brim: where a hole pocket
/// and an electron pocket touch (a p-n junction inside the crystal) the junction may sit reverse
/// biased, the n side above the p side, and each pocket holds its carriers below the barrier the
/// other forms.
pub fn deepest_empty_depression_v(
    mesh: &Mesh,
    phi_v: &[f64],
    undepleted: &[bool],
    side: Carrier,
    bounds_v: (f64, f64),
) -> (f64, Option<usize>) {
    let (nr, nz) = (mesh.grid.nr(), mesh.grid.nz());
    let sign = match side {
        Carrier::Hole => 1.0,
        Carrier::Electron => -1.0,
    };
    let v = |n: usize| sign * phi_v[n];
    let semi = |n: usize| mesh.kind[n] == NodeKind::Semiconductor;
    let holds = |n: usize| semi(n) && super::holds(side, mesh.charge_c[n]);
    // Highest reachable carrier level first (a max-heap on the level): every node takes the
    // highest level that reaches it.
    let mut level = vec![f64::NEG_INFINITY; phi_v.len()];
    let mut heap = BinaryHeap::new();
    for n in (0..phi_v.len()).filter(|&n| holds(n) && undepleted[n]) {
        heap.push(Entry {
            level: v(n),
            node: n,
            from: n,
        });
    }
    while let Some(Entry { level: l, node, .. }) = heap.pop() {
        if level[node] >= l {
            continue;
        }
        level[node] = l;
        for m in neighbours(nr, nz, node) {
            if semi(m) && mesh.edge_conducts(node, m) && v(m) <= l && level[m] < l {
                heap.push(Entry {
                    level: l,
                    node: m,
                    from: node,
                });
            }
        }
    }
    let f = flood(mesh, phi_v, side, bounds_v, None, 0.0);
    let lines = super::line_depressions(mesh, side, &f.pour);
    let fill = f.fill_v;
    let mut best = (0.0, None);
    for n in (0..phi_v.len()).filter(|&n| holds(n) && !undepleted[n]) {
        if f.pour[n].is_some_and(|s| lines.contains(&s)) {
            continue;
        }
        let d = level[n].min(sign * fill[n]) - v(n);
        if d > best.0 {
            best = (d, Some(n));
        }
    }
    best
}

#[cfg(test)]
mod tests {
    use super::*;

    /// A 1D landscape on a 7 x 1 strip is awkward on the tensor grid; flood's logic is tested on
    /// real meshes in `pockets::tests`. Here: the entry order is total and deterministic.
    #[test]
    fn entries_order_by_level_then_node() {
        let a = Entry {
            level: 1.0,
            node: 5,
            from: 0,
        };
        let b = Entry {
            level: 1.0,
            node: 3,
            from: 9,
        };
        let c = Entry {
            level: 0.5,
            node: 7,
            from: 1,
        };
        let mut h = BinaryHeap::new();
        for e in [a, b, c] {
            h.push(Reverse(e));
        }
        let order: Vec<usize> = std::iter::from_fn(|| h.pop().map(|Reverse(e)| e.node)).collect();
        assert_eq!(order, vec![7, 3, 5]);
    }
}
