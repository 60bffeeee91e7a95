"""Example 4: incremental NMF — non-negativity, falling reconstruction error, determinism."""

from __future__ import annotations

import numpy as np
import pytest
from helpers import load

syn = load("synergies")
dec = load("decomposition")  # for its log reader


def planted(seed: int = 0, m: int = 8, r: int = 3):
    """Envelopes that truly are r synergies: V = (W H)ᵀ + noise, clipped at 0."""
    rng = np.random.default_rng(seed)
    W = rng.gamma(1.0, 1.0, (m, r))
    W /= np.linalg.norm(W, axis=0)

    def sample(n: int) -> np.ndarray:
        H = rng.gamma(0.5, 1.0, (r, n))
        V = (W @ H).T + 0.01 * rng.standard_normal((n, m))
        return np.maximum(V, 0.0)

    return W, sample


def stream(params: dict, V: np.ndarray, checkpoints, held_out: np.ndarray):
    """Feeds V row by row; returns the outputs and the held-out error at the checkpoints."""
    state = syn.init(params)
    outs, errors = [], []
    for i, v in enumerate(V):
        outs.append(np.asarray(syn.step(v[np.newaxis], state)))
        if i + 1 in checkpoints:
            errors.append(syn.reconstruction_error(syn.synergies(state), held_out))
    return state, outs, errors


@pytest.mark.parametrize("solver", ["bcd", "mu"])
def test_nonnegative_and_error_decreases(solver):
    W_true, sample = planted(seed=0)
    held_out, V = sample(300), sample(3000)
    floor = syn.reconstruction_error(W_true, held_out)  # the noise
    checkpoints = (1, 10, 100, 1000, 3000)
    params = {"n_synergies": 3, "forgetting": 0.999, "solver": solver, "seed": 0}
    state, outs, errors = stream(params, V, checkpoints, held_out)
    print(f"{solver}: held-out relative error {np.round(errors, 4)} (noise floor {floor:.4f})")
    assert all(o.shape == (1, 3) for o in outs)
    assert all(np.all(o >= 0) for o in outs)
    assert np.all(syn.synergies(state) >= 0)
    assert all(b <= a for a, b in zip(errors, errors[1:]))  # never worse with more data
    assert errors[-1] < 0.25 * errors[0]
    assert errors[-1] < 2 * floor
    # The planted synergies are found (up to order): cosine similarity of the best matches.
    W = syn.synergies(state)
    W = W / np.linalg.norm(W, axis=0)
    assert np.all(np.max(W.T @ W_true, axis=0) > 0.99)


def test_deterministic_and_output_modes():
    _, sample = planted(seed=1)
    V = sample(200)
    a, b = syn.init({"n_synergies": 3}), syn.init({"n_synergies": 3})
    for v in V:
        np.testing.assert_array_equal(syn.step(v[np.newaxis], a), syn.step(v[np.newaxis], b))
    np.testing.assert_array_equal(syn.synergies(a), syn.synergies(b))
    # A window of rows updates the model row by row: the same as feeding the rows one by one.
    whole = syn.init({"n_synergies": 3, "output": "all"})
    H = np.asarray(syn.step(V, whole))
    assert H.shape == (200, 3)
    np.testing.assert_array_equal(syn.synergies(whole), syn.synergies(a))
    last = syn.init({"n_synergies": 3})
    assert np.shape(syn.step(V, last)) == (1, 3)


def test_simulated_emg_envelopes():
    """The calibration envelopes (8 channels, 6 gestures): error falls as synergies are learnt."""
    V = dec.load_table("calibration/Features.txt")[1]
    state = syn.init({"n_synergies": 4, "forgetting": 0.998})
    errors = []
    for i, v in enumerate(V):
        h = np.asarray(syn.step(v[np.newaxis], state))
        assert h.shape == (1, 4) and np.all(h >= 0)
        if i + 1 in (50, 300, len(V)):
            errors.append(syn.reconstruction_error(syn.synergies(state), V))
    print(f"calibration envelopes, 4 synergies: relative error {np.round(errors, 4)}")
    assert errors[-1] < errors[0]
    assert errors[-1] < 0.2


def test_bad_params():
    with pytest.raises(ValueError, match="forgetting"):
        syn.init({"forgetting": 1.5})
    with pytest.raises(ValueError, match="solver"):
        syn.init({"solver": "als"})


@pytest.mark.parametrize("solver", ["bcd", "mu"])
def test_zero_input_keeps_the_model_alive(solver):
    """All-zero rows (the sidecar's probe call, a silent start) give zero activations and do
    not destroy W; learning proceeds afterwards."""
    _, sample = planted(seed=2)
    state = syn.init({"n_synergies": 3, "solver": solver})
    for _ in range(5):
        np.testing.assert_array_equal(syn.step(np.zeros((1, 8)), state), np.zeros((1, 3)))
    W0 = syn.synergies(state)
    assert np.all(np.linalg.norm(W0, axis=0) > 0.99)
    for v in sample(500):
        syn.step(v[np.newaxis], state)
    assert syn.reconstruction_error(syn.synergies(state), sample(200)) < 0.1
