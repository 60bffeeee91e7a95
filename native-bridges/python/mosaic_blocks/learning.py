"""PythonNetLearning: the original MOSAIC's scikit-learn block (MosaicLibary/Blocks/Learning/
PythonNetLearning.cs at AIROB-Lab/MOSAIC e9830ca): PCA, ICA or LDA fitted on the rows of a
Buffer, then applied to every input vector.

The block writes the Buffer's rows to `training` (a CSV file, one row `target…,data…` as the
Buffer saves them) and resets the sidecar, so `init` fits the model on them; before the file
exists the model is unfitted and every output is zeros (the original sent nothing).

Params:
  method        pca | ica | lda-transform | lda-predict
  n_components  outputs of pca, ica and lda-transform (lda-transform: at most classes − 1;
                missing components are 0)
  targets       T, values per target (the first T columns of a training row)
  features      d, values per input row
  training      the training file (absolute path)
  seed          random_state of FastICA
Classes (LDA) are the distinct target vectors. lda-predict outputs the target vector of the
predicted class (T values): with MOSAIC's one-number labels, the label.
"""

from __future__ import annotations

import os

import numpy as np
from sklearn.decomposition import PCA, FastICA
from sklearn.discriminant_analysis import LinearDiscriminantAnalysis

METHODS = ("pca", "ica", "lda-transform", "lda-predict")


def output_width(params: dict) -> int:
    return int(params["targets"]) if params["method"] == "lda-predict" else int(params["n_components"])


def init(params: dict) -> dict:
    method = str(params.get("method", "pca"))
    if method not in METHODS:
        raise ValueError(f"method must be one of {METHODS}, not {method!r}")
    state = {
        "method": method,
        "k": output_width(params),
        "T": int(params["targets"]),
        "d": int(params["features"]),
        "model": None,
        "classes": None,
        "rows": 0,
    }
    path = params.get("training")
    if not path or not os.path.exists(path):
        return state
    table = np.loadtxt(path, delimiter=",", ndmin=2)
    if table.size == 0:
        return state
    T, d = state["T"], state["d"]
    if table.shape[1] != T + d:
        raise ValueError(f"{path}: rows of {table.shape[1]} values, expected {T} + {d}")
    y_vec, X = table[:, :T], table[:, T:]
    n = int(params.get("n_components", 2))
    if method == "pca":
        model = PCA(n_components=n).fit(X)
    elif method == "ica":
        model = FastICA(
            n_components=n, whiten="unit-variance", random_state=int(params.get("seed", 0)), max_iter=1000
        ).fit(X)
    else:
        classes, y = np.unique(y_vec, axis=0, return_inverse=True)
        if len(classes) < 2:
            raise ValueError(f"LDA needs at least two different targets in {path}; it has {len(classes)}")
        lda_n = min(n, len(classes) - 1, d)
        model = LinearDiscriminantAnalysis(n_components=lda_n).fit(X, y.ravel())
        state["classes"] = classes
    state["model"] = model
    state["rows"] = len(X)
    return state


def apply(x: np.ndarray, state: dict) -> np.ndarray:
    """[rows, d] → [rows, k]: transform, or the predicted class's target (lda-predict)."""
    x = np.asarray(x, dtype=np.float64)
    if x.ndim == 1:
        x = x[np.newaxis, :]
    out = np.zeros((x.shape[0], state["k"]))
    model = state["model"]
    if model is None:
        return out
    if state["method"] == "lda-predict":
        return state["classes"][model.predict(x)]
    z = model.transform(x)
    out[:, : z.shape[1]] = z
    return out
