//! Options of the commands that load a detector and solve fields, as a user states them: the
//! detector ([`DetectorInput`]), the backend, the potential method, the device precision and the
//! weighting mode (on top of the grid options, [`GridOverrides`]), and bias-voltage lists. The
//! command line flattens these structs (feature `clap`), so every option and default is declared
//! here once; the defaults are those of [`FieldSettings::default`].

use std::path::PathBuf;

use crate::error::{Error, Result};
#[cfg(feature = "clap")]
use crate::expr::Parameters;
use crate::field::{Backend, FieldSettings, Method, WeightingMode};
use crate::gpu::Precision;
use crate::grid::GridOverrides;

/// The detector of every command that loads one: its file, an impurity model replacing the
/// file's, and overrides of the parameters it declares.
#[derive(Debug, Clone, PartialEq)]
#[cfg_attr(feature = "clap", derive(clap::Args))]
pub struct DetectorInput {
    /// Detector description (TOML), e.g. detectors/super-siegfried-k1.toml.
    #[cfg_attr(feature = "clap", arg(long, value_name = "FILE"))]
    pub detector: PathBuf,
    /// Impurity model file (TOML) replacing the detector's default model.
    #[cfg_attr(feature = "clap", arg(long, value_name = "FILE"))]
    pub impurity: Option<PathBuf>,
    /// Override a parameter declared in the detector's `[parameters]`, e.g. --param d_li_mm=3.
    #[cfg_attr(
        feature = "clap",
        arg(
            long = "param",
            value_name = "NAME=VALUE",
            value_parser = Parameters::parse_assignment
        )
    )]
    pub params: Vec<(String, f64)>,
}

/// Backend, potential method, device precision and grid options of every command that solves
/// fields.
#[derive(Debug, Clone, PartialEq)]
#[cfg_attr(feature = "clap", derive(clap::Args))]
pub struct SolverOptions {
    /// Potential method [default: fast on the cpu backend, sor on wgpu].
    #[cfg_attr(feature = "clap", arg(long, value_enum))]
    pub method: Option<Method>,
    /// Where the potential and weighting potentials are solved.
    #[cfg_attr(
        feature = "clap",
        arg(long, value_enum, default_value_t = FieldSettings::default().backend)
    )]
    pub backend: Backend,
    /// Floating-point precision on the wgpu backend.
    #[cfg_attr(
        feature = "clap",
        arg(
            long = "gpu-precision",
            value_enum,
            default_value_t = FieldSettings::default().gpu_precision
        )
    )]
    pub gpu_precision: Precision,
    /// The grid and its accuracy.
    #[cfg_attr(feature = "clap", command(flatten))]
    pub grid: GridOverrides,
}

impl Default for SolverOptions {
    /// The defaults of [`FieldSettings::default`] (the same as the command line's).
    fn default() -> Self {
        let d = FieldSettings::default();
        Self {
            method: None,
            backend: d.backend,
            gpu_precision: d.gpu_precision,
            grid: GridOverrides::default(),
        }
    }
}

impl SolverOptions {
    /// The method a backend runs when none is given: the exact `fast` method on the cpu, the
    /// `sor` method on wgpu (the only one it has).
    pub fn default_method(backend: Backend) -> Method {
        match backend {
            Backend::Cpu => FieldSettings::default().method,
            Backend::Wgpu => Method::Sor,
        }
    }

    /// Field settings with these choices and `weighting` (the rest default; the grid options
    /// are applied per detector by [`GridOverrides::apply`]).
    pub fn field_settings(&self, weighting: WeightingMode) -> FieldSettings {
        FieldSettings {
            method: self
                .method
                .unwrap_or_else(|| Self::default_method(self.backend)),
            weighting,
            backend: self.backend,
            gpu_precision: self.gpu_precision,
            ..FieldSettings::default()
        }
    }
}

/// The weighting-potential mode of the commands that offer a choice (`simulate`,
/// `capacitance`; the others use the default).
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
#[cfg_attr(feature = "clap", derive(clap::Args))]
pub struct WeightingOptions {
    /// Weighting-potential mode.
    #[cfg_attr(
        feature = "clap",
        arg(long, value_enum, default_value_t = FieldSettings::default().weighting)
    )]
    pub weighting: WeightingMode,
}

impl Default for WeightingOptions {
    /// The mode of [`FieldSettings::default`].
    fn default() -> Self {
        Self {
            weighting: FieldSettings::default().weighting,
        }
    }
}

/// A list of bias voltages (V) as given to `--voltages`.
#[derive(Debug, Clone, PartialEq)]
pub struct VoltageList(pub Vec<f64>);

/// Most voltages a `START:STOP:STEP` list may give.
pub const MAX_VOLTAGES: usize = 100_000;

/// Parses a voltage list: "START:STOP:STEP" (inclusive of STOP when it falls on the step) or
/// "V1,V2,...". Values are checked to be finite numbers; the caller checks signs and sorts.
///
/// # Errors
/// [`Error::Syntax`] saying what was expected (the command line shows it beside the option).
pub fn parse_voltages(text: &str) -> Result<VoltageList> {
    let bad = |message: String| Error::Syntax {
        text: text.into(),
        message,
    };
    let num = |s: &str| -> Result<f64> {
        let v: f64 = s
            .trim()
            .parse()
            .map_err(|_| bad(format!("`{}` in `{text}` is not a number", s.trim())))?;
        if v.is_finite() {
            Ok(v)
        } else {
            Err(bad(format!("`{}` in `{text}` must be finite", s.trim())))
        }
    };
    if text.contains(':') {
        let parts: Vec<&str> = text.split(':').collect();
        if parts.len() != 3 {
            return Err(bad(format!("expected START:STOP:STEP, got `{text}`")));
        }
        let (a, b, s) = (num(parts[0])?, num(parts[1])?, num(parts[2])?);
        if s <= 0.0 {
            return Err(bad(format!("the step in `{text}` must be positive")));
        }
        if b < a {
            return Err(bad(format!("STOP must not be below START in `{text}`")));
        }
        let n = ((b - a) / s + 1e-9).floor() as usize;
        if n > MAX_VOLTAGES {
            return Err(bad(format!(
                "`{text}` gives more than {MAX_VOLTAGES} voltages"
            )));
        }
        Ok(VoltageList((0..=n).map(|k| a + s * k as f64).collect()))
    } else {
        text.split(',')
            .map(num)
            .collect::<Result<_>>()
            .map(VoltageList)
    }
}

/// The command line's names and one-line descriptions of the solver's closed sets (the names
/// are the types' `as_str`).
#[cfg(feature = "clap")]
mod value_enums {
    use clap::ValueEnum;
    use clap::builder::PossibleValue;

    use super::{Backend, Method, Precision, WeightingMode};

    impl ValueEnum for Method {
        fn value_variants<'a>() -> &'a [Self] {
            &[Method::Fast, Method::Sor]
        }

        fn to_possible_value(&self) -> Option<PossibleValue> {
            Some(PossibleValue::new(self.as_str()).help(match self {
                Method::Fast => {
                    "Primal-dual active set with sparse Cholesky solves (exact discrete solution)"
                }
                Method::Sor => {
                    "Red-black projected SOR (the SolidStateDetectors.jl class of method)"
                }
            }))
        }
    }

    impl ValueEnum for Backend {
        fn value_variants<'a>() -> &'a [Self] {
            &[Backend::Cpu, Backend::Wgpu]
        }

        fn to_possible_value(&self) -> Option<PossibleValue> {
            Some(PossibleValue::new(self.as_str()).help(match self {
                Backend::Cpu => "The host's cores",
                Backend::Wgpu => {
                    "A GPU through wgpu (Vulkan, Metal, DX12; Mesa's lavapipe without one): the \
                     sor method"
                }
            }))
        }
    }

    impl ValueEnum for Precision {
        fn value_variants<'a>() -> &'a [Self] {
            &[Precision::Auto, Precision::F32, Precision::F64]
        }

        fn to_possible_value(&self) -> Option<PossibleValue> {
            Some(PossibleValue::new(self.as_str()).help(match self {
                Precision::Auto => "f64 where the adapter offers shader-f64, else f32",
                Precision::F32 => "f32",
                Precision::F64 => "f64 (an error without shader-f64)",
            }))
        }
    }

    impl ValueEnum for WeightingMode {
        fn value_variants<'a>() -> &'a [Self] {
            &[WeightingMode::Conductor, WeightingMode::PaperEpsilon]
        }

        fn to_possible_value(&self) -> Option<PossibleValue> {
            Some(PossibleValue::new(self.as_str()).help(match self {
                WeightingMode::Conductor => {
                    "Undepleted regions are conductors ending at the sub-cell depletion front \
                     (exact; default)"
                }
                WeightingMode::PaperEpsilon => {
                    "The paper's approach: eps_r x 1e5 in undepleted semiconductor (for \
                     comparison)"
                }
            }))
        }
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn voltages() {
        assert_eq!(
            parse_voltages("25:125:50").unwrap().0,
            vec![25.0, 75.0, 125.0]
        );
        assert_eq!(parse_voltages("25:2975:50").unwrap().0.len(), 60);
        assert_eq!(
            parse_voltages("25, 75,125").unwrap().0,
            vec![25.0, 75.0, 125.0]
        );
        assert!(parse_voltages("25:10:5").is_err());
        assert!(parse_voltages("25:100:0").is_err());
        assert!(parse_voltages("25:100").is_err());
        assert!(parse_voltages("25,x").is_err());
        assert!(parse_voltages("nan").is_err());
    }

    #[test]
    fn method_follows_the_backend() {
        let mut o = SolverOptions::default();
        assert_eq!(
            o.field_settings(WeightingMode::Conductor).method,
            Method::Fast
        );
        o.backend = Backend::Wgpu;
        assert_eq!(
            o.field_settings(WeightingMode::Conductor).method,
            Method::Sor
        );
        o.method = Some(Method::Fast);
        assert_eq!(
            o.field_settings(WeightingMode::Conductor).method,
            Method::Fast
        );
        let s = o.field_settings(WeightingMode::PaperEpsilon);
        assert_eq!(s.weighting, WeightingMode::PaperEpsilon);
        assert_eq!(s.subcell_front, FieldSettings::default().subcell_front);
    }
}
