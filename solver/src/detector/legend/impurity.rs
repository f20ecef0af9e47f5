//! The impurity profile (`production.impcc`) and the n+ dead-layer thickness
//! (`characterization`) of a record.

use serde_json::Value;

use super::LegendOptions;
use super::reader::Reader;
use crate::error::Result;

/// dotted path it was found at.
pub(super) fn find_number(v: Option<&Value>, key: &str) -> Option<(f64, String)> {
    let obj = v?.as_object()?;
    if let Some(x) = obj.get(key) {
        let n = x
            .as_f64()
            .or_else(|| x.get("value").and_then(Value::as_f64));
        if let Some(n) = n {
            return Some((n, key.to_string()));
        }
    }
    for (k, sub) in obj {
        if sub.is_object()
            && let Some((n, path)) = find_number(Some(sub), key)
        {
            return Some((n, format!("{k}.{path}")));
        }
    }
    None
}

/// The record's depletion voltage (V) and where it was found: the first positive
/// `depletion_voltage_in_V` under `characterization`, the site's measurement (`l200_site`)
/// before the manufacturer's data sheet (`manufacturer`) before any other sub-table. A zero or
/// negative value is a placeholder (the public test records carry `l200_site` values of 0) and
/// is passed over, never returned as a depletion voltage.
pub(super) fn depletion_voltage(characterization: Option<&Value>) -> Option<(f64, String)> {
    let obj = characterization?.as_object()?;
    let key = "depletion_voltage_in_V";
    let preferred = ["l200_site", "manufacturer"];
    let positive = |found: Option<(f64, String)>| found.filter(|(u, _)| u.is_finite() && *u > 0.0);
    if let Some(found) = positive(
        obj.get(key)
            .and_then(Value::as_f64)
            .map(|u| (u, key.into())),
    ) {
        return Some(found);
    }
    let rest = obj.keys().filter(|k| !preferred.contains(&k.as_str()));
    for k in preferred.iter().copied().chain(rest.map(String::as_str)) {
        if let Some((u, path)) = positive(find_number(obj.get(k), key)) {
            return Some((u, format!("{k}.{path}")));
        }
    }
    None
}

pub(super) fn n_plus_thickness(
    rd: &Reader<'_>,
    v: &Value,
    o: &LegendOptions,
) -> Result<(f64, String)> {
    for key in ["fccd_in_mm", "dl_thickness_in_mm"] {
        if let Some((t, path)) = find_number(v.get("characterization"), key) {
            let full = format!("characterization.{path}");
            if !(t.is_finite() && t > 0.0) {
                return Err(rd.err(&full, format!("must be a positive number of mm, got {t}")));
            }
            return Ok((t, full));
        }
    }
    Ok((
        o.n_plus_thickness_mm,
        "the default (no dead-layer thickness in `characterization`)".to_string(),
    ))
}

/// The impurity model's TOML lines (without the table header) and where they came from.
///
/// `production.impcc` in the collaboration's format (legend-testdata's diode records): the table
/// `array` (`dist_from_contact_in_mm`, `value_in_1e9e/cm3`: 1e9 cm^-3) and `function_pars`
/// (`z0_in_1e10e/cm3`, `gradient_in_1e10e/cm4`, `quadratic_in_1e10e/cm5`: 1e10 cm^-3 and per cm,
/// per cm^2, the units in the names), the table first where both are given (the measured values;
/// LegendGeSim.jl fits those too). hpge-cv's short form (detectors/legend/): `function_pars`
/// {`z0`, `gradient`, `quadratic`} in 1e9 cm^-3 per mm, per mm^2, or the tables
/// `dist_from_contact_in_mm` and `value_in_1e9e_cm3` directly under `impcc`. A profile that is
/// zero everywhere is a placeholder (the public test records' are): the default density then,
/// and the file says so.
pub(super) fn impurity(
    rd: &Reader<'_>,
    v: &Value,
    height_mm: f64,
    o: &LegendOptions,
) -> Result<(String, String)> {
    let default = |why: String| {
        (
            format!(
                "model = \"constant\"\nzeta_cm3 = {:e}\n",
                o.default_impurity_cm3
            ),
            format!("the default ({why})"),
        )
    };
    let Some(imp) = v.get("production").and_then(|p| p.get("impcc")) else {
        return Ok(default("the record has no production.impcc".into()));
    };
    let num = |x: Option<&Value>, key: &str| -> Result<f64> {
        let x = x.ok_or_else(|| rd.err(key, "missing"))?;
        x.as_f64()
            .filter(|f| f.is_finite())
            .ok_or_else(|| rd.err(key, format!("must be a finite number, got {x}")))
    };
    let mut placeholders: Vec<String> = Vec::new();
    // 1. LEGEND's measured table.
    if let Some(t) = imp.get("array").filter(|t| !t.is_null()) {
        let k = "production.impcc.array";
        // The key as legend-testdata spells it; the crystal records' spelling too.
        let value_key =
            if t.get("value_in_1e9e/cm3").is_none() && t.get("value_in_1e9e_cm3").is_some() {
                "value_in_1e9e_cm3"
            } else {
                "value_in_1e9e/cm3"
            };
        if let Some(r) = table(rd, t, k, value_key, 1e9, &mut placeholders)? {
            return Ok(r);
        }
    }
    // 2. A polynomial in the distance from the contact.
    if let Some(f) = imp.get("function_pars").filter(|f| !f.is_null()) {
        let k = "production.impcc.function_pars";
        let legend = ["z0_in_1e10e/cm3", "gradient_in_1e10e/cm4"]
            .iter()
            .any(|n| f.get(*n).is_some());
        // (key of z0, gradient, quadratic), cm^-3 per unit, mm per length unit of the key.
        let (keys, unit, length_mm) = if legend {
            (
                [
                    "z0_in_1e10e/cm3",
                    "gradient_in_1e10e/cm4",
                    "quadratic_in_1e10e/cm5",
                ],
                1e10,
                10.0,
            )
        } else {
            (["z0", "gradient", "quadratic"], 1e9, 1.0)
        };
        let a = num(f.get(keys[0]), &format!("{k}.{}", keys[0]))?;
        let b = num(f.get(keys[1]), &format!("{k}.{}", keys[1]))?;
        let c = match f.get(keys[2]) {
            None | Some(Value::Null) => 0.0,
            x => num(x, &format!("{k}.{}", keys[2]))?,
        };
        if a == 0.0 && b == 0.0 && c == 0.0 {
            placeholders.push(k.to_string());
        } else {
            let zeta = |d_mm: f64| {
                let d = d_mm / length_mm;
                -(a + b * d + c * d * d) * unit
            };
            if c == 0.0 {
                return Ok((
                    format!(
                        "model = \"linear-z\"\nbottom_cm3 = {:e}\ntop_cm3 = {:e}\n",
                        zeta(0.0),
                        zeta(height_mm)
                    ),
                    format!("{k} (linear)"),
                ));
            }
            // The quadratic on 81 points: linear interpolation is within quadratic h^2 / 8 of it.
            let n = 80;
            let z: Vec<f64> = (0..=n).map(|i| height_mm * i as f64 / n as f64).collect();
            let values: Vec<f64> = z.iter().map(|&d| zeta(d)).collect();
            return Ok((
                z_table(&z, &values),
                format!("{k} (quadratic, on 81 points)"),
            ));
        }
    }
    // 3. hpge-cv's short form of the table.
    if imp.get("dist_from_contact_in_mm").is_some() || imp.get("value_in_1e9e_cm3").is_some() {
        let k = "production.impcc";
        if let Some(r) = table(rd, imp, k, "value_in_1e9e_cm3", 1e9, &mut placeholders)? {
            return Ok(r);
        }
    }
    if placeholders.is_empty() {
        return Err(rd.err(
            "production.impcc",
            "has no profile: give `array` (`dist_from_contact_in_mm`, `value_in_1e9e/cm3`) or `function_pars` (`z0_in_1e10e/cm3`, `gradient_in_1e10e/cm4`, `quadratic_in_1e10e/cm5`)",
        ));
    }
    Ok(default(format!(
        "the record's {} zero everywhere, a placeholder",
        match placeholders.as_slice() {
            [one] => format!("{one} is"),
            many => format!("{} are", many.join(" and ")),
        }
    )))
}

/// A table of densities against the distance from the contact (`dist_from_contact_in_mm` and
/// `value_key`, in `unit` cm^-3) under `t` (at `k` in the record): the model, or `None` with `k`
/// added to `placeholders` when every value is zero.
fn table(
    rd: &Reader<'_>,
    t: &Value,
    k: &str,
    value_key: &str,
    unit: f64,
    placeholders: &mut Vec<String>,
) -> Result<Option<(String, String)>> {
    let dk = format!("{k}.dist_from_contact_in_mm");
    let vk = format!("{k}.{value_key}");
    let list = |x: Option<&Value>, key: &str| -> Result<Vec<f64>> {
        let x = x.ok_or_else(|| {
            rd.err(
                key,
                "missing (give `function_pars` or both the distances and the values)",
            )
        })?;
        let a = x
            .as_array()
            .ok_or_else(|| rd.err(key, format!("must be a list of numbers, got {x}")))?;
        a.iter()
            .enumerate()
            .map(|(i, y)| {
                y.as_f64().filter(|f| f.is_finite()).ok_or_else(|| {
                    rd.err(
                        &format!("{key}[{i}]"),
                        format!("must be a finite number, got {y}"),
                    )
                })
            })
            .collect()
    };
    let d = list(t.get("dist_from_contact_in_mm"), &dk)?;
    let val = list(t.get(value_key), &vk)?;
    if d.len() != val.len() || d.is_empty() {
        return Err(rd.err(
            &vk,
            format!(
                "has {} values for {} distances (need the same number, at least one)",
                val.len(),
                d.len()
            ),
        ));
    }
    if val.iter().all(|x| *x == 0.0) {
        placeholders.push(k.to_string());
        return Ok(None);
    }
    for i in 1..d.len() {
        if d[i] <= d[i - 1] {
            return Err(rd.err(
                &format!("{dk}[{i}]"),
                format!("distances must increase: {} after {}", d[i], d[i - 1]),
            ));
        }
    }
    let values: Vec<f64> = val.iter().map(|x| -x * unit).collect();
    if d.len() == 1 {
        return Ok(Some((
            format!("model = \"constant\"\nzeta_cm3 = {:e}\n", values[0]),
            format!("{k} (one value)"),
        )));
    }
    Ok(Some((z_table(&d, &values), format!("{k} tables"))))
}

fn z_table(z: &[f64], values: &[f64]) -> String {
    let fmt = |v: &[f64], e: bool| {
        v.iter()
            .map(|x| if e { format!("{x:e}") } else { format!("{x}") })
            .collect::<Vec<_>>()
            .join(", ")
    };
    format!(
        "model = \"z-table\"\nz_mm = [{}]\nvalues_cm3 = [{}]\n",
        fmt(z, false),
        fmt(values, true)
    )
}
