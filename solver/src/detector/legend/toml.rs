//! A converted diode as a detector TOML text (detectors/README.md): the crystal, the n+ layer and
//! the p+ contact as offsets of the outline, in a grounded can.

use std::path::Path;

use super::{LegendDiode, LegendOptions, Surface};

/// right: the side where `inside` holds.
fn inward_normal(a: [f64; 2], b: [f64; 2], outline: &[[f64; 2]]) -> [f64; 2] {
    let (dx, dz) = (b[0] - a[0], b[1] - a[1]);
    let len = (dx * dx + dz * dz).sqrt();
    let n = [-dz / len, dx / len];
    let mid = [(a[0] + b[0]) / 2.0, (a[1] + b[1]) / 2.0];
    let probe = [mid[0] + 1e-6 * n[0], mid[1] + 1e-6 * n[1]];
    if point_in(outline, probe) {
        n
    } else {
        [-n[0], -n[1]]
    }
}

fn point_in(poly: &[[f64; 2]], p: [f64; 2]) -> bool {
    let mut inside = false;
    let n = poly.len();
    for i in 0..n {
        let (a, b) = (poly[i], poly[(i + 1) % n]);
        if (a[1] > p[1]) != (b[1] > p[1]) {
            let x = a[0] + (p[1] - a[1]) / (b[1] - a[1]) * (b[0] - a[0]);
            if p[0] < x {
                inside = !inside;
            }
        }
    }
    inside
}

/// `v + k * param` as a TOML value: a number when k = 0, else an expression.
fn offset(v: f64, k: f64, param: &str) -> String {
    let k = if k.abs() < 1e-12 { 0.0 } else { k };
    if k == 0.0 {
        format!("{v}")
    } else if k > 0.0 {
        format!("\"{v} + {k} * {param}\"")
    } else {
        format!("\"{v} - {} * {param}\"", -k)
    }
}

/// The layer under the surfaces of kind `s`: for every such segment the strip between it and
/// its inward offset by `param` (mm), and at every reflex joint of two such segments the
/// quadrilateral that closes the gap between their strips.
fn layer(d: &LegendDiode, s: Surface, param: &str) -> Vec<String> {
    let pts = &d.outline_mm;
    let mut polys = Vec::new();
    let normals: Vec<Option<[f64; 2]>> = (0..d.surfaces.len())
        .map(|k| (d.surfaces[k] == s).then(|| inward_normal(pts[k], pts[k + 1], pts)))
        .collect();
    let pt = |p: [f64; 2], n: [f64; 2]| {
        format!(
            "[{}, {}]",
            offset(p[0], n[0], param),
            offset(p[1], n[1], param)
        )
    };
    for k in 0..d.surfaces.len() {
        let Some(n) = normals[k] else { continue };
        let (a, b) = (pts[k], pts[k + 1]);
        polys.push(format!(
            "{{ polygon = {{ points_mm = [{}, {}, {}, {}] }} }}",
            pt(a, [0.0, 0.0]),
            pt(b, [0.0, 0.0]),
            pt(b, n),
            pt(a, n)
        ));
        if k + 1 < d.surfaces.len()
            && let Some(m) = normals[k + 1]
        {
            // Only where the outline turns away from the crystal (a reflex corner) do the two
            // strips leave a gap; at a convex corner they overlap already.
            let c = pts[k + 2];
            let turn = (c[0] - b[0]) * n[0] + (c[1] - b[1]) * n[1];
            if turn < -1e-12 {
                let sum = [n[0] + m[0], n[1] + m[1]];
                polys.push(format!(
                    "{{ polygon = {{ points_mm = [{}, {}, {}, {}] }} }}",
                    pt(b, [0.0, 0.0]),
                    pt(b, n),
                    pt(b, sum),
                    pt(b, m)
                ));
            }
        }
    }
    polys
}

/// The detector TOML text of a converted record.
pub fn to_toml(d: &LegendDiode, file: &Path, o: &LegendOptions) -> String {
    let gap = o.can_gap_mm;
    let mut t = String::new();
    t += &format!(
        "# {}: converted by hpge-cv {} from the LEGEND diode record {}.\n",
        d.name,
        env!("CARGO_PKG_VERSION"),
        file.display()
    );
    t += "# Environment (hpge-cv's default for LEGEND records): the crystal alone in a grounded can\n";
    t += &format!(
        "# (vacuum), {gap} mm from it on every side; n+ layer at the bias, p+ contact at 0 V, passivated\n# surfaces bare. n+ thickness: {} mm from {}. Impurity: {}.\n",
        d.n_plus_thickness_mm.0, d.n_plus_thickness_mm.1, d.impurity_toml.1
    );
    if let Some(u) = d.depletion_voltage_v {
        t += &format!("# The record's characterization gives a depletion voltage of {u} V.\n");
    }
    for n in &d.notes {
        t += &format!("# Note: {n}.\n");
    }
    t += &format!(
        "\nname = {:?}\ndescription = {:?}\n\n[parameters]\nn_plus_mm = {}  # n+ (Li) layer thickness\np_plus_mm = {}  # p+ contact layer thickness in the model\n\n",
        d.name,
        format!(
            "LEGEND {} {} (from its diode record), height {} mm, radius {} mm, in a grounded can",
            d.kind, d.name, d.height_mm, d.radius_mm
        ),
        d.n_plus_thickness_mm.0,
        o.p_plus_thickness_mm
    );
    t += &format!(
        "[world]\nr_max_mm = {}\nz_min_mm = {}\nz_max_mm = {}\nmedium = \"vacuum\"\n\n[world.boundary]\nr_max = \"grounded\"\nz_min = \"grounded\"\nz_max = \"grounded\"\n\n[world.label]\nr_max = \"can\"\nz_min = \"can\"\nz_max = \"can\"\n\n",
        d.radius_mm + gap,
        -gap,
        d.height_mm + gap
    );
    let points = d
        .outline_mm
        .iter()
        .map(|p| format!("[{}, {}]", p[0], p[1]))
        .collect::<Vec<_>>()
        .join(", ");
    t += &format!(
        "[semiconductor]\nname = \"{} crystal\"\nmaterial = \"HPGe\"\ngeometry = {{ polygon = {{ points_mm = [{points}] }} }}\n\n[semiconductor.impurity]\n{}\n",
        d.name, d.impurity_toml.0
    );
    let union = |polys: Vec<String>| format!("{{ union = [\n  {},\n] }}", polys.join(",\n  "));
    t += &format!(
        "[[contacts]]\nid = 1\nname = \"p+ contact\"\npotential = 0.0\ngeometry = {}\n\n",
        union(layer(d, Surface::PPlus, "p_plus_mm"))
    );
    t += &format!(
        "[[contacts]]\nid = 2\nname = \"n+ (Li)\"\npotential = \"bias\"\ngeometry = {}\n",
        union(layer(d, Surface::NPlus, "n_plus_mm"))
    );
    t
}
