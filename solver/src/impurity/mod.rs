//! Impurity-density models zeta(r, z) in cm^-3 (signed: positive is n-type), the paper's parameter
//! transform y -> x -> zeta with its exact inverses, the radial splines of the zeta_RZ model, and
//! the TOML description of a model (DESIGN.md, "Impurity models").
//!
//! * [`LogTransform`]: x = T(y) and zeta(x) (paper Eqs. (18)-(20)) and their inverses;
//! * [`ClampedNaturalSpline`]: y_bot(r), y_top(r);
//! * [`ImpurityModel`]: the open set of models; [`ConstantModel`], [`LinearZModel`] (the
//!   manufacturer's, Eq. (14)), [`RzModel`] (the paper's zeta_RZ, Eqs. (18)-(21)),
//!   [`ZTableModel`] and [`PolynomialZModel`] (LEGEND's quadratic z profile);
//! * [`ImpuritySpec`]: the TOML table, built into a model with an [`ImpurityContext`]; one
//!   struct of keys per model ([`ModelSpec`]), each in the model's own file.

mod constant;
mod linear_z;
mod model;
mod polynomial_z;
mod rz;
mod rz_spec;
mod solve;
mod spec;
mod spline;
mod transform;
mod z_table;

pub use constant::ConstantModel;
pub use linear_z::LinearZModel;
pub use model::{ImpurityModel, PointDensity, ScaledModel, TiltedModel};
pub use polynomial_z::PolynomialZModel;
pub use rz::RzModel;
pub(crate) use spec::explain;
pub use spec::{
    BuildModel, ConstantSpec, ImpurityContext, ImpuritySpec, Keys, LinearZSpec, ModelSpec,
    PolynomialZSpec, RzSpec, ZTableSpec, model_names,
};
pub use spline::ClampedNaturalSpline;
pub use transform::LogTransform;
pub use z_table::ZTableModel;
