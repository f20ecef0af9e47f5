//! Model files: safetensors with the weights (f32 as trained; the polynomial's coefficients in
//! f64) and the [`ModelInfo`] as JSON under the metadata key `hpge-cv`.

use std::collections::HashMap;
use std::path::Path;

use safetensors::tensor::{Dtype, SafeTensors, TensorView};

use super::dataset::network_order;
use super::network::{Dense, Network};
use super::polynomial::{Polynomial, monomials};
use super::steps::{BiasMap, StepsHead};
use super::surrogate::{FORMAT, FORMAT_VERSION, ModelInfo, Predictor, Surrogate};
use crate::error::{Error, Result};

const META_KEY: &str = "hpge-cv";

fn layers(net: &Network) -> Vec<(String, &Dense)> {
    let mut v: Vec<(String, &Dense)> = Vec::new();
    for (i, l) in net.trunk.iter().enumerate() {
        v.push((format!("trunk.{i}"), l));
    }
    for (i, l) in net.head.iter().enumerate() {
        v.push((format!("head.{i}"), l));
    }
    v.push(("out".into(), &net.out));
    v
}

impl Surrogate {
    /// Writes the model file.
    pub fn save(&self, path: &Path) -> Result<()> {
        let mut blobs: Vec<(String, Dtype, Vec<usize>, Vec<u8>)> = Vec::new();
        match &self.predictor {
            Predictor::Networks(nets) => {
                for (m, net) in nets.iter().enumerate() {
                    for (name, l) in layers(net) {
                        let w: Vec<u8> = l
                            .row_major()
                            .iter()
                            .flat_map(|&x| (x as f32).to_le_bytes())
                            .collect();
                        let b: Vec<u8> =
                            l.b.iter().flat_map(|&x| (x as f32).to_le_bytes()).collect();
                        blobs.push((
                            format!("m{m}.{name}.weight"),
                            Dtype::F32,
                            vec![l.n_out, l.n_in],
                            w,
                        ));
                        blobs.push((format!("m{m}.{name}.bias"), Dtype::F32, vec![l.n_out], b));
                    }
                }
            }
            Predictor::Polynomial(p) => {
                let a: Vec<u8> = p
                    .coefficients
                    .iter()
                    .flat_map(|x| x.to_le_bytes())
                    .collect();
                blobs.push((
                    "poly.coefficients".into(),
                    Dtype::F64,
                    vec![p.coefficients.len()],
                    a,
                ));
            }
        }
        let views: Vec<(String, TensorView<'_>)> = blobs
            .iter()
            .map(|(n, t, s, d)| {
                TensorView::new(*t, s.clone(), d)
                    .map(|v| (n.clone(), v))
                    .map_err(|e| Error::Invalid {
                        file: path.into(),
                        key: n.clone(),
                        message: e.to_string(),
                    })
            })
            .collect::<Result<_>>()?;
        let meta = serde_json::to_string(&self.info).map_err(|e| Error::Invalid {
            file: path.into(),
            key: "metadata".into(),
            message: e.to_string(),
        })?;
        let info = HashMap::from([(META_KEY.to_string(), meta)]);
        let bytes = safetensors::serialize(views, Some(info)).map_err(|e| Error::Io {
            file: path.into(),
            action: "cannot write the model file",
            source: std::io::Error::other(e.to_string()),
        })?;
        write_replacing(path, &bytes).map_err(|e| Error::Io {
            file: path.into(),
            action: "cannot write the model file",
            source: e,
        })
    }

    /// Reads a model file written by [`Self::save`]; refuses other formats and versions.
    pub fn load(path: &Path) -> Result<Self> {
        let bytes = std::fs::read(path).map_err(|e| Error::Io {
            file: path.into(),
            action: "cannot read the model file",
            source: e,
        })?;
        let bad = |key: &str, message: String| Error::Invalid {
            file: path.into(),
            key: key.into(),
            message,
        };
        let st = SafeTensors::deserialize(&bytes)
            .map_err(|e| bad("safetensors", format!("not a safetensors file: {e}")))?;
        let (_, meta) = SafeTensors::read_metadata(&bytes)
            .map_err(|e| bad("safetensors", format!("unreadable header: {e}")))?;
        let text = meta
            .metadata()
            .as_ref()
            .and_then(|m| m.get(META_KEY))
            .ok_or_else(|| {
                bad(
                    "metadata",
                    format!("no `{META_KEY}` entry: not an hpge-cv model"),
                )
            })?;
        let value: serde_json::Value =
            serde_json::from_str(text).map_err(|e| bad("metadata", format!("not JSON: {e}")))?;
        let format = value.get("format").and_then(|v| v.as_str()).unwrap_or("");
        let version = value
            .get("format_version")
            .and_then(|v| v.as_u64())
            .unwrap_or(0);
        if format != FORMAT {
            return Err(bad(
                "metadata.format",
                format!("`{format}`, expected `{FORMAT}`"),
            ));
        }
        if version != u64::from(FORMAT_VERSION) {
            let program = value
                .get("program_version")
                .and_then(|v| v.as_str())
                .unwrap_or("?");
            return Err(bad(
                "metadata.format_version",
                format!(
                    "version {version} (written by hpge-cv {program}); this hpge-cv {} reads \
                     version {FORMAT_VERSION}: retrain the model with this version",
                    env!("CARGO_PKG_VERSION")
                ),
            ));
        }
        let mut info: ModelInfo = serde_json::from_value(value)
            .map_err(|e| bad("metadata", format!("does not fit the model schema: {e}")))?;
        info.space.file = path.into();
        let tensor = |name: &str, dtype: Dtype| -> Result<(Vec<usize>, Vec<f64>)> {
            let t = st
                .tensor(name)
                .map_err(|e| bad(name, format!("missing tensor: {e}")))?;
            if t.dtype() != dtype {
                return Err(bad(
                    name,
                    format!("dtype {:?}, expected {dtype:?}", t.dtype()),
                ));
            }
            let data = match dtype {
                Dtype::F32 => t
                    .data()
                    .chunks_exact(4)
                    .map(|c| f64::from(f32::from_le_bytes(c.try_into().expect("4 bytes"))))
                    .collect(),
                _ => t
                    .data()
                    .chunks_exact(8)
                    .map(|c| f64::from_le_bytes(c.try_into().expect("8 bytes")))
                    .collect(),
            };
            // A weight that is not a number would make every prediction NaN (issue 66).
            let data: Vec<f64> = data;
            if let Some(k) = data.iter().position(|v| !v.is_finite()) {
                return Err(bad(
                    name,
                    format!(
                        "element {k} is {}: a model's weights must be finite numbers (a \
                         training that diverged, or a damaged file)",
                        data[k]
                    ),
                ));
            }
            Ok((t.shape().to_vec(), data))
        };
        let n_params = info.space.dim().saturating_sub(1);
        let predictor = match &info.recipe {
            Some(recipe) => {
                recipe
                    .validate()
                    .map_err(|e| bad("metadata.recipe", e.to_string()))?;
                let steps = match recipe.architecture.steps {
                    Some(count) => {
                        let order = network_order(&info.space)?;
                        let bias = &info.space.dimensions[order[n_params]];
                        let bias =
                            BiasMap::of(bias).map_err(|e| bad("metadata.space", e.to_string()))?;
                        Some(StepsHead {
                            count,
                            bias,
                            gate: recipe.architecture.gate,
                        })
                    }
                    None => None,
                };
                let mut nets = Vec::new();
                for m in 0..recipe.members {
                    let dense = |name: String, n_in: usize, n_out: usize| -> Result<Dense> {
                        let (ws, w) = tensor(&format!("m{m}.{name}.weight"), Dtype::F32)?;
                        let (_, b) = tensor(&format!("m{m}.{name}.bias"), Dtype::F32)?;
                        if ws != [n_out, n_in] || b.len() != n_out {
                            return Err(bad(
                                &format!("m{m}.{name}.weight"),
                                format!("shape {ws:?}, the recipe needs [{n_out}, {n_in}]"),
                            ));
                        }
                        Ok(Dense::from_row_major(n_out, n_in, &w, &b))
                    };
                    let arch = &recipe.architecture;
                    let mut width = n_params;
                    let mut trunk = Vec::new();
                    for (i, &w) in arch.trunk.iter().enumerate() {
                        trunk.push(dense(format!("trunk.{i}"), width, w)?);
                        width = w;
                    }
                    if steps.is_none() {
                        width += 1;
                    }
                    let mut head = Vec::new();
                    for (i, &w) in arch.head.iter().enumerate() {
                        head.push(dense(format!("head.{i}"), width, w)?);
                        width = w;
                    }
                    let out = dense("out".into(), width, steps.map_or(1, |s| s.outputs()))?;
                    nets.push(Network {
                        n_params,
                        trunk,
                        head,
                        out,
                        steps,
                    });
                }
                Predictor::Networks(nets)
            }
            None => {
                let (_, a) = tensor("poly.coefficients", Dtype::F64)?;
                let mons = monomials(n_params + 1, 3);
                if a.len() != mons.len() {
                    return Err(bad(
                        "poly.coefficients",
                        format!("{} values, expected {}", a.len(), mons.len()),
                    ));
                }
                Predictor::Polynomial(Polynomial {
                    dim: n_params + 1,
                    degree: 3,
                    monomials: mons,
                    coefficients: a,
                })
            }
        };
        Surrogate::new(info, predictor)
    }
}

/// Writes `bytes` to `<path>.tmp` and renames it onto `path`: a reader never sees a half-written
/// model, and the file gets the permissions of every other output (0666 less the umask, 0644
/// usually; safetensors' own `serialize_to_file` goes through a temporary file created 0600).
fn write_replacing(path: &Path, bytes: &[u8]) -> std::io::Result<()> {
    hpge_files::write(path, bytes)
}
