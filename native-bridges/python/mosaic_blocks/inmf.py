"""iNMF: the original MOSAIC's incremental NMF block (MosaicLibary/Blocks/Learning/iNMF.cs at
AIROB-Lab/MOSAIC e9830ca; its Python model was not published), on the online NMF of
pipelines/python/synergies.py (Mairal et al. 2010, with forgetting): synergies W ≥ 0 learnt
from EMG envelopes, activations h ≥ 0 of every sample.

The block sends x [rows, 1 + m]: column 0 says what to do with the row's m values —
  0  predict: the activations with W fixed (the original's samples input),
  1  update: learn from the row (the original's update batches),
  2  update, then emit its activations (one input: every sample both),
  NaN  nothing (padding).
The result is [1, 1 + k]: column 0 is 1 when a row was predicted or emitted (then columns 1…r
hold the last such row's activations, zeros up to k), else 0 (the block emits nothing).

Params: those of synergies.init (n_synergies, forgetting, solver, w_iters, h_iters, seed), and
outputs k ≥ n_synergies (the original's outputDim; activations padded with zeros).
"""

from __future__ import annotations

import importlib.util
from pathlib import Path

import numpy as np

_SYNERGIES = Path(__file__).resolve().parents[3] / "pipelines" / "python" / "synergies.py"


def _load_synergies():
    spec = importlib.util.spec_from_file_location("mosaic_synergies", _SYNERGIES)
    module = importlib.util.module_from_spec(spec)
    spec.loader.exec_module(module)
    return module


S = _load_synergies()


def init(params: dict) -> dict:
    state = S.init(params)
    state["k"] = int(params.get("outputs", state["r"]))
    if state["k"] < state["r"]:
        raise ValueError(f"outputs ({state['k']}) must be at least n_synergies ({state['r']})")
    return state


def step(x: np.ndarray, state: dict) -> np.ndarray:
    x = np.asarray(x, dtype=np.float64)
    if x.ndim == 1:
        x = x[np.newaxis, :]
    m = x.shape[1] - 1
    if state["W"] is None or state["W"].shape[0] != m:
        S._start(state, m)
    out = np.zeros((1, 1 + state["k"]))
    for row in x:
        flag = row[0]
        if not np.isfinite(flag):
            continue
        v = np.maximum(np.nan_to_num(row[1:], nan=0.0, posinf=0.0, neginf=0.0), 0.0)
        if flag == 0:
            W = state["W"]
            if state["solver"] == "mu":
                h = S.activations_mu(W, v, state["h_iters"])
            else:
                h = S.activations_nnls(W, v)
        else:
            h = S.update(state, v)
            if flag != 2:
                continue
        out[0, 0] = 1.0
        out[0, 1 : 1 + state["r"]] = h
    return out


def synergies(state: dict):
    return S.synergies(state)
