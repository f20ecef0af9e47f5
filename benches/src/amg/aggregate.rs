//! Aggregation of strongly coupled unknowns (Vanek, Mandel & Brezina 1996, the three passes).

use super::Csr;

/// The aggregate of each unknown (None for unknowns without off-diagonal couplings) and the
/// number of aggregates. j is strongly coupled to i when -a_ij >= theta sqrt(a_ii a_jj).
///
/// 1. Every unknown whose strong neighbours are all unaggregated roots a new aggregate of itself
///    and them.
/// 2. Every unknown left joins the aggregate of a strong neighbour from pass 1.
/// 3. What is still left forms aggregates with its unaggregated strong neighbours.
pub(crate) fn aggregate(a: &Csr, diag: &[f64], theta: f64) -> (Vec<Option<usize>>, usize) {
    let n = a.rows;
    let strong: Vec<Vec<usize>> = (0..n)
        .map(|i| {
            (a.ptr[i]..a.ptr[i + 1])
                .filter(|&e| {
                    let j = a.idx[e];
                    j != i && -a.val[e] >= theta * (diag[i] * diag[j]).abs().sqrt()
                })
                .map(|e| a.idx[e])
                .collect()
        })
        .collect();
    let coupled: Vec<bool> = (0..n)
        .map(|i| (a.ptr[i]..a.ptr[i + 1]).any(|e| a.idx[e] != i && a.val[e] != 0.0))
        .collect();
    let mut agg: Vec<Option<usize>> = vec![None; n];
    let mut count = 0;
    for i in 0..n {
        if !coupled[i] || agg[i].is_some() || strong[i].is_empty() {
            continue;
        }
        if strong[i].iter().all(|&j| agg[j].is_none()) {
            agg[i] = Some(count);
            for &j in &strong[i] {
                agg[j] = Some(count);
            }
            count += 1;
        }
    }
    let first = agg.clone();
    for i in 0..n {
        if coupled[i]
            && agg[i].is_none()
            && let Some(g) = strong[i].iter().find_map(|&j| first[j])
        {
            agg[i] = Some(g);
        }
    }
    for i in 0..n {
        if !coupled[i] || agg[i].is_some() {
            continue;
        }
        agg[i] = Some(count);
        for &j in &strong[i] {
            if agg[j].is_none() {
                agg[j] = Some(count);
            }
        }
        count += 1;
    }
    (agg, count)
}
