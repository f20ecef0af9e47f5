//! Probe for issue 21: replays one refinement round of a fit offline. Reads the exact curves a
//! fit's rounds solved (`FITDIR/rounds/round-K.json`), fits the error model to the curves of
//! the rounds TRAIN (a comma list; round T + 1 of the fit used 0,..,T), and scores it on the
//! check draws of round TEST: the log-ratios ln L_exact - ln L_corrected that the check
//! re-weights with, their PSIS k-hat and ESS, the shift of each mean, and the error model's
//! calibration there. No exact solve. With EXTRA, also the error models of TRAIN plus 5, 10,
//! 20 and 40 curves of round EXTRA's check.
//! `cargo run --release -p hpge-validation --example refine_replay -- FITDIR TRAIN TEST [EVALS [EXTRA]]`

use hpge_inference::CvModel;
use hpge_inference::fit::{FitJob, SavedRound};
use hpge_inference::refine::{CorrectedModel, GpCorrection};
use hpge_inference::summary::psis;
use hpge_solver::GridOverrides;
use hpge_validation::shipped_fit_files;

type Curves = Vec<(Vec<f64>, Vec<f64>)>;

fn main() -> Result<(), Box<dyn std::error::Error>> {
    let args: Vec<String> = std::env::args().skip(1).collect();
    let dir = std::path::PathBuf::from(
        args.first()
            .ok_or("usage: FITDIR TRAIN TEST [EVALS [EXTRA]]")?,
    );
    let train_rounds: Vec<usize> = args
        .get(1)
        .ok_or("TRAIN")?
        .split(',')
        .map(str::parse)
        .collect::<Result<_, _>>()?;
    let test: usize = args.get(2).ok_or("TEST")?.parse()?;
    let evals: usize = args.get(3).map_or(Ok(600), |a| a.parse())?;
    let files = shipped_fit_files();
    let job = FitJob::from_files(&files, Default::default(), &GridOverrides::default())?;
    let read = |k: usize| -> Result<SavedRound, Box<dyn std::error::Error>> {
        let p = dir.join(format!("rounds/round-{k}.json"));
        Ok(serde_json::from_str(&std::fs::read_to_string(p)?)?)
    };
    let mut train: Curves = Vec::new();
    for &k in &train_rounds {
        train.extend(read(k)?.solved);
    }
    let next = read(test)?;
    let draws: Curves = next.solved[..next.check.draws - next.check.failed].to_vec();
    let nv = job.data.voltage_v.len();
    let sm = &job.surrogate;
    let ratio = |(x, ce): &(Vec<f64>, Vec<f64>)| -> Option<(Vec<f64>, Vec<f64>)> {
        let mut cs = vec![0.0; nv];
        sm.curve(x, &mut cs).ok()?;
        Some((
            x.clone(),
            ce.iter().zip(&cs).map(|(e, s)| (e / s).ln()).collect(),
        ))
    };
    let (xs, rs): (Vec<Vec<f64>>, Vec<Vec<f64>>) = train.iter().filter_map(ratio).unzip();
    let exact_like = job.likelihood.with_sigma_rel(0.0);
    // The best exact curve of the training set (the variance reference of `best`).
    let best = train
        .iter()
        .max_by(|a, b| {
            exact_like
                .ln_likelihood(&a.1, None)
                .total_cmp(&exact_like.ln_likelihood(&b.1, None))
        })
        .map(|c| c.0.clone())
        .ok_or("no training curve")?;
    let gp = GpCorrection::fit(&xs, &rs, None, evals)?;
    println!(
        "train {} curves (rounds {train_rounds:?}), test {} draws of round {test}; hyper {:?}",
        xs.len(),
        draws.len(),
        gp.hyper
    );
    report("as fitted", &job, &draws, &gp, &best);
    // Round 0 plus K curves from a later round's check (near the exact posterior), every
    // STRIDE-th: how much a few curves where the next round samples would help.
    if let Some(extra_round) = args.get(4) {
        let extra = read(extra_round.parse()?)?;
        for k in [5usize, 10, 20, 40] {
            let stride = (extra.check.draws / k).max(1);
            let mut tr = train.clone();
            tr.extend(extra.solved.iter().step_by(stride).take(k).cloned());
            let (xs, rs): (Vec<Vec<f64>>, Vec<Vec<f64>>) = tr.iter().filter_map(ratio).unzip();
            let g = GpCorrection::fit(&xs, &rs, None, evals)?;
            report(
                &format!("+{k} of round {extra_round}"),
                &job,
                &draws,
                &g,
                &best,
            );
        }
    }
    Ok(())
}

fn report(name: &str, job: &FitJob, draws: &Curves, gp: &GpCorrection, best: &[f64]) {
    let nv = job.data.voltage_v.len();
    let model = CorrectedModel::new(&job.surrogate, gp.clone())
        .unwrap()
        .variance_fixed_at(best);
    let exact_like = job.likelihood.with_sigma_rel(0.0);
    let mut lr = Vec::new();
    let (mut se, mut z2, mut n) = (0.0, 0.0, 0.0);
    let mut se_plain = 0.0;
    for (x, ce) in draws {
        let mut c = vec![0.0; nv];
        let mut var = vec![0.0; nv];
        model.curve(x, &mut c).unwrap();
        model.curve_variance(x, &mut var, None).unwrap();
        let mut cs = vec![0.0; nv];
        job.surrogate.curve(x, &mut cs).unwrap();
        let p = gp.predict(x, false);
        lr.push(
            exact_like.ln_likelihood(ce, None)
                - job.likelihood.ln_likelihood_var(&c, &var, None, None),
        );
        for k in 0..nv {
            let e = (ce[k] / c[k]).ln();
            se += e * e;
            se_plain += (ce[k] / cs[k]).ln().powi(2);
            z2 += e * e / p.var[k].max(1e-30);
            n += 1.0;
        }
    }
    let p = psis(&lr);
    if std::env::var("REPLAY_DUMP").is_ok() {
        let mut o: Vec<usize> = (0..lr.len()).collect();
        o.sort_by(|a, b| lr[*a].total_cmp(&lr[*b]));
        let l0 = lr[o[o.len() / 2]];
        for &i in o.iter().take(6).chain(o.iter().rev().take(3)) {
            let (x, ce) = &draws[i];
            let mut c = vec![0.0; nv];
            model.curve(x, &mut c).unwrap();
            let errs: Vec<String> = (0..nv)
                .step_by(6)
                .map(|k| format!("{:.2}", 100.0 * (ce[k] / c[k]).ln()))
                .collect();
            println!(
                "  draw {i}: ln w - median {:.2}; x {:?}; err% every 6th U {:?}",
                lr[i] - l0,
                x.iter()
                    .map(|v| (v * 1000.0).round() / 1000.0)
                    .collect::<Vec<_>>(),
                errs
            );
        }
    }
    let mean = lr.iter().sum::<f64>() / lr.len() as f64;
    let sd = (lr.iter().map(|v| (v - mean).powi(2)).sum::<f64>() / lr.len() as f64).sqrt();
    let d = draws[0].0.len();
    let mut shifts = Vec::new();
    for j in 0..d {
        let v: Vec<f64> = draws.iter().map(|c| c.0[j]).collect();
        let m = v.iter().sum::<f64>() / v.len() as f64;
        let s = (v.iter().map(|a| (a - m).powi(2)).sum::<f64>() / (v.len() as f64 - 1.0)).sqrt();
        let mw: f64 = v.iter().zip(&p.weights).map(|(a, w)| a * w).sum();
        shifts.push((mw - m) / s);
    }
    let max_shift = shifts.iter().fold(0.0f64, |a, b| a.max(b.abs()));
    println!(
        "{name}: rms ln err {:.3}% (plain {:.3}%), rms z {:.2}; ln w sd {sd:.3}; k-hat {:.2} ESS {:.1}; max |shift| {max_shift:.3} sd; shifts {:?}",
        100.0 * (se / n).sqrt(),
        100.0 * (se_plain / n).sqrt(),
        (z2 / n).sqrt(),
        p.k_hat,
        p.ess,
        shifts
            .iter()
            .map(|s| (s * 1000.0).round() / 1000.0)
            .collect::<Vec<_>>()
    );
}
