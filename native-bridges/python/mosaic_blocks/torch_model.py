"""SimplePyTorch: the original MOSAIC's PyTorch example (MosaicLibary/Blocks/Learning/SimplePyTorch.cs
at AIROB-Lab/MOSAIC e9830ca): a TorchScript model (torch.jit.load) evaluated on every input
vector as a float32 tensor [1, N]; the first value of its output is the block's output [1, 1].

PyTorch is not part of the sidecar's environment (as it was not part of the original's: its
comments ask the user to install it). Without it `init` fails with a message that names the
ONNX route: export the model with torch.onnx.export and run it with ONNX Runtime, which the
environment has (pipelines/python/onnx_cnn.py).

Params: model (path of the TorchScript file).
"""

from __future__ import annotations

import os

import numpy as np

ONNX_ROUTE = (
    "PyTorch (torch) is not installed in the Python sidecar's environment (native-bridges/python; "
    "MOSAIC does not ship it). Export the model to ONNX (torch.onnx.export) and run it with a "
    "Python block and ONNX Runtime, as pipelines/python/onnx_cnn.py does, or add torch to "
    "native-bridges/python/pyproject.toml"
)


def init(params: dict) -> dict:
    try:
        import torch  # noqa: PLC0415 (optional dependency)
    except ImportError:
        raise RuntimeError(ONNX_ROUTE) from None
    path = str(params.get("model", "model.pt"))
    if not os.path.exists(path):
        raise FileNotFoundError(f"TorchScript model not found: {path}")
    model = torch.jit.load(path)
    model.eval()
    return {"torch": torch, "model": model}


def predict(x: np.ndarray, state: dict) -> np.ndarray:
    torch = state["torch"]
    v = np.asarray(x, dtype=np.float32).reshape(1, -1)
    with torch.no_grad():
        y = state["model"](torch.from_numpy(v)).detach().numpy()
    return np.array([[float(np.asarray(y).reshape(-1)[0])]])
