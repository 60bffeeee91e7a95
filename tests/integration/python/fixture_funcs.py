"""Functions for tests/integration/python.test.ts (the Python block's contract)."""

import time

import numpy as np


def identity(x):
    return x


def bits(x):
    """The raw bit pattern of every value, as two exact u32 halves (low, high) in float64."""
    return np.ascontiguousarray(x, dtype="<f8").view("<u4").astype(np.float64)


def init(params):
    return {"seconds": float(params.get("seconds", 0.0)), "calls": 0}


def sleepy(x, state):
    time.sleep(state["seconds"])
    return x


def fails_sometimes(x, state):
    state["calls"] += 1
    if state["calls"] % 3 == 0:
        raise ValueError("every third call fails")
    return x
