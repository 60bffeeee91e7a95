/**
 * Blocks that are a Python module behind a fixed configuration (the original MOSAIC's
 * Python.NET blocks): they run the `Python` block's machinery — the sidecar process, its
 * restarts, asynchronous calls, status and errors — on a module of native-bridges/python
 * (`mosaic_blocks.*`), with params they compute. `innerContext` lets a block present the Python
 * block another input shape and intercept what it emits.
 */
import {
  Frame,
  type BlockContext,
  type BlockInstance,
  type InputInfo,
  type OutputPort,
  type Shape,
} from "../../engine";
import { Python } from "./python";

export interface PythonModuleSpec {
  /** Module name (importable from the sidecar's PYTHONPATH) or .py file. */
  module: string;
  function: string;
  init: string;
  params: Record<string, unknown>;
  /** [rows, cols] the function returns (checked against the probe call at load). */
  outputShape?: readonly [number, number];
  /** Milliseconds a call may take (default: one period). */
  budget?: number;
  /** What to emit when the function raises (default hold). */
  onError?: "hold" | "skip";
}

/** Creates the Python block's instance for `spec` in `ctx` (its errors are BlockConfigErrors). */
export async function createPythonModule(
  ctx: BlockContext,
  spec: PythonModuleSpec,
): Promise<BlockInstance> {
  const params = Python.params.parse({
    Module: spec.module,
    Function: spec.function,
    Init: spec.init,
    Params: spec.params,
    OnError: spec.onError ?? "hold",
    ...(spec.outputShape ? { OutputShape: [...spec.outputShape] } : {}),
    ...(spec.budget !== undefined ? { Budget: spec.budget } : {}),
  });
  return Python.create(ctx, params);
}

/**
 * A context for the Python block that shows it one input of shape `inputShape` and hands what
 * it emits to `onEmit` (a frame of the function's output shape, borrowed during the call)
 * instead of an output port of this block.
 */
export function innerContext(
  ctx: BlockContext,
  inputShape: Shape,
  onEmit: (f: Frame) => void,
): BlockContext {
  const first = ctx.inputs[0]!;
  const input: InputInfo = { ...first, index: 0, shape: inputShape };
  let scratch: Frame | undefined;
  const output = (shape: Shape, port?: string): OutputPort => ({
    name: port ?? "out",
    shape,
    idle: false,
    frame(n: number): Frame {
      if (!scratch || scratch.capacity < n) scratch = new Frame(shape, Math.max(1, n));
      scratch.n = n;
      return scratch;
    },
    emit(f: Frame): void {
      onEmit(f);
    },
  });
  return Object.create(ctx, {
    inputs: { value: [input] },
    output: { value: output },
  }) as BlockContext;
}
