"""Which model of the surrogate's error (issue 21): held-out accuracy of candidate corrections.

Input: the CSV that `cargo run --release -p hpge-validation --example refine_probe -- FITDIR N OUT.csv`
writes (N posterior draws of a fit, their surrogate and exact curves on the mode's grids, the
mode last) and its OUT.csv.data (voltages, measured curve). Output: a Markdown table of the error
left in ln c on draws not used for fitting, for
  - no correction,
  - the mean error curve,
  - a linear and a quadratic regression on the standardised parameters (per voltage),
  - the Gaussian process of hpge_inference::refine (squared-exponential with one length per
    parameter plus a linear term, hyperparameters by marginal likelihood), and the coverage of
    its predicted sd.
Usage: python3 reports/error-models.py OUT.csv [SEED]   (numpy, scipy)
"""
import sys

import numpy as np
from scipy.optimize import minimize

path = sys.argv[1]
seed = int(sys.argv[2]) if len(sys.argv) > 2 else 1
head = open(path).readline().strip().split(",")
npar = sum(1 for h in head if h != "i" and not (h[0] in "se" and h[1:].isdigit()))
A = np.genfromtxt(path, delimiter=",", skip_header=1)
th = A[:, 1:1 + npar]
nv = (A.shape[1] - 1 - npar) // 2
cs, ce = A[:, 1 + npar:1 + npar + nv], A[:, 1 + npar + nv:]
R = np.log(ce / cs)
n = len(th)
X = (th - th.mean(0)) / th.std(0)
rng = np.random.default_rng(seed)
perm = rng.permutation(n - 1)


def stats(E):
    a = np.abs(E)
    return np.sqrt((E ** 2).mean()), np.quantile(a, 0.99), a.max(), np.sqrt((E[-1] ** 2).mean())


def basis(Z, quad):
    cols = [np.ones(len(Z))] + [Z[:, j] for j in range(Z.shape[1])]
    if quad:
        cols += [Z[:, j] * Z[:, k] for j in range(Z.shape[1]) for k in range(j, Z.shape[1])]
    return np.array(cols).T


def gp(tr, te):
    scale = np.sqrt((R[tr] ** 2).mean(0))
    Y = R[tr] / scale
    d = npar

    def K(a, b, p):
        ls, sf = np.exp(p[:d]), np.exp(p[d])
        q = (((a[:, None] - b[None]) / ls) ** 2).sum(-1)
        return sf ** 2 * np.exp(-0.5 * q) + 1.0 + a @ b.T

    def nlml(p):
        k = K(X[tr], X[tr], p) + np.exp(2 * max(p[d + 1], -4.6)) * np.eye(len(tr))
        L = np.linalg.cholesky(k)
        a = np.linalg.solve(L, Y)
        return 0.5 * (a ** 2).sum() + Y.shape[1] * np.log(np.diag(L)).sum()

    p = minimize(nlml, np.r_[np.log(np.full(d, 2.0)), 0.0, np.log(0.1)], method="Nelder-Mead",
                 options={"maxfev": 3000, "xatol": 1e-4, "fatol": 1e-6}).x
    k = K(X[tr], X[tr], p) + np.exp(2 * max(p[d + 1], -4.6)) * np.eye(len(tr))
    ks = K(X[te], X[tr], p)
    mean = ks @ np.linalg.solve(k, Y) * scale
    kss = np.exp(2 * p[d]) + 1.0 + (X[te] ** 2).sum(1)
    var = kss - np.einsum("ij,ji->i", ks, np.linalg.solve(k, ks.T))
    return mean, np.sqrt(np.maximum(var, 0))[:, None] * scale


print(f"{n - 1} draws and the mode, {npar} parameters, {nv} voltages; held-out error in ln c\n")
print("| correction | training draws | rms | q99 | max | rms at the mode | within 1 / 2 predicted sd |")
print("|---|---|---|---|---|---|---|")
for ntr in (100, 200):
    tr = perm[:ntr]
    te = np.r_[perm[ntr:], n - 1]
    rows = [("none", R[te]), ("mean error curve", R[te] - R[tr].mean(0))]
    for name, quad in (("linear", False), ("quadratic", True)):
        B = basis(X[tr], quad)
        beta = np.linalg.lstsq(B, R[tr], rcond=None)[0]
        rows.append((name, R[te] - basis(X[te], quad) @ beta))
    for name, E in rows:
        print("| %s | %d | %.4f | %.4f | %.4f | %.4f | - |" % ((name, ntr) + stats(E)))
    m, s = gp(tr, te)
    E = R[te] - m
    z = np.abs(E / s)
    print("| Gaussian process | %d | %.4f | %.4f | %.4f | %.4f | %.2f / %.2f |"
          % ((ntr,) + stats(E) + ((z < 1).mean(), (z < 2).mean())))
