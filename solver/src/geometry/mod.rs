//! Axisymmetric (r, z) geometry: primitives, constructive solid geometry and the file format.
//!
//! Every solid is a closed set in the half plane r >= 0 (mm) that is revolved about the z axis.
//! Membership tests take a tolerance: `tol > 0` grows the set (a point on or within `tol` of the
//! boundary counts), `tol < 0` shrinks it (interior points only).

mod bbox;
mod primitive;
mod sampling;
mod solid;
mod spec;

pub use bbox::BoundingBox;
pub use primitive::Primitive;
pub(crate) use sampling::common_point;
pub use solid::Solid;
pub(crate) use solid::sorted_unique;
pub(crate) use spec::SolidSpec;

/// Membership tolerance (mm) used for "on the boundary counts as inside".
pub(crate) const BOUNDARY_TOL_MM: f64 = 1e-9;
