//! Depleted layers and their fronts: the ends of a layer, and the discrete solution seen as layers
//! with the fronts at their grid estimates (the context of the exact front equations).

use super::obstacle::{Obstacle, Status};
use super::profile::Profile;

/// Search window of a front around its grid estimate, in node spacings.
pub(super) const WINDOW_CELLS: f64 = 3.0;

/// One end of a depleted layer.
#[derive(Debug, Clone, Copy, PartialEq)]
pub(super) enum End {
    /// A contact at radius r (m) and potential phi (V).
    Fixed { r: f64, phi: f64 },
    /// A depletion front at s (m) next to an undepleted region at the bound beta (V), searched in
    /// [lo, hi]; `contact`: radius of the contact the undepleted region is attached to, if any.
    Free {
        s: f64,
        beta: f64,
        lo: f64,
        hi: f64,
        contact: Option<f64>,
    },
}

impl End {
    pub(super) fn r(&self) -> f64 {
        match *self {
            End::Fixed { r, .. } => r,
            End::Free { s, .. } => s,
        }
    }

    pub(super) fn with_s(self, x: f64) -> Self {
        match self {
            End::Free {
                beta,
                lo,
                hi,
                contact,
                ..
            } => End::Free {
                s: x,
                beta,
                lo,
                hi,
                contact,
            },
            fixed => fixed,
        }
    }
}

/// A depleted interval [left, right].
#[derive(Debug, Clone, Copy, PartialEq)]
pub(super) struct Layer {
    pub(super) left: End,
    pub(super) right: End,
    pub(super) solved: bool,
}

/// The discrete solution seen as layers, and the exact equations of their fronts.
pub(super) struct Fronts<'p, 'z> {
    pub(super) prof: &'p Profile<'z>,
    pub(super) disc: &'p Obstacle,
    pub(super) bias: f64,
    pub(super) lo: f64,
    pub(super) up: f64,
    pub(super) a: f64,
    pub(super) b: f64,
    /// Volt scale for tolerances: |V| + (q / eps) max|zeta| b^2.
    pub(super) vscale: f64,
}

impl<'p, 'z> Fronts<'p, 'z> {
    pub(super) fn new(prof: &'p Profile<'z>, bias: f64, disc: &'p Obstacle) -> Self {
        let (a, b) = (prof.grid.r[0], prof.grid.r[prof.grid.r.len() - 1]);
        Self {
            prof,
            disc,
            bias,
            lo: bias.min(0.0),
            up: bias.max(0.0),
            a,
            b,
            vscale: bias.abs() + prof.k * prof.zref * b * b,
        }
    }

    fn window(&self, s: f64) -> (f64, f64) {
        let w = WINDOW_CELLS * self.prof.grid.h;
        ((s - w).max(self.a), (s + w).min(self.b))
    }

    /// Conductors (maximal runs of contact or bound nodes at one potential) and the layers between
    /// them, fronts at their grid estimates.
    pub(super) fn initial_layers(&self) -> Vec<Layer> {
        let (st, n) = (&self.disc.status, self.disc.status.len());
        let potential = |i: usize| -> Option<f64> {
            if i == 0 {
                Some(self.bias)
            } else if i == n - 1 {
                Some(0.0)
            } else {
                match st[i] {
                    Status::Upper => Some(self.up),
                    Status::Lower => Some(self.lo),
                    Status::Free => None,
                }
            }
        };
        // (first, last, potential)
        let mut conductors: Vec<(usize, usize, f64)> = Vec::new();
        for i in 0..n {
            if let Some(p) = potential(i) {
                match conductors.last_mut() {
                    Some(c) if c.1 + 1 == i && c.2 == p => c.1 = i,
                    _ => conductors.push((i, i, p)),
                }
            }
        }
        conductors
            .windows(2)
            .map(|w| {
                let (c, d) = (w[0], w[1]);
                let left = if c.1 == 0 {
                    End::Fixed {
                        r: self.a,
                        phi: self.bias,
                    }
                } else {
                    let s = self.estimate_right_of(c.1);
                    let (lo, hi) = self.window(s);
                    End::Free {
                        s,
                        beta: c.2,
                        lo,
                        hi,
                        contact: (c.0 == 0).then_some(self.a),
                    }
                };
                let right = if d.0 == n - 1 {
                    End::Fixed {
                        r: self.b,
                        phi: 0.0,
                    }
                } else {
                    let s = self.estimate_left_of(d.0);
                    let (lo, hi) = self.window(s);
                    End::Free {
                        s,
                        beta: d.2,
                        lo,
                        hi,
                        contact: (d.1 == n - 1).then_some(self.b),
                    }
                };
                Layer {
                    left,
                    right,
                    solved: false,
                }
            })
            .collect()
    }

    /// Front right of the last node k of an undepleted run: the flux g_k (x_k - x_{k+1}) is the charge
    /// of [s, rho_{k+1/2}].
    fn estimate_right_of(&self, k: usize) -> f64 {
        let (g, x, face) = (&self.prof.grid.g, &self.disc.x, &self.prof.grid.face);
        let theta = fraction(g[k] * (x[k] - x[k + 1]), self.prof.f[k]);
        let (r2, l2) = (face[k] * face[k], face[k - 1] * face[k - 1]);
        (r2 - theta * (r2 - l2)).sqrt()
    }

    /// Front left of the first node j of an undepleted run: g_{j-1}(x_j - x_{j-1}) is the charge of
    /// [rho_{j-1/2}, s].
    fn estimate_left_of(&self, j: usize) -> f64 {
        let (g, x, face) = (&self.prof.grid.g, &self.disc.x, &self.prof.grid.face);
        let theta = fraction(g[j - 1] * (x[j] - x[j - 1]), self.prof.f[j]);
        let (r2, l2) = (face[j] * face[j], face[j - 1] * face[j - 1]);
        (l2 + theta * (r2 - l2)).sqrt()
    }
}

/// The charged fraction e / f of a control volume, clamped to [0, 1] (1/2 for an empty one).
fn fraction(e: f64, f: f64) -> f64 {
    if f != 0.0 {
        (e / f).clamp(0.0, 1.0)
    } else {
        0.5
    }
}
