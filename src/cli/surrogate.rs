//! `train`, `evaluate` and `predict`: the surrogate's command-line side.

use std::io::Write as _;
use std::path::{Path, PathBuf};

use anyhow::{Context, Result, bail};
use hpge_surrogate::model::{
    DataInfo, EpochRecord, FORMAT, FORMAT_VERSION, Member, OutputTransform, Polynomial, Trained,
    unit_to_z,
};
use hpge_surrogate::{DataSet, Figures, ModelInfo, ParameterSpace, Predictor, Recipe, Surrogate};
use indicatif::{ProgressBar, ProgressStyle};
use serde::Serialize;

/// Options of `train`.
pub struct TrainOptions<'a> {
    pub data: &'a Path,
    pub test: &'a Path,
    pub space: &'a Path,
    pub recipe: &'a str,
    pub out: &'a Path,
    pub seed: u64,
    pub plot: Option<&'a Path>,
    pub quiet: bool,
    pub detector: Option<&'a Path>,
}

/// The detector record of a model: the file and the hash a generation run's fingerprint gives
/// it (the detector is checked against the space on the way).
pub fn detector_info(
    space: &hpge_surrogate::ParameterSpace,
    detector: &Path,
) -> Result<hpge_surrogate::model::DetectorInfo> {
    let exact = hpge_surrogate::ExactSolver::new(
        space.clone(),
        detector,
        hpge_solver::FieldSettings::default(),
    )?;
    Ok(hpge_surrogate::model::DetectorInfo {
        file: detector.display().to_string(),
        hash: exact.detector_hash(),
    })
}

/// The learning-curve CSV beside a model: models/NAME.safetensors -> models/NAME.curves.csv.
pub fn curves_path(model: &Path) -> PathBuf {
    model.with_extension("curves.csv")
}

fn write_curves(path: &Path, curves: &[EpochRecord], model: &Path) -> Result<()> {
    let mut f = std::fs::File::create(path)
        .with_context(|| format!("cannot write the learning curves {}", path.display()))?;
    let mut text = format!(
        "# learning curves of {} (hpge-cv {}): mean loss over each set after every epoch\n\
         member,epoch,cycle,lr,train_loss,test_loss,test_rel_rms,seconds\n",
        model.display(),
        env!("CARGO_PKG_VERSION")
    );
    for r in curves {
        text += &format!(
            "{},{},{},{:e},{:e},{:e},{:e},{:.3}\n",
            r.member, r.epoch, r.cycle, r.lr, r.train_loss, r.test_loss, r.test_rel_rms, r.seconds
        );
    }
    f.write_all(text.as_bytes())
        .with_context(|| format!("cannot write the learning curves {}", path.display()))
}

/// Where finished ensemble members of an unfinished run wait: models/NAME.partial/.
fn partial_dir(model: &Path) -> PathBuf {
    model.with_extension("partial")
}

/// Checkpoints member m (a one-member model file plus its learning curves).
fn save_member(dir: &Path, info: &ModelInfo, m: usize, member: &Member) -> Result<()> {
    std::fs::create_dir_all(dir)
        .with_context(|| format!("cannot create the checkpoint folder {}", dir.display()))?;
    let mut one = info.clone();
    if let Some(r) = one.recipe.as_mut() {
        r.members = 1;
    }
    let file = dir.join(format!("member-{m}.safetensors"));
    Surrogate::new(one, Predictor::Networks(vec![member.0.clone()]))?.save(&file)?;
    write_curves(
        &dir.join(format!("member-{m}.curves.csv")),
        &member.1,
        &file,
    )
}

/// Members finished by an interrupted run with the same recipe, seed and data (refuses a
/// checkpoint folder of other settings).
fn resume_members(dir: &Path, info: &ModelInfo) -> Result<Vec<Member>> {
    let mut done = Vec::new();
    loop {
        let m = done.len();
        let file = dir.join(format!("member-{m}.safetensors"));
        let curves = dir.join(format!("member-{m}.curves.csv"));
        if !file.is_file() || !curves.is_file() {
            return Ok(done);
        }
        let s = Surrogate::load(&file)?;
        let same = s.info.recipe_name == info.recipe_name
            && s.info.seed == info.seed
            && s.info.training.hash == info.training.hash
            && s.info.test.hash == info.test.hash
            && s.info.space.dimensions == info.space.dimensions;
        if !same {
            bail!(
                "{}: a checkpoint of another run (recipe, seed or data differ); remove the folder \
                 {} or choose another --out",
                file.display(),
                dir.display()
            );
        }
        let Predictor::Networks(mut nets) = s.predictor else {
            bail!("{}: not a network checkpoint", file.display());
        };
        let text = std::fs::read_to_string(&curves)
            .with_context(|| format!("cannot read {}", curves.display()))?;
        let mut records = Vec::new();
        for line in text
            .lines()
            .filter(|l| !l.starts_with('#') && !l.starts_with("member"))
        {
            let v: Vec<f64> = line.split(',').filter_map(|x| x.parse().ok()).collect();
            if v.len() != 8 {
                bail!("{}: malformed line `{line}`", curves.display());
            }
            records.push(EpochRecord {
                member: m,
                epoch: v[1] as usize,
                cycle: v[2] as usize,
                lr: v[3],
                train_loss: v[4],
                test_loss: v[5],
                test_rel_rms: v[6],
                seconds: v[7],
            });
        }
        done.push((nets.remove(0), records));
    }
}

/// Trains, evaluates on the test set and writes the model file and its learning curves.
pub fn train(o: &TrainOptions) -> Result<()> {
    if o.out.extension().and_then(|e| e.to_str()) != Some("safetensors") {
        bail!(
            "--out {}: the model file must end in .safetensors",
            o.out.display()
        );
    }
    if let Some(dir) = o.out.parent().filter(|d| !d.as_os_str().is_empty())
        && !dir.is_dir()
    {
        bail!(
            "--out {}: the folder {} does not exist",
            o.out.display(),
            dir.display()
        );
    }
    if let Some(dir) = o.plot {
        std::fs::create_dir_all(dir)
            .with_context(|| format!("--plot {}: cannot create the folder", dir.display()))?;
    }
    let space = ParameterSpace::from_file(o.space)?;
    let recipe = if o.recipe == "poly3" {
        None
    } else {
        Some(Recipe::named(o.recipe)?)
    };
    let train = DataSet::read(o.data, &space)?;
    let test = DataSet::read(o.test, &space)?;
    if !o.quiet {
        eprintln!(
            "training `{}` on {} samples ({} without c12 left out), testing on {} ({} left out)",
            o.recipe,
            train.len(),
            train.excluded,
            test.len(),
            test.excluded
        );
    }
    let start = std::time::Instant::now();
    let inputs: Vec<String> = {
        let order = hpge_surrogate::network_order(&space)?;
        order
            .iter()
            .map(|&j| space.dimensions[j].name.clone())
            .collect()
    };
    let log_output = recipe.as_ref().is_none_or(|r| r.log_output);
    let mut info = ModelInfo {
        format: FORMAT.into(),
        format_version: FORMAT_VERSION,
        program_version: env!("CARGO_PKG_VERSION").into(),
        space: space.clone(),
        inputs,
        input_map: "u = (x - lo)/(hi - lo) per the space's distribution, clamped to \
                    [1e-6, 1 - 1e-6]; z = Phi^-1(u) (standard-normal coordinates)"
            .into(),
        output: hpge_surrogate::model::output_transform(log_output, &train),
        recipe_name: o.recipe.into(),
        recipe: recipe.clone(),
        seed: o.seed,
        training: DataInfo::of(&train),
        test: DataInfo::of(&test),
        train_seconds: 0.0,
        threads: std::thread::available_parallelism().map_or(1, |n| n.get()),
        test_figures: Figures::of(&[], &[]),
        detector: match o.detector {
            Some(d) => Some(detector_info(&space, d)?),
            None => None,
        },
        sigma_p: f64::NAN,
    };
    let (predictor, curves, seconds) = match &recipe {
        Some(recipe) => {
            let total = (recipe.total_epochs() * recipe.members) as u64;
            let bar = if o.quiet {
                ProgressBar::hidden()
            } else {
                ProgressBar::new(total)
            };
            bar.set_style(
                ProgressStyle::with_template(
                    "{bar:40} epoch {pos}/{len}, {elapsed} elapsed, eta {eta} {msg}",
                )
                .unwrap_or_else(|_| ProgressStyle::default_bar()),
            );
            let log_lines = !o.quiet && !std::io::IsTerminal::is_terminal(&std::io::stderr());
            let mut progress = |r: &EpochRecord| {
                if log_lines {
                    eprintln!(
                        "member {} epoch {:>4} cycle {} lr {:.2e}: train loss {:.5e}, test loss \
                         {:.5e}, test rel rms {:.4}%, {:.1} s",
                        r.member,
                        r.epoch,
                        r.cycle,
                        r.lr,
                        r.train_loss,
                        r.test_loss,
                        100.0 * r.test_rel_rms,
                        r.seconds
                    );
                }
                bar.inc(1);
                bar.set_message(format!(
                    "train loss {:.4e}, test loss {:.4e}, test rel rms {:.3}%",
                    r.train_loss,
                    r.test_loss,
                    100.0 * r.test_rel_rms
                ));
            };
            let partial = partial_dir(o.out);
            let finished = resume_members(&partial, &info)?;
            if !finished.is_empty() && !o.quiet {
                eprintln!(
                    "resuming: {} of {} members finished in {}",
                    finished.len(),
                    recipe.members,
                    partial.display()
                );
            }
            bar.inc((finished.len() * recipe.total_epochs()) as u64);
            let mut checkpoint = |m: usize, member: &Member| -> hpge_surrogate::Result<()> {
                save_member(&partial, &info, m, member).map_err(|e| {
                    hpge_surrogate::Error::Training {
                        message: format!("{e:#}"),
                    }
                })
            };
            let Trained {
                members,
                curves,
                seconds,
                ..
            } = hpge_surrogate::model::train_resuming(
                recipe,
                &train,
                &test,
                o.seed,
                finished,
                &mut progress,
                &mut checkpoint,
            )?;
            bar.finish_and_clear();
            (Predictor::Networks(members), curves, seconds)
        }
        None => {
            let z: Vec<f64> = train.unit.iter().map(|&u| unit_to_z(u)).collect();
            let OutputTransform::LogStandardised { mean, sd } = info.output else {
                unreachable!("the polynomial learns ln c12")
            };
            let t: Vec<f64> = train.c12_pf.iter().map(|c| (c.ln() - mean) / sd).collect();
            let p = Polynomial::fit(train.dim, 3, &z, &t)?;
            (
                Predictor::Polynomial(p),
                Vec::new(),
                start.elapsed().as_secs_f64(),
            )
        }
    };
    info.train_seconds = seconds;
    let mut model = Surrogate::new(info.clone(), predictor)?;
    let pred = model.predict_set(&test);
    info.test_figures = Figures::of(&pred, &test.c12_pf);
    info.sigma_p = info.test_figures.rel_sigma;
    model.info = info;
    model.save(o.out)?;
    let partial = partial_dir(o.out);
    if partial.is_dir() {
        std::fs::remove_dir_all(&partial)
            .with_context(|| format!("cannot remove the checkpoints {}", partial.display()))?;
    }
    let curves_file = curves_path(o.out);
    if !curves.is_empty() {
        write_curves(&curves_file, &curves, o.out)?;
    }
    if let Some(dir) = o.plot {
        if !curves.is_empty() {
            crate::plot::learning_curves(&curves, &model.info, dir)?;
        }
        crate::plot::surrogate_errors(&pred, &test.c12_pf, &model.info, "test", dir)?;
    }
    let f = &model.info.test_figures;
    if !o.quiet {
        eprintln!(
            "trained in {:.1} s; test set: sigma {:.3}%, mean {:+.3}%, |rel| q50 {:.3}% q90 \
             {:.3}% q99 {:.3}% max {:.2}%",
            seconds,
            100.0 * f.rel_sigma,
            100.0 * f.rel_mean,
            100.0 * f.abs_rel_q50,
            100.0 * f.abs_rel_q90,
            100.0 * f.abs_rel_q99,
            100.0 * f.abs_rel_max
        );
        eprintln!("wrote {}", o.out.display());
        if !curves.is_empty() {
            eprintln!("wrote {}", curves_file.display());
        }
    }
    Ok(())
}

/// One of the worst samples.
#[derive(Debug, Serialize)]
struct Worst {
    index: u64,
    inputs: Vec<(String, f64)>,
    c12_solver_pf: f64,
    c12_surrogate_pf: f64,
    rel: f64,
}

/// `evaluate --json`: the fields first, then the rest.
#[derive(Debug, Serialize)]
struct EvaluateJson<'a> {
    n: usize,
    rel_sigma: f64,
    rel_mean: f64,
    abs_rel_q50: f64,
    abs_rel_q90: f64,
    abs_rel_q99: f64,
    abs_rel_max: f64,
    abs_rel_q999: f64,
    rel_rms: f64,
    abs_rms_pf: f64,
    excluded: usize,
    model: String,
    data: String,
    data_hash: String,
    recipe: &'a str,
    sigma_p: f64,
    worst: Vec<Worst>,
    program_version: &'static str,
}

/// Options of `evaluate`.
pub struct EvaluateOptions<'a> {
    pub model: &'a Path,
    pub data: &'a Path,
    pub json: bool,
    pub plot: Option<&'a Path>,
    pub worst: usize,
}

/// Accuracy of a model on a data set of its space.
pub fn evaluate(o: &EvaluateOptions) -> Result<()> {
    let model = Surrogate::load(o.model)?;
    if let Some(dir) = o.plot {
        std::fs::create_dir_all(dir)
            .with_context(|| format!("--plot {}: cannot create the folder", dir.display()))?;
    }
    let data = DataSet::read(o.data, &model.info.space).map_err(|e| {
        anyhow::anyhow!(
            "{e}\n(the model {} was trained on space `{}`)",
            o.model.display(),
            model.info.space.name
        )
    })?;
    let pred = model.predict_set(&data);
    let f = Figures::of(&pred, &data.c12_pf);
    let names = &model.info.inputs;
    let mut order: Vec<usize> = (0..data.len()).collect();
    let rel = |i: usize| (pred[i] - data.c12_pf[i]) / data.c12_pf[i];
    order.sort_by(|&a, &b| rel(b).abs().total_cmp(&rel(a).abs()));
    let worst: Vec<Worst> = order
        .iter()
        .take(o.worst)
        .map(|&i| Worst {
            index: data.index[i],
            inputs: names
                .iter()
                .cloned()
                .zip(data.physical_row(i).iter().copied())
                .collect(),
            c12_solver_pf: data.c12_pf[i],
            c12_surrogate_pf: pred[i],
            rel: rel(i),
        })
        .collect();
    if let Some(dir) = o.plot {
        crate::plot::surrogate_errors(&pred, &data.c12_pf, &model.info, "evaluated", dir)?;
    }
    if o.json {
        let j = EvaluateJson {
            n: f.n,
            rel_sigma: f.rel_sigma,
            rel_mean: f.rel_mean,
            abs_rel_q50: f.abs_rel_q50,
            abs_rel_q90: f.abs_rel_q90,
            abs_rel_q99: f.abs_rel_q99,
            abs_rel_max: f.abs_rel_max,
            abs_rel_q999: f.abs_rel_q999,
            rel_rms: f.rel_rms,
            abs_rms_pf: f.abs_rms_pf,
            excluded: data.excluded,
            model: o.model.display().to_string(),
            data: o.data.display().to_string(),
            data_hash: data.hash.clone(),
            recipe: &model.info.recipe_name,
            sigma_p: model.sigma_p(),
            worst,
            program_version: env!("CARGO_PKG_VERSION"),
        };
        println!("{}", serde_json::to_string(&j)?);
        return Ok(());
    }
    println!(
        "model {} (recipe {}), data {}: {} samples ({} without c12 left out)",
        o.model.display(),
        model.info.recipe_name,
        o.data.display(),
        f.n,
        data.excluded
    );
    println!(
        "relative error (c_p - c_s)/c_s: Gaussian sigma {:.4}%, mean {:+.4}%, rms {:.4}%",
        100.0 * f.rel_sigma,
        100.0 * f.rel_mean,
        100.0 * f.rel_rms
    );
    println!(
        "|relative error| quantiles: 50% {:.4}%  90% {:.4}%  99% {:.4}%  99.9% {:.4}%  max {:.4}%",
        100.0 * f.abs_rel_q50,
        100.0 * f.abs_rel_q90,
        100.0 * f.abs_rel_q99,
        100.0 * f.abs_rel_q999,
        100.0 * f.abs_rel_max
    );
    println!(
        "absolute error rms {:.4} pF; sigma_p of the model {:.4}%",
        f.abs_rms_pf,
        100.0 * model.sigma_p()
    );
    println!("worst samples:");
    for w in &worst {
        let inputs: Vec<String> = w
            .inputs
            .iter()
            .map(|(n, v)| format!("{n}={v:.4}"))
            .collect();
        println!(
            "  #{:<7} c_s {:9.4} pF  c_p {:9.4} pF  rel {:+.3}%  {}",
            w.index,
            w.c12_solver_pf,
            w.c12_surrogate_pf,
            100.0 * w.rel,
            inputs.join(" ")
        );
    }
    Ok(())
}

/// Options of `predict`.
pub struct PredictOptions<'a> {
    pub model: &'a Path,
    pub params: &'a [String],
    pub voltages: &'a [f64],
    pub json: bool,
    pub jacobian: bool,
}

/// Parses `--params`: NAME=VALUE pairs (any order, all names) or bare values in the model's order.
fn parse_params(model: &Surrogate, items: &[String]) -> Result<Vec<f64>> {
    let names = model.parameter_names();
    let parts: Vec<&str> = items
        .iter()
        .flat_map(|s| s.split(','))
        .map(str::trim)
        .filter(|s| !s.is_empty())
        .collect();
    let mut values = vec![f64::NAN; names.len()];
    let named = parts.iter().any(|p| p.contains('='));
    if named {
        for p in &parts {
            let Some((n, v)) = p.split_once('=') else {
                bail!("--params: `{p}` is not NAME=VALUE (do not mix names and bare values)");
            };
            let k = names.iter().position(|&x| x == n.trim()).with_context(|| {
                format!(
                    "--params: unknown parameter `{}`; the model takes {}",
                    n.trim(),
                    names.join(", ")
                )
            })?;
            values[k] = v
                .trim()
                .parse()
                .map_err(|_| anyhow::anyhow!("--params: `{v}` (for {n}) is not a number"))?;
        }
        if let Some(k) = values.iter().position(|v| v.is_nan()) {
            bail!(
                "--params: no value for `{}`; the model takes {}",
                names[k],
                names.join(", ")
            );
        }
    } else {
        if parts.len() != names.len() {
            bail!(
                "--params: {} values given, the model takes {} ({})",
                parts.len(),
                names.len(),
                names.join(", ")
            );
        }
        for (k, p) in parts.iter().enumerate() {
            values[k] = p.parse().map_err(|_| {
                anyhow::anyhow!("--params: `{p}` (for {}) is not a number", names[k])
            })?;
        }
    }
    if let Some(k) = values.iter().position(|v| !v.is_finite()) {
        bail!(
            "--params: `{}` = {} is not a finite number",
            names[k],
            values[k]
        );
    }
    Ok(values)
}

#[derive(Debug, Serialize)]
struct PredictJson<'a> {
    model: String,
    recipe: &'a str,
    params: Vec<(String, f64)>,
    voltages_v: &'a [f64],
    c12_pf: Vec<f64>,
    sigma_pf: Vec<f64>,
    ensemble_spread_pf: Option<Vec<f64>>,
    jacobian_pf: Option<Vec<Vec<f64>>>,
    sigma_p: f64,
    program_version: &'static str,
}

/// c12 along a curve from a model file.
pub fn predict(o: &PredictOptions) -> Result<()> {
    let model = Surrogate::load(o.model)?;
    let params = parse_params(&model, o.params)?;
    let u = model.voltages(o.voltages)?;
    let n = o.voltages.len();
    let mut c = vec![0.0; n];
    let mut spread = vec![0.0; n];
    model.curve_into(&params, &u, &mut c, Some(&mut spread))?;
    let np = model.n_params();
    let jac = if o.jacobian {
        let mut j = vec![0.0; n * np];
        let mut c2 = vec![0.0; n];
        model.curve_jacobian_into(&params, &u, &mut c2, &mut j)?;
        Some(j.chunks(np).map(<[f64]>::to_vec).collect::<Vec<_>>())
    } else {
        None
    };
    let sigma: Vec<f64> = c.iter().map(|c| model.sigma_p() * c).collect();
    let ensemble = model.members() > 1;
    if o.json {
        let j = PredictJson {
            model: o.model.display().to_string(),
            recipe: &model.info.recipe_name,
            params: model
                .parameter_names()
                .iter()
                .map(|s| s.to_string())
                .zip(params.iter().copied())
                .collect(),
            voltages_v: o.voltages,
            c12_pf: c,
            sigma_pf: sigma,
            ensemble_spread_pf: ensemble.then_some(spread),
            jacobian_pf: jac,
            sigma_p: model.sigma_p(),
            program_version: env!("CARGO_PKG_VERSION"),
        };
        println!("{}", serde_json::to_string(&j)?);
        return Ok(());
    }
    println!(
        "# model {} (recipe {}), sigma_p {:.4}%",
        o.model.display(),
        model.info.recipe_name,
        100.0 * model.sigma_p()
    );
    let mut header = "voltage_V,c12_pF,sigma_pF".to_string();
    if ensemble {
        header += ",ensemble_spread_pF";
    }
    if o.jacobian {
        for name in model.parameter_names() {
            header += &format!(",dc12/d{name}");
        }
    }
    println!("{header}");
    for k in 0..n {
        let mut line = format!("{},{:.6},{:.6}", o.voltages[k], c[k], sigma[k]);
        if ensemble {
            line += &format!(",{:.6}", spread[k]);
        }
        if let Some(j) = &jac {
            for x in &j[k] {
                line += &format!(",{x:.6e}");
            }
        }
        println!("{line}");
    }
    Ok(())
}
