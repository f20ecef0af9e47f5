//! Training with candle-nn: seeded Glorot initialisation (Flux's default), Adam cycles, and the
//! learning curves (the mean loss of every sample of the training and the test set after each
//! epoch, as the paper plots them).

use candle_core::{DType, Device, Tensor, Var};
use candle_nn::optim::{AdamW, Optimizer, ParamsAdamW};
use rand::rngs::StdRng;
use rand::seq::SliceRandom;
use rand::{RngExt, SeedableRng};
use serde::{Deserialize, Serialize};

use super::dataset::DataSet;
use super::network::{Dense, Network};
use super::recipe::{Architecture, Loss, OutputTransform, Recipe};
use super::steps::{BiasMap, StepsHead};
use super::transform::unit_to_z;
use crate::error::{Error, Result};

/// One point of the learning curves.
#[derive(Debug, Clone, Copy, PartialEq, Serialize, Deserialize)]
pub struct EpochRecord {
    /// Ensemble member (0-based).
    pub member: usize,
    /// Epoch (1-based, over all cycles).
    pub epoch: usize,
    /// Cycle (1-based).
    pub cycle: usize,
    /// Learning rate at the end of the epoch.
    pub lr: f64,
    /// Mean loss over the training set.
    pub train_loss: f64,
    /// Mean loss over the test set.
    pub test_loss: f64,
    /// Root mean square of the relative error (c_p - c_s)/c_s over the test set.
    pub test_rel_rms: f64,
    /// Wall time since the member's start (s).
    pub seconds: f64,
}

impl EpochRecord {
    /// One data line of a learning-curve CSV (`member,epoch,cycle,lr,train_loss,test_loss,
    /// test_rel_rms,seconds`, as `job::write_curves` writes it), or `None` where the line does not
    /// hold eight numbers.
    pub fn from_csv_line(line: &str) -> Option<Self> {
        let v: Vec<f64> = line.split(',').filter_map(|x| x.parse().ok()).collect();
        if v.len() != 8 {
            return None;
        }
        Some(EpochRecord {
            member: v[0] as usize,
            epoch: v[1] as usize,
            cycle: v[2] as usize,
            lr: v[3],
            train_loss: v[4],
            test_loss: v[5],
            test_rel_rms: v[6],
            seconds: v[7],
        })
    }
}

/// The result of [`train`].
#[derive(Debug, Clone)]
pub struct Trained {
    /// One network per ensemble member.
    pub members: Vec<Network>,
    /// The output transform.
    pub output: OutputTransform,
    /// Learning curves of all members.
    pub curves: Vec<EpochRecord>,
    /// Wall time (s).
    pub seconds: f64,
}

fn candle_err(e: candle_core::Error) -> Error {
    Error::Training {
        message: e.to_string(),
    }
}

/// Glorot-uniform weights U(+-sqrt(6 / (n_in + n_out))) and zero biases, from `seed`. A steps
/// head needs `bias`, the map of z_U ([`Error::Argument`] without it); other networks ignore it.
pub fn initial_network(
    arch: &Architecture,
    n_params: usize,
    bias: Option<BiasMap>,
    seed: u64,
) -> Result<Network> {
    let steps = match (arch.steps, bias) {
        (None, _) => None,
        (Some(count), Some(bias)) => Some(StepsHead {
            count,
            bias,
            gate: arch.gate,
        }),
        (Some(_), None) => {
            return Err(Error::Argument {
                name: "architecture.steps".into(),
                message: "a steps head needs the bias dimension's map".into(),
            });
        }
    };
    let mut rng = StdRng::seed_from_u64(seed);
    let mut layer = |n_in: usize, n_out: usize| {
        let a = (6.0 / (n_in + n_out) as f64).sqrt();
        let w: Vec<f64> = (0..n_in * n_out)
            .map(|_| (rng.random::<f64>() * 2.0 - 1.0) * a)
            .map(|x| f64::from(x as f32))
            .collect();
        Dense::from_row_major(n_out, n_in, &w, &vec![0.0; n_out])
    };
    let mut width = n_params;
    let trunk: Vec<Dense> = arch
        .trunk
        .iter()
        .map(|&w| {
            let l = layer(width, w);
            width = w;
            l
        })
        .collect();
    if steps.is_none() {
        width += 1;
    }
    let head: Vec<Dense> = arch
        .head
        .iter()
        .map(|&w| {
            let l = layer(width, w);
            width = w;
            l
        })
        .collect();
    let out = layer(width, steps.map_or(1, |s| s.outputs()));
    Ok(Network {
        n_params,
        trunk,
        head,
        out,
        steps,
    })
}

/// The network as candle variables (f32).
struct CandleNet {
    n_params: usize,
    steps: Option<StepsHead>,
    trunk: Vec<(Var, Var)>,
    head: Vec<(Var, Var)>,
    out: (Var, Var),
}

impl CandleNet {
    fn from_network(net: &Network) -> Result<Self> {
        let var = |l: &Dense| -> Result<(Var, Var)> {
            let w: Vec<f32> = l.row_major().iter().map(|&x| x as f32).collect();
            let b: Vec<f32> = l.b.iter().map(|&x| x as f32).collect();
            let w = Tensor::from_vec(w, (l.n_out, l.n_in), &Device::Cpu).map_err(candle_err)?;
            let b = Tensor::from_vec(b, l.n_out, &Device::Cpu).map_err(candle_err)?;
            Ok((
                Var::from_tensor(&w).map_err(candle_err)?,
                Var::from_tensor(&b).map_err(candle_err)?,
            ))
        };
        Ok(CandleNet {
            n_params: net.n_params,
            steps: net.steps,
            trunk: net.trunk.iter().map(var).collect::<Result<_>>()?,
            head: net.head.iter().map(var).collect::<Result<_>>()?,
            out: var(&net.out)?,
        })
    }

    fn to_network(&self) -> Result<Network> {
        let dense = |(w, b): &(Var, Var)| -> Result<Dense> {
            let (n_out, n_in) = w.dims2().map_err(candle_err)?;
            let w: Vec<f64> = w
                .flatten_all()
                .and_then(|t| t.to_dtype(DType::F64))
                .and_then(|t| t.to_vec1())
                .map_err(candle_err)?;
            let b: Vec<f64> = b
                .to_dtype(DType::F64)
                .and_then(|t| t.to_vec1())
                .map_err(candle_err)?;
            Ok(Dense::from_row_major(n_out, n_in, &w, &b))
        };
        Ok(Network {
            n_params: self.n_params,
            trunk: self.trunk.iter().map(dense).collect::<Result<_>>()?,
            head: self.head.iter().map(dense).collect::<Result<_>>()?,
            out: dense(&self.out)?,
            steps: self.steps,
        })
    }

    fn vars(&self) -> Vec<Var> {
        self.trunk
            .iter()
            .chain(&self.head)
            .chain(std::iter::once(&self.out))
            .flat_map(|(w, b)| [w.clone(), b.clone()])
            .collect()
    }

    /// y (n) for inputs x (n x (n_params + 1), bias last).
    fn forward(&self, x: &Tensor) -> candle_core::Result<Tensor> {
        let dense = |x: &Tensor, (w, b): &(Var, Var)| x.matmul(&w.t()?)?.broadcast_add(b);
        let mut h = x.narrow(1, 0, self.n_params)?;
        let u = x.narrow(1, self.n_params, 1)?;
        for l in &self.trunk {
            h = dense(&h, l)?.gelu()?;
        }
        if let Some(s) = &self.steps {
            for l in &self.head {
                h = dense(&h, l)?.gelu()?;
            }
            return s.forward(&dense(&h, &self.out)?, &u);
        }
        let mut a = Tensor::cat(&[&h, &u], 1)?;
        for l in &self.head {
            a = dense(&a, l)?.gelu()?;
        }
        dense(&a, &self.out)?.squeeze(1)
    }
}

/// Per-sample loss of outputs y against targets t (the target in output units).
fn loss_tensor(
    y: &Tensor,
    t: &Tensor,
    loss: Loss,
    out: OutputTransform,
) -> candle_core::Result<Tensor> {
    let d = (y - t)?;
    match (loss, out) {
        (Loss::PaperRobust { h }, _) => ((d.sqr()? / h)? + 1.0)?.log()? * h,
        (Loss::RelativeSquared, OutputTransform::LogStandardised { sd, .. }) => {
            (d * (100.0 * sd))?.sqr()
        }
        (Loss::RelativeRobust { h }, OutputTransform::LogStandardised { sd, .. }) => {
            (((d * (100.0 * sd))?.sqr()? / h)? + 1.0)?.log()? * h
        }
        (Loss::RelativeSquared | Loss::RelativeRobust { .. }, OutputTransform::Picofarad) => {
            // validate() refuses this combination.
            Err(candle_core::Error::Msg(
                "the relative loss needs a log output".into(),
            ))
        }
    }
}

/// Inputs (f32 tensor n x d in standard-normal coordinates) and targets of a data set.
fn tensors(set: &DataSet, out: OutputTransform) -> Result<(Tensor, Tensor)> {
    let x: Vec<f32> = set.unit.iter().map(|&u| unit_to_z(u) as f32).collect();
    let t: Vec<f32> = set
        .c12_pf
        .iter()
        .map(|&c| match out {
            OutputTransform::Picofarad => c as f32,
            OutputTransform::LogStandardised { mean, sd } => ((c.ln() - mean) / sd) as f32,
        })
        .collect();
    let x = Tensor::from_vec(x, (set.len(), set.dim), &Device::Cpu).map_err(candle_err)?;
    let t = Tensor::from_vec(t, set.len(), &Device::Cpu).map_err(candle_err)?;
    Ok((x, t))
}

/// The output transform on a training set: c12 in pF, or ln c12 standardised.
pub fn output_transform(log_output: bool, train: &DataSet) -> OutputTransform {
    if !log_output {
        return OutputTransform::Picofarad;
    }
    let n = train.len() as f64;
    let mean = train.c12_pf.iter().map(|c| c.ln()).sum::<f64>() / n;
    let var = train
        .c12_pf
        .iter()
        .map(|c| (c.ln() - mean).powi(2))
        .sum::<f64>()
        / n;
    OutputTransform::LogStandardised {
        mean,
        sd: var.sqrt().max(1e-12),
    }
}

/// Mean loss and the relative-error rms of a whole set, in chunks.
fn evaluate(
    net: &CandleNet,
    x: &Tensor,
    t: &Tensor,
    recipe: &Recipe,
    out: OutputTransform,
) -> candle_core::Result<(f64, f64)> {
    let n = x.dim(0)?;
    let (mut loss, mut rel2) = (0.0, 0.0);
    let chunk = 8192;
    let mut start = 0;
    while start < n {
        let len = chunk.min(n - start);
        let xb = x.narrow(0, start, len)?;
        let tb = t.narrow(0, start, len)?;
        let y = net.forward(&xb)?;
        loss += loss_tensor(&y, &tb, recipe.loss, out)?
            .sum_all()?
            .to_scalar::<f32>()? as f64;
        let (yv, tv): (Vec<f32>, Vec<f32>) = (y.to_vec1()?, tb.to_vec1()?);
        for (&yp, &ts) in yv.iter().zip(&tv) {
            let r = match out {
                OutputTransform::Picofarad => (yp as f64 - ts as f64) / ts as f64,
                OutputTransform::LogStandardised { sd, .. } => ((yp - ts) as f64 * sd).exp() - 1.0,
            };
            rel2 += r * r;
        }
        start += len;
    }
    Ok((loss / n as f64, (rel2 / n as f64).sqrt()))
}

/// Trains `recipe` on `train`, recording learning curves on `train` and `test`; `seed` fixes the
/// initial weights and the batch order (member m uses seed + m). `progress` is called after
/// every epoch.
pub fn train(
    recipe: &Recipe,
    train: &DataSet,
    test: &DataSet,
    seed: u64,
    progress: &mut dyn FnMut(&EpochRecord),
) -> Result<Trained> {
    train_resuming(
        recipe,
        train,
        test,
        seed,
        Vec::new(),
        progress,
        &mut |_, _| Ok(()),
    )
}

/// A finished ensemble member: its network and its learning curves.
pub type Member = (Network, Vec<EpochRecord>);

/// As [`train`], but starting after the members in `finished` (from an interrupted run of the
/// same recipe, seed and data; the caller checks that), and handing each newly finished member to
/// `on_member` (to checkpoint it) before the next one starts. Members are independent (member m
/// uses seed + m), so a resumed run ends with the same networks as an uninterrupted one.
pub fn train_resuming(
    recipe: &Recipe,
    train: &DataSet,
    test: &DataSet,
    seed: u64,
    finished: Vec<Member>,
    progress: &mut dyn FnMut(&EpochRecord),
    on_member: &mut dyn FnMut(usize, &Member) -> Result<()>,
) -> Result<Trained> {
    recipe.validate()?;
    let bias = match recipe.architecture.steps {
        Some(_) => Some(BiasMap::of(&train.bias)?),
        None => None,
    };
    let start = std::time::Instant::now();
    let out = output_transform(recipe.log_output, train);
    let (xt, tt) = tensors(train, out)?;
    let (xs, ts) = tensors(test, out)?;
    let n = train.len();
    let first = finished.len();
    let mut members = Vec::new();
    let mut curves = Vec::new();
    for (net, c) in finished {
        members.push(net);
        curves.extend(c);
    }
    for m in first..recipe.members {
        let mut member_curves = Vec::new();
        let member_start = std::time::Instant::now();
        let member_seed = seed.wrapping_add(m as u64);
        let net = CandleNet::from_network(&initial_network(
            &recipe.architecture,
            train.dim - 1,
            bias,
            member_seed,
        )?)?;
        let mut rng = StdRng::seed_from_u64(member_seed ^ 0x05ee_d0fb_a7c4);
        let mut order: Vec<u32> = (0..n as u32).collect();
        let mut epoch = 0;
        for (c, cycle) in recipe.cycles.iter().enumerate() {
            let params = ParamsAdamW {
                lr: cycle.lr,
                weight_decay: recipe.weight_decay,
                ..Default::default()
            };
            let mut opt = AdamW::new(net.vars(), params).map_err(candle_err)?;
            let steps = n.div_ceil(cycle.batch);
            for e in 0..cycle.epochs {
                order.shuffle(&mut rng);
                for s in 0..steps {
                    let lr = Recipe::learning_rate(cycle, e, s as f64 / steps as f64);
                    opt.set_learning_rate(lr);
                    let lo = s * cycle.batch;
                    let hi = (lo + cycle.batch).min(n);
                    let idx = Tensor::from_slice(&order[lo..hi], hi - lo, &Device::Cpu)
                        .map_err(candle_err)?;
                    let step = || -> candle_core::Result<Tensor> {
                        let xb = xt.index_select(&idx, 0)?;
                        let tb = tt.index_select(&idx, 0)?;
                        let y = net.forward(&xb)?;
                        loss_tensor(&y, &tb, recipe.loss, out)?.mean_all()
                    };
                    let loss = step().map_err(candle_err)?;
                    let value = loss.to_scalar::<f32>().map_err(candle_err)?;
                    if !value.is_finite() {
                        return Err(Error::Training {
                            message: format!(
                                "the loss became {value} in epoch {} (member {m}); lower the \
                                 learning rate",
                                epoch + 1
                            ),
                        });
                    }
                    opt.backward_step(&loss).map_err(candle_err)?;
                }
                epoch += 1;
                let (train_loss, _) = evaluate(&net, &xt, &tt, recipe, out).map_err(candle_err)?;
                let (test_loss, test_rel_rms) =
                    evaluate(&net, &xs, &ts, recipe, out).map_err(candle_err)?;
                let rec = EpochRecord {
                    member: m,
                    epoch,
                    cycle: c + 1,
                    lr: Recipe::learning_rate(cycle, e, 1.0),
                    train_loss,
                    test_loss,
                    test_rel_rms,
                    seconds: member_start.elapsed().as_secs_f64(),
                };
                progress(&rec);
                member_curves.push(rec);
            }
        }
        let member = (net.to_network()?, member_curves);
        on_member(m, &member)?;
        members.push(member.0);
        curves.extend(member.1);
    }
    Ok(Trained {
        members,
        output: out,
        curves,
        seconds: start.elapsed().as_secs_f64(),
    })
}

/// Network outputs through candle (f32) for inputs in network order, unit coordinates: the
/// independent check of the plain f64 path.
pub fn candle_outputs(net: &Network, unit_rows: &[f64], dim: usize) -> Result<Vec<f64>> {
    let cn = CandleNet::from_network(net)?;
    let x: Vec<f32> = unit_rows.iter().map(|&u| unit_to_z(u) as f32).collect();
    let n = unit_rows.len() / dim;
    let x = Tensor::from_vec(x, (n, dim), &Device::Cpu).map_err(candle_err)?;
    let y = cn.forward(&x).map_err(candle_err)?;
    let y: Vec<f32> = y.to_vec1().map_err(candle_err)?;
    Ok(y.into_iter().map(f64::from).collect())
}
