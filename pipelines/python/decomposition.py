"""Example 2 (paper III-J): PCA, ICA or LDA from scikit-learn, chosen by a param.

`init` builds the chosen estimator and — with `fit: calibration`, the default — fits it at once
on a calibration recording; every call then transforms each row of `x` (one feature vector per
row, e.g. an 8-channel EMG envelope) into `n_components` values. With `fit: first` (PCA and ICA
only: they need no labels) the estimator is instead fitted online on the first `n_fit` rows
that arrive; until then the block emits zeros of the final shape, so downstream blocks see a
fixed shape from the first event.

Used by decomposition.yaml as:

    Type: Python
    Params:
      Module: decomposition.py
      Init: init
      Function: transform
      Params: { method: lda, n_components: 3, calibration: calibration/Features.txt,
                labels: calibration/Labels.txt }

Params (the block's `Params` dict):
  method        pca | ica | lda (default pca). pca: sklearn.decomposition.PCA; ica:
                sklearn.decomposition.FastICA (whiten="unit-variance"); lda:
                sklearn.discriminant_analysis.LinearDiscriminantAnalysis (needs labels).
  n_components  outputs per row (default 2; LDA: at most classes − 1)
  fit           calibration (default) | first
  calibration   calibration features, relative to this file: a text file of rows
                `timestamp,f1,…,fn` as a Logger or a block's Path writes them (the first column
                is dropped when `timestamp_column` is true, the default), or any CSV with
                `timestamp_column: false`. Lines starting with # and a non-numeric header are
                skipped.
  labels        LDA only: the label of each calibration row, same format: one column (the
                class) or several (a one-hot or target vector; its argmax is the class). Rows
                are matched to the features by timestamp when both files have one.
  n_fit         with fit: first, rows to collect before fitting (default 250, 10 s at 25 Hz)
  standardize   scale every feature to zero mean and unit variance before PCA / ICA
                (default true; LDA is scale-invariant and ignores it)
  seed          random_state of FastICA (default 0): the same seed gives the same unmixing
"""

from __future__ import annotations

import os

import numpy as np
from sklearn.decomposition import PCA, FastICA
from sklearn.discriminant_analysis import LinearDiscriminantAnalysis
from sklearn.pipeline import make_pipeline
from sklearn.preprocessing import StandardScaler

HERE = os.path.dirname(os.path.abspath(__file__))
METHODS = ("pca", "ica", "lda")


def _path(name: str) -> str:
    return name if os.path.isabs(name) else os.path.join(HERE, name)


def load_table(name: str, timestamp_column: bool = True) -> tuple[np.ndarray | None, np.ndarray]:
    """(timestamps or None, values [rows, cols]) of a Logger/Path log or a plain CSV."""
    rows = []
    with open(_path(name), encoding="utf-8") as f:
        for line in f:
            line = line.strip()
            if not line or line.startswith("#"):
                continue
            fields = line.replace(";", ",").replace("\t", ",").split(",")
            try:
                rows.append([float(v) for v in fields])
            except ValueError:
                if rows:  # a bad line after data is an error; a header before it is not
                    raise ValueError(f"{name}: cannot read line {line[:60]!r}") from None
    if not rows:
        raise ValueError(f"{name}: no numeric rows")
    table = np.asarray(rows, dtype=np.float64)
    if timestamp_column:
        return table[:, 0], table[:, 1:]
    return None, table


def _estimator(method: str, n_components: int, standardize: bool, seed: int):
    if method == "pca":
        est = PCA(n_components=n_components)
    elif method == "ica":
        est = FastICA(
            n_components=n_components, whiten="unit-variance", random_state=seed, max_iter=1000
        )
    elif method == "lda":
        return LinearDiscriminantAnalysis(n_components=n_components)
    else:
        raise ValueError(f"method must be one of {METHODS}, not {method!r}")
    return make_pipeline(StandardScaler(), est) if standardize else est


def init(params: dict) -> dict:
    """Builds the estimator; fits it on the calibration file unless fit is 'first'."""
    method = str(params.get("method", "pca")).lower()
    fit = str(params.get("fit", "calibration")).lower()
    n_components = int(params.get("n_components", 2))
    standardize = bool(params.get("standardize", True))
    seed = int(params.get("seed", 0))
    if fit not in ("calibration", "first"):
        raise ValueError(f"fit must be 'calibration' or 'first', not {fit!r}")
    if method == "lda" and fit != "calibration":
        raise ValueError("LDA is supervised: it needs fit: calibration with a labels file")
    state = {
        "method": method,
        "n_components": n_components,
        "model": _estimator(method, n_components, standardize, seed),
        "fitted": False,
        "buffer": [],
        "n_fit": int(params.get("n_fit", 250)),
    }
    if fit == "calibration":
        if "calibration" not in params:
            raise ValueError("fit: calibration needs a 'calibration' file param")
        ts_col = bool(params.get("timestamp_column", True))
        t, features = load_table(params["calibration"], ts_col)
        if method == "lda":
            if "labels" not in params:
                raise ValueError("method: lda needs a 'labels' file param")
            tl, labels = load_table(params["labels"], ts_col)
            if t is not None and tl is not None:
                # Keep the rows whose timestamps both files have (rounded to the microsecond
                # that the logs print).
                _, fi, li = np.intersect1d(
                    np.round(t, 6), np.round(tl, 6), assume_unique=False, return_indices=True
                )
                features, labels = features[fi], labels[li]
            if len(labels) != len(features):
                raise ValueError(f"{len(features)} calibration rows but {len(labels)} labels")
            y = labels[:, 0] if labels.shape[1] == 1 else np.argmax(labels, axis=1)
            state["model"].fit(features, y)
        else:
            state["model"].fit(features)
        state["fitted"] = True
        state["n_features"] = features.shape[1]
    return state


def transform(x: np.ndarray, state: dict) -> np.ndarray:
    """[rows, features] → [rows, n_components]; zeros while still collecting with fit: first."""
    x = np.asarray(x, dtype=np.float64)
    if x.ndim == 1:
        x = x[np.newaxis, :]
    if not state["fitted"]:
        state["buffer"].append(x.copy())
        collected = sum(len(b) for b in state["buffer"])
        if collected < state["n_fit"]:
            return np.zeros((x.shape[0], state["n_components"]))
        data = np.concatenate(state["buffer"], axis=0)
        state["model"].fit(data)
        state["fitted"] = True
        state["n_features"] = data.shape[1]
        state["buffer"] = []
    return state["model"].transform(x)
