"""Example 4 (paper III-J): incremental non-negative matrix factorisation (iNMF) for muscle
synergies.

Muscle synergies model the EMG envelopes of m muscles as a non-negative mix of r < m synergies:
v(t) ≈ W h(t), W [m, r] ≥ 0 the synergies (each column a fixed pattern of co-activation),
h(t) ≥ 0 their activations. Batch NMF (Lee & Seung) needs the whole recording; this module
learns W online, one envelope sample at a time, and emits h(t) on every event, so the
activations can drive a device while the synergies are still being learnt and adapt when
they drift (electrode shift, fatigue).

Algorithm (per row v of the input, clipped at 0), the online matrix factorisation of
Mairal et al. (2010: their Algorithm 1, with the non-negativity constraints of their NMF
extension) with a forgetting factor β instead of their 1/t weights:
  1. activations — W fixed: h = argmin_{h ≥ 0} ‖v − W h‖² (scipy.optimize.nnls, exact);
  2. sufficient statistics: A ← βA + v hᵀ, B ← βB + h hᵀ (A = Σ β^(n−k) v_k h_kᵀ,
     B = Σ β^(n−k) h_k h_kᵀ: the whole weighted past in a fixed-size state, nothing is stored
     per sample; old data fades with a time constant of 1/(1 − β) samples);
  3. synergies — block-coordinate descent on Σ β^(n−k) ‖v_k − W h_k‖² (their Algorithm 2),
     column by column: u = w_j + (a_j − W b_j) / B_jj, w_j = max(u, 0) / max(‖max(u, 0)‖, 1)
     (non-negative, norm ≤ 1, which removes NMF's scale ambiguity).
`solver: mu` replaces steps 1 and 3 by multiplicative updates (Lee & Seung 2001), the
incremental NMF of Bucak & Günsel (2009): h ← h ⊙ (Wᵀv) / (WᵀW h + ε) (`h_iters` times) and
W ← W ⊙ A / (W B + ε) (`w_iters` times), then columns rescaled to unit norm (W ← W D⁻¹,
A ← A D, B ← D B D, which leaves the cost unchanged). Both learn planted synergies from
noisy mixtures (tests/test_synergies.py); the multiplicative updates move entries near zero
only slowly and now and then settle in a poorer factorisation, hence bcd as the default.

  J. Mairal, F. Bach, J. Ponce, G. Sapiro, "Online learning for matrix factorization and sparse
    coding", JMLR 11, 19–60, 2010.
  D. D. Lee, H. S. Seung, "Algorithms for non-negative matrix factorization", NIPS 13, 2001.
  S. S. Bucak, B. Günsel, "Incremental subspace learning via non-negative matrix
    factorization", Pattern Recognition 42(5), 788–797, 2009.
(The paper's own references [61], [62] for its iNMF example are not in the text we have.)

Used by synergies.yaml as:

    Type: Python
    Params:
      Module: synergies.py
      Init: init
      Function: step
      Params: { n_synergies: 4, forgetting: 0.998, seed: 0 }

`x` is [rows, m]: rectified, low-passed EMG envelopes, one sample per row (a vector event is
one row). Every row updates the model in order. The output is the activations of the last row,
[1, r] (`output: last`, the default) or of every row, [rows, r] (`output: all`).

Params (the block's `Params` dict):
  n_synergies  r (default 4)
  forgetting   β in (0, 1] (default 0.998: a memory of about 500 samples, 10 s at 50 Hz)
  solver       bcd (default: exact NNLS activations, block-coordinate descent on W) | mu
  w_iters      passes over W's columns (bcd) or multiplicative W updates (mu) per row
               (default 1)
  h_iters      mu only: multiplicative updates of h per row (default 30)
  seed         seed of the random positive initial W (default 0): same seed, same output
  output       last | all (default last)
"""

from __future__ import annotations

import numpy as np
from scipy.optimize import nnls

EPS = 1e-12
SOLVERS = ("bcd", "mu")


def init(params: dict) -> dict:
    """A fresh model; W is created on the first call, when the number of channels is known."""
    beta = float(params.get("forgetting", 0.998))
    if not 0.0 < beta <= 1.0:
        raise ValueError(f"forgetting must be in (0, 1], not {beta}")
    solver = str(params.get("solver", "bcd"))
    if solver not in SOLVERS:
        raise ValueError(f"solver must be one of {SOLVERS}, not {solver!r}")
    output = str(params.get("output", "last"))
    if output not in ("last", "all"):
        raise ValueError(f"output must be 'last' or 'all', not {output!r}")
    return {
        "r": int(params.get("n_synergies", 4)),
        "beta": beta,
        "solver": solver,
        "h_iters": int(params.get("h_iters", 30)),
        "w_iters": int(params.get("w_iters", 1)),
        "seed": int(params.get("seed", 0)),
        "output": output,
        "W": None,
        "A": None,
        "B": None,
        "samples": 0,
    }


def _start(state: dict, m: int) -> None:
    r = state["r"]
    rng = np.random.default_rng(state["seed"])
    W = rng.uniform(0.5, 1.5, size=(m, r))
    state["W"] = W / np.linalg.norm(W, axis=0)
    state["A"] = np.zeros((m, r))
    state["B"] = np.zeros((r, r))
    state["samples"] = 0


def activations_mu(W: np.ndarray, v: np.ndarray, iters: int) -> np.ndarray:
    """Non-negative h with v ≈ W h by multiplicative updates (W fixed); v [m] or [m, n]."""
    WtV = W.T @ v
    WtW = W.T @ W
    h = WtV / (WtW @ np.ones_like(WtV) + EPS)  # one update from h = 1
    for _ in range(iters):
        h *= WtV / (WtW @ h + EPS)
    return h


def activations_nnls(W: np.ndarray, v: np.ndarray) -> np.ndarray:
    """The exact h = argmin_{h ≥ 0} ‖v − W h‖ (Lawson–Hanson active set); v [m]."""
    return nnls(W, v)[0]


def update(state: dict, v: np.ndarray) -> np.ndarray:
    """One sample: its activations, then the statistics and W. Returns h [r]."""
    W, A, B, beta = state["W"], state["A"], state["B"], state["beta"]
    mu = state["solver"] == "mu"
    h = activations_mu(W, v, state["h_iters"]) if mu else activations_nnls(W, v)
    A *= beta
    A += np.outer(v, h)
    B *= beta
    B += np.outer(h, h)
    if mu:
        # Only synergies that have been active (B_jj > 0) are updated: a multiplicative step
        # on a column with no statistics yet (e.g. after all-zero input) would zero it for good.
        active = np.diag(B) >= EPS
        if np.any(active):
            for _ in range(state["w_iters"]):
                W[:, active] *= (A / (W @ B + EPS))[:, active]
            norms = np.linalg.norm(W, axis=0)
            norms[norms < EPS] = 1.0  # a column that died stays zero
            W /= norms
            A *= norms[np.newaxis, :]
            B *= np.outer(norms, norms)
    else:
        for _ in range(state["w_iters"]):
            for j in range(W.shape[1]):
                if B[j, j] < EPS:  # this synergy has not been active yet: nothing to learn
                    continue
                u = np.maximum(W[:, j] + (A[:, j] - W @ B[:, j]) / B[j, j], 0.0)
                W[:, j] = u / max(np.linalg.norm(u), 1.0)
    state["samples"] += 1
    return h


def step(x: np.ndarray, state: dict) -> np.ndarray:
    """Updates the model with every row of x and emits the synergy activations."""
    x = np.asarray(x, dtype=np.float64)
    if x.ndim == 1:
        x = x[np.newaxis, :]
    if state["W"] is None or state["W"].shape[0] != x.shape[1]:
        _start(state, x.shape[1])
    v_all = np.maximum(np.nan_to_num(x, nan=0.0, posinf=0.0, neginf=0.0), 0.0)
    hs = np.empty((x.shape[0], state["r"]))
    for i, v in enumerate(v_all):
        hs[i] = update(state, v)
    return hs if state["output"] == "all" else hs[-1:]


def synergies(state: dict) -> np.ndarray | None:
    """The current synergies W [m, r] (None before the first call)."""
    return None if state["W"] is None else state["W"].copy()


def reconstruction_error(W: np.ndarray, V: np.ndarray) -> float:
    """Relative error ‖V − W H‖_F / ‖V‖_F of rows V [n, m] with their best H ≥ 0 for W."""
    V = np.maximum(np.asarray(V, dtype=np.float64), 0.0)
    H = np.stack([activations_nnls(W, v) for v in V], axis=1)
    return float(np.linalg.norm(V.T - W @ H) / np.linalg.norm(V))
