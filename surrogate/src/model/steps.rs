//! The steps head of the recipe `split-steps`: the C-V curve of one parameter point as a sum of
//! K logistic steps in the log-bias coordinate. c12 then falls monotonically with U_B, as a
//! depleting detector's does, and a pinch-off (c12 dropping by tens of percent within a few volts
//! where an undepleted pocket loses its contact, `reports/surrogate.md`) is one narrow step whose
//! place v_k(p) is a smooth function of the parameters: a network learns that place from far
//! fewer rows than it needs to draw the step itself from a bias input.
//!
//! With o = (o_0, ..., o_3K) the network's outputs from the parameters alone (the trunk and head
//! layers see p only), and t the bias coordinate,
//!
//!   y(p, U) = o_0 + ln(1 + sum_k a_k s_k),   s_k = sigmoid((v_k - t) / w_k),
//!   a_k = softplus(o_{1+k}),   v_k = k/(K-1) + o_{1+K+k} / 2,
//!   w_k = 0.05 softplus(o_{1+2K+k}) + 0.001,
//!   t = ln(U / U_lo) / ln(U_hi / U_lo)   (t = u for a log-uniform bias),
//!
//! y the standardised ln c12 (the output transform of the log recipes). Every a_k >= 0 and every
//! s_k falls with t, so dy/dU <= 0 everywhere.
//!
//! **The pinch-off gate** (`gate`, recipe `split-gate`, issue 59): where an undepleted pocket
//! loses its contact, every step still ahead in t collapses at once (c12 drops to the depleted
//! plateau, `reports/surrogate.md`). Without a gate all the steps' places v_k(p) must move
//! together for that; with it one place does:
//!
//!   y(p, U) = o_0 + ln(1 + g sum_k a_k s_k),   g = gamma + (1 - gamma) sigmoid((v_g - t) / w_g),
//!   v_g = GATE_HOME + o_{1+3K} / 2,   w_g = 0.05 softplus(o_{2+3K}) + 0.001,
//!   gamma = sigmoid(o_{3+3K}),
//!
//! so g S (S = sum_k a_k s_k) is a product of two non-negative non-increasing functions of t
//! and the curve still never rises. The floor gamma keeps a share of the steps ahead after the
//! pinch-off: the pocket still shrinks as the bias grows, and c12 falls by a few percent more
//! (row 301043 of the held-out set: 116.8 pF at 1000 V, 41.3 pF at 1050 V, then 38.6 pF at
//! 1800 V). At initialisation (o = 0) v_g = 1.25 lies beyond the bias range and the gate is
//! open (g >= 0.99 on t <= 1).

use candle_core::Tensor;

use crate::error::{Error, Result};
use crate::space::{Dimension, Distribution, normal_cdf};

/// Scale of a step's width: w_k = WIDTH_SCALE softplus(.) + WIDTH_MIN (in t, the whole bias
/// range being 1).
pub const WIDTH_SCALE: f64 = 0.05;
/// The narrowest step: 0.1% of the log-bias range (about 6 mV at 10 V, 1.7 V at 3000 V for the
/// paper's 10-3000 V).
pub const WIDTH_MIN: f64 = 1e-3;
/// How far a step moves from its home k/(K-1) per unit of its output.
pub const SHIFT_SCALE: f64 = 0.5;
/// The gate's place at initialisation, beyond the bias range (t in [0, 1]): open.
pub const GATE_HOME: f64 = 1.25;
/// Width (in t) added to the gate's own in its proximity feature ([`StepsHead::gate_proximity`]):
/// a surrogate's error near a pinch-off spreads over how far it misplaces the switch, not over
/// the switch's width (0.02 of the log-bias range is 12% in U_B for the paper's 10-3000 V).
pub const PROXIMITY_WIDTH: f64 = 0.02;

/// The map from the network's bias coordinate z_U to the steps' coordinate t.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct BiasMap {
    /// U_lo (V), the bias range's lower end (> 0).
    pub lo_v: f64,
    /// U_hi (V).
    pub hi_v: f64,
    /// The bias is sampled log-uniformly (then t = u).
    pub log_uniform: bool,
}

impl BiasMap {
    /// The map of a space's bias dimension; its range must be positive.
    pub fn of(bias: &Dimension) -> Result<Self> {
        let [lo, hi] = bias.range;
        if !(lo > 0.0 && hi > lo && hi.is_finite()) {
            return Err(Error::Argument {
                name: format!("dimension {}", bias.name),
                message: format!(
                    "the steps head takes ln U_B: its range [{lo}, {hi}] must be positive"
                ),
            });
        }
        Ok(BiasMap {
            lo_v: lo,
            hi_v: hi,
            log_uniform: bias.distribution == Distribution::LogUniform,
        })
    }

    /// t of the unit coordinate u: ln(1 + u (U_hi/U_lo - 1)) / ln(U_hi/U_lo) (uniform bias),
    /// u (log-uniform).
    pub fn t_of_unit(&self, u: f64) -> f64 {
        if self.log_uniform {
            return u;
        }
        let r = self.hi_v / self.lo_v;
        (u * (r - 1.0)).ln_1p() / r.ln()
    }

    /// t of the network coordinate z = Phi^-1(u).
    pub fn t_of_z(&self, z: f64) -> f64 {
        self.t_of_unit(normal_cdf(z))
    }

    /// The same map on a column of z (candle, f32): u = (1 + erf(z / sqrt 2)) / 2.
    pub fn t_tensor(&self, z: &Tensor) -> candle_core::Result<Tensor> {
        let u = (((z / std::f64::consts::SQRT_2)?.erf()? + 1.0)? * 0.5)?;
        if self.log_uniform {
            return Ok(u);
        }
        let r = self.hi_v / self.lo_v;
        ((u * (r - 1.0))? + 1.0)?.log()? / r.ln()
    }
}

/// The steps head: K steps and the bias map.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct StepsHead {
    /// K, the number of steps (>= 2).
    pub count: usize,
    /// z_U -> t.
    pub bias: BiasMap,
    /// With the pinch-off gate (module doc): two more outputs, its place and width.
    pub gate: bool,
}

/// The gate's place, width and floor with the derivatives of the latter two by their outputs.
#[derive(Debug, Clone, Copy)]
struct Gate {
    v: f64,
    w: f64,
    dw: f64,
    floor: f64,
}

impl Gate {
    /// g and sigma_g = sigmoid((v_g - t) / w_g) at t.
    fn at(&self, t: f64) -> (f64, f64) {
        let s = sigmoid((self.v - t) / self.w);
        (self.floor + (1.0 - self.floor) * s, s)
    }
}

/// One step's amplitude, place and width with their derivatives by their own outputs.
#[derive(Debug, Clone, Copy)]
struct Step {
    a: f64,
    v: f64,
    w: f64,
    da: f64,
    dw: f64,
}

fn sigmoid(x: f64) -> f64 {
    1.0 / (1.0 + (-x).exp())
}

/// ln(1 + e^x) without overflow.
fn softplus(x: f64) -> f64 {
    x.max(0.0) + (-x.abs()).exp().ln_1p()
}

impl StepsHead {
    /// The network outputs the head takes: 1 + 3K, and 3 more with the gate.
    pub fn outputs(&self) -> usize {
        1 + 3 * self.count + if self.gate { 3 } else { 0 }
    }

    fn gate_of(&self, o: &[f64]) -> Option<Gate> {
        let i = 1 + 3 * self.count;
        self.gate.then(|| Gate {
            v: GATE_HOME + SHIFT_SCALE * o[i],
            w: WIDTH_SCALE * softplus(o[i + 1]) + WIDTH_MIN,
            dw: WIDTH_SCALE * sigmoid(o[i + 1]),
            floor: sigmoid(o[i + 2]),
        })
    }

    fn home(&self, k: usize) -> f64 {
        k as f64 / (self.count - 1) as f64
    }

    fn steps(&self, o: &[f64]) -> Vec<Step> {
        let n = self.count;
        (0..n)
            .map(|k| Step {
                a: softplus(o[1 + k]),
                v: self.home(k) + SHIFT_SCALE * o[1 + n + k],
                w: WIDTH_SCALE * softplus(o[1 + 2 * n + k]) + WIDTH_MIN,
                da: sigmoid(o[1 + k]),
                dw: WIDTH_SCALE * sigmoid(o[1 + 2 * n + k]),
            })
            .collect()
    }

    /// y at the bias coordinates z_U of a curve, from the outputs o (module formula).
    pub fn curve(&self, o: &[f64], zu: &[f64], y: &mut [f64]) {
        let steps = self.steps(o);
        let gate = self.gate_of(o);
        for (yk, &z) in y.iter_mut().zip(zu) {
            let t = self.bias.t_of_z(z);
            let sum: f64 = steps.iter().map(|s| s.a * sigmoid((s.v - t) / s.w)).sum();
            let g = gate.map_or(1.0, |q| q.at(t).0);
            *yk = o[0] + (g * sum).ln_1p();
        }
    }

    /// y at z_U and dy/do (len [`Self::outputs`]) into `g`:
    /// dy/do_0 = 1; with D = 1 + g S, S = sum_k a_k s_k, s'_k = s_k (1 - s_k) (g = 1 without
    /// the gate), dy/da_k = g s_k / D, dy/dv_k = g a_k s'_k / (w_k D),
    /// dy/dw_k = -g a_k s'_k (v_k - t) / (w_k^2 D); the gate's, with sigma_g' = sigma_g (1 -
    /// sigma_g): dy/dv_g = S (1 - gamma) sigma_g' / (w_g D),
    /// dy/dw_g = -S (1 - gamma) sigma_g' (v_g - t) / (w_g^2 D), dy/dgamma = S (1 - sigma_g) / D.
    pub fn value_gradient(&self, o: &[f64], z: f64, g: &mut [f64]) -> f64 {
        self.gradient_at(&self.steps(o), o, z, g)
    }

    /// [`Self::value_gradient`] along a curve, the steps' amplitudes, places and widths computed
    /// once: `each(k, y_k, dy_k/do)` for every z_U,k.
    pub fn curve_gradient(&self, o: &[f64], zu: &[f64], each: &mut dyn FnMut(usize, f64, &[f64])) {
        let steps = self.steps(o);
        let mut g = vec![0.0; self.outputs()];
        for (k, &z) in zu.iter().enumerate() {
            let y = self.gradient_at(&steps, o, z, &mut g);
            each(k, y, &g);
        }
    }

    fn gradient_at(&self, steps: &[Step], o: &[f64], z: f64, g: &mut [f64]) -> f64 {
        let n = self.count;
        let t = self.bias.t_of_z(z);
        let s: Vec<f64> = steps.iter().map(|st| sigmoid((st.v - t) / st.w)).collect();
        let sum: f64 = steps.iter().zip(&s).map(|(st, &sk)| st.a * sk).sum();
        let gate = self.gate_of(o);
        let (gv, sg) = gate.map_or((1.0, 1.0), |q| q.at(t));
        let d = 1.0 + gv * sum;
        g[0] = 1.0;
        for (k, (st, &sk)) in steps.iter().zip(&s).enumerate() {
            let ds = sk * (1.0 - sk);
            g[1 + k] = gv * sk / d * st.da;
            g[1 + n + k] = gv * st.a * ds / (st.w * d) * SHIFT_SCALE;
            g[1 + 2 * n + k] = -gv * st.a * ds * (st.v - t) / (st.w * st.w * d) * st.dw;
        }
        if let Some(q) = gate {
            let ds = (1.0 - q.floor) * sg * (1.0 - sg);
            g[1 + 3 * n] = sum * ds / (q.w * d) * SHIFT_SCALE;
            g[2 + 3 * n] = -sum * ds * (q.v - t) / (q.w * q.w * d) * q.dw;
            g[3 + 3 * n] = sum * (1.0 - sg) / d * q.floor * (1.0 - q.floor);
        }
        o[0] + (gv * sum).ln_1p()
    }

    /// The pinch-off gate's proximity at z_U, an input of the calibrated error model (issue 59:
    /// sigma_s grows near the switching surface), and de/do into `g` (len [`Self::outputs`]):
    ///
    ///   e = 4 (1 - gamma) q (1 - q),   q = sigmoid((v_g - t) / (w_g + PROXIMITY_WIDTH)),
    ///
    /// in [0, 1], 1 - gamma where the gate switches and 0 far from it or with a gate that does
    /// nothing (gamma = 1). With b = 4 q (1 - q) and omega = w_g + PROXIMITY_WIDTH:
    /// de/dv_g = (1 - gamma) b (1 - 2q) / omega, de/dw_g = -(1 - gamma) b (1 - 2q) (v_g - t) /
    /// omega^2, de/dgamma = -b. `None` without a gate.
    pub fn gate_proximity(&self, o: &[f64], z: f64, g: &mut [f64]) -> Option<f64> {
        let q = self.gate_of(o)?;
        let n = self.count;
        let t = self.bias.t_of_z(z);
        let omega = q.w + PROXIMITY_WIDTH;
        let x = sigmoid((q.v - t) / omega);
        let b = 4.0 * x * (1.0 - x);
        let keep = 1.0 - q.floor;
        g.fill(0.0);
        g[1 + 3 * n] = keep * b * (1.0 - 2.0 * x) / omega * SHIFT_SCALE;
        g[2 + 3 * n] = -keep * b * (1.0 - 2.0 * x) * (q.v - t) / (omega * omega) * q.dw;
        g[3 + 3 * n] = -b * q.floor * (1.0 - q.floor);
        Some(keep * b)
    }

    /// The head on candle outputs `o` (n x (1 + 3K), f32) and the bias column z (n x 1): y (n).
    pub fn forward(&self, o: &Tensor, z: &Tensor) -> candle_core::Result<Tensor> {
        let n = self.count;
        let softplus = |x: Tensor| -> candle_core::Result<Tensor> {
            x.relu()? + (x.abs()?.neg()?.exp()? + 1.0)?.log()?
        };
        let t = self.bias.t_tensor(z)?;
        let homes: Vec<f32> = (0..n).map(|k| self.home(k) as f32).collect();
        let homes = Tensor::from_vec(homes, (1, n), o.device())?;
        let a = softplus(o.narrow(1, 1, n)?)?;
        let v = (o.narrow(1, 1 + n, n)? * SHIFT_SCALE)?.broadcast_add(&homes)?;
        let w = ((softplus(o.narrow(1, 1 + 2 * n, n)?)? * WIDTH_SCALE)? + WIDTH_MIN)?;
        let s = candle_nn::ops::sigmoid(&(v.broadcast_sub(&t)? / w)?)?;
        let mut sum = (a * s)?.sum_keepdim(1)?;
        if self.gate {
            let vg = ((o.narrow(1, 1 + 3 * n, 1)? * SHIFT_SCALE)? + GATE_HOME)?;
            let wg = ((softplus(o.narrow(1, 2 + 3 * n, 1)?)? * WIDTH_SCALE)? + WIDTH_MIN)?;
            let floor = candle_nn::ops::sigmoid(&o.narrow(1, 3 + 3 * n, 1)?)?;
            let sg = candle_nn::ops::sigmoid(&((vg - &t)? / wg)?)?;
            let g = ((floor.ones_like()? - &floor)? * sg)?.add(&floor)?;
            sum = (sum * g)?;
        }
        (o.narrow(1, 0, 1)? + (sum + 1.0)?.log()?)?.squeeze(1)
    }
}

#[cfg(test)]
mod tests {
    use proptest::prelude::*;

    use super::*;
    use crate::model::unit_to_z;

    const K: usize = 5;

    fn head_with(gate: bool) -> StepsHead {
        StepsHead {
            count: K,
            bias: BiasMap {
                lo_v: 10.0,
                hi_v: 3000.0,
                log_uniform: false,
            },
            gate,
        }
    }

    fn head() -> StepsHead {
        head_with(false)
    }

    /// At initialisation (o = 0) the gate is open over the whole bias range, and a closed gate
    /// (its place below t) leaves the plateau o_0 whatever the steps.
    #[test]
    fn the_gate_opens_at_initialisation_and_closes_to_the_plateau() {
        let h = head_with(true);
        let zu: Vec<f64> = (1..100).map(|k| unit_to_z(k as f64 / 100.0)).collect();
        let (mut open, mut plain) = (vec![0.0; zu.len()], vec![0.0; zu.len()]);
        let o = vec![0.0; h.outputs()];
        h.curve(&o, &zu, &mut open);
        head().curve(&o[..head().outputs()], &zu, &mut plain);
        for (a, b) in open.iter().zip(&plain) {
            assert!((a - b).abs() < 0.01 * b.abs().max(1.0), "{a} vs {b}");
        }
        let mut closed = vec![1.0; h.outputs()];
        closed[0] = -0.3;
        closed[1 + 3 * K] = -4.0; // v_g = 1.25 - 2 < 0
        closed[3 + 3 * K] = -30.0; // gamma = 1e-13
        let mut y = vec![0.0; zu.len()];
        h.curve(&closed, &zu, &mut y);
        for v in y {
            assert!((v + 0.3).abs() < 1e-3, "{v}");
        }
    }

    proptest! {
        /// The gate's proximity lies in [0, 1], its de/do is the derivative, and a head without
        /// a gate has none.
        #[test]
        fn the_gate_proximity_is_bounded_and_its_gradient_the_derivative(
            o in proptest::collection::vec(-3.0f64..3.0, 4 + 3 * K),
            u in 0.01f64..0.99,
        ) {
            let h = head_with(true);
            let z = unit_to_z(u);
            let mut g = vec![0.0; h.outputs()];
            let e = h.gate_proximity(&o, z, &mut g).unwrap();
            prop_assert!((0.0..=1.0).contains(&e));
            prop_assert!(head().gate_proximity(&o[..head().outputs()], z, &mut g.clone()).is_none());
            for i in 0..o.len() {
                let d = 1e-6;
                let (mut a, mut b) = (o.clone(), o.clone());
                a[i] += d;
                b[i] -= d;
                let mut scratch = vec![0.0; h.outputs()];
                let fd = (h.gate_proximity(&a, z, &mut scratch).unwrap()
                    - h.gate_proximity(&b, z, &mut scratch).unwrap())
                    / (2.0 * d);
                prop_assert!((fd - g[i]).abs() < 1e-6 * (1.0 + fd.abs()), "output {}: {} vs {}", i, fd, g[i]);
            }
        }

        /// Any outputs give a curve that never rises with U_B.
        #[test]
        fn the_curve_never_rises(
            o in proptest::collection::vec(-6.0f64..6.0, 4 + 3 * K),
            gate in proptest::bool::ANY,
        ) {
            let zu: Vec<f64> = (1..300).map(|k| unit_to_z(k as f64 / 300.0)).collect();
            let mut y = vec![0.0; zu.len()];
            head_with(gate).curve(&o, &zu, &mut y);
            for k in 1..y.len() {
                prop_assert!(y[k] <= y[k - 1], "k {}: {} > {}", k, y[k], y[k - 1]);
            }
        }

        /// dy/do of `value_gradient` against central differences, and its y against `curve`'s.
        #[test]
        fn the_gradient_is_the_derivative(
            o in proptest::collection::vec(-3.0f64..3.0, 4 + 3 * K),
            u in 0.01f64..0.99,
            gate in proptest::bool::ANY,
        ) {
            let h = head_with(gate);
            let o = o[..h.outputs()].to_vec();
            let z = unit_to_z(u);
            let mut g = vec![0.0; h.outputs()];
            let y = h.value_gradient(&o, z, &mut g);
            let mut yc = [0.0];
            h.curve(&o, &[z], &mut yc);
            prop_assert_eq!(y, yc[0]);
            for i in 0..o.len() {
                let d = 1e-6;
                let (mut a, mut b) = (o.clone(), o.clone());
                a[i] += d;
                b[i] -= d;
                let fd = (h.value_gradient(&a, z, &mut vec![0.0; h.outputs()])
                    - h.value_gradient(&b, z, &mut vec![0.0; h.outputs()]))
                    / (2.0 * d);
                prop_assert!((fd - g[i]).abs() < 1e-6 * (1.0 + fd.abs()), "output {}: {} vs {}", i, fd, g[i]);
            }
        }
    }
}
