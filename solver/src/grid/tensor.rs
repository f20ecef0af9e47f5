//! The tensor grid: ticks in r and z (mm), node index n = j * nr + i.

use super::GridSettings;
use super::axis::limit_ratio;
use crate::error::{Error, Result};

/// A non-uniform tensor grid over the world; node (i, j) sits at (r\[i\], z\[j\]) in mm.
///
/// A detector's initial grid is [`Grid::initial`] (in `detector/initial_grid.rs`: it reads the
/// detector, which this module does not know).
#[derive(Debug, Clone, PartialEq)]
pub struct Grid {
    r_mm: Vec<f64>,
    z_mm: Vec<f64>,
}

impl Grid {
    /// A grid from explicit ticks (each strictly increasing, at least two).
    pub fn new(r_mm: Vec<f64>, z_mm: Vec<f64>) -> Result<Self> {
        for (name, t) in [("r", &r_mm), ("z", &z_mm)] {
            if t.len() < 2 {
                return Err(Error::invalid_value(
                    "grid ticks",
                    format!("the {name} axis needs at least two ticks"),
                ));
            }
            if t.windows(2)
                .any(|w| w[1] <= w[0] || w[1].is_nan() || !w[0].is_finite() || !w[1].is_finite())
            {
                return Err(Error::invalid_value(
                    "grid ticks",
                    format!("the {name} ticks must be finite and strictly increasing"),
                ));
            }
        }
        Ok(Self { r_mm, z_mm })
    }

    /// A grid from ticks built by the axis rules (strictly increasing by construction).
    pub(crate) fn from_ticks(r_mm: Vec<f64>, z_mm: Vec<f64>) -> Self {
        Self { r_mm, z_mm }
    }

    /// r ticks in mm.
    pub fn r_mm(&self) -> &[f64] {
        &self.r_mm
    }

    /// z ticks in mm.
    pub fn z_mm(&self) -> &[f64] {
        &self.z_mm
    }

    /// Number of r ticks.
    pub fn nr(&self) -> usize {
        self.r_mm.len()
    }

    /// Number of z ticks.
    pub fn nz(&self) -> usize {
        self.z_mm.len()
    }

    /// Number of nodes.
    pub fn len(&self) -> usize {
        self.nr() * self.nz()
    }

    /// Always false (a grid has at least 2 x 2 nodes).
    pub fn is_empty(&self) -> bool {
        false
    }

    /// Node index of (i, j).
    pub fn index(&self, i: usize, j: usize) -> usize {
        j * self.nr() + i
    }

    /// Halves every interval across which `field` (one value per node) changes by more than
    /// `limit`, never below `min_tick_mm`, then restores the spacing-ratio limit. Returns
    /// `None` when nothing needed refining.
    pub fn refined(&self, field: &[f64], limit: f64, s: &GridSettings) -> Option<Grid> {
        let (nr, nz) = (self.nr(), self.nz());
        let mut split_r = vec![false; nr - 1];
        let mut split_z = vec![false; nz - 1];
        for j in 0..nz {
            for i in 0..nr {
                let v = field[self.index(i, j)];
                if i + 1 < nr && (field[self.index(i + 1, j)] - v).abs() > limit {
                    split_r[i] = true;
                }
                if j + 1 < nz && (field[self.index(i, j + 1)] - v).abs() > limit {
                    split_z[j] = true;
                }
            }
        }
        self.halved(&split_r, &split_z, s)
    }

    /// Divides every r interval for which `split_r[i]` and every z interval for which
    /// `split_z[j]` holds into equal parts no wider than `max_width_mm`, then restores the
    /// ratio limit.
    /// `None` when nothing was split.
    pub fn split(
        &self,
        split_r: &[bool],
        split_z: &[bool],
        max_width_mm: f64,
        s: &GridSettings,
    ) -> Option<Grid> {
        let width = max_width_mm.max(s.min_tick_distance_mm);
        self.with_ticks_added(split_r, split_z, s, |a, b, out| {
            let h = b - a;
            if h > width * (1.0 + 1e-9) {
                // Straight to the target width: one pass instead of repeated halving.
                let parts = (h / width - 1e-9).ceil() as usize;
                for p in 1..parts {
                    out.push(a + h * p as f64 / parts as f64);
                }
                true
            } else {
                false
            }
        })
    }

    /// The grid with the ticks `insert(a, b, out)` adds (after `a`, before `b`) in every r
    /// interval [a, b] with `split_r[i]` and z interval with `split_z[j]`; `insert` says whether
    /// it added any. The ratio limit is restored on an axis that gained ticks. `None` when no
    /// interval gained any.
    fn with_ticks_added(
        &self,
        split_r: &[bool],
        split_z: &[bool],
        s: &GridSettings,
        insert: impl Fn(f64, f64, &mut Vec<f64>) -> bool,
    ) -> Option<Grid> {
        let go = |t: &[f64], split: &[bool]| -> (Vec<f64>, bool) {
            let mut out = Vec::with_capacity(t.len() * 2);
            let mut any = false;
            for k in 0..t.len() - 1 {
                out.push(t[k]);
                if split[k] && insert(t[k], t[k + 1], &mut out) {
                    any = true;
                }
            }
            out.push(t[t.len() - 1]);
            if any {
                limit_ratio(&mut out, s.min_tick_distance_mm, s.max_distance_ratio);
            }
            (out, any)
        };
        let (r, ar) = go(&self.r_mm, split_r);
        let (z, az) = go(&self.z_mm, split_z);
        (ar || az).then_some(Grid { r_mm: r, z_mm: z })
    }

    /// The grid with every other tick removed between ticks that must stay (`keep_r_mm`,
    /// `keep_z_mm`: geometry edges; the axis ends always stay): in each run of removable ticks
    /// between two kept ones, the 1st, 3rd, ... go for an even `phase`, the 2nd, 4th, ... for an
    /// odd one (the two phases together leave out every removable tick once). Spacings roughly
    /// double; geometry is represented exactly as before. `None` when nothing can be removed.
    pub fn coarsened_phase(
        &self,
        keep_r_mm: &[f64],
        keep_z_mm: &[f64],
        phase: usize,
    ) -> Option<Grid> {
        let thin = |t: &[f64], keep: &[f64]| -> (Vec<f64>, bool) {
            let must = |x: f64| keep.iter().any(|k| (k - x).abs() <= 1e-9 * (1.0 + x.abs()));
            let mut out = Vec::with_capacity(t.len());
            let mut run = 0usize;
            for (k, &x) in t.iter().enumerate() {
                if k == 0 || k + 1 == t.len() || must(x) {
                    out.push(x);
                    run = 0;
                } else {
                    run += 1;
                    if (run + phase).is_multiple_of(2) {
                        out.push(x);
                    }
                }
            }
            let any = out.len() < t.len();
            (out, any)
        };
        let (r, ar) = thin(&self.r_mm, keep_r_mm);
        let (z, az) = thin(&self.z_mm, keep_z_mm);
        (ar || az).then_some(Grid { r_mm: r, z_mm: z })
    }

    /// Halves every r interval with `split_r[i]` and z interval with `split_z[j]` (never below
    /// `min_tick_distance_mm`), then restores the ratio limit. `None` when nothing was split.
    pub fn halved(&self, split_r: &[bool], split_z: &[bool], s: &GridSettings) -> Option<Grid> {
        self.with_ticks_added(split_r, split_z, s, |a, b, out| {
            if (b - a) / 2.0 >= s.min_tick_distance_mm {
                out.push(0.5 * (a + b));
                true
            } else {
                false
            }
        })
    }

    /// Every interval divided into `parts` equal ones (spacings / `parts`, nodes ~ `parts`^2 x):
    /// the reference grids of convergence checks.
    pub fn subdivided(&self, parts: usize) -> Grid {
        let go = |t: &[f64]| -> Vec<f64> {
            let mut out = Vec::with_capacity((t.len() - 1) * parts.max(1) + 1);
            for w in t.windows(2) {
                for p in 0..parts.max(1) {
                    out.push(w[0] + (w[1] - w[0]) * p as f64 / parts.max(1) as f64);
                }
            }
            out.push(t[t.len() - 1]);
            out
        };
        Grid {
            r_mm: go(&self.r_mm),
            z_mm: go(&self.z_mm),
        }
    }

    /// Bilinear interpolation of a node field of `self` onto the nodes of `finer` (whose
    /// extent must equal this grid's).
    pub fn interpolate_to(&self, field: &[f64], finer: &Grid) -> Vec<f64> {
        let rl: Vec<(usize, f64)> = finer.r_mm.iter().map(|&r| locate(&self.r_mm, r)).collect();
        let zl: Vec<(usize, f64)> = finer.z_mm.iter().map(|&z| locate(&self.z_mm, z)).collect();
        let mut out = Vec::with_capacity(finer.len());
        for &jz in &zl {
            for &ir in &rl {
                out.push(self.bilinear(field, ir, jz));
            }
        }
        out
    }

    /// Bilinear interpolation of a node field at (r, z) in mm (clamped to the grid).
    pub fn interpolate_at(&self, field: &[f64], r_mm: f64, z_mm: f64) -> f64 {
        self.bilinear(field, locate(&self.r_mm, r_mm), locate(&self.z_mm, z_mm))
    }

    /// The indices of the four corner nodes of the cell holding (r, z) in mm (clamped to the
    /// grid), in the order (i, j), (i + 1, j), (i, j + 1), (i + 1, j + 1).
    pub fn cell_nodes(&self, r_mm: f64, z_mm: f64) -> [usize; 4] {
        let (i, _) = locate(&self.r_mm, r_mm);
        let (j, _) = locate(&self.z_mm, z_mm);
        [
            self.index(i, j),
            self.index(i + 1, j),
            self.index(i, j + 1),
            self.index(i + 1, j + 1),
        ]
    }

    /// Index of the node nearest to (r, z) in mm within its cell.
    pub fn nearest(&self, r_mm: f64, z_mm: f64) -> usize {
        let (i, fr) = locate(&self.r_mm, r_mm);
        let (j, fz) = locate(&self.z_mm, z_mm);
        self.index(i + usize::from(fr >= 0.5), j + usize::from(fz >= 0.5))
    }

    fn bilinear(&self, field: &[f64], (i, fr): (usize, f64), (j, fz): (usize, f64)) -> f64 {
        let v00 = field[self.index(i, j)];
        let v10 = field[self.index(i + 1, j)];
        let v01 = field[self.index(i, j + 1)];
        let v11 = field[self.index(i + 1, j + 1)];
        (1.0 - fz) * ((1.0 - fr) * v00 + fr * v10) + fz * ((1.0 - fr) * v01 + fr * v11)
    }
}

/// The interval k with t[k] <= x <= t[k+1] (clamped) and the fraction of x within it.
fn locate(t: &[f64], x: f64) -> (usize, f64) {
    let k = match t.binary_search_by(|v| v.total_cmp(&x)) {
        Ok(k) => k.min(t.len() - 2),
        Err(k) => k.clamp(1, t.len() - 1) - 1,
    };
    (k, ((x - t[k]) / (t[k + 1] - t[k])).clamp(0.0, 1.0))
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn cell_nodes_are_the_corners_of_the_cell_holding_the_point() {
        let g = Grid::new(vec![0.0, 1.0, 2.0], vec![0.0, 1.0, 3.0]).unwrap();
        assert_eq!(
            g.cell_nodes(1.5, 2.0),
            [g.index(1, 1), g.index(2, 1), g.index(1, 2), g.index(2, 2)]
        );
        // Outside: the nearest cell.
        assert_eq!(
            g.cell_nodes(-1.0, 9.0),
            [g.index(0, 1), g.index(1, 1), g.index(0, 2), g.index(1, 2)]
        );
    }

    #[test]
    fn refine_and_interpolate() {
        let g = Grid::new(vec![0.0, 1.0, 2.0], vec![0.0, 1.0]).unwrap();
        // A step between r = 1 and r = 2.
        let f = vec![0.0, 0.0, 1.0, 0.0, 0.0, 1.0];
        let s = GridSettings::default();
        let h = g.refined(&f, 0.5, &s).unwrap();
        assert_eq!(h.r_mm(), &[0.0, 1.0, 1.5, 2.0]);
        assert_eq!(h.z_mm(), &[0.0, 1.0]);
        assert!(g.refined(&f, 2.0, &s).is_none());
        let fi = g.interpolate_to(&f, &h);
        assert_eq!(fi, vec![0.0, 0.0, 0.5, 1.0, 0.0, 0.0, 0.5, 1.0]);
        assert!(Grid::new(vec![0.0], vec![0.0, 1.0]).is_err());
        // Coarsening keeps the ends and the required ticks, drops every other one between.
        let g = Grid::new(vec![0.0, 1.0, 2.0, 3.0, 4.0, 5.0, 6.0], vec![0.0, 1.0]).unwrap();
        let c = g.coarsened_phase(&[3.0], &[], 0).unwrap();
        assert_eq!(c.r_mm(), &[0.0, 2.0, 3.0, 5.0, 6.0]);
        assert_eq!(c.z_mm(), &[0.0, 1.0]);
        let c = g.coarsened_phase(&[3.0], &[], 1).unwrap();
        assert_eq!(c.r_mm(), &[0.0, 1.0, 3.0, 4.0, 6.0]);
        assert!(
            Grid::new(vec![0.0, 1.0], vec![0.0, 1.0])
                .unwrap()
                .coarsened_phase(&[], &[], 0)
                .is_none()
        );
        assert!(Grid::new(vec![0.0, 0.0], vec![0.0, 1.0]).is_err());
    }
}
