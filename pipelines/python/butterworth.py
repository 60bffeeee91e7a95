"""Example 1 (paper III-J): an online Butterworth filter with scipy.signal.

The filter is designed once, in `init`, as second-order sections (numerically safer than
(b, a) for high orders and low cut-offs), and every call filters the rows it receives with
`scipy.signal.sosfilt`, keeping the filter state `zi` (one per section and channel) across
calls. Filtering a signal chunk by chunk therefore gives the same numbers as filtering the
whole signal at once offline (`sosfilt(sos, x, axis=0)`): tests/test_butterworth.py checks it
on the real biceps recording.

Used by butterworth.yaml as:

    Type: Python
    Params:
      Module: butterworth.py
      Init: init
      Function: step
      Params: { order: 4, cutoff: [20, 450], fs: 1000, btype: bandpass }

`x` is an array [rows, channels]: rows are consecutive samples (one row for a vector event,
Length rows for a SlidingWindow's window), columns are channels, each filtered independently.
The output has the shape of the input.

Params (the block's `Params` dict):
  order   filter order (default 4; a band-pass or band-stop has 2 × order poles, as in SciPy)
  cutoff  corner frequency in Hz, or [low, high] for bandpass / bandstop (default 20)
  fs      sample rate of the input in Hz (default 1000)
  btype   lowpass | highpass | bandpass | bandstop (default lowpass)
"""

from __future__ import annotations

import numpy as np
from scipy import signal


def design(params: dict) -> np.ndarray:
    """The second-order sections [n_sections, 6] for the block's params."""
    order = int(params.get("order", 4))
    cutoff = params.get("cutoff", 20.0)
    if isinstance(cutoff, (list, tuple)):
        cutoff = [float(c) for c in cutoff]
    else:
        cutoff = float(cutoff)
    fs = float(params.get("fs", 1000.0))
    btype = str(params.get("btype", "lowpass"))
    return signal.butter(order, cutoff, btype=btype, fs=fs, output="sos")


def init(params: dict) -> dict:
    """Called once when the pipeline loads and after every reset: a fresh, zero filter state."""
    return {"sos": design(params), "zi": None}


def step(x: np.ndarray, state: dict) -> np.ndarray:
    """Filters the rows of x (samples) channel by channel, continuing from the kept state."""
    x = np.asarray(x, dtype=np.float64)
    if x.ndim == 1:
        x = x[np.newaxis, :]
    sos = state["sos"]
    zi = state["zi"]
    if zi is None or zi.shape[2] != x.shape[1]:
        # Zero initial conditions, like scipy's default (and the Filter block's): the state
        # is (re)created for the input's channel count on the first call.
        zi = np.zeros((sos.shape[0], 2, x.shape[1]))
    y, state["zi"] = signal.sosfilt(sos, x, axis=0, zi=zi)
    return y
