"""Example 1: online (chunked) Butterworth filtering equals scipy's offline filtering."""

from __future__ import annotations

import os

import numpy as np
import pytest
from helpers import DATA, load
from scipy import signal

bw = load("butterworth")

BANDPASS = {"order": 4, "cutoff": [20, 450], "fs": 1000, "btype": "bandpass"}
LOWPASS = {"order": 2, "cutoff": 3, "fs": 1000, "btype": "lowpass"}


def recording() -> np.ndarray:
    """The real biceps recording as [samples, 1] (column emg_mV)."""
    data = np.loadtxt(os.path.join(DATA, "emg_bursts_1000hz.csv"), delimiter=",", skiprows=1)
    return data[:, 1:2]


def run_online(params: dict, x: np.ndarray, sizes) -> np.ndarray:
    """Feeds x to the module in chunks of the given sizes (cycled), as the sidecar would."""
    state = bw.init(params)
    out, i, k = [], 0, 0
    while i < len(x):
        n = sizes[k % len(sizes)]
        y = np.asarray(bw.step(x[i : i + n], state))
        assert y.shape == x[i : i + n].shape
        out.append(y)
        i, k = i + n, k + 1
    return np.concatenate(out, axis=0)


@pytest.mark.parametrize("params", [BANDPASS, LOWPASS], ids=["bandpass", "lowpass"])
@pytest.mark.parametrize(
    "sizes",
    [[1], [200], [7, 1, 130, 64, 2, 999]],
    ids=["per-sample", "chunks-200", "irregular"],
)
def test_chunked_equals_offline_sosfilt(params, sizes):
    x = recording()
    sos = signal.butter(
        params["order"], params["cutoff"], btype=params["btype"], fs=params["fs"], output="sos"
    )
    offline = signal.sosfilt(sos, x, axis=0)
    online = run_online(params, x, sizes)
    err = float(np.max(np.abs(online - offline)))
    print(f"{params['btype']} {sizes}: max |online - offline| = {err:.3g} over {len(x)} samples")
    assert err <= 1e-12
    # sosfilt processes sample by sample whatever the chunking: in practice bit-exact.
    assert np.array_equal(online, offline)


def test_design_matches_scipy():
    sos = bw.init(BANDPASS)["sos"]
    expected = signal.butter(4, [20, 450], "bandpass", fs=1000, output="sos")
    np.testing.assert_array_equal(sos, expected)
    assert sos.shape == (4, 6)  # band-pass of order 4: 8 poles, 4 sections


def test_channels_are_independent():
    rng = np.random.default_rng(0)
    x = rng.standard_normal((500, 3))
    both = run_online(LOWPASS, x, [1])
    for c in range(3):
        alone = run_online(LOWPASS, x[:, c : c + 1], [1])
        np.testing.assert_array_equal(both[:, c : c + 1], alone)


def test_vector_event_shape_and_reset():
    state = bw.init(LOWPASS)
    y1 = bw.step(np.ones((1, 8)), state)
    assert np.shape(y1) == (1, 8)
    bw.step(np.ones((1, 8)), state)
    # A new init (as after a reset) starts from zero state again: same first output.
    np.testing.assert_array_equal(bw.step(np.ones((1, 8)), bw.init(LOWPASS)), y1)


def test_deterministic():
    x = recording()[:3000]
    np.testing.assert_array_equal(run_online(BANDPASS, x, [50]), run_online(BANDPASS, x, [50]))
