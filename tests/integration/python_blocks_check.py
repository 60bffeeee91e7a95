#!/usr/bin/env python3
"""Checks what the Python-backed blocks logged against NumPy/SciPy/scikit-learn computed here,
independently of the blocks' modules (except iNMF, whose reference is the example module
pipelines/python/synergies.py it runs on). Prints one JSON object: {"ok": true, ...} or
{"ok": false, "why": ...}.

  filt  --input LOG --output LOG --kind lowpass|notch --n N --frequency F --fs FS
        the output rows equal scipy.signal.lfilter over the input rows, every channel from
        lfilter_zi(b, a) (the original's start), bit for bit
  pca   --training CSV --targets T --input LOG --output LOG --after S --components K
        the outputs S seconds after the first input equal sklearn PCA fitted on the training rows
  inmf  --input LOG --output LOG --synergies R --forgetting B --seed S
        the outputs equal synergies.step on the input rows, in order
A log line is `t,v1,…,vn` (a window is its rows, one after the other).
"""

import argparse
import importlib.util
import json
from pathlib import Path

import numpy as np
from scipy import signal
from sklearn.decomposition import PCA


def log(path):
    rows = np.loadtxt(path, delimiter=",", ndmin=2)
    return rows[:, 0], rows[:, 1:]


def out(ok, **kw):
    print(json.dumps({"ok": bool(ok), **kw}))


def filt(a):
    _, x = log(a.input)
    _, y = log(a.output)
    ch = a.channels
    x = x.reshape(-1, ch)
    y = y.reshape(-1, ch)
    if a.kind == "lowpass":
        b, aa = signal.butter(a.n, 2 * a.frequency / a.fs, "low")
    else:
        b, aa = signal.iirnotch(a.frequency, a.n, a.fs)
    z0 = signal.lfilter_zi(b, aa)
    want = np.stack([signal.lfilter(b, aa, x[:, c], zi=z0)[0] for c in range(ch)], axis=1)
    n = len(y)
    if n == 0:
        return out(False, why="no output")
    same = np.array_equal(y, want[:n])
    out(same, rows=n, maxdiff=float(np.max(np.abs(y - want[:n]))))


def pca(a):
    table = np.loadtxt(a.training, delimiter=",", ndmin=2)
    X = table[:, a.targets :]
    model = PCA(n_components=a.components).fit(X)
    tx, x = log(a.input)
    ty, y = log(a.output)
    keep = ty > tx[0] + a.after
    xs = {round(t, 6): row for t, row in zip(tx, x)}
    got = y[keep]
    want = model.transform(np.array([xs[round(t, 6)] for t in ty[keep]]))
    out(
        len(got) > 0 and np.allclose(got, want, rtol=0, atol=1e-12),
        rows=int(len(got)),
        training_rows=int(len(X)),
        maxdiff=float(np.max(np.abs(got - want))) if len(got) else None,
    )


def inmf(a):
    spec = importlib.util.spec_from_file_location(
        "synergies", Path(__file__).resolve().parents[2] / "pipelines" / "python" / "synergies.py"
    )
    S = importlib.util.module_from_spec(spec)
    spec.loader.exec_module(S)
    tx, x = log(a.input)
    ty, y = log(a.output)
    state = S.init({"n_synergies": a.synergies, "forgetting": a.forgetting, "seed": a.seed})
    want = np.stack([S.step(row[np.newaxis, :], state)[0] for row in x])
    # Every input answered, in order; only the last ones may still have been in flight at stop.
    n = len(y)
    same = n >= len(tx) - 3 and np.array_equal(ty, tx[:n]) and np.array_equal(y, want[:n])
    out(same, rows=int(n), inputs=int(len(x)))


def main():
    ap = argparse.ArgumentParser()
    sub = ap.add_subparsers(dest="mode", required=True)
    f = sub.add_parser("filt")
    for k in ("--input", "--output", "--kind"):
        f.add_argument(k, required=True)
    f.add_argument("--n", type=int, required=True)
    f.add_argument("--frequency", type=float, required=True)
    f.add_argument("--fs", type=float, required=True)
    f.add_argument("--channels", type=int, required=True)
    p = sub.add_parser("pca")
    for k in ("--training", "--input", "--output"):
        p.add_argument(k, required=True)
    p.add_argument("--targets", type=int, required=True)
    p.add_argument("--after", type=float, required=True)
    p.add_argument("--components", type=int, required=True)
    i = sub.add_parser("inmf")
    for k in ("--input", "--output"):
        i.add_argument(k, required=True)
    i.add_argument("--synergies", type=int, required=True)
    i.add_argument("--forgetting", type=float, required=True)
    i.add_argument("--seed", type=int, default=0)
    a = ap.parse_args()
    {"filt": filt, "pca": pca, "inmf": inmf}[a.mode](a)


if __name__ == "__main__":
    main()
