"""PythonNetFiltUC: the original MOSAIC's SciPy filter block (MosaicLibary/Blocks/PythonNetFiltUC.cs
at AIROB-Lab/MOSAIC e9830ca), as it designed and ran its filter:

  kind "lowpass": b, a = scipy.signal.butter(order, 2 * frequency / fs, "low")
  kind "notch":   b, a = scipy.signal.iirnotch(frequency, q, fs)

and every channel filtered with scipy.signal.lfilter, its state kept between calls. The original
started every channel at zi = scipy.signal.lfilter_zi(b, a) — the steady state for an input that
had been 1 for ever, not scaled by the first sample (`initial: step`); `initial: zero` starts
from rest, as lfilter does by default.

Params: kind (lowpass | notch), order (lowpass), q (notch), frequency (Hz), fs (Hz),
initial (step | zero). x: [rows, channels], rows consecutive samples; the output has its shape.
"""

from __future__ import annotations

import numpy as np
from scipy import signal


def design(params: dict) -> tuple[np.ndarray, np.ndarray]:
    kind = str(params.get("kind", "lowpass"))
    freq = float(params["frequency"])
    fs = float(params["fs"])
    if kind == "lowpass":
        b, a = signal.butter(int(params.get("order", 2)), 2 * freq / fs, "low")
    elif kind == "notch":
        b, a = signal.iirnotch(freq, float(params.get("q", 30)), fs)
    else:
        raise ValueError(f"kind must be lowpass or notch, not {kind!r}")
    return b, a


def init(params: dict) -> dict:
    b, a = design(params)
    initial = str(params.get("initial", "step"))
    if initial not in ("step", "zero"):
        raise ValueError(f"initial must be step or zero, not {initial!r}")
    return {"b": b, "a": a, "initial": initial, "zi": None}


def step(x: np.ndarray, state: dict) -> np.ndarray:
    x = np.asarray(x, dtype=np.float64)
    if x.ndim == 1:
        x = x[np.newaxis, :]
    b, a = state["b"], state["a"]
    zi = state["zi"]
    if zi is None or len(zi) != x.shape[1]:
        z0 = signal.lfilter_zi(b, a) if state["initial"] == "step" else np.zeros(max(len(a), len(b)) - 1)
        zi = [z0.copy() for _ in range(x.shape[1])]
    y = np.empty_like(x)
    for c in range(x.shape[1]):
        y[:, c], zi[c] = signal.lfilter(b, a, x[:, c], zi=zi[c])
    state["zi"] = zi
    return y
