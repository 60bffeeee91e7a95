"""Functions for tests/robustness/python-*.test.ts: hangs, busy loops, errors, crashes, memory.

Call 1 of every process is the probe at load (with a throwaway state), so a misbehaviour that
starts "from call `at`" (default 3) leaves the load alone and begins once the pipeline runs.
"""

import os
import random
import time
from pathlib import Path

import numpy as np


def init(params):
    return {"n": 0, "at": int(params.get("at", 3)), **params}


def _due(state):
    state["n"] += 1
    return state["n"] >= state["at"]


def hang(x, state):
    """Sleeps (practically) forever from call `at` on; touches `flag` (if given) first."""
    if _due(state):
        if state.get("flag"):
            Path(state["flag"]).touch()
        time.sleep(1e6)
    return x


def spin(x, state):
    """Busy in pure Python forever from call `at` on."""
    if _due(state):
        if state.get("flag"):
            Path(state["flag"]).touch()
        while True:
            pass
    return x


def raises(x, state):
    """Raises from call `at` on."""
    if _due(state):
        raise ValueError(f"call {state['n']} fails")
    return x


def crashes(x, state):
    """The process exits abruptly at call `at` (a segfault-like death, no traceback)."""
    if _due(state):
        os._exit(7)
    return x


def allocates(x, state):
    """Allocates `mb` megabytes (untouched) on every call from `at` on."""
    if _due(state):
        block = np.empty(int(state["mb"]) * 131072)
        return x + 0 * block[:1].size
    return x


def running_sum(x, state):
    """A result that depends on every input before it (one skipped input changes all later
    results), after a random delay of up to `jitter_ms` so that timing differs between runs."""
    state["n"] += 1
    state["acc"] = state.get("acc", 0) + x
    jitter = float(state.get("jitter_ms", 0))
    if jitter > 0:
        time.sleep(random.random() * jitter / 1000)
    return np.concatenate([state["acc"], [[float(state["n"])]]], axis=1)
