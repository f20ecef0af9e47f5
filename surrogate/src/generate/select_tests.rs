//! `generate --where`: the refusals (share, space, detector), and the choice: the top share of
//! the candidates by the committee's disagreement, the same on every call.

use std::path::{Path, PathBuf};

use hpge_solver::FieldSettings;

use super::{SelectionInfo, committee_scores};
use crate::generate::{Generator, Shard};
use crate::model::Surrogate;
use crate::sequence::SequenceKind;
use crate::space::ParameterSpace;

fn repo(p: &str) -> PathBuf {
    PathBuf::from(env!("CARGO_MANIFEST_DIR")).join("..").join(p)
}

const DEFAULT: &str = "models/super-siegfried-rz-split-steps-t256-256-256-hd128-wd0.01.safetensors";
const PAPER: &str = "models/super-siegfried-rz-paper.safetensors";

fn generator(space: &str, detector: &Path, n: u64) -> Generator {
    let space = ParameterSpace::from_file(&repo(space)).unwrap();
    Generator::new(
        space,
        detector,
        FieldSettings::default(),
        SequenceKind::Golden,
        0,
        700_000,
        n,
        Shard::WHOLE,
    )
    .unwrap()
}

fn model(file: &str) -> (String, Vec<u8>, Surrogate) {
    let path = repo(file);
    (
        file.to_string(),
        std::fs::read(&path).unwrap(),
        Surrogate::load(&path).unwrap(),
    )
}

#[test]
fn a_share_outside_0_1_a_model_of_another_space_or_detector_are_refused_naming_both() {
    let det = repo("detectors/super-siegfried-k1.toml");
    let models = [model(DEFAULT)];
    for share in [0.0, -0.5, 1.5, f64::NAN] {
        let e = generator("spaces/super-siegfried-rz.toml", &det, 10)
            .with_selection(&models, share)
            .unwrap_err()
            .to_string();
        assert!(e.contains("--share") && e.contains("(0, 1]"), "{e}");
    }
    let slice = generator("spaces/super-siegfried-bz-slice.toml", &det, 10);
    let e = slice
        .clone()
        .with_selection(&models, 0.5)
        .unwrap_err()
        .to_string();
    assert!(
        e.contains("--where")
            && e.contains(&slice.fingerprint.space_hash)
            && e.contains("super-siegfried-rz"),
        "{e}"
    );
    // The same detector with one more comment line: another hash.
    let dir = std::env::temp_dir().join(format!("hpge-where-det-{}", std::process::id()));
    std::fs::create_dir_all(&dir).unwrap();
    let copy = dir.join("super-siegfried-k1.toml");
    let text = std::fs::read_to_string(&det).unwrap();
    std::fs::write(&copy, format!("# a copy\n{text}")).unwrap();
    let g = generator("spaces/super-siegfried-rz.toml", &copy, 10);
    let e = g
        .clone()
        .with_selection(&models, 0.5)
        .unwrap_err()
        .to_string();
    let trained = models[0].2.info.detector.as_ref().unwrap().hash.clone();
    assert!(
        trained != g.fingerprint.detector_hash
            && e.contains(&trained)
            && e.contains(&g.fingerprint.detector_hash),
        "{e}"
    );
    let _ = std::fs::remove_dir_all(&dir);
}

#[test]
fn the_top_share_by_committee_disagreement_is_chosen_the_same_every_time() {
    let det = repo("detectors/super-siegfried-k1.toml");
    let n = 200;
    let models = [model(DEFAULT), model(PAPER)];
    let g = generator("spaces/super-siegfried-rz.toml", &det, n)
        .with_selection(&models, 0.1)
        .unwrap();
    let chosen: Vec<u64> = g.units().collect();
    assert_eq!(chosen.len(), 20);
    assert!(chosen.windows(2).all(|w| w[0] < w[1]));
    assert!(chosen.iter().all(|&i| (700_000..700_000 + n).contains(&i)));
    // Every chosen candidate scores at least as high as every other.
    let loaded: Vec<&Surrogate> = models.iter().map(|m| &m.2).collect();
    let xs: Vec<Vec<f64>> = (700_000..700_000 + n)
        .map(|i| g.space.from_sampled_unit(&g.sequence.point(i)).1)
        .collect();
    let scores = committee_scores(&loaded, &g, &xs).unwrap();
    assert!(scores.iter().all(|s| s.is_finite() && *s >= 0.0));
    let score = |i: u64| scores[(i - 700_000) as usize];
    let low = chosen
        .iter()
        .map(|&i| score(i))
        .fold(f64::INFINITY, f64::min);
    let high_out = (700_000..700_000 + n)
        .filter(|i| !chosen.contains(i))
        .map(score)
        .fold(0.0, f64::max);
    assert!(low >= high_out, "{low} < {high_out}");
    // The committee's spread where it chose is several times its median.
    let mut all = scores.clone();
    all.sort_by(f64::total_cmp);
    assert!(
        low > 2.0 * all[all.len() / 2],
        "{low} vs median {}",
        all[all.len() / 2]
    );
    // Deterministic, recorded in the fingerprint; shards split the chosen rows.
    let again = generator("spaces/super-siegfried-rz.toml", &det, n)
        .with_selection(&models, 0.1)
        .unwrap();
    assert_eq!(again.units().collect::<Vec<_>>(), chosen);
    let info: &SelectionInfo = g.fingerprint.selection.as_ref().unwrap();
    assert_eq!(
        (info.share, info.score.as_str(), info.models.len()),
        (0.1, "committee", 2)
    );
    let mut sharded = g.clone();
    sharded.shard = Shard { k: 1, m: 3 };
    let part: Vec<u64> = sharded.units().collect();
    assert!(
        part.iter()
            .all(|i| chosen.contains(i) && (i - 700_000) % 3 == 1)
    );
    // One single-network model alone scores by its own sigma_s.
    let solo = generator("spaces/super-siegfried-rz.toml", &det, n)
        .with_selection(&models[..1], 0.1)
        .unwrap();
    assert_eq!(solo.fingerprint.selection.unwrap().score, "sigma_s");
}
