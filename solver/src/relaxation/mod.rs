//! The SOR iteration's settings (over-relaxation factor, tolerance, sweep limits) and its stopping
//! rule, shared by the CPU sweeps (`field/sor/`) and the wgpu device layer (`gpu/`).

mod settings;
mod stop;

pub use settings::{SorSettings, default_omega};
pub(crate) use stop::StopRule;
