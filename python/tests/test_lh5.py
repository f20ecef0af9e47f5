"""Raw data in LH5 (issue 22, item 3): the pulses of `synthesize`, written as LH5 waveform tables
by legend-pydataobj (with legend-lh5io, its LH5 writer), measure to the same curve as the .npy files (c12 to 1e-9 relative); a bad
LH5 file exits 2 with a message naming it."""

import shutil
from pathlib import Path

import numpy as np
import pytest

# legend-pydataobj's LH5 writer moved to its own package, legend-lh5io (module `lh5`).
import lh5
from lgdo import Array, ArrayOfEqualSizedArrays, Table, WaveformTable

from conftest import ROOT

TRUTH = ROOT / "data" / "super-siegfried-k1" / "truth-cv.csv"
REL = 1e-9


def read_sidecar(path):
    """The sidecar's `key = value` lines (bias_V, sampling_period_ns, charge_unit, ...)."""
    out = {}
    for line in path.read_text().splitlines():
        if "=" in line:
            key, value = (s.strip() for s in line.split("=", 1))
            out[key] = value.strip('"')
    return out


def write_lh5(npy, lh5_path):
    """One .npy pulse file as an LH5 file: ch000/raw holding a waveform table (t0, dt in ns,
    values [pulses, samples] in the sidecar's charge unit) and a per-event column."""
    values = np.load(npy)
    side = read_sidecar(npy.with_suffix(".toml"))
    n = values.shape[0]
    waveform = WaveformTable(
        t0=np.zeros(n),
        t0_units="ns",
        dt=np.full(n, float(side["sampling_period_ns"])),
        dt_units="ns",
        values=ArrayOfEqualSizedArrays(nda=values),
        values_units=side["charge_unit"],
    )
    table = Table(col_dict={"waveform": waveform, "eventnumber": Array(np.arange(n))})
    lh5.write(table, name="raw", group="ch000", lh5_file=str(lh5_path), wo_mode="overwrite_file")


def curve(path):
    """(voltage_V, c12_pF) of a curve CSV (comment lines start with #)."""
    data = np.genfromtxt(path, delimiter=",", comments="#", names=True)
    return data["voltage_V"], data["c12_pF"]


@pytest.fixture(scope="module")
def runs(cli, tmp_path_factory):
    """A small synthetic run as .npy files, and the same pulses as .lh5 files."""
    tmp = tmp_path_factory.mktemp("lh5")
    rows = TRUTH.read_text().splitlines()
    small = tmp / "truth.csv"
    small.write_text("\n".join([rows[0], rows[1], rows[10], rows[30]]) + "\n")
    npy_dir = tmp / "npy"
    code, _, err = cli(
        "synthesize",
        "--curve",
        small,
        "--out",
        npy_dir,
        "--pulses",
        60,
        "--decimate",
        40,
        # three biases below full depletion: the curve cannot say where it ends
        "--depletion-voltage",
        4000,
    )
    assert code == 0, err
    lh5_dir = tmp / "lh5"
    lh5_dir.mkdir()
    npys = sorted(npy_dir.glob("*.npy"))
    assert len(npys) == 3
    for npy in npys:
        write_lh5(npy, lh5_dir / (npy.stem + ".lh5"))
        shutil.copy(npy.with_suffix(".toml"), lh5_dir / (npy.stem + ".toml"))
    shutil.copy(npy_dir / "measurement.toml", lh5_dir / "measurement.toml")
    return tmp, npy_dir, lh5_dir


def test_lh5_measures_to_the_npy_curve(cli, runs):
    tmp, npy_dir, lh5_dir = runs
    results = {}
    for name, raw in [("npy", npy_dir), ("lh5", lh5_dir)]:
        out = tmp / f"cv-{name}.csv"
        code, _, err = cli("measure", "--raw", raw, "--out", out)
        assert code == 0, err
        results[name] = curve(out)
    (u_npy, c_npy), (u_lh5, c_lh5) = results["npy"], results["lh5"]
    assert len(u_npy) == 3
    np.testing.assert_array_equal(u_npy, u_lh5)
    np.testing.assert_allclose(c_lh5, c_npy, rtol=REL, atol=0)

    # One .lh5 file given instead of a folder: that bias alone, the same c12.
    one = sorted(lh5_dir.glob("*.lh5"))[1]
    out = tmp / "cv-one.csv"
    code, _, err = cli("measure", "--raw", one, "--out", out)
    assert code == 0, err
    u_one, c_one = curve(out)
    assert np.atleast_1d(u_one)[0] == u_npy[1]
    np.testing.assert_allclose(np.atleast_1d(c_one)[0], c_npy[1], rtol=REL, atol=0)


def bad_file(tmp, name, runs):
    """A folder for one bad .lh5 file with a valid sidecar."""
    _, npy_dir, _ = runs
    d = tmp / name
    d.mkdir()
    sidecar = sorted(npy_dir.glob("*.toml"))
    sidecar = [s for s in sidecar if s.name != "measurement.toml"][0]
    shutil.copy(sidecar, d / f"{name}.toml")
    return d / f"{name}.lh5"


def test_lh5_without_the_waveform_table_exits_2_naming_it(cli, runs, tmp_path):
    path = bad_file(tmp_path, "notable", runs)
    table = Table(col_dict={"energy": Array(np.arange(5.0))})
    lh5.write(table, name="raw", group="ch000", lh5_file=str(path), wo_mode="overwrite_file")
    for raw in [path, path.parent]:
        code, out, err = cli("measure", "--raw", raw, "--out", tmp_path / "cv.csv")
        assert code == 2, err
        assert str(path) in err, err
        assert "waveform" in err, err
        assert "panicked" not in err and "HDF5-DIAG" not in err, err


def test_truncated_lh5_exits_2_naming_it(cli, runs, tmp_path):
    _, _, lh5_dir = runs
    path = bad_file(tmp_path, "truncated", runs)
    good = sorted(lh5_dir.glob("*.lh5"))[0].read_bytes()
    path.write_bytes(good[: len(good) // 3])
    for raw in [path, path.parent]:
        code, out, err = cli("measure", "--raw", raw, "--out", tmp_path / "cv.csv")
        assert code == 2, err
        assert str(path) in err, err
        assert "panicked" not in err and "HDF5-DIAG" not in err, err
