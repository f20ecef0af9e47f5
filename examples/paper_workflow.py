"""The paper's workflow in Python (Abt et al., EPJ C 2023): detector, C-V curve, surrogate, fit.

Run from anywhere after `pip install .` at the repository root:  python examples/paper_workflow.py
"""
from pathlib import Path

import numpy as np

import hpge_cv

ROOT = Path(__file__).resolve().parents[1]
DETECTOR = ROOT / "detectors" / "super-siegfried-k1.toml"
MODEL = ROOT / "models" / "super-siegfried-rz-split.safetensors"
DATA = ROOT / "data" / "super-siegfried-k1" / "cv.csv"

# 1. The detector and its C-V curve from the field solver (manufacturer's model, d_Li = 1 mm).
det = hpge_cv.Detector(DETECTOR, params={"d_li_mm": 1.0})
sim = hpge_cv.simulate(det, np.arange(25.0, 3000.0, 500.0), progress=False)
for u, c in zip(sim["voltage_V"], sim["c12_pF"]):
    print(f"field solver: U_B = {u:6.0f} V  c12 = {c:8.3f} pF")

# 2. The surrogate at one parameter point, with its Jacobian dc12/dp.
p = {"d_li_mm": 1.0, "y1_bot": 0.66, "y2_bot": 0.66, "y3_bot": 0.6, "y4_bot": 0.3,
     "y1_top": 0.57, "y2_top": 0.57, "y3_top": 0.5, "y4_top": 0.2}
pred = hpge_cv.predict(MODEL, p, sim["voltage_V"], jacobian=True)
print("surrogate c12 (pF):", np.round(pred["c12_pF"], 3), "Jacobian", pred["jacobian_pF"].shape)

# 3. The B_RZ fit of the shipped curve: `hpge-cv fit --seed 0 --no-exact-check` (the defaults).
fit = hpge_cv.fit(data=DATA, model=MODEL, prior=ROOT / "priors" / "b-rz.toml",
                  detector=DETECTOR, seed=0, progress=False)
s = fit["summary"]
print(f"converged {s['converged']}, chi2/ndf {s['chi2']:.2f}/{s['ndf']}, draws {fit['draws'].shape}")
for q in s["parameters"]:
    print(f"{q['name']:>8}: mean {q['mean']:.5f} sd {q['std']:.5f} mode {q['global_mode']:.5f}")
