//! Physical constants (SI), fixed for all crates (DESIGN.md, "Conventions").

/// Elementary charge q in C (exact, SI 2019).
pub const ELEMENTARY_CHARGE_C: f64 = 1.602_176_634e-19;
/// Vacuum permittivity eps0 in F/m (CODATA 2018).
pub const VACUUM_PERMITTIVITY_F_PER_M: f64 = 8.854_187_812_8e-12;
/// Boltzmann's constant k_B in J/K (exact, SI 2019).
pub const BOLTZMANN_J_PER_K: f64 = 1.380_649e-23;
/// Relative permittivity of germanium at 78 K.
pub const EPS_R_GERMANIUM: f64 = 16.0;
/// Conversion: densities in cm^-3 times this give m^-3.
pub const CM3_TO_M3: f64 = 1.0e6;
