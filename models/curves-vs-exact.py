"""Surrogates against the exact curves of a fit's refinement round (issue 59: why B_Z fails with
the gate).

    python3 models/curves-vs-exact.py ROUND_JSON OUT_JSON MODEL [MODEL ...]

ROUND_JSON is a `fit`'s OUT/rounds/round-K.json: its `solved` list holds the exact solver's c12
at the data's voltages for every parameter point the round's check solved (the draws, the mode
last). Each MODEL predicts the same points (`hpge-cv predict --extrapolate`, the release build);
OUT_JSON records, per model, the relative error (c_surrogate - c_exact) / c_exact by band of the
bias and at each of the first two voltages, and the mode's curve (the last point) in full; and
per point the chi^2 of the measured curve (data/super-siegfried-k1/cv.csv) against the exact
curve under the paper likelihood's data and solver terms.
"""
import json
import subprocess
import sys


def quantiles(values):
    v = sorted(values)
    n = len(v)
    return {"n": n, "q50": v[n // 2], "q90": v[int(0.9 * n)], "max": v[-1]}


def main():
    if len(sys.argv) < 4:
        sys.exit(__doc__)
    round_file, out_file, models = sys.argv[1], sys.argv[2], sys.argv[3:]
    rnd = json.load(open(round_file))
    with open("data/super-siegfried-k1/cv.csv") as f:
        lines = [l for l in f.read().split("\n")[1:] if l]
    volts = [float(l.split(",")[0]) for l in lines]
    measured = [float(l.split(",")[1]) for l in lines]
    bands = [(0, 100), (100, 400), (400, 1000), (1000, 2000), (2000, 3100)]
    out = {"round_file": round_file, "round": rnd["round"]["round"], "points": len(rnd["solved"]),
           "voltages_V": volts, "models": {}}
    for m in models:
        errs = []
        for p, exact in rnd["solved"]:
            r = subprocess.run(["target/release/hpge-cv", "predict", "--model", m, "--params",
                                ",".join(map(repr, p)), "--voltages", ",".join(map(repr, volts)),
                                "--json", "--extrapolate"], capture_output=True, text=True, check=True)
            c = json.loads(r.stdout)["c12_pf"]
            errs.append([(a - b) / b for a, b in zip(c, exact)])
        rec = {"bands": [], "at": []}
        for lo, hi in bands:
            idx = [i for i, v in enumerate(volts) if lo <= v < hi]
            rec["bands"].append({"range_V": [lo, hi], **quantiles([abs(e[i]) for e in errs for i in idx])})
        for i in (0, 1):
            col = sorted(e[i] for e in errs)
            rec["at"].append({"voltage_V": volts[i], "min": col[0], "median": col[len(col) // 2], "max": col[-1]})
        p, exact = rnd["solved"][-1]
        rec["mode"] = {"params": p, "exact_pF": exact, "rel_error": errs[-1]}
        out["models"][m] = rec
        at = rec["at"][0]
        print(f"{m}: at {at['voltage_V']:.0f} V {at['min']:+.3f} .. {at['median']:+.3f} .. {at['max']:+.3f};",
              " ".join(f"{b['range_V'][0]}-{b['range_V'][1]} V q50 {b['q50']:.4f} q90 {b['q90']:.4f}" for b in rec["bands"]))
    out["measured_pF"] = measured
    # chi^2 of the measured curve against each exact curve under the paper likelihood's data and
    # solver terms (3% of c_m; 1% of c + 1 pF), without a surrogate term; and without the first
    # voltage.
    def chi2(exact, skip):
        return sum((a - b) ** 2 / ((0.03 * a) ** 2 + (0.01 * b + 1.0) ** 2)
                   for a, b in list(zip(measured, exact))[skip:])
    out["chi2_paper_terms"] = [{"params": p, "chi2": chi2(c, 0), "chi2_without_first": chi2(c, 1)}
                               for p, c in rnd["solved"]]
    with open(out_file, "w") as f:
        json.dump(out, f, indent=1)


if __name__ == "__main__":
    main()
