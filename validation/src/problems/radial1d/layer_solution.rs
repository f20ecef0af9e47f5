//! The exact-front solution of a layer: field and potential (also between two contacts), the
//! potential at the nodes, and the checks that it is consistent with the bounds and conductors.

use hpge_solver::constants::CM3_TO_M3;

use super::layers::{End, Fronts, Layer};
use crate::error::Result;

impl<'p, 'z> Fronts<'p, 'z> {
    /// r phi'(r) (V) of a layer's solution.
    pub(super) fn field(&self, layer: &Layer, r: f64) -> Result<f64> {
        let mr = self.prof.moments(r)?;
        Ok(match (layer.left, layer.right) {
            (End::Free { s, .. }, _) | (_, End::Free { s, .. }) => {
                -self.prof.k * (mr.0 - self.prof.moments(s)?.0)
            }
            (End::Fixed { r: r1, phi: p1 }, End::Fixed { r: r2, phi: p2 }) => {
                let b = self.fixed_slope(r1, p1, r2, p2)?;
                let m1 = self.prof.moments(r1)?;
                b - self.prof.k * (mr.0 - m1.0)
            }
        })
    }

    /// Between two contacts: phi(r) = phi1 + B ln(r / r1) - (q/eps) psi_{r1}(r) with
    /// B = (phi2 - phi1 + (q/eps) psi_{r1}(r2)) / ln(r2 / r1).
    fn fixed_slope(&self, r1: f64, p1: f64, r2: f64, p2: f64) -> Result<f64> {
        let (m1, m2) = (self.prof.moments(r1)?, self.prof.moments(r2)?);
        Ok((p2 - p1 + self.prof.k * self.prof.psi(r2, m1, m2)) / (r2 / r1).ln())
    }

    /// Potential (V) of a layer's solution at r.
    fn layer_potential(&self, layer: &Layer, r: f64) -> Result<f64> {
        let mr = self.prof.moments(r)?;
        Ok(match (layer.left, layer.right) {
            (End::Free { s, beta, .. }, _) | (_, End::Free { s, beta, .. }) => {
                beta - self.prof.k * self.prof.psi(r, self.prof.moments(s)?, mr)
            }
            (End::Fixed { r: r1, phi: p1 }, End::Fixed { r: r2, phi: p2 }) => {
                let b = self.fixed_slope(r1, p1, r2, p2)?;
                p1 + b * (r / r1).ln() - self.prof.k * self.prof.psi(r, self.prof.moments(r1)?, mr)
            }
        })
    }

    /// The exact-front potential at the nodes: layer solutions inside layers, the bound of the
    /// neighbouring undepleted region elsewhere (the discrete value if there are no layers).
    pub(super) fn exact_potential(&self, layers: &[Layer]) -> Result<Vec<f64>> {
        let r = &self.prof.grid.r;
        if layers.is_empty() {
            return Ok(self.disc.x.clone());
        }
        let end_potential = |e: End| match e {
            End::Fixed { phi, .. } => phi,
            End::Free { beta, .. } => beta,
        };
        let mut out = Vec::with_capacity(r.len());
        let mut j = 0;
        for &ri in r {
            while j < layers.len() && layers[j].right.r() < ri {
                j += 1;
            }
            out.push(if j == layers.len() {
                end_potential(layers[j - 1].right)
            } else if ri < layers[j].left.r() {
                end_potential(layers[j].left)
            } else {
                self.layer_potential(&layers[j], ri)?
            });
        }
        Ok(out)
    }

    /// The layer solutions stay within [l, u] at the nodes inside them (else an island was missed).
    pub(super) fn within_bounds(&self, layers: &[Layer]) -> Result<bool> {
        let tol = 1e-9 * self.vscale;
        for layer in layers {
            let (l, r) = (layer.left.r(), layer.right.r());
            for &ri in self.prof.grid.r.iter().filter(|&&ri| ri > l && ri < r) {
                let p = self.layer_potential(layer, ri)?;
                if p > self.up + tol || p < self.lo - tol {
                    return Ok(false);
                }
            }
        }
        Ok(true)
    }

    /// Free carriers can neutralise only charge of one sign: an undepleted region at u (> l) holds
    /// zeta >= 0 (n-type), one at l holds zeta <= 0. A cell inside a conductor with the other sign
    /// is a depleted layer the grid did not see (thinner than a node spacing).
    pub(super) fn conductors_hold(&self, layers: &[Layer]) -> bool {
        if self.up == self.lo {
            return true;
        }
        let potential = |e: End| match e {
            End::Fixed { phi, .. } => phi,
            End::Free { beta, .. } => beta,
        };
        // (from, to, potential) of every undepleted stretch, contacts included.
        let mut regions = Vec::new();
        let mut from = (self.a, self.bias);
        for l in layers {
            regions.push((from.0, l.left.r(), potential(l.left)));
            from = (l.right.r(), potential(l.right));
        }
        regions.push((from.0, self.b, if layers.is_empty() { 0.0 } else { from.1 }));
        let (r, tol) = (&self.prof.grid.r, 1e-12 * self.prof.zref);
        regions.iter().all(|&(x0, x1, p)| {
            (0..r.len() - 1)
                .filter(|&i| r[i] >= x0 && r[i + 1] <= x1)
                .all(|i| {
                    if p == self.up {
                        self.prof.zmin[i] * CM3_TO_M3 >= -tol
                    } else {
                        self.prof.zmax[i] * CM3_TO_M3 <= tol
                    }
                })
        })
    }
}
