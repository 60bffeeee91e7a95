import { z } from "zod";
import {
  BlockConfigError,
  closest,
  defineBlock,
  errorMessage,
  legacyNumber,
  legacyPair,
  LegacyParamsError,
  legacyVector,
  type BlockContext,
  type Frame,
  type OutputPort,
  type Shape,
} from "../../engine";
import { FunctionKernel, type FunctionOperation } from "../../engine/dsp";
import { requireDsp } from "../shared/dsp";
import { inputName, signalInput, type SignalInput } from "../shared/inputs";
import { extendedNumber } from "../shared/params";
import { MAX_CHANNELS } from "../shared/limits";

const OPERATIONS = ["add", "multiply", "abs", "power", "clip"] as const;

const params = z
  .strictObject({
    Operation: z
      .enum(OPERATIONS)
      .describe(
        "add: x + Value; multiply: x · Value; abs: |x|; power: x^Exponent; clip: x limited to " +
          "[Min, Max]",
      ),
    Value: z
      .union([z.number(), z.array(z.number()).min(1).max(MAX_CHANNELS)])
      .optional()
      .describe(
        "Operand of add and multiply: one number for every element, or one per channel (the " +
          "input width; for a matrix, one per column or one per element). Not used with a " +
          "second input, whose latest value is the operand",
      ),
    Exponent: z
      .number()
      .default(2)
      .describe("Exponent of power (negative bases with a non-integer exponent give NaN)"),
    Min: extendedNumber()
      .optional()
      .describe("Lower bound of clip (default: none, i.e. −∞; YAML -.inf is accepted)"),
    Max: extendedNumber()
      .optional()
      .describe("Upper bound of clip (default: none, i.e. +∞; YAML .inf is accepted)"),
  })
  .refine((p) => p.Min === undefined || p.Max === undefined || p.Min <= p.Max, {
    message: "Min must not be greater than Max",
    path: ["Min"],
  });

type Params = z.output<typeof params>;

/** Expands an operand of 1, cols or rows·cols values to what the kernel takes (1 or size). */
function expandOperand(values: readonly number[], shape: Shape, into: Float64Array): void {
  const size = shape.rows * shape.cols;
  if (values.length === 1) into.fill(values[0]!);
  else if (values.length === size) for (let k = 0; k < size; k++) into[k] = values[k]!;
  else for (let k = 0; k < size; k++) into[k] = values[k % shape.cols]!;
}

/** Whether an operand of `len` values fits the shape: 1, one per column or one per element. */
function operandFits(len: number, shape: Shape): boolean {
  return len === 1 || len === shape.cols || len === shape.rows * shape.cols;
}

/** The operand widths that fit the shape, as messages write them. */
function expectedWidths(shape: Shape): string {
  return shape.rows === 1
    ? `1 or ${shape.cols}`
    : `1, ${shape.cols} (one per column) or ${shape.rows * shape.cols} (one per element)`;
}

/** Shared by every kernel of one instance: the operation, the signal input, the operand source. */
interface Setup {
  op: FunctionOperation;
  sig: SignalInput;
  /** A second input gives the operand (then Value is not used). */
  withInput: boolean;
}

/** add and multiply take an operand; abs, power and clip do not. */
function takesOperand(op: FunctionOperation): boolean {
  return op === "add" || op === "multiply";
}

/** Checks where the operand comes from (Value or a second input); the operand input's shape. */
function checkOperandSource(ctx: BlockContext, p: Params, sig: SignalInput): Shape | null {
  const op = p.Operation;
  if (ctx.inputs.length === 2) {
    if (!takesOperand(op)) {
      throw new BlockConfigError(
        `a second input (${inputName(ctx.inputs[1]!)}) is only used by add and multiply, not ` +
          `by ${op}; remove it`,
        "Operation",
      );
    }
    if (p.Value !== undefined) {
      throw new BlockConfigError(
        `Value is set, but the second input ${inputName(ctx.inputs[1]!)} provides the operand; ` +
          "remove one of them",
        "Value",
      );
    }
    const o = signalInput(ctx, 1);
    if (o.shape.rows !== 1 || !operandFits(o.size, sig.shape)) {
      throw new BlockConfigError(
        `the operand input ${inputName(o.info)} has shape [${o.shape.rows}, ${o.shape.cols}]; ` +
          `expected a vector of width ${expectedWidths(sig.shape)} to match input ${inputName(sig.info)}`,
      );
    }
    return o.shape;
  }
  if (takesOperand(op) && p.Value === undefined) {
    throw new BlockConfigError(
      `${op} needs Value (a number, or one per channel) or a second input giving the operand`,
      "Value",
    );
  }
  return null;
}

/** Value as a list of numbers, refused unless its length fits the signal's shape. */
function checkValue(v: number | number[] | undefined, sig: SignalInput): number[] | undefined {
  if (v === undefined) return undefined;
  const shape = sig.shape;
  const list = typeof v === "number" ? [v] : v;
  if (!operandFits(list.length, shape)) {
    throw new BlockConfigError(
      `Value has ${list.length} numbers, but input ${inputName(sig.info)} has shape ` +
        `[${shape.rows}, ${shape.cols}]; expected ${expectedWidths(shape)} numbers`,
      "Value",
    );
  }
  return list;
}

/** The kernel's operand: the identity with an operand input, else Value (1 or per element). */
function kernelOperand(setup: Setup, q: Params): number[] | undefined {
  if (!takesOperand(setup.op)) return undefined;
  if (setup.withInput) return [setup.op === "add" ? 0 : 1];
  const { shape, size } = setup.sig;
  const list = checkValue(q.Value, setup.sig)!;
  if (list.length === 1 || list.length === size) return list;
  const full = new Float64Array(size);
  expandOperand(list, shape, full);
  return Array.from(full);
}

/** A kernel for these params; its failure is a BlockConfigError naming the operation. */
function buildKernel(setup: Setup, q: Params): FunctionKernel {
  const operand = kernelOperand(setup, q);
  try {
    return new FunctionKernel(
      setup.op,
      {
        ...(operand !== undefined ? { operand } : {}),
        exponent: q.Exponent,
        ...(q.Min !== undefined ? { min: q.Min } : {}),
        ...(q.Max !== undefined ? { max: q.Max } : {}),
      },
      setup.sig.size,
    );
  } catch (e) {
    throw new BlockConfigError(`cannot create the ${setup.op} kernel: ${errorMessage(e)}`);
  }
}

/** The params after a live change of `name`; refused if Value is unused or misfits or Min > Max. */
function checkedChange(setup: Setup, current: Params, name: string, value: unknown): Params {
  const next: Params = { ...current, [name]: value };
  if (name === "Value") {
    if (setup.withInput) {
      throw new Error("Value is not used while a second input provides the operand");
    }
    checkValue(next.Value, setup.sig);
  }
  if (next.Min !== undefined && next.Max !== undefined && next.Min > next.Max) {
    throw new Error(`Min ${next.Min} would be greater than Max ${next.Max}`);
  }
  return next;
}

/** Keeps the latest operand event (of `oCols` values), expanded to one value per element. */
function takeLatestOperand(f: Frame, oCols: number, operand: Float64Array): void {
  const size = operand.length;
  const last = (f.n - 1) * oCols;
  const v = f.v;
  if (oCols === 1) operand.fill(v[last]!);
  else if (oCols === size) for (let k = 0; k < size; k++) operand[k] = v[last + k]!;
  else for (let k = 0; k < size; k++) operand[k] = v[last + (k % oCols)]!;
}

/** Applies the kernel to a signal frame (with the operand input's values, if any) and emits it. */
function emitApplied(
  f: Frame,
  kernel: FunctionKernel,
  operand: Float64Array | null,
  out: OutputPort,
): void {
  const n = f.n;
  const o = out.frame(n);
  const ft = f.t;
  for (let e = 0; e < n; e++) o.t[e] = ft[e]!;
  if (operand !== null) kernel.processWithOperand(f.v, operand, o.v, n);
  else kernel.process(f.v, o.v, n);
  out.emit(o);
}

export const FunctionBlock = defineBlock({
  type: "Function",
  category: "Signal processing",
  summary: "Element-wise add, multiply, abs, power or clip of every input value.",
  help:
    "Applies one element-wise operation to every value of its input (paper III-F, Table 1): " +
    "`add` a constant or another vector, `multiply` by a constant or another vector, `abs`, " +
    "`power` (x^Exponent) and `clip` (to [Min, Max]); the output has the input's shape (matrices " +
    "too) and timestamps. The operand of add and multiply is `Value`, or, with a second input, " +
    "that input's latest value (width 1 or the first input's width). Before the second input " +
    "has produced anything the identity applies (0 for add, 1 for multiply), so the first input " +
    "passes unchanged. As in NumPy, a negative base with a non-integer exponent gives NaN and " +
    "NaN passes through clip. MOSAIC's positional form `[op:value]` is converted: `multiply:5`, " +
    "`add:2`, `abs:0`, `power:2`, `clip:max` (MOSAIC clipped to [0, max]); when several " +
    "operations are listed, MOSAIC applied only the last one, and so does the conversion.",
  params,
  legacyParams(args) {
    const ops = args.filter((a) => a.trim() !== "");
    if (ops.length === 0) {
      throw new LegacyParamsError("expected an operation such as multiply:5", "Operation");
    }
    const { key, value } = legacyPair(ops[ops.length - 1]!);
    const op = key.toLowerCase();
    switch (op) {
      case "add":
      case "multiply":
        return {
          Operation: op,
          Value: value.includes(";")
            ? legacyVector(value, `${op} value`, "Value")
            : legacyNumber(value, `${op} value`, "Value"),
        };
      case "abs":
        return { Operation: "abs" };
      case "power":
        return { Operation: "power", Exponent: legacyNumber(value, "power exponent", "Exponent") };
      case "clip":
        return { Operation: "clip", Min: 0, Max: legacyNumber(value, "clip maximum", "Max") };
      default: {
        const s = closest(key, OPERATIONS);
        throw new LegacyParamsError(
          `unknown operation '${key}' (expected one of ${OPERATIONS.join(", ")})` +
            (s !== undefined ? `; did you mean '${s}'?` : ""),
          "Operation",
        );
      }
    }
  },
  legacyForm:
    "[op:value]: multiply:5, add:2, abs:0, power:2 or clip:max (clip to [0, max]); only the last listed op applies",
  inputs: { min: 1, max: 2, labels: ["signal", "operand"] },
  live: ["Value", "Exponent", "Min", "Max"],
  views: ["scope"],
  panel: "Scope of the output.",
  create(ctx, p) {
    requireDsp(ctx.type);
    const sig = signalInput(ctx, 0);
    const operandShape = checkOperandSource(ctx, p, sig);
    const setup: Setup = { op: p.Operation, sig, withInput: operandShape !== null };
    const current: Params = { ...p };
    let kernel = buildKernel(setup, current);
    const identity = p.Operation === "add" ? 0 : 1;
    const operand = new Float64Array(sig.size).fill(identity);
    const out = ctx.output(sig.shape);
    const oCols = operandShape?.cols ?? 0;

    return {
      process(f, port) {
        if (f.n === 0) return;
        if (port === 1) takeLatestOperand(f, oCols, operand);
        else emitApplied(f, kernel, setup.withInput ? operand : null, out);
      },
      reset() {
        operand.fill(identity);
      },
      setParam(name, value) {
        const next = checkedChange(setup, current, name, value);
        const k = buildKernel(setup, next);
        kernel.dispose();
        kernel = k;
        Object.assign(current, next);
      },
      dispose() {
        kernel.dispose();
      },
    };
  },
});
