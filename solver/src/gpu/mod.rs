//! The wgpu backend's device layer: adapter and device (`context.rs`), the WGSL kernels
//! (`sor.wgsl`), the dimension-free SOR problem (`stencil.rs`) and its execution (`run.rs`).
//!
//! The kernels implement red-black projected SOR on any stencil whose graph is two-coloured:
//! the (r, z) grid's 5-point stencil now, a 7-point (r, phi, z) stencil later (the host
//! assembles neighbours and normalised coefficients; the kernels only index). f64 runs where the
//! adapter has shader-f64, f32 elsewhere; the stopping rule is evaluated every `check_every`
//! sweeps from a device-side max-reduction of the updates (4 bytes read back), the potential is
//! read back once at the end, and everything downstream (undepleted nodes, capacitances) is
//! computed in f64 on the host.

mod context;
mod run;
mod stencil;
#[cfg(test)]
mod tests;

pub(crate) use context::shared;
pub use context::{AdapterReport, Precision, gpu_adapter, gpu_test_gate};
pub(crate) use run::run;
pub(crate) use stencil::{BlockRows, ColourRows, StencilProblem};
