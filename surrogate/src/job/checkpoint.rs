//! The files of a training run beside its model: the learning curves (`NAME.curves.csv`) and the
//! checkpoints of finished ensemble members (`NAME.partial/member-M.safetensors` with
//! `member-M.curves.csv`), from which an interrupted run resumes.

use std::path::{Path, PathBuf};

use crate::model::{EpochRecord, Member, ModelInfo, Predictor, Recipe, Surrogate};
use crate::{Error, Result};

/// The learning-curve CSV beside a model: models/NAME.safetensors -> models/NAME.curves.csv.
pub fn curves_path(model: &Path) -> PathBuf {
    model.with_extension("curves.csv")
}

/// Where finished ensemble members of an unfinished run wait: models/NAME.partial/.
pub fn partial_dir(model: &Path) -> PathBuf {
    model.with_extension("partial")
}

/// Writes learning curves: the header `member,epoch,cycle,lr,train_loss,test_loss,test_rel_rms,
/// seconds`, one line per epoch (losses in `{:e}`, seconds with 3 decimals), no comment lines;
/// the provenance (this program's version, `model`) goes to the sidecar `<stem>.json`
/// (`NAME.curves.csv` -> `NAME.curves.json`).
pub fn write_curves(path: &Path, curves: &[EpochRecord], model: &Path) -> Result<()> {
    let failed = |source| Error::RunFile {
        action: "cannot write the learning curves",
        file: path.into(),
        source,
    };
    let mut text =
        String::from("member,epoch,cycle,lr,train_loss,test_loss,test_rel_rms,seconds\n");
    for r in curves {
        text += &format!(
            "{},{},{},{:e},{:e},{:e},{:e},{:.3}\n",
            r.member, r.epoch, r.cycle, r.lr, r.train_loss, r.test_loss, r.test_rel_rms, r.seconds
        );
    }
    hpge_files::write(path, text.as_bytes()).map_err(failed)?;
    let sidecar = path.with_extension("json");
    let meta = serde_json::json!({
        "program": "hpge-cv",
        "version": env!("CARGO_PKG_VERSION"),
        "what": "learning curves: mean loss over each set after every epoch",
        "model": model.display().to_string(),
        "csv": path.file_name().map(|n| n.to_string_lossy().into_owned()),
    });
    hpge_files::write(&sidecar, format!("{meta:#}\n").as_bytes()).map_err(|source| Error::RunFile {
        action: "cannot write the learning curves' sidecar",
        file: sidecar.clone(),
        source,
    })
}

/// Reads the learning curves of checkpoint member `m` (the lines [`write_curves`] writes).
fn read_curves(path: &Path, m: usize) -> Result<Vec<EpochRecord>> {
    let text = std::fs::read_to_string(path).map_err(|source| Error::RunFile {
        action: "cannot read",
        file: path.into(),
        source,
    })?;
    let mut records = Vec::new();
    for line in text
        .lines()
        .filter(|l| !l.starts_with('#') && !l.starts_with("member"))
    {
        let record = EpochRecord::from_csv_line(line).ok_or_else(|| Error::Parse {
            file: path.into(),
            message: format!("malformed line `{line}`"),
        })?;
        records.push(EpochRecord {
            member: m,
            ..record
        });
    }
    Ok(records)
}

/// Checkpoints member m in `dir` (a one-member model file plus its learning curves).
pub fn save_member(dir: &Path, info: &ModelInfo, m: usize, member: &Member) -> Result<()> {
    std::fs::create_dir_all(dir).map_err(|source| Error::RunFile {
        action: "cannot create the checkpoint folder",
        file: dir.into(),
        source,
    })?;
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

/// Members finished by an interrupted run with the same recipe, seed and data (members 0, 1, ...
/// as long as both files of each are in `dir`; none without the folder). Refuses a checkpoint of
/// other settings ([`Error::Checkpoint`]).
pub fn resume_members(dir: &Path, info: &ModelInfo) -> Result<Vec<Member>> {
    let mut done = Vec::new();
    loop {
        let m = done.len();
        let file = dir.join(format!("member-{m}.safetensors"));
        let curves = dir.join(format!("member-{m}.curves.csv"));
        if !file.is_file() || !curves.is_file() {
            return Ok(done);
        }
        let s = Surrogate::load(&file)?;
        // A checkpoint holds one member: the recipes must agree in all but the member count.
        let one = |r: &Option<Recipe>| r.clone().map(|r| Recipe { members: 1, ..r });
        let same = s.info.recipe_name == info.recipe_name
            && one(&s.info.recipe) == one(&info.recipe)
            && s.info.seed == info.seed
            && s.info.training.hash == info.training.hash
            && s.info.test.hash == info.test.hash
            && s.info.space.dimensions == info.space.dimensions;
        if !same {
            return Err(Error::Checkpoint {
                message: format!(
                    "a checkpoint of another run (recipe, its epochs or loss, seed or data differ); remove the \
                     folder {} or choose another --out",
                    dir.display()
                ),
                file,
            });
        }
        let net = match s.predictor {
            Predictor::Networks(nets) => nets.into_iter().next(),
            Predictor::Polynomial(_) => None,
        };
        let Some(net) = net else {
            return Err(Error::Checkpoint {
                file,
                message: "not a network checkpoint".into(),
            });
        };
        let records = read_curves(&curves, m)?;
        done.push((net, records));
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    /// Learning curves as written before issue 22 (a leading `#` line, as the shipped
    /// models/*.curves.csv still are) read as well as today's plain tables.
    #[test]
    fn reads_old_curves_with_a_comment_line_and_new_ones_without() {
        let d = std::env::temp_dir().join(format!("hpge-curves-old-{}", std::process::id()));
        std::fs::create_dir_all(&d).unwrap();
        let rows = "member,epoch,cycle,lr,train_loss,test_loss,test_rel_rms,seconds\n\
                    0,1,1,1e-2,2e0,3e0,1e-1,0.100\n0,2,1,1e-2,1e0,2e0,5e-2,0.200\n";
        let old = d.join("old.curves.csv");
        std::fs::write(
            &old,
            format!("# learning curves of m.safetensors (hpge-cv 0.1.0): mean loss\n{rows}"),
        )
        .unwrap();
        let a = read_curves(&old, 3).unwrap();
        assert_eq!(a.len(), 2);
        assert_eq!(a[1].member, 3);
        assert_eq!(a[1].train_loss, 1.0);
        // Today's: written without a comment line, with the sidecar; read back the same.
        let new = d.join("new.curves.csv");
        write_curves(&new, &a, Path::new("m.safetensors")).unwrap();
        let text = std::fs::read_to_string(&new).unwrap();
        assert!(text.starts_with("member,epoch,"), "{text}");
        assert!(!text.contains('#'), "{text}");
        assert_eq!(read_curves(&new, 3).unwrap(), a);
        let side: serde_json::Value =
            serde_json::from_str(&std::fs::read_to_string(d.join("new.curves.json")).unwrap())
                .unwrap();
        assert_eq!(side["model"], "m.safetensors");
        assert_eq!(side["version"], env!("CARGO_PKG_VERSION"));
        let _ = std::fs::remove_dir_all(&d);
    }
}
