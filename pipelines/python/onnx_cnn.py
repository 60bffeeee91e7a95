"""Example 3 (paper III-J, V-(c)): deep-model inference with ONNX Runtime.

The paper's MOSAIC loads a PyTorch model in Python; here the model is an ONNX file, run by
onnxruntime on the CPU with one thread, so the sidecar needs no PyTorch at run time and the
numbers do not depend on a GPU. `init` creates the InferenceSession once (loading and
optimising the graph takes milliseconds, far beyond a 40 ms frame); `predict` runs one window.

Used by onnx_cnn.yaml (the paper's pipeline (c)) as:

    Type: Python
    Params:
      Module: onnx_cnn.py
      Init: init
      Function: predict
      Params: { model: cnn1d.onnx, gain: 2.0 }
      Budget: 40

`x` is a SlidingWindow's window [200 samples, 32 channels] (float64); it is scaled by `gain`,
transposed to the model's [1, 32, 200] float32 layout and run; the output is the model's
[1, 5] activations in [0, 1], as float64, which a ControlAlgorithm turns into commands.

Params (the block's `Params` dict):
  model    the .onnx file, relative to this file (default cnn1d.onnx, made by make_model.py)
  gain     factor applied to the EMG before inference (default 1): the place for the input
           normalisation the model was trained with (e.g. 1 / the calibration RMS)
  threads  onnxruntime intra-op threads (default 1: one core, predictable latency)

Your own PyTorch model: export it once to ONNX (see README.md, "PyTorch → ONNX"):

    torch.onnx.export(model.eval(), (torch.zeros(1, 32, 200),), "mymodel.onnx",
                      input_names=["emg"], output_names=["activations"],
                      opset_version=17, dynamo=False)

and set `model: mymodel.onnx`. The session reads the input's name and shape from the file.
"""

from __future__ import annotations

import os

import numpy as np
import onnxruntime as ort

HERE = os.path.dirname(os.path.abspath(__file__))


def init(params: dict) -> dict:
    """Loads the model into an InferenceSession (CPU, single-threaded by default)."""
    path = str(params.get("model", "cnn1d.onnx"))
    if not os.path.isabs(path):
        path = os.path.join(HERE, path)
    if not os.path.exists(path):
        raise FileNotFoundError(f"ONNX model not found: {path} (run make_model.py)")
    options = ort.SessionOptions()
    options.intra_op_num_threads = int(params.get("threads", 1))
    options.inter_op_num_threads = 1
    options.execution_mode = ort.ExecutionMode.ORT_SEQUENTIAL
    options.graph_optimization_level = ort.GraphOptimizationLevel.ORT_ENABLE_ALL
    session = ort.InferenceSession(path, sess_options=options, providers=["CPUExecutionProvider"])
    inp = session.get_inputs()[0]
    channels, samples = inp.shape[1], inp.shape[2]
    if not isinstance(channels, int) or not isinstance(samples, int):
        raise ValueError(
            f"{path}: input {inp.name} needs fixed channels and samples, got {inp.shape}"
        )
    return {
        "session": session,
        "input": inp.name,
        "output": session.get_outputs()[0].name,
        "channels": channels,
        "samples": samples,
        "gain": float(params.get("gain", 1.0)),
    }


def predict(x: np.ndarray, state: dict) -> np.ndarray:
    """One window [samples, channels] → the model's output [1, outputs] (float64)."""
    x = np.asarray(x)
    want = (state["samples"], state["channels"])
    if x.shape != want:
        raise ValueError(
            f"expected a window of {want[0]} samples × {want[1]} channels, got {x.shape}"
        )
    # [samples, channels] → [1, channels, samples], float32 and contiguous for onnxruntime.
    batch = np.ascontiguousarray((x.T * state["gain"])[np.newaxis], dtype=np.float32)
    out = state["session"].run([state["output"]], {state["input"]: batch})[0]
    return np.asarray(out, dtype=np.float64).reshape(1, -1)
