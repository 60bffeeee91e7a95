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
  type Shape,
} from "../../engine";
import { FunctionKernel, type FunctionOperation } from "../../engine/dsp";
import { requireDsp } from "../shared/dsp";
import { inputName, signalInput } from "../shared/inputs";
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

function operandFits(len: number, shape: Shape): boolean {
  return len === 1 || len === shape.cols || len === shape.rows * shape.cols;
}

function expectedWidths(shape: Shape): string {
  return shape.rows === 1
    ? `1 or ${shape.cols}`
    : `1, ${shape.cols} (one per column) or ${shape.rows * shape.cols} (one per element)`;
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
    const shape = sig.shape;
    const size = sig.size;
    const op: FunctionOperation = p.Operation;
    const takesOperand = op === "add" || op === "multiply";
    const withInput = ctx.inputs.length === 2;
    let operandShape: Shape | null = null;
    if (withInput) {
      if (!takesOperand) {
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
      if (o.shape.rows !== 1 || !operandFits(o.size, shape)) {
        throw new BlockConfigError(
          `the operand input ${inputName(o.info)} has shape [${o.shape.rows}, ${o.shape.cols}]; ` +
            `expected a vector of width ${expectedWidths(shape)} to match input ${inputName(sig.info)}`,
        );
      }
      operandShape = o.shape;
    } else if (takesOperand && p.Value === undefined) {
      throw new BlockConfigError(
        `${op} needs Value (a number, or one per channel) or a second input giving the operand`,
        "Value",
      );
    }

    const checkValue = (v: number | number[] | undefined): number[] | undefined => {
      if (v === undefined) return undefined;
      const list = typeof v === "number" ? [v] : v;
      if (!operandFits(list.length, shape)) {
        throw new BlockConfigError(
          `Value has ${list.length} numbers, but input ${inputName(sig.info)} has shape ` +
            `[${shape.rows}, ${shape.cols}]; expected ${expectedWidths(shape)} numbers`,
          "Value",
        );
      }
      return list;
    };

    const build = (q: Params): FunctionKernel => {
      let operand: number[] | undefined;
      if (takesOperand) {
        if (withInput) operand = [op === "add" ? 0 : 1];
        else {
          const list = checkValue(q.Value)!;
          if (list.length === 1 || list.length === size) operand = list;
          else {
            const full = new Float64Array(size);
            expandOperand(list, shape, full);
            operand = Array.from(full);
          }
        }
      }
      try {
        return new FunctionKernel(
          op,
          {
            ...(operand !== undefined ? { operand } : {}),
            exponent: q.Exponent,
            ...(q.Min !== undefined ? { min: q.Min } : {}),
            ...(q.Max !== undefined ? { max: q.Max } : {}),
          },
          size,
        );
      } catch (e) {
        throw new BlockConfigError(`cannot create the ${op} kernel: ${errorMessage(e)}`);
      }
    };

    const current: Params = { ...p };
    let kernel = build(current);
    const identity = op === "add" ? 0 : 1;
    const operand = new Float64Array(size).fill(identity);
    const out = ctx.output(shape);
    const oCols = operandShape?.cols ?? 0;

    return {
      process(f, port) {
        const n = f.n;
        if (n === 0) return;
        if (port === 1) {
          // The latest operand value, expanded to one value per element.
          const last = (n - 1) * oCols;
          const v = f.v;
          if (oCols === 1) operand.fill(v[last]!);
          else if (oCols === size) for (let k = 0; k < size; k++) operand[k] = v[last + k]!;
          else for (let k = 0; k < size; k++) operand[k] = v[last + (k % oCols)]!;
          return;
        }
        const o = out.frame(n);
        const ft = f.t;
        for (let e = 0; e < n; e++) o.t[e] = ft[e]!;
        if (withInput) kernel.processWithOperand(f.v, operand, o.v, n);
        else kernel.process(f.v, o.v, n);
        out.emit(o);
      },
      reset() {
        operand.fill(identity);
      },
      setParam(name, value) {
        const next: Params = { ...current, [name]: value };
        if (name === "Value") {
          if (withInput) {
            throw new Error("Value is not used while a second input provides the operand");
          }
          checkValue(next.Value);
        }
        if (next.Min !== undefined && next.Max !== undefined && next.Min > next.Max) {
          throw new Error(`Min ${next.Min} would be greater than Max ${next.Max}`);
        }
        const k = build(next);
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
