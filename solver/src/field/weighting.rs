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
use super::union_find::UnionFind;
use crate::detector::Detector;
use crate::error::{Error, Result};

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
pub enum Owner {
    /// Contact k (its index in the detector's contacts).
    Contact(usize),
    /// A grounded part.
    Ground,
    /// Floating conductor g (one shared unknown).
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

/// Labels every node: its owner if it is a conductor (contact, grounded, floating passive or an
/// undepleted semiconductor node attached to one); `None` for free nodes.
pub fn owners(
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
    let mut uf = UnionFind::new(nn + nc + 1 + np);
    let root_of = |k: NodeKind| match k {
        NodeKind::Contact(c) => Some(contact_root(c)),
        NodeKind::Grounded => Some(ground_root),
        NodeKind::Floating(p) => Some(passive_root(p)),
        _ => None,
    };
    // Conductors first: every conductor node joins its virtual root (no two roots share a set).
    for (n, k) in mesh.kind.iter().enumerate() {
        if let Some(r) = root_of(*k) {
            uf.union(n, r);
        }
    }
    // Which virtual root a set holds, if any (indexed by the set's representative).
    let mut root_in = vec![None; nn + nc + 1 + np];
    for r in nn..nn + nc + 1 + np {
        let s = uf.find(r);
        root_in[s] = Some(r);
    }
    // Then the undepleted semiconductor, edge by edge, only along edges that conduct (through
    // semiconductor or conductor material, never across a dielectric or vacuum gap). Two sets
    // holding different contacts (or a contact and ground) joined by an edge are a short: the
    // first such edge is where the undepleted region bridges them.
    let name = |r: usize| -> String {
        if r < nn + nc {
            format!("contact {}", det.contacts[r - nn].label())
        } else if r == ground_root {
            "ground".to_string()
        } else {
            format!("floating passive `{}`", det.passives[r - nn - nc - 1].name)
        }
    };
    let mut bridge: Option<(usize, usize, usize)> = None;
    mesh.for_each_edge(|p, q, _| {
        if bridge.is_some() || !(undepleted[p] || undepleted[q]) {
            return;
        }
        let joins = (undepleted[p] || root_of(mesh.kind[p]).is_some())
            && (undepleted[q] || root_of(mesh.kind[q]).is_some());
        if !joins || !mesh.edge_conducts(p, q) {
            return;
        }
        let (sp, sq) = (uf.find(p), uf.find(q));
        if sp == sq {
            return;
        }
        match (root_in[sp], root_in[sq]) {
            (Some(a), Some(b)) if a < nn + nc + 1 && b < nn + nc + 1 => {
                // Contacts or ground on both sides: a short (floating passives merge harmlessly).
                let at = if undepleted[p] { p } else { q };
                bridge = Some((a, b, at));
                return;
            }
            _ => {}
        }
        uf.union(sp, sq);
        let s = uf.find(sp);
        // Keep the contact/ground root if the set holds one, else a floating passive's.
        let keep = match (root_in[sp], root_in[sq]) {
            (Some(a), Some(b)) => Some(a.min(b)),
            (a, b) => a.or(b),
        };
        root_in[s] = keep;
    });
    if let Some((a, b, at)) = bridge {
        let (first, second) = (name(a.min(b)), name(a.max(b)));
        let nr = mesh.grid.nr();
        return Err(Error::UndepletedBridge {
            first,
            second,
            bias_v,
            r_mm: mesh.grid.r_mm()[at % nr],
            z_mm: mesh.grid.z_mm()[at / nr],
        });
    }
    let mut set_owner: std::collections::HashMap<usize, Owner> = Default::default();
    for r in nn..nn + nc + 1 {
        let owner = if r == ground_root {
            Owner::Ground
        } else {
            Owner::Contact(r - nn)
        };
        set_owner.insert(uf.find(r), owner);
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
            Some(o) => *o,
            None => {
                let next = islands.len();
                Owner::Floating(*islands.entry(s).or_insert(next))
            }
        });
    }
    Ok(out)
}

/// The unknowns of the weighting problem: free where no conductor owns a node, fixed on contacts
/// and grounded parts (their values per contact come with the right-hand side), one shared
/// unknown per floating conductor.
pub fn weighting_dofs(own: &[Option<Owner>]) -> Vec<Dof> {
    own.iter()
        .map(|o| match o {
            None => Dof::Free,
            Some(Owner::Contact(_) | Owner::Ground) => Dof::Fixed(0.0),
            Some(Owner::Floating(g)) => Dof::Group(*g),
        })
        .collect()
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
    let sys = System::assemble(mesh, &weighting_dofs(&own), &vec![0.0; mesh.kind.len()]);
    let llt = if sys.n > 0 {
        let sym = sys.symbolic()?;
        Some(sys.factor(&sym, &sys.val)?)
    } else {
        None
    };
    let owned: Vec<Vec<bool>> = (0..nc)
        .map(|k| own.iter().map(|o| *o == Some(Owner::Contact(k))).collect())
        .collect();
    let fixed: Vec<Vec<f64>> = owned
        .iter()
        .map(|mine| mine.iter().map(|&m| f64::from(u8::from(m))).collect())
        .collect();
    // Every contact's right-hand side in one solve (the factor read once).
    let xs = match &llt {
        Some(llt) => {
            let rhs: Vec<Vec<f64>> = fixed.iter().map(|f| sys.rhs_for_fixed(mesh, f)).collect();
            llt.solve_many(&rhs.iter().map(Vec::as_slice).collect::<Vec<_>>())
        }
        None => vec![Vec::new(); nc],
    };
    let w = xs
        .iter()
        .zip(&fixed)
        .map(|(x, f)| sys.to_nodes_with(x, f))
        .collect();
    Ok(WeightingPotentials { w, owned })
}
