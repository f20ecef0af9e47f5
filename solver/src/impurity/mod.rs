//! Impurity-density models zeta(r, z) in cm^-3 (signed: positive is n-type), the paper's parameter
//! transform y -> x -> zeta with its exact inverses, the radial splines of the zeta_RZ model, and
//! the TOML description of a model (DESIGN.md, "Impurity models").
//!
//! * [`LogTransform`]: x = T(y) and zeta(x) (paper Eqs. (18)-(20)) and their inverses;
//! * [`ClampedNaturalSpline`]: y_bot(r), y_top(r);
//! * [`ImpurityModel`]: the open set of models; [`ConstantModel`], [`LinearZModel`] (the
//!   manufacturer's, Eq. (14)) and [`RzModel`] (the paper's zeta_RZ, Eqs. (18)-(21));
//! * [`ImpuritySpec`]: the TOML table, built into a model with an [`ImpurityContext`].

mod model;
mod rz;
mod solve;
mod spec;
mod spline;
mod transform;

pub use model::{
    ConstantModel, ImpurityModel, LinearZModel, PointDensity, ScaledModel, TiltedModel, ZTableModel,
};
pub use rz::RzModel;
pub use spec::{ImpurityContext, ImpuritySpec, ModelKind};
pub use spline::ClampedNaturalSpline;
pub use transform::LogTransform;
