//! Weighting potentials with depletion.
//!
//! W_k = 1 on contact k, 0 on every other contact and grounded part; Laplace's equation elsewhere
//! (no space charge). Undepleted regions are conductors: a region touching a contact is part of
//! that contact (the exact limit of the paper's eps_r x 1e5 in undepleted cells); a region
//! touching nothing is a floating conductor (one unknown potential, zero net charge).
//!
//! For comparison the paper's own mode is available too (`WeightingMode::PaperEpsilon`): no
//! conductors, the permittivity of undepleted semiconductor multiplied by 1e5.

use serde::{Deserialize, Serialize};

use super::mesh::{Mesh, NodeKind};
use super::system::{Dof, System};
use crate::{Detector, Error, Result};

/// How undepleted semiconductor enters the weighting potentials (a closed set).
#[derive(Debug, Clone, Copy, PartialEq, Eq, Default, Serialize, Deserialize)]
#[serde(rename_all = "kebab-case")]
pub enum WeightingMode {
    /// Undepleted regions are conductors: part of the contact they touch, or floating (exact).
    #[default]
    Conductor,
    /// The paper's approach (section 3, as in SolidStateDetectors.jl): eps_r x
    /// `PAPER_EPSILON_FACTOR` in undepleted semiconductor, every node free except the contacts.
    PaperEpsilon,
}

impl WeightingMode {
    /// Name as on the command line.
    pub fn as_str(self) -> &'static str {
        match self {
            WeightingMode::Conductor => "conductor",
            WeightingMode::PaperEpsilon => "paper-epsilon",
        }
    }
}

/// Factor on the permittivity of undepleted semiconductor in `WeightingMode::PaperEpsilon`.
pub const PAPER_EPSILON_FACTOR: f64 = 1e5;

/// The mesh of the paper's weighting mode: the conductance of every edge inside the undepleted
/// region multiplied by `factor` (the node-based form of eps_r x factor in the cells of the
/// undepleted region). An edge is inside when both ends are undepleted semiconductor nodes, or
/// one is and the other lies on a contact (the undepleted bulk reaches up to the contact it
/// touches); edges into depleted semiconductor keep their value.
pub(crate) fn paper_epsilon_mesh(mesh: &Mesh, undepleted: &[bool], factor: f64) -> Mesh {
    let mut out = mesh.clone();
    let (nr, nz) = (mesh.grid.nr(), mesh.grid.nz());
    let und = |n: usize| undepleted[n] && mesh.kind[n] == NodeKind::Semiconductor;
    let contact = |n: usize| matches!(mesh.kind[n], NodeKind::Contact(_));
    let inside = |a: usize, b: usize| (und(a) && (und(b) || contact(b))) || (und(b) && contact(a));
    for n in 0..nr * nz {
        let (i, j) = (n % nr, n / nr);
        if i + 1 < nr && inside(n, n + 1) {
            out.w_r[j * (nr - 1) + i] *= factor;
        }
        if j + 1 < nz && inside(n, n + nr) {
            out.w_z[n] *= factor;
        }
    }
    out
}

/// What an undepleted node belongs to.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub(crate) enum Owner {
    Contact(usize),
    Ground,
    Floating(usize),
}

/// Weighting potentials of all contacts on one mesh.
#[derive(Debug, Clone)]
pub struct WeightingPotentials {
    /// W_k for every contact k (node fields).
    pub w: Vec<Vec<f64>>,
    /// Nodes that belong to contact k (the contact and its undepleted extension).
    pub owned: Vec<Vec<bool>>,
}

struct UnionFind(Vec<usize>);

impl UnionFind {
    fn find(&mut self, mut a: usize) -> usize {
        while self.0[a] != a {
            self.0[a] = self.0[self.0[a]];
            a = self.0[a];
        }
        a
    }
    fn union(&mut self, a: usize, b: usize) {
        let (ra, rb) = (self.find(a), self.find(b));
        if ra != rb {
            self.0[ra] = rb;
        }
    }
}

/// Labels every node: its owner if it is a conductor (contact, grounded, floating passive or an
/// undepleted semiconductor node attached to one); `None` for free nodes.
pub(crate) fn owners(
    mesh: &Mesh,
    det: &Detector,
    undepleted: &[bool],
    bias_v: f64,
) -> Result<Vec<Option<Owner>>> {
    let nn = mesh.kind.len();
    let nc = det.contacts.len();
    let np = det.passives.len();
    // Virtual roots: contacts, ground, floating passives.
    let contact_root = |c: usize| nn + c;
    let ground_root = nn + nc;
    let passive_root = |p: usize| nn + nc + 1 + p;
    let mut uf = UnionFind((0..nn + nc + 1 + np).collect());
    let root_of = |k: NodeKind| match k {
        NodeKind::Contact(c) => Some(contact_root(c)),
        NodeKind::Grounded => Some(ground_root),
        NodeKind::Floating(p) => Some(passive_root(p)),
        _ => None,
    };
    for (n, k) in mesh.kind.iter().enumerate() {
        if let Some(r) = root_of(*k) {
            uf.union(n, r);
        }
    }
    mesh.for_each_edge(|p, q, _| {
        let (up, uq) = (undepleted[p], undepleted[q]);
        if up && uq {
            uf.union(p, q);
        } else if up {
            if let Some(r) = root_of(mesh.kind[q]) {
                uf.union(p, r);
            }
        } else if uq && let Some(r) = root_of(mesh.kind[p]) {
            uf.union(q, r);
        }
    });
    // Which virtual roots share a set: that is a short through an undepleted region.
    let name = |r: usize| -> String {
        if r < nn + nc {
            format!("contact {}", det.contacts[r - nn].label())
        } else if r == ground_root {
            "ground".to_string()
        } else {
            format!("floating passive `{}`", det.passives[r - nn - nc - 1].name)
        }
    };
    let mut set_owner: std::collections::HashMap<usize, (usize, Owner)> = Default::default();
    for r in nn..nn + nc + 1 {
        let owner = if r == ground_root {
            Owner::Ground
        } else {
            Owner::Contact(r - nn)
        };
        let s = uf.find(r);
        if let Some((other, _)) = set_owner.get(&s) {
            // Contacts at the same potential may be joined harmlessly only if they are the same.
            return Err(Error::UndepletedBridge {
                first: name(*other),
                second: name(r),
                bias_v,
            });
        }
        set_owner.insert(s, (r, owner));
    }
    let mut out = vec![None; nn];
    let mut islands = std::collections::HashMap::new();
    for n in 0..nn {
        let conductor = undepleted[n] || root_of(mesh.kind[n]).is_some();
        if !conductor {
            continue;
        }
        let s = uf.find(n);
        out[n] = Some(match set_owner.get(&s) {
            Some((_, o)) => *o,
            None => {
                let next = islands.len();
                Owner::Floating(*islands.entry(s).or_insert(next))
            }
        });
    }
    Ok(out)
}

/// Weighting potentials of all contacts given the undepleted nodes of the potential solve.
pub fn weighting_potentials(
    mesh: &Mesh,
    det: &Detector,
    undepleted: &[bool],
    bias_v: f64,
) -> Result<WeightingPotentials> {
    let own = owners(mesh, det, undepleted, bias_v)?;
    let nc = det.contacts.len();
    // One pattern and one factorisation for all contacts: only the fixed values differ.
    let dofs: Vec<Dof> = own
        .iter()
        .map(|o| match o {
            None => Dof::Free,
            Some(Owner::Contact(_) | Owner::Ground) => Dof::Fixed(0.0),
            Some(Owner::Floating(g)) => Dof::Group(*g),
        })
        .collect();
    let sys = System::assemble(mesh, &dofs, &vec![0.0; mesh.kind.len()]);
    let llt = if sys.n > 0 {
        let sym = sys.symbolic()?;
        Some(sys.factor(&sym, &sys.val)?)
    } else {
        None
    };
    let mut w = Vec::with_capacity(nc);
    let mut owned = Vec::with_capacity(nc);
    for k in 0..nc {
        let mine: Vec<bool> = own.iter().map(|o| *o == Some(Owner::Contact(k))).collect();
        let fixed: Vec<f64> = mine.iter().map(|&m| if m { 1.0 } else { 0.0 }).collect();
        let x = match &llt {
            Some(llt) => llt.solve(&sys.rhs_for_fixed(mesh, &fixed)),
            None => Vec::new(),
        };
        w.push(sys.to_nodes_with(&x, &fixed));
        owned.push(mine);
    }
    Ok(WeightingPotentials { w, owned })
}
