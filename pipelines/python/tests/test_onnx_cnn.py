"""Example 3: the ResNet-style 1-D CNN (cnn1d.onnx) in ONNX Runtime."""

from __future__ import annotations

import os
import time

import numpy as np
import pytest
from helpers import EXAMPLES, load

ort = pytest.importorskip("onnxruntime")
cnn = load("onnx_cnn")
mm = load("make_model")

MODEL = os.path.join(EXAMPLES, "cnn1d.onnx")
PARAMS = {"model": "cnn1d.onnx", "gain": 2.0}


def emg_windows(n: int, seed: int = 0) -> np.ndarray:
    """n windows [200, 32] of EMG-like noise (mV, about 0.3 RMS)."""
    return np.random.default_rng(seed).standard_normal((n, 200, 32)) * 0.3


def test_model_file_is_small_and_committed():
    assert os.path.getsize(MODEL) < 1_000_000


def test_generator_reproduces_the_committed_model(tmp_path):
    pytest.importorskip("onnx")
    out = tmp_path / "cnn1d.onnx"
    mm.main(["make_model.py", str(out)])
    with open(MODEL, "rb") as a, open(out, "rb") as b:
        assert a.read() == b.read()


def test_output_shape_range_and_determinism():
    state = cnn.init(PARAMS)
    assert (state["channels"], state["samples"]) == (32, 200)
    w = emg_windows(5)
    ys = [np.asarray(cnn.predict(x, state)) for x in w]
    for y in ys:
        assert y.shape == (1, 5)
        assert y.dtype == np.float64
        assert np.all((y >= 0) & (y <= 1))
    # Same window → the same numbers, in this session and in a new one.
    np.testing.assert_array_equal(cnn.predict(w[0], state), ys[0])
    np.testing.assert_array_equal(cnn.predict(w[0], cnn.init(PARAMS)), ys[0])
    # Different windows → different outputs (the model is not constant).
    assert not np.allclose(ys[0], ys[1])


def test_onnxruntime_matches_the_numpy_reference():
    state = cnn.init(PARAMS)
    x = emg_windows(3, seed=1)
    for w in x:
        ref = mm.reference_forward((w.T * 2.0)[np.newaxis].astype(np.float32))
        np.testing.assert_allclose(cnn.predict(w, state), ref, rtol=0, atol=1e-5)


def test_wrong_window_shape_is_a_clear_error():
    state = cnn.init(PARAMS)
    with pytest.raises(ValueError, match="200 samples × 32 channels"):
        cnn.predict(np.zeros((32, 200)), state)
    with pytest.raises(FileNotFoundError, match="make_model.py"):
        cnn.init({"model": "nope.onnx"})


def test_inference_time_fits_the_25_hz_budget():
    state = cnn.init(PARAMS)
    x = emg_windows(1)[0]
    for _ in range(20):  # warm-up
        cnn.predict(x, state)
    times = []
    for _ in range(200):
        t0 = time.perf_counter()
        cnn.predict(x, state)
        times.append(time.perf_counter() - t0)
    p50, p99 = np.percentile(times, [50, 99]) * 1e3
    print(f"onnx_cnn.predict, 1 thread: p50 {p50:.3f} ms, p99 {p99:.3f} ms (budget 40 ms)")
    assert p50 < 40
