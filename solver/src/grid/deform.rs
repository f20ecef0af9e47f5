//! A grid carried along when the geometry moves: every tick mapped piecewise-linearly from one
//! set of geometry ticks to another, so a node keeps its place relative to the boundaries
//! around it and a small change of a dimension moves the nodes by a small amount instead of
//! adding or removing grid lines (`field::near`: forward differences of c12 in a geometry
//! parameter).

use super::Grid;

impl Grid {
    /// This grid with its ticks mapped from the geometry ticks `from` (r, z; mm; each must be a
    /// tick of this grid) to `to` (the same number of ticks per axis, strictly increasing):
    /// a tick t in [from_k, from_k+1] goes to
    ///
    ///   to_k + (t - from_k) (to_k+1 - to_k) / (from_k+1 - from_k).
    ///
    /// `None` when the tick counts differ (two boundaries merged or split), a `from` tick is not
    /// on the grid, the grid reaches outside [from_0, from_last], or `to` is not strictly
    /// increasing.
    pub fn deformed(&self, from: (&[f64], &[f64]), to: (&[f64], &[f64])) -> Option<Grid> {
        let r = map_axis(self.r_mm(), from.0, to.0)?;
        let z = map_axis(self.z_mm(), from.1, to.1)?;
        Some(Grid::from_ticks(r, z))
    }
}

/// One axis of [`Grid::deformed`].
fn map_axis(t: &[f64], from: &[f64], to: &[f64]) -> Option<Vec<f64>> {
    let close = |a: f64, b: f64| (a - b).abs() <= 1e-9 * (1.0 + a.abs().max(b.abs()));
    if from.len() != to.len()
        || from.len() < 2
        || to
            .windows(2)
            .any(|w| w[1].partial_cmp(&w[0]) != Some(std::cmp::Ordering::Greater))
        || !close(t[0], from[0])
        || !close(t[t.len() - 1], from[from.len() - 1])
    {
        return None;
    }
    let mut out = Vec::with_capacity(t.len());
    let mut k = 0;
    for &x in t {
        while k + 2 < from.len() && x >= from[k + 1] - 1e-9 * (1.0 + x.abs()) {
            k += 1;
        }
        let (a, b) = (from[k], from[k + 1]);
        out.push(if close(x, a) {
            to[k]
        } else if close(x, b) {
            to[k + 1]
        } else {
            to[k] + (x - a) * (to[k + 1] - to[k]) / (b - a)
        });
    }
    // Every geometry tick must be a grid tick (else a boundary would fall between nodes).
    let on_grid = from.iter().all(|&f| t.iter().any(|&x| close(x, f)));
    (on_grid && out.windows(2).all(|w| w[1] > w[0])).then_some(out)
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn ticks_keep_their_place_between_the_boundaries() {
        let g = Grid::new(vec![0.0, 1.0, 2.0, 3.0, 5.0], vec![0.0, 0.5, 1.0]).unwrap();
        // The boundary at r = 2 moves to 2.2; z unchanged.
        let d = g
            .deformed(
                (&[0.0, 2.0, 5.0], &[0.0, 1.0]),
                (&[0.0, 2.2, 5.0], &[0.0, 1.0]),
            )
            .unwrap();
        assert_eq!(d.z_mm(), g.z_mm());
        let want = [0.0, 1.1, 2.2, 2.2 + 2.8 / 3.0, 5.0];
        for (a, b) in d.r_mm().iter().zip(want) {
            assert!((a - b).abs() < 1e-12, "{a} vs {b}");
        }
        // Identity when nothing moves.
        let same = g.deformed(
            (&[0.0, 2.0, 5.0], &[0.0, 1.0]),
            (&[0.0, 2.0, 5.0], &[0.0, 1.0]),
        );
        assert_eq!(same.unwrap(), g);
        // A boundary that is not a tick, or a changed number of boundaries: no deformation.
        assert!(
            g.deformed(
                (&[0.0, 2.5, 5.0], &[0.0, 1.0]),
                (&[0.0, 2.6, 5.0], &[0.0, 1.0])
            )
            .is_none()
        );
        assert!(
            g.deformed((&[0.0, 2.0, 5.0], &[0.0, 1.0]), (&[0.0, 5.0], &[0.0, 1.0]))
                .is_none()
        );
    }
}
