//! Exact fronts with topology repair: each layer's front equations solved, contact layers added
//! or removed and squeezed islands merged until the topology settles.

use super::layers::{End, Fronts, Layer, WINDOW_CELLS};
use crate::error::Result;

/// Passes of the topology repair before giving up on exact fronts.
const MAX_PASSES: usize = 8;

impl<'p, 'z> Fronts<'p, 'z> {
    /// Exact fronts with topology repair; on failure the grid estimates and `false`.
    pub(super) fn refine(&self, grid_layers: &[Layer]) -> Result<(Vec<Layer>, bool)> {
        let mut layers = grid_layers.to_vec();
        let mut exact = true;
        for _ in 0..MAX_PASSES {
            let mut changed = false;
            for layer in layers.iter_mut().filter(|l| !l.solved) {
                if self.solve_layer(layer)? {
                    layer.solved = true;
                } else if self.detach_from_contact(layer) {
                    changed = true;
                } else {
                    layer.solved = true;
                    exact = false;
                }
            }
            for layer in &mut layers {
                changed |= self.attach_to_contact(layer)?;
            }
            if let Some(j) =
                (1..layers.len()).find(|&j| layers[j - 1].right.r() >= layers[j].left.r())
            {
                let right = layers.remove(j).right;
                layers[j - 1].right = right;
                layers[j - 1].solved = false;
                changed = true;
            }
            if !changed {
                let consistent = self.within_bounds(&layers)? && self.conductors_hold(&layers);
                return Ok((layers, exact && consistent));
            }
        }
        Ok((grid_layers.to_vec(), false))
    }

    /// Solve one layer's front equations; false if a root was not found in the windows.
    fn solve_layer(&self, layer: &mut Layer) -> Result<bool> {
        match (layer.left, layer.right) {
            (End::Fixed { .. }, End::Fixed { .. }) => Ok(true),
            (
                End::Free {
                    s, beta, lo, hi, ..
                },
                End::Fixed { r, phi },
            ) => Ok(match self.front_root(beta, r, phi, s, lo, hi)? {
                Some(x) => {
                    layer.left = layer.left.with_s(x);
                    true
                }
                None => false,
            }),
            (
                End::Fixed { r, phi },
                End::Free {
                    s, beta, lo, hi, ..
                },
            ) => Ok(match self.front_root(beta, r, phi, s, lo, hi)? {
                Some(x) => {
                    layer.right = layer.right.with_s(x);
                    true
                }
                None => false,
            }),
            (End::Free { .. }, End::Free { .. }) => {
                Ok(match self.front_pair(layer.left, layer.right)? {
                    Some((x1, x2)) => {
                        layer.left = layer.left.with_s(x1);
                        layer.right = layer.right.with_s(x2);
                        true
                    }
                    None => false,
                })
            }
        }
    }

    /// A front with no root near its estimate whose undepleted region is attached to a contact and
    /// whose window reaches it: the region has vanished, the layer reaches the contact.
    fn detach_from_contact(&self, layer: &mut Layer) -> bool {
        let mut changed = false;
        for end in [&mut layer.left, &mut layer.right] {
            if let End::Free {
                beta,
                lo,
                hi,
                contact: Some(rc),
                ..
            } = *end
                && (lo == rc || hi == rc)
            {
                *end = End::Fixed { r: rc, phi: beta };
                changed = true;
            }
        }
        changed
    }

    /// A contact end whose field would carry the potential past the bound just inside: an undepleted
    /// layer (thinner than the grid saw) sits on the contact; its front is searched next to it.
    fn attach_to_contact(&self, layer: &mut Layer) -> Result<bool> {
        let tol = 1e-10 * self.vscale;
        let mut changed = false;
        for left_end in [true, false] {
            let end = if left_end { layer.left } else { layer.right };
            let End::Fixed { r: rc, phi } = end else {
                continue;
            };
            // r phi'(r_c), V; inward derivative sign: +1 at the left end, -1 at the right end.
            let inward = if left_end { 1.0 } else { -1.0 } * self.field(layer, rc)?;
            let above = phi == self.up && inward > tol;
            let below = phi == self.lo && inward < -tol;
            if above || below {
                let w = WINDOW_CELLS * self.prof.grid.h;
                let (lo, hi, s) = if left_end {
                    (rc, (rc + w).min(layer.right.r()), rc)
                } else {
                    ((rc - w).max(layer.left.r()), rc, rc)
                };
                let free = End::Free {
                    s,
                    beta: phi,
                    lo,
                    hi,
                    contact: Some(rc),
                };
                if left_end {
                    layer.left = free;
                } else {
                    layer.right = free;
                }
                layer.solved = false;
                changed = true;
            }
        }
        Ok(changed)
    }
}
