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

/// A copy of `mesh` whose edge conductances across the depletion front are corrected for the
/// sub-cell front position. Returns the corrected mesh and the number of edges corrected.
pub(crate) fn front_corrected(
    mesh: &Mesh,
    phi_v: &[f64],
    undepleted: &[bool],
    bounds_v: (f64, f64),
) -> (Mesh, usize) {
    let mut out = mesh.clone();
    let g = &mesh.grid;
    let (nr, nz) = (g.nr(), g.nz());
    let r = g.r_mm();
    let z = g.z_mm();
    let semi = |n: usize| mesh.kind[n] == NodeKind::Semiconductor;
    let depleted = |n: usize| semi(n) && !undepleted[n];
    let bound_of = |n: usize| {
        if (phi_v[n] - bounds_v.1).abs() <= (phi_v[n] - bounds_v.0).abs() {
            bounds_v.1
        } else {
            bounds_v.0
        }
    };
    // Front position along a line through p (undepleted, u = 0), q1 and q2 (depleted), u = |B - phi|:
    // the vertex of the parabola through the three points.
    let front = |b: f64, xp: f64, x1: f64, x2: f64, p1: f64, p2: f64| -> Option<f64> {
        let (u1, u2) = ((b - p1).abs(), (b - p2).abs());
        let f01 = u1 / (x1 - xp);
        let f12 = (u2 - u1) / (x2 - x1);
        let a = (f12 - f01) / (x2 - xp);
        if !(a > 0.0 && u1 > 0.0 && u2 > u1) {
            return None;
        }
        let xf = 0.5 * (xp + x1) - f01 / (2.0 * a);
        let h = x1 - xp;
        // Between half a spacing behind p and a tenth of a spacing before q1 (h may be negative).
        let lo = xp - 0.5 * h;
        let hi = x1 - 0.1 * h;
        let (a, c) = if lo < hi { (lo, hi) } else { (hi, lo) };
        Some(xf.clamp(a, c))
    };
    let mut count = 0;
    for j in 0..nz {
        for i in 0..nr {
            let p = j * nr + i;
            if !(semi(p) && undepleted[p]) {
                continue;
            }
            let b = bound_of(p);
            // Radial neighbours: direction +1 and -1.
            for dir in [1isize, -1] {
                let i1 = i as isize + dir;
                let i2 = i as isize + 2 * dir;
                if i2 < 0 || i2 >= nr as isize {
                    continue;
                }
                let (i1, i2) = (i1 as usize, i2 as usize);
                let (q1, q2) = (j * nr + i1, j * nr + i2);
                if !(depleted(q1) && depleted(q2)) {
                    continue;
                }
                let Some(rf) = front(b, r[i], r[i1], r[i2], phi_v[q1], phi_v[q2]) else {
                    continue;
                };
                let e = j * (nr - 1) + i.min(i1);
                let (rp, r1) = (r[i], r[i1]);
                let scale = if rp > 0.0 && rf > 0.0 && r1 > 0.0 {
                    (r1 / rp).ln() / (r1 / rf).ln()
                } else {
                    (r1 - rp) / (r1 - rf)
                };
                if scale.is_finite() && scale > 0.0 {
                    out.w_r[e] = mesh.w_r[e] * scale;
                    count += 1;
                }
            }
            // Axial neighbours.
            for dir in [1isize, -1] {
                let j1 = j as isize + dir;
                let j2 = j as isize + 2 * dir;
                if j2 < 0 || j2 >= nz as isize {
                    continue;
                }
                let (j1, j2) = (j1 as usize, j2 as usize);
                let (q1, q2) = (j1 * nr + i, j2 * nr + i);
                if !(depleted(q1) && depleted(q2)) {
                    continue;
                }
                let Some(zf) = front(b, z[j], z[j1], z[j2], phi_v[q1], phi_v[q2]) else {
                    continue;
                };
                let e = j.min(j1) * nr + i;
                let scale = (z[j1] - z[j]) / (z[j1] - zf);
                if scale.is_finite() && scale > 0.0 {
                    out.w_z[e] = mesh.w_z[e] * scale;
                    count += 1;
                }
            }
        }
    }
    (out, count)
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
    // An undepleted node next to a contact at another potential: the depleted layer in front of
    // the contact is thinner than the spacing (low bias on a coarse grid); split that interval so
    // the layer can appear, else the undepleted bulk would touch the contact.
    let span = phi_v
        .iter()
        .fold(0.0f64, |m, &p| m.max(p.abs()))
        .max(f64::MIN_POSITIVE);
    let touches = |n: usize, m: usize| {
        semi(n)
            && undepleted[n]
            && matches!(mesh.kind[m], NodeKind::Contact(_))
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
    // Also the neighbouring intervals: the front may move by a cell after the re-solve, and the
    // sub-cell extrapolation reads the potential two and three nodes away.
    let widen = |v: Vec<bool>| -> Vec<bool> {
        (0..v.len())
            .map(|k| v[k] || (k > 0 && v[k - 1]) || (k + 1 < v.len() && v[k + 1]))
            .collect()
    };
    (widen(split_r), widen(split_z))
}
