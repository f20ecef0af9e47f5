//! One axis of the tensor grid: required ticks, merged, subdivided and ratio-limited.

/// Spacing rules of one axis (all mm).
#[derive(Debug, Clone, Copy)]
pub(crate) struct AxisRule {
    /// Range where the fine spacing applies (the semiconductor's extent).
    pub fine_range: (f64, f64),
    /// Largest spacing inside `fine_range`.
    pub fine: f64,
    /// Largest spacing elsewhere.
    pub coarse: f64,
    /// Smallest tick distance.
    pub min_tick: f64,
    /// Largest neighbouring spacing ratio.
    pub max_ratio: f64,
}

/// Builds the ticks of one axis (mm).
///
/// 1. `required` ticks (geometry edges, world ends) are sorted; ticks closer than `min_tick` to
///    the previous kept one are dropped (the ends are always kept);
/// 2. every interval is split uniformly so that its spacing is at most `fine` where it overlaps
///    `fine_range` and at most `coarse` elsewhere;
/// 3. while two neighbouring spacings differ by more than `max_ratio`, the larger is halved
///    (never below `min_tick`).
pub(crate) fn build_axis(required: &[f64], lo: f64, hi: f64, rule: &AxisRule) -> Vec<f64> {
    let AxisRule {
        fine_range,
        fine,
        coarse,
        min_tick,
        max_ratio,
    } = *rule;
    let mut t: Vec<f64> = required
        .iter()
        .copied()
        .filter(|v| v.is_finite() && *v > lo && *v < hi)
        .collect();
    t.push(lo);
    t.push(hi);
    t.sort_by(f64::total_cmp);
    let mut kept: Vec<f64> = Vec::with_capacity(t.len());
    for v in t {
        match kept.last() {
            Some(&last) if v - last < min_tick => {
                // Keep the world's upper end exactly.
                if v == hi {
                    kept.pop();
                    kept.push(hi);
                }
            }
            _ => kept.push(v),
        }
    }
    if kept.len() < 2 {
        return vec![lo, hi];
    }
    let mut out = vec![kept[0]];
    for w in kept.windows(2) {
        let (a, b) = (w[0], w[1]);
        let overlaps_fine = b > fine_range.0 && a < fine_range.1;
        let h = if overlaps_fine { fine } else { coarse };
        let n = ((b - a) / h).ceil().max(1.0) as usize;
        for k in 1..n {
            out.push(a + (b - a) * k as f64 / n as f64);
        }
        out.push(b);
    }
    limit_ratio(&mut out, min_tick, max_ratio);
    out
}

/// Halves intervals until neighbouring spacings differ by at most `max_ratio`.
pub(crate) fn limit_ratio(t: &mut Vec<f64>, min_tick: f64, max_ratio: f64) {
    loop {
        let mut split = Vec::new();
        for k in 0..t.len().saturating_sub(2) {
            let h0 = t[k + 1] - t[k];
            let h1 = t[k + 2] - t[k + 1];
            if h0 > max_ratio * h1 && h0 / 2.0 >= min_tick {
                split.push(k);
            } else if h1 > max_ratio * h0 && h1 / 2.0 >= min_tick {
                split.push(k + 1);
            }
        }
        if split.is_empty() {
            return;
        }
        split.sort_unstable();
        split.dedup();
        let mut out = Vec::with_capacity(t.len() + split.len());
        let mut s = split.iter().peekable();
        for k in 0..t.len() {
            out.push(t[k]);
            if s.peek() == Some(&&k) {
                s.next();
                out.push(0.5 * (t[k] + t[k + 1]));
            }
        }
        *t = out;
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    fn rule(fine_range: (f64, f64), fine: f64, coarse: f64) -> AxisRule {
        AxisRule {
            fine_range,
            fine,
            coarse,
            min_tick: 0.01,
            max_ratio: 3.0,
        }
    }

    #[test]
    fn keeps_required_ticks_and_limits_spacing() {
        let t = build_axis(&[5.0, 6.0, 37.5], 0.0, 55.0, &rule((0.0, 37.5), 0.5, 4.0));
        for v in [0.0, 5.0, 6.0, 37.5, 55.0] {
            assert!(t.contains(&v), "{v} missing");
        }
        for w in t.windows(2) {
            let h = w[1] - w[0];
            assert!(h > 0.0);
            if w[1] <= 37.5 {
                assert!(h <= 0.5 + 1e-12);
            }
            assert!(h <= 4.0 + 1e-12);
        }
        for w in t.windows(3) {
            let (h0, h1) = (w[1] - w[0], w[2] - w[1]);
            assert!(h0 <= 3.0 * h1 + 1e-12 && h1 <= 3.0 * h0 + 1e-12);
        }
    }

    #[test]
    fn merges_close_ticks() {
        let t = build_axis(&[1.0, 1.005, 2.0], 0.0, 3.0, &rule((0.0, 3.0), 1.0, 1.0));
        assert!(t.contains(&1.0) && !t.contains(&1.005));
        let t = build_axis(&[2.995], 0.0, 3.0, &rule((0.0, 3.0), 1.0, 1.0));
        assert_eq!(*t.last().unwrap(), 3.0);
        assert!(!t.contains(&2.995));
    }

    #[test]
    fn ratio_limit_terminates_at_min_tick() {
        let mut t = vec![0.0, 0.01, 10.0];
        limit_ratio(&mut t, 0.01, 3.0);
        for w in t.windows(3) {
            let (h0, h1) = (w[1] - w[0], w[2] - w[1]);
            assert!(h1 <= 3.0 * h0 + 1e-12, "{t:?}");
        }
    }
}
