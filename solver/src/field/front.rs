//! Sub-cell location of the depletion front, carried into the weighting potentials.
//!
//! The discrete obstacle problem places the free boundary on nodes, which makes c12's error
//! O(h / depleted depth) and the C-V curve step-like. Next to the front the potential of the
//! depleted side behaves like phi = B - a (x - x_f)^2 (B the bound, the field vanishes at the
//! front), so sqrt|B - phi| is linear in x: two depleted nodes q1, q2 beyond the last undepleted
//! node p give the front x_f by linear extrapolation to zero. In the weighting problem the
//! conductor (the undepleted region) then ends at x_f instead of at p: the conductance of edge
//! p-q1 becomes that of the gap [x_f, x_q1],
//!   axial: w' = w |z_q1 - z_p| / |z_q1 - z_f|,
//!   radial: w' = w ln(r_q1 / r_p) / ln(r_q1 / r_f)   (log conductance, same sign convention),
//! with x_f clamped to lie between half a spacing behind p and a tenth of a spacing before q1.

use super::mesh::{Mesh, NodeKind};

/// The front found inside one cell along a grid line.
#[derive(Debug, Clone, Copy)]
pub(crate) struct Crossing {
    /// Index into `w_r` (radial) or `w_z` (axial) of the edge p-q1.
    pub edge: usize,
    /// Along r (else z).
    pub radial: bool,
    /// Interval index (along the line's axis) of the edge.
    pub interval: usize,
    /// Coordinates (mm along the axis) of p, q1 and the front.
    pub xp: f64,
    pub x1: f64,
    pub xf: f64,
    /// p is a contact node at a bound: an undepleted layer thinner than the cell separates the
    /// contact from the depleted region (no node is undepleted there).
    pub at_contact: bool,
}

/// True when the material at semiconductor node `n` can hold an undepleted layer at the upper
/// bound (`upper`) or at the lower one: n-type (positive fixed charge when depleted) or neutral
/// material at the upper, p-type or neutral at the lower. Free holes sit at the lowest potential
/// they reach, free electrons at the highest; and depleted p-type material has
/// laplacian(phi) = -rho/eps > 0, so its potential cannot rise above the contacts' maximum
/// (maximum principle, discrete too on this M-matrix scheme). A sub-cell "layer" of p-type
/// material at the upper bound is then a staircase artefact: on a slanted contact the first node
/// off a contact node has a second contact neighbour, which bends the potential along one grid
/// line although no layer exists (LEGEND's P99000A, a PPC with a 30 degree taper of its n+
/// contact, was "not fully depleted" up to 100 kV because of it).
pub(crate) fn can_hold_layer(mesh: &Mesh, n: usize, upper: bool) -> bool {
    let q = mesh.charge_c[n];
    if upper { q >= 0.0 } else { q <= 0.0 }
}

/// Front position along a line through p (u = 0), q1 and q2 (depleted), u = |B - phi|: the vertex
/// of the parabola through the three points, or None when the data are not parabola-like.
fn vertex(b: f64, xp: f64, x1: f64, x2: f64, p1: f64, p2: f64) -> Option<f64> {
    let (u1, u2) = ((b - p1).abs(), (b - p2).abs());
    let f01 = u1 / (x1 - xp);
    let f12 = (u2 - u1) / (x2 - x1);
    let a = (f12 - f01) / (x2 - xp);
    if !(a > 0.0 && u1 > 0.0 && u2 > u1) {
        return None;
    }
    Some(0.5 * (xp + x1) - f01 / (2.0 * a))
}

/// Every sub-cell front crossing: along each grid line from an anchor p (an undepleted
/// semiconductor node, or a contact node at a bound) over two depleted nodes q1, q2.
///
/// For an undepleted p the front is clamped between half a spacing behind p and a tenth of a
/// spacing before q1. For a contact p it must lie in front of the contact (between p and a tenth
/// of a spacing before q1) by more than 1e-3 of the spacing, else there is no layer.
pub(crate) fn crossings(
    mesh: &Mesh,
    phi_v: &[f64],
    undepleted: &[bool],
    bounds_v: (f64, f64),
) -> Vec<Crossing> {
    let g = &mesh.grid;
    let (nr, nz) = (g.nr(), g.nz());
    let (r, z) = (g.r_mm(), g.z_mm());
    let semi = |n: usize| mesh.kind[n] == NodeKind::Semiconductor;
    let depleted = |n: usize| semi(n) && !undepleted[n];
    let span = (bounds_v.1 - bounds_v.0).abs().max(f64::MIN_POSITIVE);
    let bound_of = |n: usize| {
        if (phi_v[n] - bounds_v.1).abs() <= (phi_v[n] - bounds_v.0).abs() {
            bounds_v.1
        } else {
            bounds_v.0
        }
    };
    let mut out = Vec::new();
    for p in 0..nr * nz {
        let at_contact = match mesh.kind[p] {
            NodeKind::Semiconductor if undepleted[p] => false,
            NodeKind::Contact(_) if (phi_v[p] - bound_of(p)).abs() <= 1e-9 * span => true,
            _ => continue,
        };
        // The undepleted side's own potential: a contact bound, or a pocket's level.
        let b = if at_contact { bound_of(p) } else { phi_v[p] };
        let (i, j) = ((p % nr) as isize, (p / nr) as isize);
        for (di, dj) in [(1isize, 0isize), (-1, 0), (0, 1), (0, -1)] {
            let (i2, j2) = (i + 2 * di, j + 2 * dj);
            if i2 < 0 || j2 < 0 || i2 >= nr as isize || j2 >= nz as isize {
                continue;
            }
            let q1 = ((j + dj) as usize) * nr + (i + di) as usize;
            let q2 = (j2 as usize) * nr + i2 as usize;
            if !(depleted(q1) && depleted(q2)) {
                continue;
            }
            if at_contact && !can_hold_layer(mesh, q1, b == bounds_v.1) {
                continue;
            }
            let radial = di != 0;
            let (t, k0, k1, k2) = if radial {
                (r, i as usize, (i + di) as usize, i2 as usize)
            } else {
                (z, j as usize, (j + dj) as usize, j2 as usize)
            };
            let Some(xv) = vertex(b, t[k0], t[k1], t[k2], phi_v[q1], phi_v[q2]) else {
                continue;
            };
            let (xp, x1) = (t[k0], t[k1]);
            let h = x1 - xp;
            let lo = if at_contact { xp } else { xp - 0.5 * h };
            let hi = x1 - 0.1 * h;
            let (a, c) = if lo < hi { (lo, hi) } else { (hi, lo) };
            let xf = xv.clamp(a, c);
            if at_contact && (xf - xp).abs() <= 1e-3 * h.abs() {
                continue;
            }
            let interval = k0.min(k1);
            let edge = if radial {
                j as usize * (nr - 1) + interval
            } else {
                interval * nr + i as usize
            };
            out.push(Crossing {
                edge,
                radial,
                interval,
                xp,
                x1,
                xf,
                at_contact,
            });
        }
    }
    out
}

/// A copy of `mesh` whose edge conductances across the depletion front are corrected for the
/// sub-cell front positions `cross` (from [`crossings`] on the same mesh).
pub(crate) fn front_corrected(mesh: &Mesh, cross: &[Crossing]) -> Mesh {
    let mut out = mesh.clone();
    for c in cross {
        let (rp, r1, rf) = (c.xp, c.x1, c.xf);
        let scale = if c.radial && rp > 0.0 && rf > 0.0 && r1 > 0.0 {
            (r1 / rp).ln() / (r1 / rf).ln()
        } else {
            (r1 - rp) / (r1 - rf)
        };
        if scale.is_finite() && scale > 0.0 {
            let w = if c.radial {
                &mut out.w_r[c.edge]
            } else {
                &mut out.w_z[c.edge]
            };
            *w *= scale;
        }
    }
    out
}

/// Intervals the depletion front crosses, for refinement: an r interval is marked when an edge
/// along r joins an undepleted and a depleted semiconductor node and the front is not nearly
/// parallel to r there, likewise for z. The front's normal is estimated from the potential
/// gradient at the depleted node; a component below a quarter of the gradient's magnitude
/// (front within about 15 degrees of the edge) does not mark its interval. This keeps a
/// tensor grid from filling with lines along a curved front.
pub(crate) fn front_splits(
    mesh: &Mesh,
    phi_v: &[f64],
    undepleted: &[bool],
    bounds_v: (f64, f64),
) -> (Vec<bool>, Vec<bool>) {
    let g = &mesh.grid;
    let (nr, nz) = (g.nr(), g.nz());
    let (r, z) = (g.r_mm(), g.z_mm());
    let semi = |n: usize| mesh.kind[n] == NodeKind::Semiconductor;
    let grad = |n: usize| -> (f64, f64) {
        let (i, j) = (n % nr, n / nr);
        let (i0, i1) = (i.saturating_sub(1), (i + 1).min(nr - 1));
        let (j0, j1) = (j.saturating_sub(1), (j + 1).min(nz - 1));
        let gr = (phi_v[j * nr + i1] - phi_v[j * nr + i0]) / (r[i1] - r[i0]);
        let gz = (phi_v[j1 * nr + i] - phi_v[j0 * nr + i]) / (z[j1] - z[j0]);
        (gr, gz)
    };
    let mut split_r = vec![false; nr - 1];
    let mut split_z = vec![false; nz - 1];
    for n in (0..nr * nz).filter(|&n| semi(n)) {
        let (i, j) = (n % nr, n / nr);
        if i + 1 < nr && semi(n + 1) && undepleted[n] != undepleted[n + 1] {
            let d = if undepleted[n] { n + 1 } else { n };
            let (gr, gz) = grad(d);
            if gr.abs() >= 0.25 * gr.hypot(gz) || gr.hypot(gz) == 0.0 {
                split_r[i] = true;
            }
        }
        if j + 1 < nz && semi(n + nr) && undepleted[n] != undepleted[n + nr] {
            let d = if undepleted[n] { n + nr } else { n };
            let (gr, gz) = grad(d);
            if gz.abs() >= 0.25 * gr.hypot(gz) || gr.hypot(gz) == 0.0 {
                split_z[j] = true;
            }
        }
    }
    // An undepleted node next to a contact or grounded part at another potential: the depleted
    // layer in front of it is thinner than the spacing (low bias on a coarse grid); split that interval so
    // the layer can appear, else the undepleted bulk would touch the contact.
    let span = (bounds_v.1 - bounds_v.0).abs().max(f64::MIN_POSITIVE);
    let touches = |n: usize, m: usize| {
        semi(n)
            && undepleted[n]
            && matches!(mesh.kind[m], NodeKind::Contact(_) | NodeKind::Grounded)
            && (phi_v[m] - phi_v[n]).abs() > 1e-9 * span
    };
    for n in 0..nr * nz {
        let (i, j) = (n % nr, n / nr);
        if i + 1 < nr && (touches(n, n + 1) || touches(n + 1, n)) {
            split_r[i] = true;
        }
        if j + 1 < nz && (touches(n, n + nr) || touches(n + nr, n)) {
            split_z[j] = true;
        }
    }
    // An undepleted layer thinner than the first cell in front of a contact (near full depletion):
    // split that cell so the layer gets nodes.
    for c in crossings(mesh, phi_v, undepleted, bounds_v) {
        if c.at_contact {
            if c.radial {
                split_r[c.interval] = true;
            } else {
                split_z[c.interval] = true;
            }
        }
    }
    // Also the neighbouring intervals: the front may move by a cell after the re-solve, and the
    // sub-cell extrapolation reads the potential two and three nodes away.
    let widen = |v: Vec<bool>| -> Vec<bool> {
        (0..v.len())
            .map(|k| v[k] || (k > 0 && v[k - 1]) || (k + 1 < v.len() && v[k + 1]))
            .collect()
    };
    (widen(split_r), widen(split_z))
}
