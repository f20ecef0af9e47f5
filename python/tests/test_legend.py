"""LEGEND diode records: conversion, errors naming the field, and the crystal's r-z outline
against legend-pygeom-hpges's own profile of the same record (to 0.01 mm)."""

import copy
import json
import subprocess
import sys
import tarfile
from pathlib import Path

import numpy as np
import pytest

import hpge_cv

TOL_MM = 0.01


def record(name, kind, **geometry):
    g = {
        "height_in_mm": 60.0,
        "radius_in_mm": 35.0,
        "groove": {"depth_in_mm": 2.0, "radius_in_mm": {"inner": 9.0, "outer": 12.0}},
        "pp_contact": {"radius_in_mm": 4.0, "depth_in_mm": 0.0},
        "taper": {
            "top": {"angle_in_deg": 0.0, "height_in_mm": 0.0},
            "bottom": {"angle_in_deg": 0.0, "height_in_mm": 0.0},
            "borehole": {"angle_in_deg": 0.0, "height_in_mm": 0.0},
        },
    }
    for k, v in geometry.items():
        g[k] = v
    return {
        "name": name,
        "type": kind,
        "production": {
            "enrichment": {"val": 0.9, "unc": 0.01},
            "mass_in_g": 1500.0,
            "impcc": {"function_pars": {"z0": 1.2, "gradient": 0.01, "quadratic": 0.0002}},
        },
        "geometry": g,
    }


def taper(top=(0.0, 0.0), bottom=(0.0, 0.0), borehole=(0.0, 0.0)):
    t = lambda a: {"angle_in_deg": a[0], "height_in_mm": a[1]}
    return {"top": t(top), "bottom": t(bottom), "borehole": t(borehole)}


# Our own records: every type and every option the converter reads.
OWN = [
    record("B00001A", "bege"),
    record("B00002A", "bege", taper=taper(top=(45, 3), bottom=(30, 4)),
           pp_contact={"radius_in_mm": 5.0, "depth_in_mm": 1.5}),
    record("B00003A", "bege", pp_contact={"radius_in_mm": 9.0, "depth_in_mm": 0.0}),
    record("P00001A", "ppc", taper=taper(bottom=(30, 4))),
    record("P00002A", "ppc", pp_contact={"radius_in_mm": 3.0, "depth_in_mm": 2.0},
           taper=taper(top=(10, 8))),
    record("V00001A", "icpc", height_in_mm=80.0, radius_in_mm=38.0,
           borehole={"radius_in_mm": 5.0, "depth_in_mm": 55.0}, taper=taper(top=(20, 10))),
    record("V00002A", "icpc", height_in_mm=85.0, radius_in_mm=40.0,
           borehole={"radius_in_mm": 5.5, "depth_in_mm": 50.0},
           taper=taper(top=(35, 2), bottom=(35, 2), borehole=(5, 40))),
    record("V00003A", "icpc", height_in_mm=70.0, radius_in_mm=36.0,
           borehole={"radius_in_mm": 5.0, "depth_in_mm": 30.0},
           taper=taper(borehole=(3, 30)),
           pp_contact={"radius_in_mm": 3.5, "depth_in_mm": 1.0}),
    record("C00001A", "coax", height_in_mm=80.0, radius_in_mm=38.0,
           borehole={"radius_in_mm": 6.0, "depth_in_mm": 65.0},
           groove={"depth_in_mm": 2.0, "radius_in_mm": {"inner": 9.0, "outer": 13.0}},
           taper=taper(top=(45, 3), borehole=(10, 5))),
    record("C00002A", "coax", height_in_mm=70.0, radius_in_mm=37.0,
           borehole={"radius_in_mm": 5.0, "depth_in_mm": 50.0}),
]


def public_records():
    """The example records in legend-pygeom-hpges's tests (from its source distribution)."""
    import importlib.metadata as md

    version = md.version("legend-pygeom-hpges")
    dest = Path(__file__).resolve().parent / ".cache" / f"pygeom-hpges-{version}"
    if not dest.exists():
        dest.mkdir(parents=True)
        subprocess.run(
            [sys.executable, "-m", "pip", "download", "--no-deps", "--no-binary", ":all:",
             f"legend-pygeom-hpges=={version}", "-d", str(dest), "-q"],
            check=True, timeout=300,
        )
    (sdist,) = dest.glob("*.tar.gz")
    out = {}
    with tarfile.open(sdist) as t:
        for m in t.getmembers():
            if "/tests/configs/" in m.name and m.name.endswith(".json"):
                out[Path(m.name).stem] = json.load(t.extractfile(m))
    assert out, "no example records in the sdist"
    return out


def closed(r, z):
    r, z = np.asarray(r, float), np.asarray(z, float)
    if r[0] != r[-1] or z[0] != z[-1]:
        r, z = np.append(r, r[0]), np.append(z, z[0])
    return r, z


def sample(r, z, step=0.005):
    pts = []
    for k in range(len(r) - 1):
        a, b = np.array([r[k], z[k]]), np.array([r[k + 1], z[k + 1]])
        n = max(2, int(np.ceil(np.linalg.norm(b - a) / step)) + 1)
        pts.append(a + (b - a) * np.linspace(0, 1, n)[:, None])
    return np.concatenate(pts)


def distance_to_polyline(p, r, z):
    a = np.stack([r[:-1], z[:-1]], axis=1)
    b = np.stack([r[1:], z[1:]], axis=1)
    ab = b - a
    L2 = np.maximum((ab ** 2).sum(axis=1), 1e-300)
    t = np.clip(((p[:, None, :] - a[None]) * ab[None]).sum(axis=2) / L2[None], 0.0, 1.0)
    q = a[None] + t[..., None] * ab[None]
    return np.sqrt(((p[:, None, :] - q) ** 2).sum(axis=2)).min(axis=1)


def hausdorff_mm(r1, z1, r2, z2):
    r1, z1 = closed(r1, z1)
    r2, z2 = closed(r2, z2)
    return max(
        distance_to_polyline(sample(r1, z1), r2, z2).max(),
        distance_to_polyline(sample(r2, z2), r1, z1).max(),
    )


def pygeom_profile(rec):
    pg = pytest.importorskip("pygeomhpges", reason="legend-pygeom-hpges is not installed")
    from pyg4ometry import geant4

    det = pg.make_hpge(copy.deepcopy(rec), registry=geant4.Registry(),
                       allow_cylindrical_asymmetry=False)
    return det.get_profile()


def check_against_pygeom(rec):
    r, z, surfaces = hpge_cv.legend_outline(rec)
    assert len(surfaces) == len(r) - 1
    pr, pz = pygeom_profile(rec)
    d = hausdorff_mm(r, z, pr, pz)
    assert d <= TOL_MM, f"{rec['name']}: outlines differ by {d:.4f} mm"
    return d


@pytest.mark.parametrize("rec", OWN, ids=[r["name"] for r in OWN])
def test_own_records_match_pygeom(rec):
    check_against_pygeom(rec)


def test_public_records_match_pygeom():
    pytest.importorskip("pygeomhpges", reason="legend-pygeom-hpges is not installed")
    recs = public_records()
    worst = {name: check_against_pygeom(rec) for name, rec in sorted(recs.items())}
    print("public records, outline agreement (mm):", worst)


@pytest.mark.parametrize("rec", OWN, ids=[r["name"] for r in OWN])
def test_converted_records_load(rec, tmp_path):
    text = hpge_cv.legend_to_toml(rec)
    path = tmp_path / f"{rec['name']}.toml"
    path.write_text(text)
    det = hpge_cv.Detector(path)
    assert det.contacts == ["p+ contact", "n+ (Li)"]
    # p-type, impcc = z0 + gradient d + quadratic d^2 in 1e9 cm^-3 at d = z mm.
    inside_r = 0.6 * rec["geometry"]["radius_in_mm"]
    for zmm in (2.0, 30.0, 50.0):
        want = -(1.2 + 0.01 * zmm + 0.0002 * zmm**2) * 1e9
        assert det.impurity_density(inside_r, zmm) == pytest.approx(want, rel=2e-3)
    same = hpge_cv.Detector.from_legend(rec)
    assert same.contacts == det.contacts


def test_cli_writes_the_same_file(cli, tmp_path):
    rec = OWN[6]
    src = tmp_path / "V00002A.json"
    src.write_text(json.dumps(rec))
    out = tmp_path / "V00002A.toml"
    code, _, err = cli("detector", "--from-legend", src, "--out", out)
    assert code == 0, err
    assert out.read_text() == hpge_cv.legend_to_toml(src)


BAD = [
    (lambda g: g.pop("height_in_mm"), "geometry.height_in_mm", "missing"),
    (lambda g: g.update(radius_in_mm=-2.0), "geometry.radius_in_mm", "-2"),
    (lambda g: g["borehole"].update(depth_in_mm="deep"), "geometry.borehole.depth_in_mm", "number"),
    (lambda g: g["taper"]["top"].update(angle_in_deg=95), "geometry.taper.top.angle_in_deg", "90"),
    (lambda g: g["groove"]["radius_in_mm"].update(outer=50.0), "geometry", "fit together"),
]


@pytest.mark.parametrize("edit,key,what", BAD, ids=[b[1] + ":" + b[2] for b in BAD])
def test_bad_records_name_the_field(edit, key, what, cli, tmp_path):
    rec = copy.deepcopy(OWN[5])
    edit(rec["geometry"])
    with pytest.raises(hpge_cv.HpgeError) as e:
        hpge_cv.legend_to_toml(rec)
    assert f"`{key}`" in str(e.value) and what in str(e.value), str(e.value)
    src = tmp_path / "bad.json"
    src.write_text(json.dumps(rec))
    code, _, err = cli("detector", "--from-legend", src, "--out", tmp_path / "bad.toml")
    assert code == 2 and f"`{key}`" in err and "bad.json" in err, err


def test_unknown_type_and_broken_json(cli, tmp_path):
    rec = copy.deepcopy(OWN[0])
    rec["type"] = "semi-planar"
    with pytest.raises(hpge_cv.HpgeError, match="unknown detector type `semi-planar`"):
        hpge_cv.legend_to_toml(rec)
    broken = tmp_path / "broken.json"
    broken.write_text('{"name": "X", "type": "bege", "geometry": {')
    with pytest.raises(hpge_cv.HpgeError, match="broken.json"):
        hpge_cv.legend_to_toml(broken)
    code, _, err = cli("detector", "--from-legend", broken)
    assert code == 2 and "broken.json" in err and "JSON" in err


def test_converted_bege_depletes():
    """The converted BEGe (tapered, n+ around the corners) depletes fully: no undepleted layer
    in front of its contacts (a convex corner's n+ once left one)."""
    from conftest import ROOT

    det = hpge_cv.Detector.from_legend(ROOT / "detectors" / "legend" / "B00002A.json")
    assert det.parameters["n_plus_mm"] == 0.8  # from characterization.manufacturer
    sim = hpge_cv.simulate(det, [500.0, 1000.0], tolerance=0.01, progress=False)
    assert all(sim["fully_depleted"])
    assert 50.0 < sim["depletion_voltage_V"] < 500.0
