//! Problems with known answers: closed forms and high-precision 1D references.
//!
//! - [`planar`]: the planar p-n detector (depleted layer of a parallel-plate capacitor).
//! - [`coax`]: the infinitely long true-coaxial detector with uniform impurities.
//! - [`radial1d`]: the radial 1D reference (any radial profile, depleted layers and fronts,
//!   refined to high precision) for long coaxial and radially varying cases.
//! - [`stand_in`]: the shipped stand-in detector as the exact solver sees it, its truth, and
//!   draws of a two-mode posterior around it.

pub mod coax;
pub mod planar;
pub mod radial1d;
pub mod stand_in;
