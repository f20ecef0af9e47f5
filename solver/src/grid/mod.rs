//! Non-uniform tensor grids in (r, z): ticks on every geometry boundary, bounded spacing and
//! spacing ratio, refinement where neighbouring potential differences are large.

mod axis;
mod deform;
mod overrides;
mod settings;
mod tensor;

pub(crate) use axis::{AxisRule, build_axis};
pub use overrides::{GridOverrides, parse_grid_setting};
pub use settings::{GridSettings, MIN_TOLERANCE};
pub use tensor::Grid;
