//! A coverage study loses nothing on interruption, extends, splits into shards, never mixes runs,
//! and fits exact-model data with the full pipeline (exact check and refinement) when asked: at CI
//! size, on a closed-form "detector" whose surrogate is a few percent off.

use std::path::{Path, PathBuf};

use hpge_foundation::Shard;
use hpge_inference::fit::{ExactCheckSettings, ExactGrids, FitSettings, RefineSettings};
use hpge_inference::sampler::{SampleSettings, SamplerKind, SamplerStop};
use hpge_inference::{CvData, CvModel, Likelihood, NoiseSettings, Prior, PriorSpec, Result};
use hpge_validation::studies::coverage::store::TruthStore;
use hpge_validation::studies::coverage::{PipelineSettings, TruthEvent, TruthEvents, progress};
use hpge_validation::{
    CoverageModels, CoverageOutcome, CoverageReport, CoverageRun, CoverageSettings, coverage,
};

const VOLTS: [f64; 8] = [10.0, 40.0, 90.0, 160.0, 250.0, 360.0, 490.0, 640.0];

/// c(U) = 60 pF / (1 + a U / 200 V) + 5 b pF; the surrogate multiplies it by 1 + 0.03 (a - 1),
/// `bias` = 0.03 (0 for the exact model itself).
struct Toy {
    bias: f64,
}

impl CvModel for Toy {
    fn inputs(&self) -> Vec<String> {
        vec!["a".into(), "b".into()]
    }
    fn domain(&self) -> Vec<[f64; 2]> {
        vec![[0.3, 3.0], [0.0, 2.0]]
    }
    fn voltages(&self) -> &[f64] {
        &VOLTS
    }
    fn has_jacobian(&self) -> bool {
        false
    }
    fn describe(&self) -> String {
        format!("toy (bias {})", self.bias)
    }
    fn sigma_rel(&self) -> f64 {
        if self.bias > 0.0 { 0.005 } else { 0.0 }
    }
    fn curve(&self, x: &[f64], c: &mut [f64]) -> Result<()> {
        for (ck, u) in c.iter_mut().zip(VOLTS) {
            *ck = (60.0 / (1.0 + x[0] * u / 200.0) + 5.0 * x[1]) * (1.0 + self.bias * (x[0] - 1.0));
        }
        Ok(())
    }
    fn curve_jacobian(&self, _x: &[f64], _c: &mut [f64], _jac: &mut [f64]) -> Result<()> {
        unreachable!("has_jacobian is false")
    }
}

fn prior(m: &dyn CvModel) -> Prior {
    let spec = PriorSpec::from_toml_str(
        "name = \"toy\"\n[[parameters]]\nname = \"a\"\nprior = { distribution = \"uniform\", lo = 0.5, hi = 2.5 }\n\
         [[parameters]]\nname = \"b\"\nprior = { distribution = \"uniform\", lo = 0.2, hi = 1.8 }\n",
        Path::new("toy.toml"),
    )
    .unwrap();
    Prior::bind(&spec, &m.inputs(), &m.domain()).unwrap()
}

fn template() -> Likelihood {
    let c12_pf: Vec<f64> = VOLTS.iter().map(|u| 40.0 - u / 40.0).collect();
    let data = CvData {
        voltage_v: VOLTS.to_vec(),
        sigma_pf: c12_pf.iter().map(|v| 0.03 * v).collect(),
        c12_pf,
        covariance_pf2: None,
        source: "toy.csv".into(),
    };
    Likelihood::new(&data, NoiseSettings::default(), 0.005).unwrap()
}

fn settings(n: usize, pipeline: Option<PipelineSettings>) -> CoverageSettings {
    let mut sample = SampleSettings::for_sampler(SamplerKind::Metropolis);
    sample.ess_min = 150.0;
    sample.mode_starts = 2;
    sample.max_seconds = 20.0;
    CoverageSettings {
        n_truths: n,
        seed: 3,
        fit: FitSettings {
            sample,
            ..FitSettings::default()
        },
        ranks: 19,
        pipeline,
    }
}

/// The full pipeline at test size: a 60-draw check, no ascents, at most 3 rounds.
fn pipeline() -> PipelineSettings {
    PipelineSettings {
        check: ExactCheckSettings {
            draws: 60,
            grids: ExactGrids::Own,
            grid_check: 0,
            ascents: 0,
        },
        refine: RefineSettings {
            max_rounds: 3,
            ..RefineSettings::default()
        },
    }
}

fn folder(name: &str) -> PathBuf {
    let d = std::env::temp_dir().join(format!("hpge-coverage-{name}-{}", std::process::id()));
    let _ = std::fs::remove_dir_all(&d);
    std::fs::create_dir_all(&d).unwrap();
    d
}

fn run(
    models: CoverageModels,
    s: &CoverageSettings,
    store: Option<&TruthStore>,
    shard: Shard,
) -> CoverageOutcome {
    run_telling(models, s, store, shard, &|_, _| {})
}

/// [`run`] with each truth's events going to `events`.
fn run_telling(
    models: CoverageModels,
    s: &CoverageSettings,
    store: Option<&TruthStore>,
    shard: Shard,
    events: TruthEvents,
) -> CoverageOutcome {
    let p = prior(models.data);
    coverage(
        models,
        &p,
        &template(),
        s,
        CoverageRun {
            store,
            shard,
            events,
        },
        &|_, _| {},
    )
    .unwrap()
}

fn done(o: CoverageOutcome) -> CoverageReport {
    match o {
        CoverageOutcome::Done(r) => *r,
        CoverageOutcome::Partial { done, total } => panic!("partial: {done} of {total}"),
    }
}

#[test]
fn a_study_resumes_extends_shards_and_never_mixes_runs() {
    let (exact, sur) = (Toy { bias: 0.0 }, Toy { bias: 0.03 });
    let models = CoverageModels {
        fit: &sur,
        data: &sur,
        data_sigma_rel: sur.sigma_rel(),
    };
    // The reference: 8 truths, nothing written.
    let whole = done(run(models, &settings(8, None), None, Shard::WHOLE));
    assert_eq!(whole.n_truths, 8);
    assert_eq!(whole.resumed, 0);
    // 5 truths written, then the same folder asked for 8: 5 taken back, 3 fitted, and the
    // statistics of the 8 those of the whole run (each truth depends on the seed and i only).
    let out = folder("extend");
    let store = TruthStore::open(&out, "run-a".into(), Shard::WHOLE).unwrap();
    let first = done(run(models, &settings(5, None), Some(&store), Shard::WHOLE));
    assert_eq!((first.n_truths, first.resumed), (5, 0));
    let files = std::fs::read_dir(out.join("truths")).unwrap().count();
    assert_eq!(files, 5);
    // Each truth's file says how its sampler ended, in agreement with its converged flag.
    for t in store.load().unwrap().values() {
        let s = t.sampler.expect("every new truth records its sampler");
        assert_eq!(t.converged, s.stop == SamplerStop::Converged, "{s:?}");
        assert!(s.draws_per_chain > 0 && s.ess_min > 0.0 && s.rhat_max.is_finite());
    }
    // A look while the store is held (the study running) sees the 5 truths of run-a, with the
    // statistics the run gave, and nothing of another run.
    let peek = progress(&out, "run-a", &prior(&sur), &settings(8, None))
        .unwrap()
        .expect("5 truths done");
    assert_eq!(peek.n_truths, 5);
    assert_eq!(peek.parameters, first.parameters);
    assert!(
        progress(&out, "run-b", &prior(&sur), &settings(8, None))
            .unwrap()
            .is_none()
    );
    let extended = done(run(models, &settings(8, None), Some(&store), Shard::WHOLE));
    assert_eq!((extended.n_truths, extended.resumed), (8, 5));
    assert_eq!(
        extended.unconverged_sampler.map_or(0, |u| u.recorded),
        extended.unconverged
    );
    assert_eq!(extended.parameters, whole.parameters);
    // A second process on the same shard of the folder is refused while the first holds it.
    assert!(TruthStore::open(&out, "run-a".into(), Shard::WHOLE).is_err());
    drop(store);
    // Another run (another fingerprint) clears the folder instead of mixing.
    let other = TruthStore::open(&out, "run-b".into(), Shard::WHOLE).unwrap();
    assert!(other.load().unwrap().is_empty());
    assert_eq!(std::fs::read_dir(out.join("truths")).unwrap().count(), 0);
    drop(other);
    // Two shards side by side on one folder: the first ends partial, the second writes the
    // report, equal to the whole run's.
    let out = folder("shards");
    let s0 = TruthStore::open(&out, "run-a".into(), Shard { k: 0, m: 2 }).unwrap();
    let s1 = TruthStore::open(&out, "run-a".into(), Shard { k: 1, m: 2 }).unwrap();
    match run(models, &settings(8, None), Some(&s0), Shard { k: 0, m: 2 }) {
        CoverageOutcome::Partial { done, total } => assert_eq!((done, total), (4, 8)),
        CoverageOutcome::Done(r) => panic!("one shard of two cannot finish: {r:?}"),
    }
    let joined = done(run(
        models,
        &settings(8, None),
        Some(&s1),
        Shard { k: 1, m: 2 },
    ));
    assert_eq!(joined.parameters, whole.parameters);
    let _ = std::fs::remove_dir_all(&out);
    let _ = std::fs::remove_dir_all(folder("extend"));
    // Exact-model data: the plain fit carries no check; with the pipeline every truth's fit
    // has an exact check that ends passing or failing after refinement.
    let on_exact = CoverageModels {
        fit: &sur,
        data: &exact,
        data_sigma_rel: 0.0,
    };
    let plain = done(run(on_exact, &settings(3, None), None, Shard::WHOLE));
    assert!(plain.exact_check.is_none());
    // Each truth tells its rounds as they go: (sampled, rounds ended, exact checks completed).
    let told = std::sync::Mutex::new((0usize, 0usize, 0usize));
    let full = done(run_telling(
        on_exact,
        &settings(3, Some(pipeline())),
        None,
        Shard::WHOLE,
        &|i, e| {
            assert!(i < 3, "truth {i}");
            let mut t = told.lock().unwrap();
            match e {
                TruthEvent::Sampled { .. } => t.0 += 1,
                TruthEvent::Round(r) => {
                    assert!(!r.resumed);
                    t.1 += 1;
                }
                TruthEvent::Exact { done, total } => {
                    assert!(done <= total, "{done}/{total}");
                    t.2 += usize::from(done == total);
                }
            }
        },
    ));
    let tally = full.exact_check.expect("the pipeline's checks");
    let rounds = (tally.rounds_mean * 3.0).round() as usize;
    assert_eq!(
        *told.lock().unwrap(),
        (rounds, rounds, rounds),
        "one sampling, one completed check and one end per round"
    );
    eprintln!("{tally:?}");
    assert_eq!(tally.passed + tally.failed, 3, "{tally:?}");
    assert!(tally.rounds_max >= 1 && tally.rounds_max <= 3, "{tally:?}");
    // The surrogate's 1.5-4.5% error fails some plain checks: those fits were refined, and
    // their draws (so the ranks) moved.
    assert!(tally.rounds_mean > 1.0, "{tally:?}");
    assert_ne!(full.parameters, plain.parameters);
    // Every fit records where its time went; the parts are positive where they ran.
    assert_eq!(tally.split_truths, 3, "{tally:?}");
    let split = tally.seconds_split.expect("the fits' time split");
    assert!(
        split.sampling > 0.0 && split.exact > 0.0 && split.error_model >= 0.0,
        "{split:?}"
    );
}

/// The exact toy model, which stops the process (a panic, as a kill would) at its first call
/// after a truth's first refinement round was written under `out`.
struct StopAfterARound<'a> {
    exact: Toy,
    out: &'a Path,
}

fn saved_rounds(out: &Path) -> usize {
    let Ok(truths) = std::fs::read_dir(out.join("truth-rounds")) else {
        return 0;
    };
    truths
        .flatten()
        .filter_map(|t| std::fs::read_dir(t.path().join("rounds")).ok())
        .map(|r| r.count())
        .sum()
}

impl CvModel for StopAfterARound<'_> {
    fn inputs(&self) -> Vec<String> {
        self.exact.inputs()
    }
    fn domain(&self) -> Vec<[f64; 2]> {
        self.exact.domain()
    }
    fn voltages(&self) -> &[f64] {
        &VOLTS
    }
    fn has_jacobian(&self) -> bool {
        false
    }
    fn describe(&self) -> String {
        "toy, stopping after a saved round".into()
    }
    fn sigma_rel(&self) -> f64 {
        0.0
    }
    fn curve(&self, x: &[f64], c: &mut [f64]) -> Result<()> {
        assert!(saved_rounds(self.out) == 0, "stopped after a saved round");
        self.exact.curve(x, c)
    }
    fn curve_jacobian(&self, _x: &[f64], _c: &mut [f64], _jac: &mut [f64]) -> Result<()> {
        unreachable!("has_jacobian is false")
    }
}

#[test]
fn a_truth_interrupted_inside_its_refinement_takes_its_rounds_back() {
    let (exact, sur) = (Toy { bias: 0.0 }, Toy { bias: 0.03 });
    let s = settings(3, Some(pipeline()));
    fn on<'a>(fit: &'a dyn CvModel, data: &'a dyn CvModel) -> CoverageModels<'a> {
        CoverageModels {
            fit,
            data,
            data_sigma_rel: 0.0,
        }
    }
    // One thread: the truths one after the other, so the stop falls inside one truth's fit.
    let one = rayon::ThreadPoolBuilder::new()
        .num_threads(1)
        .build()
        .unwrap();
    let whole = done(one.install(|| run(on(&sur, &exact), &s, None, Shard::WHOLE)));
    let out = folder("rounds");
    let stopping = StopAfterARound {
        exact: Toy { bias: 0.0 },
        out: &out,
    };
    {
        let store = TruthStore::open(&out, "run-r".into(), Shard::WHOLE).unwrap();
        let stopped = std::panic::catch_unwind(std::panic::AssertUnwindSafe(|| {
            one.install(|| run(on(&sur, &stopping), &s, Some(&store), Shard::WHOLE))
        }));
        assert!(
            stopped.is_err(),
            "the study ran through without a refined truth"
        );
    }
    // The interrupted truth's round is on disk; the study started again takes it back and ends
    // with the uninterrupted study's statistics, leaving no rounds behind.
    assert!(saved_rounds(&out) >= 1);
    let store = TruthStore::open(&out, "run-r".into(), Shard::WHOLE).unwrap();
    let again = done(one.install(|| run(on(&sur, &exact), &s, Some(&store), Shard::WHOLE)));
    assert_eq!(again.parameters, whole.parameters);
    assert_eq!(saved_rounds(&out), 0);
    assert_eq!(
        std::fs::read_dir(out.join("truth-rounds")).unwrap().count(),
        0,
        "a written truth's rounds folder is removed"
    );
    drop(store);
    let _ = std::fs::remove_dir_all(&out);
}
