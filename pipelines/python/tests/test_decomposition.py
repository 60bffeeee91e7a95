"""Example 2: PCA / FastICA / LDA chosen by a param, fitted on the calibration recording."""

from __future__ import annotations

import numpy as np
import pytest
from helpers import load
from sklearn.decomposition import PCA
from sklearn.preprocessing import StandardScaler

dec = load("decomposition")

CAL = {"calibration": "calibration/Features.txt", "labels": "calibration/Labels.txt"}


def features() -> np.ndarray:
    return dec.load_table("calibration/Features.txt")[1]


@pytest.mark.parametrize("method", ["pca", "ica", "lda"])
def test_shapes_and_determinism(method):
    params = {"method": method, "n_components": 3, **CAL}
    x = features()
    a, b = dec.init(params), dec.init(params)
    for row in x[::50]:
        ya = np.asarray(dec.transform(row[np.newaxis], a))
        yb = np.asarray(dec.transform(row[np.newaxis], b))
        assert ya.shape == (1, 3)
        assert np.all(np.isfinite(ya))
        np.testing.assert_array_equal(ya, yb)
    # A window of rows gives one output row per input row.
    assert np.shape(dec.transform(x[:10], a)) == (10, 3)


def test_pca_is_sklearn_pca_of_standardised_calibration():
    x = features()
    state = dec.init({"method": "pca", "n_components": 2, **CAL})
    ref = PCA(n_components=2).fit(StandardScaler().fit_transform(x))
    mu, sd = x.mean(axis=0), x.std(axis=0)
    expected = ref.transform((x[:100] - mu) / sd)
    np.testing.assert_allclose(dec.transform(x[:100], state), expected, rtol=0, atol=1e-9)


def test_lda_separates_the_calibration_gestures():
    state = dec.init({"method": "lda", "n_components": 3, **CAL})
    t, x = dec.load_table("calibration/Features.txt")
    tl, labels = dec.load_table("calibration/Labels.txt")
    np.testing.assert_array_equal(t, tl)  # both logged at the same 25 Hz ticks
    y = np.argmax(labels, axis=1)
    assert len(np.unique(y)) == 6  # rest, fist, open, pinch, flexion, extension
    accuracy = float(np.mean(state["model"].predict(x) == y))
    print(f"LDA training accuracy on the calibration set: {accuracy:.3f}")
    assert accuracy > 0.8  # transitions between gestures blur a few samples


def test_fit_on_first_rows():
    x = features()
    state = dec.init({"method": "pca", "n_components": 2, "fit": "first", "n_fit": 100})
    outs = [np.asarray(dec.transform(row[np.newaxis], state)) for row in x[:150]]
    assert all(o.shape == (1, 2) for o in outs)
    assert all(np.all(o == 0) for o in outs[:99])  # collecting: zeros of the final shape
    assert np.any(outs[99] != 0)  # fitted on the 100th row, which is transformed too
    ref = PCA(n_components=2).fit(StandardScaler().fit_transform(x[:100]))
    mu, sd = x[:100].mean(axis=0), x[:100].std(axis=0)
    np.testing.assert_allclose(outs[120], ref.transform((x[120:121] - mu) / sd), atol=1e-9)


def test_clear_errors():
    with pytest.raises(ValueError, match="method"):
        dec.init({"method": "svd", **CAL})
    with pytest.raises(ValueError, match="LDA"):
        dec.init({"method": "lda", "fit": "first"})
    with pytest.raises(ValueError, match="labels"):
        dec.init({"method": "lda", "calibration": CAL["calibration"]})
    with pytest.raises(FileNotFoundError):
        dec.init({"method": "pca", "calibration": "calibration/missing.txt"})
