//! Compressed sparse rows: the few operations an algebraic multigrid hierarchy needs
//! (y = A x, A^T, A B by Gustavson's row-by-row product with a dense accumulator).

/// A sparse matrix in compressed sparse rows.
#[derive(Debug, Clone, PartialEq)]
pub struct Csr {
    /// Rows.
    pub rows: usize,
    /// Columns.
    pub cols: usize,
    /// Row k's entries are `ptr[k]..ptr[k + 1]`.
    pub ptr: Vec<usize>,
    /// Column of each entry.
    pub idx: Vec<usize>,
    /// Value of each entry.
    pub val: Vec<f64>,
}

impl Csr {
    /// A square matrix from a full (both triangles) compressed-column pattern and values: for a
    /// symmetric matrix the columns are the rows.
    pub fn from_symmetric_csc(n: usize, col_ptr: &[usize], row_idx: &[usize], val: &[f64]) -> Self {
        Self {
            rows: n,
            cols: n,
            ptr: col_ptr.to_vec(),
            idx: row_idx.to_vec(),
            val: val.to_vec(),
        }
    }

    /// y = A x.
    pub fn matvec(&self, x: &[f64], y: &mut [f64]) {
        for (r, yr) in y.iter_mut().enumerate().take(self.rows) {
            let mut s = 0.0;
            for e in self.ptr[r]..self.ptr[r + 1] {
                s += self.val[e] * x[self.idx[e]];
            }
            *yr = s;
        }
    }

    /// r = b - A x.
    pub fn residual(&self, b: &[f64], x: &[f64], r: &mut [f64]) {
        for row in 0..self.rows {
            let mut s = b[row];
            for e in self.ptr[row]..self.ptr[row + 1] {
                s -= self.val[e] * x[self.idx[e]];
            }
            r[row] = s;
        }
    }

    /// The diagonal (0 where none is stored).
    pub fn diagonal(&self) -> Vec<f64> {
        (0..self.rows)
            .map(|r| {
                (self.ptr[r]..self.ptr[r + 1])
                    .find(|&e| self.idx[e] == r)
                    .map_or(0.0, |e| self.val[e])
            })
            .collect()
    }

    /// A^T.
    pub fn transpose(&self) -> Self {
        let mut count = vec![0usize; self.cols + 1];
        for &c in &self.idx {
            count[c + 1] += 1;
        }
        for k in 0..self.cols {
            count[k + 1] += count[k];
        }
        let ptr = count.clone();
        let mut next = count;
        let mut idx = vec![0; self.idx.len()];
        let mut val = vec![0.0; self.val.len()];
        for r in 0..self.rows {
            for e in self.ptr[r]..self.ptr[r + 1] {
                let c = self.idx[e];
                idx[next[c]] = r;
                val[next[c]] = self.val[e];
                next[c] += 1;
            }
        }
        Self {
            rows: self.cols,
            cols: self.rows,
            ptr,
            idx,
            val,
        }
    }

    /// A B (Gustavson: each row of the product accumulated in a dense row with a marker).
    pub fn mul(&self, b: &Self) -> Self {
        assert_eq!(self.cols, b.rows, "inner dimensions");
        let mut ptr = Vec::with_capacity(self.rows + 1);
        ptr.push(0);
        let (mut idx, mut val) = (Vec::new(), Vec::new());
        let mut acc = vec![0.0; b.cols];
        let mut mark = vec![usize::MAX; b.cols];
        let mut cols = Vec::new();
        for r in 0..self.rows {
            cols.clear();
            for e in self.ptr[r]..self.ptr[r + 1] {
                let (k, a) = (self.idx[e], self.val[e]);
                for f in b.ptr[k]..b.ptr[k + 1] {
                    let c = b.idx[f];
                    if mark[c] != r {
                        mark[c] = r;
                        acc[c] = 0.0;
                        cols.push(c);
                    }
                    acc[c] += a * b.val[f];
                }
            }
            cols.sort_unstable();
            for &c in &cols {
                idx.push(c);
                val.push(acc[c]);
            }
            ptr.push(idx.len());
        }
        Self {
            rows: self.rows,
            cols: b.cols,
            ptr,
            idx,
            val,
        }
    }

    /// Stored entries.
    pub fn nnz(&self) -> usize {
        self.idx.len()
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    fn dense(m: &Csr) -> Vec<Vec<f64>> {
        let mut d = vec![vec![0.0; m.cols]; m.rows];
        for (r, row) in d.iter_mut().enumerate() {
            for e in m.ptr[r]..m.ptr[r + 1] {
                row[m.idx[e]] += m.val[e];
            }
        }
        d
    }

    #[test]
    fn product_and_transpose_match_dense_algebra() {
        // A 3x4 and B 4x2 with a few entries each.
        let a = Csr {
            rows: 3,
            cols: 4,
            ptr: vec![0, 2, 3, 5],
            idx: vec![0, 3, 1, 0, 2],
            val: vec![1.0, 2.0, -1.0, 4.0, 0.5],
        };
        let b = Csr {
            rows: 4,
            cols: 2,
            ptr: vec![0, 1, 3, 4, 5],
            idx: vec![1, 0, 1, 0, 1],
            val: vec![3.0, 2.0, -2.0, 1.0, 5.0],
        };
        let (da, db) = (dense(&a), dense(&b));
        let c = dense(&a.mul(&b));
        for i in 0..3 {
            for j in 0..2 {
                let want: f64 = (0..4).map(|k| da[i][k] * db[k][j]).sum();
                assert!((c[i][j] - want).abs() < 1e-14);
            }
        }
        let t = dense(&a.transpose());
        for i in 0..3 {
            for j in 0..4 {
                assert_eq!(t[j][i], da[i][j]);
            }
        }
    }
}
