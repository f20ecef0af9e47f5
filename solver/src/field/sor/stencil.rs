//! The 5-point stencil of the (r, z) mesh as both SOR backends read it: per-node conductances
//! and neighbours, floating conductors, the initial iterate, the KKT readout of undepleted nodes,
//! and the device-side problem (`gpu::StencilProblem`) of the wgpu backend.

use crate::error::{Error, Result};
use crate::field::mesh::{Mesh, NodeKind};
use crate::field::system::Dof;
use crate::gpu::{BlockRows, ColourRows, StencilProblem};

/// Conductances (F) to the left (i - 1), right (i + 1), lower (j - 1), upper (j + 1) neighbour
/// of node n; 0 where there is none.
pub(super) fn weights(mesh: &Mesh, n: usize) -> [f64; 4] {
    let (nr, nz) = (mesh.grid.nr(), mesh.grid.nz());
    let (i, j) = (n % nr, n / nr);
    [
        if i > 0 {
            mesh.w_r[j * (nr - 1) + i - 1]
        } else {
            0.0
        },
        if i + 1 < nr {
            mesh.w_r[j * (nr - 1) + i]
        } else {
            0.0
        },
        if j > 0 {
            mesh.w_z[(j - 1) * nr + i]
        } else {
            0.0
        },
        if j + 1 < nz {
            mesh.w_z[j * nr + i]
        } else {
            0.0
        },
    ]
}

/// The neighbours of node n in the order of [`weights`].
pub(super) fn neighbours(mesh: &Mesh, n: usize) -> [Option<usize>; 4] {
    let (nr, nz) = (mesh.grid.nr(), mesh.grid.nz());
    let (i, j) = (n % nr, n / nr);
    [
        (i > 0).then(|| n - 1),
        (i + 1 < nr).then_some(n + 1),
        (j > 0).then(|| n - nr),
        (j + 1 < nz).then_some(n + nr),
    ]
}

/// A floating conductor: its nodes, its edges (outside node, conductance in F), net charge (C).
pub(super) struct Group {
    pub(super) nodes: Vec<usize>,
    pub(super) edges: Vec<(usize, f64)>,
    pub(super) q: f64,
    /// Sum of the edge conductances, F (> 0).
    pub(super) sum: f64,
}

/// The floating conductors of `dofs` (charges from `charge_c`), in order of first node.
pub(super) fn groups(mesh: &Mesh, dofs: &[Dof], charge_c: &[f64]) -> Result<Vec<Group>> {
    let mut out: Vec<(usize, Group)> = Vec::new();
    for (n, d) in dofs.iter().enumerate() {
        let Dof::Group(g) = *d else { continue };
        let k = match out.iter().position(|(key, _)| *key == g) {
            Some(k) => k,
            None => {
                out.push((
                    g,
                    Group {
                        nodes: Vec::new(),
                        edges: Vec::new(),
                        q: 0.0,
                        sum: 0.0,
                    },
                ));
                out.len() - 1
            }
        };
        let grp = &mut out[k].1;
        grp.nodes.push(n);
        grp.q += charge_c[n];
        for (m, w) in neighbours(mesh, n).into_iter().zip(weights(mesh, n)) {
            if let Some(m) = m
                && w > 0.0
                && dofs[m] != Dof::Group(g)
            {
                grp.edges.push((m, w));
                grp.sum += w;
            }
        }
    }
    out.into_iter()
        .map(|(g, grp)| {
            if grp.sum.is_finite() && grp.sum > 0.0 {
                Ok(grp)
            } else {
                Err(Error::Singular {
                    reason: format!(
                        "floating conductor {g} has no conductance to its surroundings"
                    ),
                })
            }
        })
        .collect()
}

/// 1 / sum w of a free node, or the error for a node without conductance.
pub(super) fn inverse_sum(w: &[f64; 4], n: usize) -> Result<f64> {
    let sum: f64 = w.iter().sum();
    if sum.is_finite() && sum > 0.0 {
        Ok(1.0 / sum)
    } else {
        Err(Error::Singular {
            reason: format!("node {n} has no conductance to any neighbour"),
        })
    }
}

/// Initial value of free node n: the guess if finite, else the bound its space charge pushes a
/// semiconductor node to (upper for q > 0), else 0; projected onto [lo, hi].
pub(super) fn initial(guess_v: Option<&[f64]>, n: usize, q: f64, (lo, hi): (f64, f64)) -> f64 {
    let bounded = lo.is_finite() || hi.is_finite();
    let x0 = match guess_v {
        Some(g) if g[n].is_finite() => g[n],
        _ if bounded && q > 0.0 => hi,
        _ if bounded && q < 0.0 => lo,
        _ => 0.0,
    };
    x0.clamp(lo, hi)
}

/// The undepleted semiconductor nodes of a converged iterate with every node's own bounds
/// (`bounds[n]`: the contact potentials, or a pocket's level for a tied node): those whose
/// unconstrained Gauss-Seidel target lies beyond a bound (KKT readout).
pub(super) fn undepleted_within(
    mesh: &Mesh,
    dofs: &[Dof],
    phi: &[f64],
    bounds: &[(f64, f64)],
) -> Vec<bool> {
    (0..phi.len())
        .map(|n| {
            if mesh.kind[n] != NodeKind::Semiconductor || dofs[n] != Dof::Free {
                return false;
            }
            let (t, _) =
                super::residual::target(mesh, phi, n, &weights(mesh, n), &neighbours(mesh, n));
            t > bounds[n].1 || t < bounds[n].0
        })
        .collect()
}

/// The device problem for `dofs` on the (r, z) mesh: free semiconductor nodes bounded to
/// `bounds_v` (None: unbounded, as in the weighting problem), other free nodes unbounded, charges `charge_c` (C), initial iterate from
/// `guess_v` (see [`initial`]; a floating conductor starts at the guess's mean over its nodes).
/// Node (i, j) is red when i + j is even.
pub(crate) fn device_problem(
    mesh: &Mesh,
    dofs: &[Dof],
    charge_c: &[f64],
    bounds_v: Option<(f64, f64)>,
    guess_v: Option<&[f64]>,
    omega: f64,
) -> Result<StencilProblem> {
    let free = (f64::NEG_INFINITY, f64::INFINITY);
    let nr = mesh.grid.nr();
    let nn = dofs.len();
    let mut x0 = vec![0.0; nn];
    let mut colours = [ColourRows::default(), ColourRows::default()];
    for n in 0..nn {
        match dofs[n] {
            Dof::Fixed(v) => x0[n] = v,
            Dof::Group(_) => {}
            Dof::Free => {
                let w = weights(mesh, n);
                let inv = inverse_sum(&w, n)?;
                let (lo, hi) = match bounds_v {
                    Some(b) if mesh.kind[n] == NodeKind::Semiconductor => b,
                    _ => free,
                };
                x0[n] = initial(guess_v, n, charge_c[n], (lo, hi));
                let c = &mut colours[(n % nr + n / nr) % 2];
                c.node.push(n as u32);
                for (m, wm) in neighbours(mesh, n).into_iter().zip(w) {
                    // A missing neighbour has w = 0; the node itself is a valid index.
                    c.nb.push(m.unwrap_or(n) as u32);
                    c.w.push(wm * inv);
                }
                c.q.push(charge_c[n] * inv);
                c.lo.push(lo);
                c.hi.push(hi);
            }
        }
    }
    let mut blocks = Vec::new();
    for g in groups(mesh, dofs, charge_c)? {
        let v0 = guess_v.map_or(0.0, |gv| {
            g.nodes.iter().map(|&n| gv[n]).sum::<f64>() / g.nodes.len() as f64
        });
        let v0 = if v0.is_finite() { v0 } else { 0.0 };
        for &n in &g.nodes {
            x0[n] = v0;
        }
        blocks.push(BlockRows {
            nodes: g.nodes.iter().map(|&n| n as u32).collect(),
            edges: g
                .edges
                .iter()
                .map(|&(m, w)| (m as u32, w / g.sum))
                .collect(),
            q: g.q / g.sum,
        });
    }
    // The fixed potentials set the scale of the stopping rule (the bounds are their range).
    let (lo, hi) = dofs.iter().fold((0.0_f64, 0.0_f64), |(l, h), d| match *d {
        Dof::Fixed(v) => (l.min(v), h.max(v)),
        _ => (l, h),
    });
    Ok(StencilProblem {
        stencil: 4,
        x0,
        colours,
        blocks,
        omega,
        scale_v: (hi - lo).abs(),
        magnitude_v: hi.abs().max(lo.abs()),
    })
}
