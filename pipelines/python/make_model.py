"""Generates cnn1d.onnx: a small ResNet-style 1-D CNN for example 3 (onnx_cnn.py).

    python make_model.py            # writes cnn1d.onnx next to this file
    python make_model.py OUT.onnx   # writes it elsewhere

The network (ResNet-18-inspired, paper V-(c), scaled down so that it runs in well under a
millisecond on one core) takes one EMG window as [batch, 32 channels, 200 samples] float32 and
returns 5 activations in [0, 1] (e.g. hand close, open, pinch, wrist flexion, extension):

    stem     Conv1d 32→32, k 7, stride 2, pad 3, ReLU; MaxPool k 3, stride 2, pad 1   → [32, 50]
    layer1   BasicBlock 32→32: Conv k3 → ReLU → Conv k3, + identity, ReLU           → [32, 50]
    layer2   BasicBlock 32→64, stride 2: the same, + Conv k1 stride 2 shortcut      → [64, 25]
    layer3   BasicBlock 64→64                                                       → [64, 25]
    head     GlobalAveragePool → Flatten → Gemm 64→5 → Sigmoid                      → [5]

(batch normalisation, as in a trained ResNet exported for inference, would be folded into
the convolutions' weights and biases, so it has no nodes of its own.) The weights are NOT
trained: they are seeded He-normal random numbers (numpy.random.default_rng(SEED)), so the file
is reproducible byte for byte and small (about 240 KB). It stands in for a trained model, to
measure the cost of deep-model inference in a pipeline; replace it with your own export (see
README.md, "PyTorch → ONNX").

The graph is built with the `onnx` helper API only (onnx.helper.make_node / make_graph /
make_model, numpy_helper.from_array), opset 17, IR version 8, so any onnxruntime ≥ 1.14
loads it. `reference_forward` is the same network in plain NumPy, which the tests compare
with onnxruntime.
"""

from __future__ import annotations

import os
import sys

import numpy as np

SEED = 1926
CHANNELS = 32
SAMPLES = 200
OUTPUTS = 5
OPSET = 17
IR_VERSION = 8
HERE = os.path.dirname(os.path.abspath(__file__))
DEFAULT_PATH = os.path.join(HERE, "cnn1d.onnx")

# (name, in channels, out channels, kernel, stride, pad) of every convolution, in graph order.
CONVS = [
    ("stem", CHANNELS, 32, 7, 2, 3),
    ("l1_c1", 32, 32, 3, 1, 1),
    ("l1_c2", 32, 32, 3, 1, 1),
    ("l2_c1", 32, 64, 3, 2, 1),
    ("l2_c2", 64, 64, 3, 1, 1),
    ("l2_sc", 32, 64, 1, 2, 0),
    ("l3_c1", 64, 64, 3, 1, 1),
    ("l3_c2", 64, 64, 3, 1, 1),
]


def weights(seed: int = SEED) -> dict[str, np.ndarray]:
    """Seeded He-normal weights (float32), small biases, in a fixed drawing order."""
    rng = np.random.default_rng(seed)
    w: dict[str, np.ndarray] = {}
    for name, cin, cout, k, _, _ in CONVS:
        std = np.sqrt(2.0 / (cin * k))
        w[name + "_W"] = (rng.standard_normal((cout, cin, k)) * std).astype(np.float32)
        w[name + "_B"] = (rng.standard_normal(cout) * 0.01).astype(np.float32)
    w["fc_W"] = (rng.standard_normal((64, OUTPUTS)) * np.sqrt(1.0 / 64)).astype(np.float32)
    w["fc_B"] = np.zeros(OUTPUTS, dtype=np.float32)
    return w


def build(seed: int = SEED):
    """The ONNX ModelProto."""
    import onnx
    from onnx import TensorProto, helper, numpy_helper

    w = weights(seed)
    nodes = []
    geometry = {c[0]: c for c in CONVS}

    def conv(name: str, x: str, out: str) -> str:
        _, _, _, k, stride, pad = geometry[name]
        nodes.append(
            helper.make_node(
                "Conv",
                [x, name + "_W", name + "_B"],
                [out],
                name=name,
                kernel_shape=[k],
                strides=[stride],
                pads=[pad, pad],
            )
        )
        return out

    def relu(x: str, out: str) -> str:
        nodes.append(helper.make_node("Relu", [x], [out], name=out))
        return out

    def add(a: str, b: str, out: str) -> str:
        nodes.append(helper.make_node("Add", [a, b], [out], name=out))
        return out

    def block(prefix: str, x: str, shortcut: str | None) -> str:
        h = relu(conv(prefix + "_c1", x, prefix + "_c1_out"), prefix + "_r1")
        h = conv(prefix + "_c2", h, prefix + "_c2_out")
        skip = conv(shortcut, x, shortcut + "_out") if shortcut else x
        return relu(add(h, skip, prefix + "_sum"), prefix + "_out")

    h = relu(conv("stem", "emg", "stem_out"), "stem_r")
    nodes.append(
        helper.make_node(
            "MaxPool", [h], ["pool"], name="pool", kernel_shape=[3], strides=[2], pads=[1, 1]
        )
    )
    h = block("l1", "pool", None)
    h = block("l2", h, "l2_sc")
    h = block("l3", h, None)
    nodes.append(helper.make_node("GlobalAveragePool", [h], ["gap"], name="gap"))
    nodes.append(helper.make_node("Flatten", ["gap"], ["flat"], name="flat", axis=1))
    nodes.append(helper.make_node("Gemm", ["flat", "fc_W", "fc_B"], ["logits"], name="fc"))
    nodes.append(helper.make_node("Sigmoid", ["logits"], ["activations"], name="sigmoid"))

    graph = helper.make_graph(
        nodes,
        "mosaic_cnn1d",
        [helper.make_tensor_value_info("emg", TensorProto.FLOAT, ["batch", CHANNELS, SAMPLES])],
        [helper.make_tensor_value_info("activations", TensorProto.FLOAT, ["batch", OUTPUTS])],
        initializer=[numpy_helper.from_array(v, name=k) for k, v in w.items()],
    )
    model = helper.make_model(
        graph,
        opset_imports=[helper.make_opsetid("", OPSET)],
        ir_version=IR_VERSION,
        producer_name="mosaic pipelines/python/make_model.py",
        producer_version="1",
        doc_string=(
            f"ResNet-style 1-D CNN, untrained: seeded (seed {seed}) He-normal weights. "
            f"Input emg [batch, {CHANNELS}, {SAMPLES}] float32; output activations "
            f"[batch, {OUTPUTS}] in [0, 1]."
        ),
    )
    onnx.checker.check_model(model, full_check=True)
    return model


def reference_forward(x: np.ndarray, seed: int = SEED) -> np.ndarray:
    """The same network in NumPy (float64), x [batch, 32, 200] → [batch, 5]."""
    w = {k: v.astype(np.float64) for k, v in weights(seed).items()}
    geometry = {c[0]: c for c in CONVS}

    def conv(name, x):
        _, _, _, k, stride, pad = geometry[name]
        xp = np.pad(x, ((0, 0), (0, 0), (pad, pad)))
        n_out = (xp.shape[2] - k) // stride + 1
        # cols [batch, cin, k, n_out]
        idx = np.arange(k)[:, None] + stride * np.arange(n_out)[None, :]
        cols = xp[:, :, idx]
        return np.einsum("ock,bckn->bon", w[name + "_W"], cols) + w[name + "_B"][None, :, None]

    def relu(v):
        return np.maximum(v, 0.0)

    def maxpool(x):
        xp = np.pad(x, ((0, 0), (0, 0), (1, 1)), constant_values=-np.inf)
        n_out = (xp.shape[2] - 3) // 2 + 1
        idx = np.arange(3)[:, None] + 2 * np.arange(n_out)[None, :]
        return xp[:, :, idx].max(axis=2)

    def block(p, x, sc=None):
        h = conv(p + "_c2", relu(conv(p + "_c1", x)))
        return relu(h + (conv(sc, x) if sc else x))

    h = maxpool(relu(conv("stem", np.asarray(x, dtype=np.float64))))
    h = block("l3", block("l2", block("l1", h), "l2_sc"))
    logits = h.mean(axis=2) @ w["fc_W"] + w["fc_B"]
    return 1.0 / (1.0 + np.exp(-logits))


def main(argv: list[str]) -> None:
    import onnx

    path = argv[1] if len(argv) > 1 else DEFAULT_PATH
    onnx.save(build(), path)
    print(f"wrote {path} ({os.path.getsize(path)} bytes)")


if __name__ == "__main__":
    main(sys.argv)
