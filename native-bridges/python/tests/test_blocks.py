"""The modules behind the Python-backed blocks (mosaic_blocks), called as the sidecar calls them."""

from __future__ import annotations

import importlib.util

import numpy as np
import pytest
from scipy import signal
from sklearn.decomposition import PCA
from sklearn.discriminant_analysis import LinearDiscriminantAnalysis

from mosaic_blocks import filt_uc, inmf, learning, torch_model


def chunks(x: np.ndarray, sizes: list[int]):
    at = 0
    for n in sizes:
        yield x[at : at + n]
        at += n


@pytest.mark.parametrize(
    "params",
    [
        {"kind": "lowpass", "order": 2, "frequency": 3, "fs": 200},
        {"kind": "notch", "q": 2, "frequency": 3, "fs": 200},
        {"kind": "lowpass", "order": 4, "frequency": 20, "fs": 1000, "initial": "zero"},
    ],
)
def test_filter_is_scipy_bit_for_bit(params):
    rng = np.random.default_rng(1)
    x = rng.normal(size=(300, 3))
    state = filt_uc.init(params)
    got = np.concatenate([filt_uc.step(c, state) for c in chunks(x, [1, 7, 1, 91, 200])])
    if params["kind"] == "lowpass":
        b, a = signal.butter(params["order"], 2 * params["frequency"] / params["fs"], "low")
    else:
        b, a = signal.iirnotch(params["frequency"], params["q"], params["fs"])
    z0 = signal.lfilter_zi(b, a) if params.get("initial", "step") == "step" else np.zeros(len(a) - 1)
    want = np.stack([signal.lfilter(b, a, x[:, c], zi=z0)[0] for c in range(3)], axis=1)
    assert np.array_equal(got, want)


def test_filter_rejects_unknown_kind():
    with pytest.raises(ValueError, match="lowpass or notch"):
        filt_uc.init({"kind": "bandpass", "frequency": 3, "fs": 200})


def training_file(tmp_path, T: int, rows: np.ndarray) -> str:
    path = tmp_path / "train.csv"
    np.savetxt(path, rows, delimiter=",")
    return str(path)


def test_learning_pca_and_lda_as_scikit_learn(tmp_path):
    rng = np.random.default_rng(2)
    X = rng.normal(size=(60, 4))
    y = np.repeat([1.0, 2.0, 3.0], 20)
    X[y == 2] += 3
    X[y == 3] -= 3
    path = training_file(tmp_path, 1, np.column_stack([y, X]))
    base = {"targets": 1, "features": 4, "training": path}

    unfitted = learning.init({**base, "method": "pca", "n_components": 2, "training": str(tmp_path / "none.csv")})
    assert np.array_equal(learning.apply(np.ones((1, 4)), unfitted), np.zeros((1, 2)))

    s = learning.init({**base, "method": "pca", "n_components": 2})
    xq = rng.normal(size=(5, 4))
    assert np.allclose(learning.apply(xq, s), PCA(n_components=2).fit(X).transform(xq), atol=1e-12)

    s = learning.init({**base, "method": "lda-transform", "n_components": 3})
    want = LinearDiscriminantAnalysis(n_components=2).fit(X, y).transform(xq)
    got = learning.apply(xq, s)
    assert got.shape == (5, 3) and np.allclose(got[:, :2], want, atol=1e-10) and not got[:, 2].any()

    s = learning.init({**base, "method": "lda-predict", "n_components": 2})
    pred = LinearDiscriminantAnalysis().fit(X, y).predict(xq)
    assert np.array_equal(learning.apply(xq, s)[:, 0], pred)


def test_learning_needs_two_classes_for_lda(tmp_path):
    path = training_file(tmp_path, 1, np.column_stack([np.ones(5), np.arange(10.0).reshape(5, 2)]))
    with pytest.raises(ValueError, match="at least two different targets"):
        learning.init({"method": "lda-predict", "targets": 1, "features": 2, "training": path})


@pytest.mark.skipif(importlib.util.find_spec("torch") is not None, reason="torch is installed")
def test_torch_missing_names_the_onnx_route():
    with pytest.raises(RuntimeError, match="ONNX.*onnx_cnn.py"):
        torch_model.init({"model": "model.pt"})


def test_inmf_one_input_is_the_synergies_example():
    S = inmf.S
    rng = np.random.default_rng(3)
    V = np.abs(rng.normal(size=(40, 6)))
    params = {"n_synergies": 3, "forgetting": 0.99, "seed": 4}
    ref = S.init(params)
    want = np.stack([S.step(v[np.newaxis, :], ref)[0] for v in V])
    state = inmf.init({**params, "outputs": 5})
    got = np.stack([inmf.step(np.concatenate([[2.0], v])[np.newaxis, :], state)[0] for v in V])
    assert np.array_equal(got[:, 0], np.ones(40))
    assert np.array_equal(got[:, 1:4], want)
    assert not got[:, 4:].any()


def test_inmf_update_rows_learn_predict_rows_do_not():
    rng = np.random.default_rng(5)
    params = {"n_synergies": 2, "forgetting": 1.0, "seed": 0}
    state = inmf.init(params)
    batch = np.column_stack([np.ones(8), np.abs(rng.normal(size=(8, 4)))])
    out = inmf.step(batch, state)
    assert out[0, 0] == 0 and state["samples"] == 8
    sample = np.array([[0.0, 1, 2, 3, 4], [np.nan, 0, 0, 0, 0]])
    W = state["W"].copy()
    out = inmf.step(sample, state)
    assert out[0, 0] == 1 and state["samples"] == 8 and np.array_equal(W, state["W"])
    assert np.allclose(out[0, 1:], inmf.S.activations_nnls(W, np.array([1.0, 2, 3, 4])))
