//! Materials: relative permittivity and whether the material conducts.
//!
//! A small built-in library covers what HPGe setups are made of; a detector file can add or
//! override entries in its `[materials]` table.

use serde::{Deserialize, Serialize};

/// A material of the r-z model.
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
pub struct Material {
    /// Name as used in the detector file.
    pub name: String,
    /// Relative permittivity eps_r (dimensionless). Irrelevant for conductors.
    pub eps_r: f64,
    /// True for metals: a conducting body is an equipotential (grounded or floating).
    #[serde(default)]
    pub conductor: bool,
}

/// Built-in materials: (name, eps_r, conductor, source of the value).
///
/// eps_r(Ge) = 16.0 is fixed by DESIGN.md (SolidStateDetectors.jl uses the same value); vacuum 1 by
/// definition; PTFE 2.1 and Kapton 3.4 are handbook values at low temperature; liquid argon 1.505
/// (87 K); the metals are conductors (their eps_r is never used).
const LIBRARY: &[(&str, f64, bool)] = &[
    ("HPGe", 16.0, false),
    ("vacuum", 1.0, false),
    ("copper", 1.0, true),
    ("aluminium", 1.0, true),
    ("PTFE", 2.1, false),
    ("kapton", 3.4, false),
    ("LAr", 1.505, false),
];

impl Material {
    /// The built-in material called `name`, if there is one.
    ///
    /// ```
    /// use hpge_solver::material::Material;
    /// let ge = Material::builtin("HPGe").expect("built in");
    /// assert_eq!((ge.eps_r, ge.conductor), (16.0, false));
    /// assert!(Material::builtin("copper").unwrap().conductor);
    /// assert!(Material::builtin("germanium").is_none(), "names are exact");
    /// ```
    pub fn builtin(name: &str) -> Option<Material> {
        LIBRARY
            .iter()
            .find(|(n, _, _)| *n == name)
            .map(|&(n, eps_r, conductor)| Material {
                name: n.to_string(),
                eps_r,
                conductor,
            })
    }

    /// Names of all built-in materials.
    pub fn builtin_names() -> Vec<&'static str> {
        LIBRARY.iter().map(|(n, _, _)| *n).collect()
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn germanium_and_vacuum() {
        assert_eq!(Material::builtin("HPGe").unwrap().eps_r, 16.0);
        assert_eq!(Material::builtin("vacuum").unwrap().eps_r, 1.0);
        assert!(Material::builtin("copper").unwrap().conductor);
        assert!(Material::builtin("unobtainium").is_none());
        assert!(Material::builtin_names().contains(&"PTFE"));
    }
}
