//! The trained network as plain f64 arrays: the prediction path of inference. A whole curve costs
//! one pass of the trunk (parameters only) and one small head pass per voltage; the Jacobian of
//! the curve with respect to the parameters is exact (reverse mode through the head, forward mode
//! through the trunk).

use super::gelu::{gelu_and_derivative, gelu_in_place};
use super::steps::StepsHead;

/// A dense layer y = W x + b, W stored transposed (`wt[j * n_out + i]` = W_ij) so that the
/// product runs as vectorisable column updates.
#[derive(Debug, Clone, PartialEq)]
pub struct Dense {
    /// Inputs.
    pub n_in: usize,
    /// Outputs.
    pub n_out: usize,
    /// W^T, n_in x n_out row-major.
    pub wt: Vec<f64>,
    /// b, n_out.
    pub b: Vec<f64>,
}

impl Dense {
    /// From W (n_out x n_in, row-major, as candle and safetensors store it) and b.
    pub fn from_row_major(n_out: usize, n_in: usize, w: &[f64], b: &[f64]) -> Self {
        let mut wt = vec![0.0; n_in * n_out];
        for i in 0..n_out {
            for j in 0..n_in {
                wt[j * n_out + i] = w[i * n_in + j];
            }
        }
        Dense {
            n_in,
            n_out,
            wt,
            b: b.to_vec(),
        }
    }

    /// W (n_out x n_in, row-major).
    pub fn row_major(&self) -> Vec<f64> {
        let mut w = vec![0.0; self.n_in * self.n_out];
        for i in 0..self.n_out {
            for j in 0..self.n_in {
                w[i * self.n_in + j] = self.wt[j * self.n_out + i];
            }
        }
        w
    }

    /// y = W x + b over the first `x.len()` inputs (the rest, if any, are added by the caller).
    #[inline(always)]
    fn apply(&self, x: &[f64], y: &mut [f64]) {
        y.copy_from_slice(&self.b);
        for (j, &xj) in x.iter().enumerate() {
            let col = &self.wt[j * self.n_out..(j + 1) * self.n_out];
            for (yi, &w) in y.iter_mut().zip(col) {
                *yi += w * xj;
            }
        }
    }

    /// dx_j = sum_i W_ij dy_i for j < dx.len().
    #[inline(always)]
    fn back(&self, dy: &[f64], dx: &mut [f64]) {
        for (j, d) in dx.iter_mut().enumerate() {
            *d = dot(&self.wt[j * self.n_out..(j + 1) * self.n_out], dy);
        }
    }

    /// Y = X W^T + b for rows of X (row-major, n_in wide) into rows of Y (n_out wide): a
    /// register-blocked kernel over 4 rows x 8 outputs (32 accumulators that stay in registers;
    /// each loaded weight serves 4 rows), the plain loop for the remainders.
    #[inline(always)]
    fn apply_rows(&self, x: &[f64], y: &mut [f64]) {
        const R: usize = 4;
        const T: usize = 8;
        let (n_in, n_out) = (self.n_in, self.n_out);
        let tiles = n_out / T;
        let mut xs = x.chunks_exact(R * n_in);
        let mut ys = y.chunks_exact_mut(R * n_out);
        for (xb, yb) in (&mut xs).zip(&mut ys) {
            for t in 0..tiles {
                let i0 = t * T;
                let mut acc = [[0.0; T]; R];
                for row in acc.iter_mut() {
                    row.copy_from_slice(&self.b[i0..i0 + T]);
                }
                for j in 0..n_in {
                    let w: &[f64; T] = self.wt[j * n_out + i0..j * n_out + i0 + T]
                        .try_into()
                        .expect("tile of T weights");
                    for (r, row) in acc.iter_mut().enumerate() {
                        let a = xb[r * n_in + j];
                        for (o, &wi) in row.iter_mut().zip(w) {
                            *o += wi * a;
                        }
                    }
                }
                for (r, row) in acc.iter().enumerate() {
                    yb[r * n_out + i0..r * n_out + i0 + T].copy_from_slice(row);
                }
            }
            if tiles * T < n_out {
                for r in 0..R {
                    let xr = &xb[r * n_in..(r + 1) * n_in];
                    let yr = &mut yb[r * n_out..(r + 1) * n_out];
                    for (i, yi) in yr.iter_mut().enumerate().skip(tiles * T) {
                        *yi = (0..n_in).fold(self.b[i], |s, j| s + self.wt[j * n_out + i] * xr[j]);
                    }
                }
            }
        }
        for (xr, yr) in xs
            .remainder()
            .chunks_exact(n_in)
            .zip(ys.into_remainder().chunks_exact_mut(n_out))
        {
            self.apply(xr, yr);
        }
    }
}

/// sum_i a_i b_i with four partial sums (vectorisable; the order of additions is fixed).
#[inline(always)]
fn dot(a: &[f64], b: &[f64]) -> f64 {
    let mut acc = [0.0; 4];
    let (ca, cb) = (a.chunks_exact(4), b.chunks_exact(4));
    let (ra, rb) = (ca.remainder(), cb.remainder());
    for (x, y) in ca.zip(cb) {
        for k in 0..4 {
            acc[k] += x[k] * y[k];
        }
    }
    let tail: f64 = ra.iter().zip(rb).map(|(x, y)| x * y).sum();
    (acc[0] + acc[1]) + (acc[2] + acc[3]) + tail
}

/// The network of [`super::Architecture`]: trunk on p, head on [h, z_U], a linear output; or,
/// with a steps head, trunk and head on p, a linear output of 1 + 3K values and the steps'
/// closed form in U ([`StepsHead`]).
#[derive(Debug, Clone, PartialEq)]
pub struct Network {
    /// Number of model parameters (inputs without the bias).
    pub n_params: usize,
    /// Layers on p.
    pub trunk: Vec<Dense>,
    /// Layers after the bias joins (the first takes [h, z_U]); with `steps`, further layers on p.
    pub head: Vec<Dense>,
    /// The output layer (n_out = 1, or 1 + 3K with `steps`).
    pub out: Dense,
    /// The steps head, when the architecture has one.
    pub steps: Option<StepsHead>,
}

/// Buffers of one curve evaluation (no allocation per voltage).
#[derive(Debug, Default)]
struct Buffers {
    h: Vec<f64>,
    tmp: Vec<f64>,
    base: Vec<f64>,
}

impl Network {
    fn trunk_width(&self) -> usize {
        self.trunk.last().map_or(self.n_params, |l| l.n_out)
    }

    /// h(p) and, when `jac` is given, dh/dz_p (trunk width x n_params, row-major).
    #[inline(always)]
    fn trunk_pass(&self, zp: &[f64], buf: &mut Buffers, mut jac: Option<&mut Vec<f64>>) {
        let np = self.n_params;
        buf.h.clear();
        buf.h.extend_from_slice(zp);
        if let Some(j) = jac.as_deref_mut() {
            j.clear();
            j.resize(np * np, 0.0);
            for k in 0..np {
                j[k * np + k] = 1.0;
            }
        }
        // A steps network's head sees p alone: its layers continue the trunk.
        let on_p: &[Dense] = if self.steps.is_some() {
            &self.head
        } else {
            &[]
        };
        for layer in self.trunk.iter().chain(on_p) {
            buf.tmp.resize(layer.n_out, 0.0);
            layer.apply(&buf.h, &mut buf.tmp);
            let mut d = vec![0.0; layer.n_out];
            gelu_and_derivative(&mut buf.tmp, &mut d);
            if let Some(j) = jac.as_deref_mut() {
                // J' = diag(gelu') W J.
                let mut next = vec![0.0; layer.n_out * np];
                for (a, row) in j.chunks(np).enumerate() {
                    let col = &layer.wt[a * layer.n_out..(a + 1) * layer.n_out];
                    for (i, &w) in col.iter().enumerate() {
                        let dst = &mut next[i * np..(i + 1) * np];
                        for (x, &r) in dst.iter_mut().zip(row) {
                            *x += w * r;
                        }
                    }
                }
                for (i, di) in d.iter().enumerate() {
                    for x in &mut next[i * np..(i + 1) * np] {
                        *x *= di;
                    }
                }
                *j = next;
            }
            std::mem::swap(&mut buf.h, &mut buf.tmp);
        }
    }

    /// The first head layer's part that does not depend on the bias: b0 + W0[:, :nh] h.
    #[inline(always)]
    fn head_base(&self, buf: &mut Buffers) {
        let first = &self.head[0];
        buf.base.resize(first.n_out, 0.0);
        first.apply(&buf.h, &mut buf.base);
    }

    /// Network outputs y_k for normal coordinates z_p (n_params) and bias coordinates z_U,k:
    /// h = trunk(z_p) once, then per voltage y_k = out(head([h, z_U,k])).
    ///
    /// Runs the AVX2+FMA build of the same code where the CPU has it (detected at run time).
    pub fn curve(&self, zp: &[f64], zu: &[f64], y: &mut [f64]) {
        #[cfg(target_arch = "x86_64")]
        if std::arch::is_x86_feature_detected!("avx2") && std::arch::is_x86_feature_detected!("fma")
        {
            // SAFETY: the CPU supports AVX2 and FMA (checked just above).
            unsafe { self.curve_avx2(zp, zu, y) };
            return;
        }
        self.curve_generic(zp, zu, y);
    }

    #[cfg(target_arch = "x86_64")]
    #[target_feature(enable = "avx2,fma")]
    fn curve_avx2(&self, zp: &[f64], zu: &[f64], y: &mut [f64]) {
        self.curve_generic(zp, zu, y);
    }

    /// Outputs y_k and the Jacobian dy_k / dz_p (row-major, len(zu) x n_params); the AVX2+FMA
    /// build where the CPU has it.
    pub fn curve_jacobian(&self, zp: &[f64], zu: &[f64], y: &mut [f64], jac: &mut [f64]) {
        #[cfg(target_arch = "x86_64")]
        if std::arch::is_x86_feature_detected!("avx2") && std::arch::is_x86_feature_detected!("fma")
        {
            // SAFETY: the CPU supports AVX2 and FMA (checked just above).
            unsafe { self.curve_jacobian_avx2(zp, zu, y, jac) };
            return;
        }
        self.curve_jacobian_generic(zp, zu, y, jac);
    }

    #[cfg(target_arch = "x86_64")]
    #[target_feature(enable = "avx2,fma")]
    fn curve_jacobian_avx2(&self, zp: &[f64], zu: &[f64], y: &mut [f64], jac: &mut [f64]) {
        self.curve_jacobian_generic(zp, zu, y, jac);
    }

    /// The head over all voltages, layer by layer (so that each weight is loaded once per block
    /// of voltages, not once per voltage): post-activations and GELU derivatives per layer, each
    /// row-major voltages x width; derivatives only when `ders` is given.
    #[inline(always)]
    fn head_batch(
        &self,
        zu: &[f64],
        buf: &Buffers,
        acts: &mut Vec<Vec<f64>>,
        mut ders: Option<&mut Vec<Vec<f64>>>,
    ) {
        let nv = zu.len();
        let nh = self.trunk_width();
        let first = &self.head[0];
        let m0 = first.n_out;
        let wu = &first.wt[nh * m0..(nh + 1) * m0];
        acts.resize(self.head.len(), Vec::new());
        if let Some(d) = ders.as_deref_mut() {
            d.resize(self.head.len(), Vec::new());
        }
        let a0 = &mut acts[0];
        a0.clear();
        a0.resize(nv * m0, 0.0);
        for (row, &u) in a0.chunks_exact_mut(m0).zip(zu) {
            for ((x, &c), &w) in row.iter_mut().zip(&buf.base).zip(wu) {
                *x = c + w * u;
            }
        }
        match ders.as_deref_mut() {
            Some(d) => {
                d[0].resize(nv * m0, 0.0);
                gelu_and_derivative(&mut acts[0], &mut d[0]);
            }
            None => gelu_in_place(&mut acts[0]),
        }
        for l in 1..self.head.len() {
            let layer = &self.head[l];
            let (prev, rest) = acts.split_at_mut(l);
            let out = &mut rest[0];
            out.clear();
            out.resize(nv * layer.n_out, 0.0);
            layer.apply_rows(&prev[l - 1], out);
            match ders.as_deref_mut() {
                Some(d) => {
                    d[l].resize(nv * layer.n_out, 0.0);
                    gelu_and_derivative(out, &mut d[l]);
                }
                None => gelu_in_place(out),
            }
        }
    }

    /// A steps network's curve: o = out(head(trunk(z_p))) once, the closed form per voltage;
    /// with `jac`, dy_k/dz_p = (dy_k/do) (do/dz_p), do/dz_p by forward mode through the layers.
    fn steps_curve(
        &self,
        s: &StepsHead,
        zp: &[f64],
        zu: &[f64],
        y: &mut [f64],
        jac: Option<&mut [f64]>,
    ) {
        let np = self.n_params;
        let (o, jo) = self.steps_outputs(zp, jac.is_some());
        let Some(jac) = jac else {
            s.curve(&o, zu, y);
            return;
        };
        s.curve_gradient(&o, zu, &mut |k, yk, g| {
            y[k] = yk;
            let row = &mut jac[k * np..(k + 1) * np];
            row.fill(0.0);
            for (i, &gi) in g.iter().enumerate() {
                for (x, &r) in row.iter_mut().zip(&jo[i * np..(i + 1) * np]) {
                    *x += gi * r;
                }
            }
        });
    }

    /// A steps network's outputs o = out(head(trunk(z_p))) and, with `jac`, do/dz_p (n_out x
    /// n_params, row-major; empty without), by forward mode through the layers.
    fn steps_outputs(&self, zp: &[f64], jac: bool) -> (Vec<f64>, Vec<f64>) {
        let np = self.n_params;
        let mut buf = Buffers::default();
        let mut jh = Vec::new();
        self.trunk_pass(zp, &mut buf, jac.then_some(&mut jh));
        let n_out = self.out.n_out;
        let mut o = vec![0.0; n_out];
        self.out.apply(&buf.h, &mut o);
        if !jac {
            return (o, Vec::new());
        }
        let mut jo = vec![0.0; n_out * np];
        for (a, row) in jh.chunks_exact(np).enumerate() {
            let col = &self.out.wt[a * n_out..(a + 1) * n_out];
            for (i, &w) in col.iter().enumerate() {
                for (x, &r) in jo[i * np..(i + 1) * np].iter_mut().zip(row) {
                    *x += w * r;
                }
            }
        }
        (o, jo)
    }

    /// Whether the network has the steps head's pinch-off gate.
    pub fn has_gate(&self) -> bool {
        self.steps.is_some_and(|s| s.gate)
    }

    /// The pinch-off gate's proximity e_k at each z_U,k ([`StepsHead::gate_proximity`]) and,
    /// with `jac`, de_k/dz_p (voltages x n_params, row-major): de/dz_p = (de/do) (do/dz_p).
    /// Returns false (and leaves `e` alone) for a network without a gate.
    pub fn gate_proximity(
        &self,
        zp: &[f64],
        zu: &[f64],
        e: &mut [f64],
        jac: Option<&mut [f64]>,
    ) -> bool {
        let Some(s) = self.steps.filter(|s| s.gate) else {
            return false;
        };
        let np = self.n_params;
        let (o, jo) = self.steps_outputs(zp, jac.is_some());
        let mut g = vec![0.0; s.outputs()];
        let mut jac = jac;
        for (k, &z) in zu.iter().enumerate() {
            e[k] = s.gate_proximity(&o, z, &mut g).unwrap_or(0.0);
            if let Some(jac) = jac.as_deref_mut() {
                let row = &mut jac[k * np..(k + 1) * np];
                row.fill(0.0);
                // Only the gate's three outputs have a non-zero de/do.
                for (i, &gi) in g.iter().enumerate().filter(|(_, gi)| **gi != 0.0) {
                    for (x, &r) in row.iter_mut().zip(&jo[i * np..(i + 1) * np]) {
                        *x += gi * r;
                    }
                }
            }
        }
        true
    }

    #[inline(always)]
    fn curve_generic(&self, zp: &[f64], zu: &[f64], y: &mut [f64]) {
        if let Some(s) = &self.steps {
            return self.steps_curve(s, zp, zu, y, None);
        }
        let mut buf = Buffers::default();
        self.trunk_pass(zp, &mut buf, None);
        self.head_base(&mut buf);
        let mut acts = Vec::new();
        self.head_batch(zu, &buf, &mut acts, None);
        let last = acts.last().expect("non-empty head");
        let width = self.out.n_in;
        for (yk, row) in y.iter_mut().zip(last.chunks_exact(width)) {
            *yk = self.out.b[0] + dot(&self.out.wt, row);
        }
    }

    #[inline(always)]
    fn curve_jacobian_generic(&self, zp: &[f64], zu: &[f64], y: &mut [f64], jac: &mut [f64]) {
        if let Some(s) = &self.steps {
            return self.steps_curve(s, zp, zu, y, Some(jac));
        }
        let np = self.n_params;
        let nv = zu.len();
        let mut buf = Buffers::default();
        let mut jh = Vec::new();
        self.trunk_pass(zp, &mut buf, Some(&mut jh));
        self.head_base(&mut buf);
        let nh = self.trunk_width();
        let first = &self.head[0];
        // d base / d z_p = W0[:, :nh] J_h  (n_out0 x np).
        let mut jbase = vec![0.0; first.n_out * np];
        for a in 0..nh {
            let col = &first.wt[a * first.n_out..(a + 1) * first.n_out];
            let row = &jh[a * np..(a + 1) * np];
            for (i, &w) in col.iter().enumerate() {
                for (x, &r) in jbase[i * np..(i + 1) * np].iter_mut().zip(row) {
                    *x += w * r;
                }
            }
        }
        let mut acts = Vec::new();
        let mut ders = Vec::new();
        self.head_batch(zu, &buf, &mut acts, Some(&mut ders));
        let width = self.out.n_in;
        let last = acts.last().expect("non-empty head");
        for (yk, row) in y.iter_mut().zip(last.chunks_exact(width)) {
            *yk = self.out.b[0] + dot(&self.out.wt, row);
        }
        // Reverse through the head for all voltages: g = dy/d(pre-activation), layer by layer.
        let mut g: Vec<f64> = Vec::with_capacity(nv * width);
        for _ in 0..nv {
            g.extend_from_slice(&self.out.wt);
        }
        for l in (0..self.head.len()).rev() {
            for (x, d) in g.iter_mut().zip(&ders[l]) {
                *x *= d;
            }
            if l > 0 {
                let layer = &self.head[l];
                let mut prev = vec![0.0; nv * layer.n_in];
                for (gk, pk) in g
                    .chunks_exact(layer.n_out)
                    .zip(prev.chunks_exact_mut(layer.n_in))
                {
                    layer.back(gk, pk);
                }
                g = prev;
            }
        }
        // dy_k/dz_p = g_k^T d base / d z_p.
        let m0 = first.n_out;
        for (k, gk) in g.chunks_exact(m0).enumerate() {
            let row = &mut jac[k * np..(k + 1) * np];
            row.fill(0.0);
            for (i, &gi) in gk.iter().enumerate() {
                for (x, &r) in row.iter_mut().zip(&jbase[i * np..(i + 1) * np]) {
                    *x += gi * r;
                }
            }
        }
    }

    /// Number of weights and biases.
    pub fn parameter_count(&self) -> usize {
        self.trunk
            .iter()
            .chain(&self.head)
            .chain(std::iter::once(&self.out))
            .map(|l| l.n_in * l.n_out + l.n_out)
            .sum()
    }
}
