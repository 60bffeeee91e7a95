import { z } from "zod";
import {
  defineBlock,
  errorMessage,
  vectorShape,
  type BlockContext,
  type BlockInstance,
} from "../../engine";
import { signalInput } from "../shared/inputs";
import { createPythonModule } from "../io/python-backed";

export const SimplePyTorch = defineBlock({
  type: "SimplePyTorch",
  category: "Learning",
  summary:
    "A TorchScript model on every input vector, in the Python sidecar (MOSAIC's PyTorch example); needs torch.",
  help:
    "MOSAIC's SimplePyTorch: loads a TorchScript model (`torch.jit.load(Model)`) and evaluates it " +
    "on every input vector as a float32 tensor [1, N]; the first value of its output is the " +
    "block's output [1, 1] (native-bridges/python/mosaic_blocks/torch_model.py, in the Python " +
    "sidecar). PyTorch is not part of the sidecar's environment (it was not part of the " +
    "original's either), so by default the block does not run: the pipeline does, and the " +
    "block says why in a warning and its status — export the model to ONNX " +
    "(`torch.onnx.export`) and run it with a Python block and ONNX Runtime, as " +
    "pipelines/python/onnx_cnn.py does, or add torch to " +
    "native-bridges/python/pyproject.toml. The original loaded a fixed file of its scripts " +
    "folder; here `Model` names it. No positional params.",
  params: z.strictObject({
    Model: z
      .string()
      .min(1)
      .default("model.pt")
      .describe("The TorchScript file (torch.jit.save), relative to the pipeline file"),
  }),
  legacyParams: () => ({}),
  legacyForm: "no params: `{ Type: SimplePyTorch, Inputs: [Features] }`",
  inputs: { min: 1, max: 1, labels: ["features"] },
  eventLoop: true,
  views: ["scope", "label"],
  panel: "The model's output; the sidecar's state and call times.",
  async create(ctx, p) {
    signalInput(ctx, 0);
    try {
      return await createPythonModule(ctx, {
        module: "mosaic_blocks.torch_model",
        init: "init",
        function: "predict",
        params: { model: ctx.resources.resolve(p.Model) },
        outputShape: [1, 1],
      });
    } catch (e) {
      if (!errorMessage(e).includes(TORCH_MISSING)) throw e;
      return withoutTorch(ctx, errorMessage(e));
    }
  },
});

/** Where the sidecar's message says that torch is missing (torch_model.py's ONNX_ROUTE). */
const TORCH_MISSING = "PyTorch (torch) is not installed";

/**
 * Without torch the block cannot run, but the rest of the pipeline can: it says why once (a
 * warning with the ONNX route) and in its status, and emits nothing.
 */
function withoutTorch(ctx: BlockContext, message: string): BlockInstance {
  const why = message.slice(message.indexOf(TORCH_MISSING));
  ctx.output(vectorShape(1));
  return {
    start() {
      ctx.warn(why);
      ctx.setText("not running: torch is not installed (see the warning for the ONNX route)");
    },
  };
}
