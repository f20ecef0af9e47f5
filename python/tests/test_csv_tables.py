"""Issue 22, item 4: every CSV hpge-cv writes loads with pandas.read_csv(path) and
numpy.genfromtxt(path, names=True, delimiter=',') without options (no comment lines; the
provenance is in the JSON sidecar). Small sizes: seconds, not minutes."""

import json

import numpy as np
import pytest

pd = pytest.importorskip("pandas")

SS = "detectors/super-siegfried-k1.toml"
COAX = "detectors/coax-analytic.toml"


def check(path, columns, rows):
    """Both readers, no options: the columns (pandas' names exactly), the row count."""
    df = pd.read_csv(path)
    assert list(df.columns) == columns, path
    assert len(df) == rows, path
    a = np.genfromtxt(path, names=True, delimiter=",")
    assert len(a.dtype.names) == len(columns), (path, a.dtype.names)
    assert a.shape == (rows,), (path, a.shape)
    with open(path) as f:
        assert not any(line.startswith("#") for line in f), path
    return df, a


def test_simulate_field_pulse_tables_load_as_they_are(cli, tmp_path):
    def ok(*args):
        code, _, err = cli(*args)
        assert code == 0, err

    cv = tmp_path / "cv.csv"
    ok("simulate", "--detector", COAX, "--voltages", "500,1500", "--out", cv)
    df, a = check(cv, ["voltage_V", "c12_pF", "fully_depleted", "c12_err_pF",
                       "tolerance_reached", "depletion_voltage_V", "depletion_voltage_err_V",
                       "pinch_off_voltage_V", "pinch_off_voltage_err_V"], 2)
    assert np.allclose(a["c12_pF"], df["c12_pF"])
    assert (df["c12_pF"] > 0).all()

    e = tmp_path / "e.csv"
    ok("field", "--detector", SS, "--voltage", "3000", "--phi", "30", "--z", "35",
       "--r-range", "5:38:12", "--out", e)
    df, a = check(e, ["r_mm", "e_V_per_cm", "status"], 12)
    assert np.allclose(a["r_mm"], df["r_mm"])
    # Empty cells (no field) are NaN in both.
    assert np.array_equal(np.isnan(a["e_V_per_cm"]), df["e_V_per_cm"].isna().to_numpy())
    side = json.loads((tmp_path / "e.json").read_text())
    assert side["program"] == "hpge-cv" and side["voltage_V"] == 3000.0

    p = tmp_path / "p.csv"
    ok("pulse", "--detector", SS, "--param", "d_li_mm=3", "--voltage", "3000", "--at",
       "37,30,35", "--normalise", "--out", p)
    df = pd.read_csv(p)
    check(p, ["t_ns", "q1", "q2"], len(df))
    assert abs(df["q1"].iloc[-1] - 1.0) < 1e-3
    assert "version" in json.loads((tmp_path / "p.json").read_text())


def test_measured_curve_and_covariance_load_as_they_are(cli, tmp_path):
    truth = tmp_path / "truth.csv"
    truth.write_text(
        "voltage_V,c12_pF,fully_depleted\n100,300,false\n900,60,false\n1300,50,true\n1700,50,true\n"
    )
    raw = tmp_path / "raw"
    code, _, err = cli("synthesize", "--curve", truth, "--out", raw, "--pulses", "20",
                       "--decimate", "40", "--seed", "1")
    assert code == 0, err
    cv = tmp_path / "cv.csv"
    code, _, err = cli("measure", "--raw", raw, "--out", cv)
    assert code == 0, err
    df, a = check(cv, ["voltage_V", "c12_pF", "sigma_pF"], 4)
    assert list(df["voltage_V"]) == [100, 900, 1300, 1700]
    assert np.allclose(a["c12_pF"], [300, 60, 50, 50], rtol=5e-3)
    cov = pd.read_csv(tmp_path / "cv.covariance.csv")
    assert list(cov.columns) == ["voltage_V", "100", "900", "1300", "1700"]
    assert cov.shape == (4, 5)
    c = np.genfromtxt(tmp_path / "cv.covariance.csv", names=True, delimiter=",")
    assert c.shape == (4,) and len(c.dtype.names) == 5
    report = json.loads((tmp_path / "cv.measure.json").read_text())
    assert report["program"] == "hpge-cv" and "uncertainties" in report


def test_paper_section9_tables_load_as_they_are(cli, tmp_path):
    code, _, err = cli("paper-section9", "--out", tmp_path)
    assert code == 0, err
    for name, first in [("field-r.csv", "r_mm"), ("pulses-nplus.csv", "t_ns"),
                        ("section9.csv", "model")]:
        df = pd.read_csv(tmp_path / name)
        assert df.columns[0] == first and len(df) > 0, name
        check(tmp_path / name, list(df.columns), len(df))
    side = json.loads((tmp_path / "section9.json").read_text())
    assert "provenance" in side and "field-r.csv" in side["tables"]


def test_predict_table_on_stdout_loads_as_it_is(cli, tmp_path):
    params = ",".join(["d_li_mm=3"] + [f"y{k}_{s}=0.5" for s in ("bot", "top") for k in range(1, 5)])
    code, out, err = cli("predict", "--model", "models/super-siegfried-rz-split.safetensors",
                         "--params", params, "--voltages", "1000,2000,2900")
    assert code == 0, err
    path = tmp_path / "c.csv"
    path.write_text(out)
    check(path, ["voltage_V", "c12_pF", "sigma_pF"], 3)
