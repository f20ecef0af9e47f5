"""Issue 62, item 1: every solver command is one library job with two faces. Each job runs
through the command line (`hpge-cv COMMAND --json`) and through Python (`hpge_cv.COMMAND`), and
the two records are compared field by field: the same keys, the same values (wall times
aside)."""

import json
import math

import numpy as np
import pytest

import hpge_cv
from conftest import ROOT

COAX = ROOT / "detectors" / "coax-analytic.toml"
# A coarse grid keeps each solve well under a second (the numbers are compared, not judged).
GRID = {"max_spacing_semiconductor_mm": "2"}
GRID_ARGS = ("--grid", "max_spacing_semiconductor_mm=2", "--tolerance", "0.01")


def plain(v):
    """A record value as JSON has it: numpy arrays to lists, NaN to None."""
    if isinstance(v, np.ndarray):
        v = v.tolist()
    if isinstance(v, dict):
        return {k: plain(x) for k, x in v.items()}
    if isinstance(v, (list, tuple)):
        return [plain(x) for x in v]
    if isinstance(v, float) and math.isnan(v):
        return None
    return v


def same_record(py, cli, path="", wall_times=("seconds",)):
    """Asserts that two records are equal field by field; `wall_times` may differ."""
    if isinstance(cli, dict):
        assert isinstance(py, dict), path
        assert set(py) == set(cli), f"{path}: keys {sorted(set(py) ^ set(cli))} differ"
        for k in cli:
            if k not in wall_times:
                same_record(py[k], cli[k], f"{path}.{k}", wall_times)
    elif isinstance(cli, list):
        assert isinstance(py, list) and len(py) == len(cli), path
        for i, (a, b) in enumerate(zip(py, cli)):
            same_record(a, b, f"{path}[{i}]", wall_times)
    elif isinstance(cli, float) and isinstance(py, (int, float)):
        assert py == pytest.approx(cli, rel=1e-12, abs=0.0), path
    else:
        assert py == cli, path


def test_simulate_record_through_both_faces(cli_json):
    det = hpge_cv.Detector(COAX)
    py = hpge_cv.simulate(det, [1000.0, 4000.0], tolerance=0.01, grid=GRID, progress=False)
    cli = cli_json("simulate", "--detector", COAX, "--voltages", "1000,4000", "--json", *GRID_ARGS)
    same_record(plain(py), cli)


def test_capacitance_record_through_both_faces(cli_json):
    det = hpge_cv.Detector(COAX)
    py = hpge_cv.capacitance(det, 2000.0, tolerance=0.01, grid=GRID)
    cli = cli_json("capacitance", "--detector", COAX, "--voltage", "2000", "--json", *GRID_ARGS)
    same_record(plain(py), cli)


def test_field_record_through_both_faces(cli_json):
    det = hpge_cv.Detector(COAX)
    py = hpge_cv.field(det, 4000.0, 30.0, 5.0, list(np.linspace(0.0, 39.0, 14)),
                       tolerance=0.01, grid=GRID)
    cli = cli_json("field", "--detector", COAX, "--voltage", "4000", "--phi", "30", "--z", "5",
                   "--r-range", "0:39:14", "--json", *GRID_ARGS)
    same_record(plain(py), cli)
    assert np.isnan(py["e_V_per_cm"]).any(), "the core contact has no field"


def test_pulse_record_through_both_faces(cli_json):
    det = hpge_cv.Detector(COAX)
    py = hpge_cv.pulse(det, 4000.0, (20.0, 10.0, 5.0), normalise=True, tolerance=0.01, grid=GRID)
    cli = cli_json("pulse", "--detector", COAX, "--voltage", "4000", "--at", "20,10,5",
                   "--normalise", "--json", *GRID_ARGS)
    signals = py.pop("signals")
    same_record(plain(py), cli)
    # The Python-only view by name is the record's signals.
    for c in cli["contacts"]:
        np.testing.assert_array_equal(signals[c["name"]], c["signal"])


def test_sensitivity_record_through_both_faces(cli_json):
    det = hpge_cv.Detector(COAX)
    cli = cli_json("sensitivity", "--detector", COAX, "--voltage", "1000",
                   "--zeta-range", "1e9:1e10:2", "--json", *GRID_ARGS)
    # The densities the command line parsed from MIN:MAX:N, given to Python as a list.
    py = hpge_cv.sensitivity(det, 1000.0, cli["zeta_cm3"], tolerance=0.01, grid=GRID,
                             progress=False)
    same_record(plain(py), cli)


def test_convergence_record_through_both_faces(cli_json):
    det = hpge_cv.Detector(COAX)
    py = hpge_cv.convergence(det, 2000.0, levels=2, tolerance=0.01, grid=GRID)
    cli = cli_json("convergence", "--detector", COAX, "--voltage", "2000", "--levels", "2",
                   "--json", *GRID_ARGS)
    same_record(plain(py), cli)


def test_job_errors_name_the_python_argument():
    det = hpge_cv.Detector(COAX)
    with pytest.raises(hpge_cv.HpgeError, match=r"^voltage -1: the bias must be a positive"):
        hpge_cv.capacitance(det, -1.0)
    with pytest.raises(hpge_cv.HpgeError, match=r"^z_mm 1000: the crystal spans z"):
        hpge_cv.field(det, 1000.0, 0.0, 1000.0)
    with pytest.raises(hpge_cv.HpgeError, match=r"^levels 9: give 1 to 8"):
        hpge_cv.convergence(det, 1000.0, levels=9)
    with pytest.raises(hpge_cv.HpgeError, match=r"^at -1,0,5: R must be"):
        hpge_cv.pulse(det, 1000.0, (-1.0, 0.0, 5.0))


def test_measure_writes_the_command_lines_files(cli_json, tmp_path):
    # The measurement's job (hpge_measurement::jobs) behind both faces: the same curve,
    # covariance and report, byte for byte apart from the report's `command`.
    raw = ROOT / "data" / "super-siegfried-k1" / "raw"
    (tmp_path / "py").mkdir()
    (tmp_path / "cli").mkdir()
    py = hpge_cv.measure(raw, out=tmp_path / "py" / "cv.csv")
    cli = cli_json("measure", "--raw", raw, "--out", tmp_path / "cli" / "cv.csv", "--json")
    for name in ("cv.csv", "cv.covariance.csv"):
        assert (tmp_path / "py" / name).read_bytes() == (tmp_path / "cli" / name).read_bytes(), name
    written = json.loads((tmp_path / "py" / "cv.measure.json").read_text())
    assert written == py["report"]
    assert written["command"][0] == "hpge_cv.measure"
    for record in (written, cli):
        record.pop("command")
    same_record(written, cli)
    assert py["report"]["covariance_file"] == "cv.covariance.csv"
    # Without `out` nothing is written and no covariance file is named.
    assert hpge_cv.measure(raw)["report"]["covariance_file"] is None
