//! From a parsed [`DetectorSpec`] to a checked [`Detector`]: expressions evaluated, materials
//! resolved, and every consistency rule checked with a message naming the key.

use std::collections::{BTreeMap, BTreeSet};
use std::path::Path;
use std::sync::Arc;

use super::spec::{DetectorSpec, MaterialSpec, PotentialSpec};
use super::{Contact, ContactPotential, Detector, Passive, PassiveKind, Semiconductor, World};
use crate::error::{DetectorPart, Error, Result};
use crate::expr::Parameters;
use crate::geometry::{BOUNDARY_TOL_MM, Solid, common_point};
use crate::impurity::{ImpurityContext, ImpurityModel, ImpuritySpec};
use crate::material::Material;

/// Shrinkage (mm) used when testing for interior overlap.
const INTERIOR_TOL_MM: f64 = 1e-6;

pub(crate) fn build(spec: &DetectorSpec, file: &Path, overrides: &Parameters) -> Result<Detector> {
    let params = parameters(spec, file, overrides)?;
    let materials = materials(spec, file)?;
    let lookup = |name: &str, key: &str| -> Result<Material> {
        materials.get(name).cloned().ok_or_else(|| {
            Error::invalid(
                file,
                key,
                format!(
                    "unknown material `{name}` (known: {})",
                    materials.keys().cloned().collect::<Vec<_>>().join(", ")
                ),
            )
        })
    };

    // World.
    let w = &spec.world;
    let num = |q: &crate::expr::Quantity, key: &str| {
        q.eval(&params)
            .map_err(|e| Error::invalid(file, key, e.to_string()))
    };
    let r_max = num(&w.r_max_mm, "world.r_max_mm")?;
    let z_min = num(&w.z_min_mm, "world.z_min_mm")?;
    let z_max = num(&w.z_max_mm, "world.z_max_mm")?;
    if r_max <= 0.0 {
        return Err(Error::invalid(
            file,
            "world.r_max_mm",
            format!("must be positive, got {r_max} mm"),
        ));
    }
    if z_max <= z_min {
        return Err(Error::invalid(
            file,
            "world.z_max_mm",
            format!("must be larger than world.z_min_mm ({z_min} mm), got {z_max} mm"),
        ));
    }
    let medium = lookup(&w.medium, "world.medium")?;
    if medium.conductor {
        return Err(Error::invalid(
            file,
            "world.medium",
            format!(
                "`{}` is a conductor; the world medium must be an insulator",
                medium.name
            ),
        ));
    }
    let world = World {
        r_max_mm: r_max,
        z_min_mm: z_min,
        z_max_mm: z_max,
        medium,
        boundaries: [w.boundary.r_max, w.boundary.z_min, w.boundary.z_max],
        labels: [
            w.label.r_max.clone(),
            w.label.z_min.clone(),
            w.label.z_max.clone(),
        ],
    };
    let wbox = world.bbox();
    let inside_world = |s: &Solid, key: &str, what: &str| -> Result<()> {
        let b = s.bbox();
        if !wbox.contains_box(&b, BOUNDARY_TOL_MM) {
            return Err(Error::invalid(
                file,
                key,
                format!(
                    "{what} extends outside the world: it spans r in [{}, {}] mm, z in [{}, {}] mm, the world is r in [0, {}] mm, z in [{}, {}] mm",
                    b.r_min_mm, b.r_max_mm, b.z_min_mm, b.z_max_mm, r_max, z_min, z_max
                ),
            ));
        }
        Ok(())
    };

    // Semiconductor.
    let s = &spec.semiconductor;
    let sc_geometry = s.geometry.build(&params, file, "semiconductor.geometry")?;
    if sc_geometry.is_surface_only() {
        return Err(Error::invalid(
            file,
            "semiconductor.geometry",
            "the crystal must be a volume, not only surfaces",
        ));
    }
    inside_world(&sc_geometry, "semiconductor.geometry", "the semiconductor")?;
    let sc_material = lookup(&s.material, "semiconductor.material")?;
    if sc_material.conductor {
        return Err(Error::invalid(
            file,
            "semiconductor.material",
            format!("`{}` is a conductor", sc_material.name),
        ));
    }
    let sb = sc_geometry.bbox();
    let z_bottom = match &s.z_bottom_mm {
        Some(q) => num(q, "semiconductor.z_bottom_mm")?,
        None => sb.z_min_mm,
    };
    let z_top = match &s.z_top_mm {
        Some(q) => num(q, "semiconductor.z_top_mm")?,
        None => sb.z_max_mm,
    };
    if z_top <= z_bottom {
        return Err(Error::invalid(
            file,
            "semiconductor.z_top_mm",
            format!("must be larger than z_bottom_mm ({z_bottom} mm), got {z_top} mm"),
        ));
    }
    if let Some(knots) = &s.rz_knots_mm {
        check_knots(knots, file, "semiconductor.rz_knots_mm")?;
        check_knots_in_crystal(knots, sb.r_max_mm, file, "semiconductor.rz_knots_mm")?;
    }
    if let Some(knots) = s.impurity.knots_mm() {
        check_knots_in_crystal(knots, sb.r_max_mm, file, "semiconductor.impurity.knots_mm")?;
    }
    let impurity_context = ImpurityContext {
        z_bottom_mm: z_bottom,
        z_top_mm: z_top,
        default_knots_mm: s.rz_knots_mm.clone(),
        parameters: params.clone(),
    };
    let impurity: Arc<dyn ImpurityModel> = Arc::from(s.impurity.build(
        &impurity_context,
        file,
        "semiconductor.impurity",
    )?);
    let semiconductor = Semiconductor {
        name: s.name.clone().unwrap_or_else(|| "crystal".to_string()),
        material: sc_material,
        geometry: sc_geometry,
        impurity_context,
        impurity,
        impurity_spec: s.impurity.clone(),
        impurity_file: file.to_path_buf(),
    };

    // Contacts.
    if spec.contacts.is_empty() {
        return Err(Error::invalid(
            file,
            "contacts",
            "a detector needs at least one contact",
        ));
    }
    let mut ids = BTreeSet::new();
    let mut contacts = Vec::with_capacity(spec.contacts.len());
    for (i, c) in spec.contacts.iter().enumerate() {
        let key = format!("contacts[{i}]");
        if !ids.insert(c.id) {
            return Err(Error::invalid(
                file,
                format!("{key}.id"),
                format!("contact id {} is used twice", c.id),
            ));
        }
        let geometry = c
            .geometry
            .build(&params, file, &format!("{key}.geometry"))?;
        inside_world(
            &geometry,
            &format!("{key}.geometry"),
            &format!("contact `{}`", c.name),
        )?;
        let potential = match c.potential {
            PotentialSpec::Bias => ContactPotential::Bias,
            PotentialSpec::Volts(v) if v.is_finite() => ContactPotential::Fixed(v),
            PotentialSpec::Volts(v) => {
                return Err(Error::invalid(
                    file,
                    format!("{key}.potential"),
                    format!("must be finite, got {v}"),
                ));
            }
        };
        if common_point(
            &geometry,
            &semiconductor.geometry,
            BOUNDARY_TOL_MM,
            BOUNDARY_TOL_MM,
        )
        .is_none()
        {
            return Err(Error::invalid(
                file,
                format!("{key}.geometry"),
                format!("contact `{}` does not touch the semiconductor", c.name),
            ));
        }
        contacts.push(Contact {
            id: c.id,
            name: c.name.clone(),
            potential,
            geometry,
        });
    }
    for i in 0..contacts.len() {
        for j in i + 1..contacts.len() {
            if let Some((r, z)) = common_point(
                &contacts[i].geometry,
                &contacts[j].geometry,
                BOUNDARY_TOL_MM,
                BOUNDARY_TOL_MM,
            ) {
                return Err(Error::Overlap {
                    file: file.to_path_buf(),
                    parts: Box::new([
                        DetectorPart::new(
                            format!("contacts[{i}].geometry"),
                            format!("contact {}", contacts[i].label()),
                        ),
                        DetectorPart::new(
                            format!("contacts[{j}].geometry"),
                            format!("contact {}", contacts[j].label()),
                        ),
                    ]),
                    r_mm: r,
                    z_mm: z,
                });
            }
        }
    }

    // Passives.
    let mut passives = Vec::with_capacity(spec.passives.len());
    for (i, p) in spec.passives.iter().enumerate() {
        let key = format!("passives[{i}]");
        let geometry = p
            .geometry
            .build(&params, file, &format!("{key}.geometry"))?;
        inside_world(
            &geometry,
            &format!("{key}.geometry"),
            &format!("passive `{}`", p.name),
        )?;
        let material = match (&p.material, p.kind) {
            (Some(m), _) => lookup(m, &format!("{key}.material"))?,
            (None, PassiveKind::Dielectric) => {
                return Err(Error::invalid(
                    file,
                    format!("{key}.material"),
                    "a dielectric passive needs a material",
                ));
            }
            (None, _) => lookup("copper", &format!("{key}.material"))?,
        };
        match (p.kind, material.conductor) {
            (PassiveKind::Dielectric, true) => {
                return Err(Error::invalid(
                    file,
                    format!("{key}.material"),
                    format!(
                        "`{}` is a conductor but the passive is a dielectric",
                        material.name
                    ),
                ));
            }
            (PassiveKind::Grounded | PassiveKind::Floating, false) => {
                return Err(Error::invalid(
                    file,
                    format!("{key}.material"),
                    format!(
                        "`{}` is an insulator but the passive is a conductor",
                        material.name
                    ),
                ));
            }
            _ => {}
        }
        if geometry.is_surface_only() && p.kind == PassiveKind::Dielectric {
            return Err(Error::invalid(
                file,
                format!("{key}.geometry"),
                "a dielectric must be a volume",
            ));
        }
        if let Some((r, z)) = common_point(
            &geometry,
            &semiconductor.geometry,
            -INTERIOR_TOL_MM,
            -INTERIOR_TOL_MM,
        ) {
            return Err(Error::Overlap {
                file: file.to_path_buf(),
                parts: Box::new([
                    DetectorPart::new(format!("{key}.geometry"), format!("passive {}", p.name)),
                    DetectorPart::new("semiconductor.geometry", "the semiconductor"),
                ]),
                r_mm: r,
                z_mm: z,
            });
        }
        if p.kind != PassiveKind::Dielectric {
            for (ci, c) in contacts.iter().enumerate() {
                if let Some((r, z)) =
                    common_point(&geometry, &c.geometry, BOUNDARY_TOL_MM, BOUNDARY_TOL_MM)
                {
                    return Err(Error::Overlap {
                        file: file.to_path_buf(),
                        parts: Box::new([
                            DetectorPart::new(
                                format!("{key}.geometry"),
                                format!("passive {}", p.name),
                            ),
                            DetectorPart::new(
                                format!("contacts[{ci}].geometry"),
                                format!("contact {}", c.label()),
                            ),
                        ]),
                        r_mm: r,
                        z_mm: z,
                    });
                }
            }
        }
        passives.push(Passive {
            name: p.name.clone(),
            kind: p.kind,
            material,
            geometry,
        });
    }
    for i in 0..passives.len() {
        for j in i + 1..passives.len() {
            if let Some((r, z)) = common_point(
                &passives[i].geometry,
                &passives[j].geometry,
                -INTERIOR_TOL_MM,
                -INTERIOR_TOL_MM,
            ) {
                return Err(Error::Overlap {
                    file: file.to_path_buf(),
                    parts: Box::new([
                        DetectorPart::new(
                            format!("passives[{i}].geometry"),
                            format!("passive {}", passives[i].name),
                        ),
                        DetectorPart::new(
                            format!("passives[{j}].geometry"),
                            format!("passive {}", passives[j].name),
                        ),
                    ]),
                    r_mm: r,
                    z_mm: z,
                });
            }
        }
    }

    Ok(Detector {
        name: spec.name.clone(),
        description: spec.description.clone(),
        file: file.to_path_buf(),
        parameters: params,
        world,
        semiconductor,
        contacts,
        passives,
        grid: match &spec.grid {
            Some(g) => {
                g.validate()
                    .map_err(|e| Error::invalid(file, "grid", e.to_string()))?;
                Some(g.clone())
            }
            None => None,
        },
    })
}

/// File parameters with overrides applied; an override must name a declared parameter.
fn parameters(spec: &DetectorSpec, file: &Path, overrides: &Parameters) -> Result<Parameters> {
    let mut params = Parameters::new();
    for (name, v) in &spec.parameters {
        if !v.is_finite() {
            return Err(Error::invalid(
                file,
                format!("parameters.{name}"),
                format!("must be finite, got {v}"),
            ));
        }
        params.set(name.clone(), *v);
    }
    for (name, v) in overrides.iter() {
        if params.get(name).is_none() {
            let known: Vec<&str> = spec.parameters.keys().map(String::as_str).collect();
            return Err(Error::Argument {
                name: name.to_string(),
                message: format!(
                    "{} declares no parameter `{name}` (declared: {})",
                    file.display(),
                    if known.is_empty() {
                        "none".to_string()
                    } else {
                        known.join(", ")
                    }
                ),
            });
        }
        if !v.is_finite() {
            return Err(Error::Argument {
                name: name.to_string(),
                message: format!("must be finite, got {v}"),
            });
        }
        params.set(name, v);
    }
    Ok(params)
}

/// Built-in materials plus the file's `[materials]` (which may override them).
fn materials(spec: &DetectorSpec, file: &Path) -> Result<BTreeMap<String, Material>> {
    let mut out: BTreeMap<String, Material> = Material::builtin_names()
        .into_iter()
        .filter_map(Material::builtin)
        .map(|m| (m.name.clone(), m))
        .collect();
    for (
        name,
        MaterialSpec {
            eps_r, conductor, ..
        },
    ) in &spec.materials
    {
        if !eps_r.is_finite() || *eps_r < 1.0 {
            return Err(Error::invalid(
                file,
                format!("materials.{name}.eps_r"),
                format!("a relative permittivity must be finite and at least 1, got {eps_r}"),
            ));
        }
        out.insert(
            name.clone(),
            Material {
                name: name.clone(),
                eps_r: *eps_r,
                conductor: *conductor,
            },
        );
    }
    Ok(out)
}

pub(crate) fn check_knots(knots: &[f64], file: &Path, key: &str) -> Result<()> {
    if knots.is_empty() {
        return Err(Error::invalid(file, key, "needs at least one knot"));
    }
    for (i, k) in knots.iter().enumerate() {
        if !k.is_finite() || *k < 0.0 {
            return Err(Error::invalid(
                file,
                format!("{key}[{i}]"),
                format!("a knot radius must be finite and non-negative, got {k}"),
            ));
        }
        if i > 0 && *k <= knots[i - 1] {
            return Err(Error::invalid(
                file,
                format!("{key}[{i}]"),
                format!(
                    "knots must be strictly increasing, but {k} follows {}",
                    knots[i - 1]
                ),
            ));
        }
    }
    Ok(())
}

/// Refuses a knot beyond the crystal's outer radius `r_max_mm`: the profile there would never be
/// used, and the knots inside would silently describe less than the user meant.
fn check_knots_in_crystal(knots: &[f64], r_max_mm: f64, file: &Path, key: &str) -> Result<()> {
    match knots.iter().position(|&k| k > r_max_mm + 1e-9) {
        Some(i) => Err(Error::invalid(
            file,
            format!("{key}[{i}]"),
            format!(
                "the knot at r = {} mm lies beyond the crystal, whose outer radius is {r_max_mm} mm",
                knots[i]
            ),
        )),
        None => Ok(()),
    }
}

/// Replaces the detector's impurity model by `spec` (read from `file`).
pub(crate) fn set_impurity(det: &mut Detector, spec: &ImpuritySpec, file: &Path) -> Result<()> {
    if let Some(knots) = spec.knots_mm() {
        check_knots_in_crystal(
            knots,
            det.semiconductor.geometry.bbox().r_max_mm,
            file,
            "knots_mm",
        )?;
    }
    let model: Arc<dyn ImpurityModel> =
        Arc::from(spec.build(&det.semiconductor.impurity_context, file, "")?);
    det.semiconductor.impurity = model;
    det.semiconductor.impurity_spec = spec.clone();
    det.semiconductor.impurity_file = file.to_path_buf();
    Ok(())
}
