import { z } from "zod";
import {
  BlockConfigError,
  closest,
  type BlockContext,
  defineBlock,
  formatShape,
  legacyPair,
  LegacyParamsError,
  legacyVector,
  matrixShape,
  type Shape,
} from "../../engine";
import { matrixParam } from "../shared/linalg";
import { inputName, signalInput, type SignalInput } from "../shared/inputs";
import { VectorialFunctionRun } from "./vectorial-function-run";

const OPERATIONS = [
  "rotate",
  "norm",
  "wrench",
  "add",
  "subtract",
  "cross",
  "dot",
  "matmul",
  "integrate",
] as const;
export type Operation = (typeof OPERATIONS)[number];

/** Operations that need a second input (sample-and-hold operand). */
const BINARY: ReadonlySet<Operation> = new Set(["add", "subtract", "cross", "dot"]);

/** MOSAIC's operation names (vectorialFunction.cs) → ours. */
const LEGACY_OPS: Record<string, Operation> = {
  rotation: "rotate",
  absolute_value: "norm",
  wrench_projection: "wrench",
  addVectors: "add",
  subtract: "subtract",
  crossVector: "cross",
  scalarProduct: "dot",
  matrix_multiply: "matmul",
  integrate: "integrate",
};

const angle = (axis: string, order: string) =>
  z
    .number()
    .default(0)
    .describe(
      `rotate: angle about the ${axis} axis in radians (${order}); can be changed while running`,
    );

const params = z.strictObject({
  Operation: z
    .enum(OPERATIONS)
    .describe(
      "rotate: R·v for every 3-vector (Roll, Pitch, Yaw); norm: L2 norm per row; wrench: " +
        "Matrix · [f; τ − r × f] for a 6-vector wrench [fx, fy, fz, τx, τy, τz] (r: optional " +
        "second input); add / subtract: first ± second; cross: first × second; dot: first · " +
        "second; matmul: Matrix · x; integrate: running integral over time",
    ),
  Roll: angle("x", "applied first"),
  Pitch: angle("y", "applied second"),
  Yaw: angle("z", "applied last"),
  Matrix: matrixParam()
    .optional()
    .describe(
      "matmul: the K × C projection matrix M as K rows of C numbers (C = input width), y = M·x; " +
        "wrench: a 6 × 6 matrix (default identity). Can be changed while running (same size)",
    ),
  Integration: z
    .enum(["trapezoid", "sum"])
    .default("trapezoid")
    .describe(
      "integrate: trapezoid: y += (x[n] + x[n−1])/2 · (t[n] − t[n−1]); sum: y += x[n] (no Δt, " +
        "what MOSAIC's integrate computed)",
    ),
});

export type VectorialFunctionParams = z.output<typeof params>;
type Params = VectorialFunctionParams;

/** Binary operations need a second input, and only they and wrench may have one; returns it. */
function checkInputs(ctx: BlockContext, op: Operation, a: SignalInput): SignalInput | null {
  const binary = BINARY.has(op);
  const n = ctx.inputs.length;
  if (binary && n !== 2) {
    throw new BlockConfigError(
      `${op} needs two inputs (${op === "subtract" ? "first − second" : "first and second"}); ` +
        `it has only ${inputName(a.info)}`,
      "Operation",
    );
  }
  if (!binary && op !== "wrench" && n === 2) {
    throw new BlockConfigError(
      `${op} takes one input; remove the second input ${inputName(ctx.inputs[1]!)} (only ` +
        "add, subtract, cross, dot and wrench use a second input)",
      "Operation",
    );
  }
  return n === 2 ? signalInput(ctx, 1) : null;
}

/** Matrix only for matmul and wrench; Roll, Pitch and Yaw only for rotate. */
function checkParamUse(op: Operation, p: Params): void {
  if (p.Matrix !== undefined && op !== "matmul" && op !== "wrench") {
    throw new BlockConfigError(`Matrix is used only by matmul and wrench, not by ${op}`, "Matrix");
  }
  if (op !== "rotate") {
    for (const k of ["Roll", "Pitch", "Yaw"] as const) {
      if (p[k] !== 0) throw new BlockConfigError(`${k} is used only by rotate, not by ${op}`, k);
    }
  }
}

/** wrench's Matrix must be 6 × 6. */
function checkWrenchMatrix(m: number[][]): void {
  if (m.length !== 6 || m[0]!.length !== 6) {
    throw new BlockConfigError(
      `Matrix is ${m.length} × ${m[0]!.length}; wrench needs a 6 × 6 matrix`,
      "Matrix",
    );
  }
}

/** matmul needs a K × C Matrix (C: the input's width); the output is [R, K]. */
function matmulShape(a: SignalInput, m: number[][] | undefined): Shape {
  const { rows, cols } = a.shape;
  const name = inputName(a.info);
  if (m === undefined) {
    throw new BlockConfigError(
      `matmul needs Matrix: K rows of ${cols} numbers (the width of input ${name}); MOSAIC's ` +
        "matrix_multiply loaded it from a file in its control panel",
      "Matrix",
    );
  }
  if (m[0]!.length !== cols) {
    throw new BlockConfigError(
      `Matrix is ${m.length} × ${m[0]!.length}, but input ${name} has width ${cols}; ` +
        `expected rows of ${cols} numbers`,
      "Matrix",
    );
  }
  return matrixShape(rows, m.length);
}

/** Shape rules of each operation; returns the output shape or throws naming the input. */
function checkShapes(op: Operation, a: SignalInput, b: SignalInput | null, p: Params): Shape {
  const { rows, cols } = a.shape;
  const name = inputName(a.info);
  const bad = (expected: string, param?: string): never => {
    throw new BlockConfigError(
      `${op}: input ${name} has shape ${formatShape(a.shape)}; expected ${expected}`,
      param,
    );
  };
  const badB = (expected: string): never => {
    throw new BlockConfigError(
      `${op}: the second input ${inputName(b!.info)} has shape ${formatShape(b!.shape)}; ` +
        `expected ${expected}`,
    );
  };
  switch (op) {
    case "rotate":
      if (cols % 3 !== 0) {
        bad(
          "a width that is a multiple of 3 (x, y, z triples): a [1, 3k] vector or an [R, 3] matrix",
        );
      }
      return a.shape;
    case "norm":
      return matrixShape(rows, 1);
    case "wrench":
      if (cols !== 6) bad("width 6: a wrench [fx, fy, fz, τx, τy, τz] (or [R, 6], one per row)");
      if (b && (b.shape.rows !== 1 || b.shape.cols !== 3)) {
        badB("[1, 3]: the point r = [x, y, z] to move the torque reference to");
      }
      if (p.Matrix) checkWrenchMatrix(p.Matrix);
      return a.shape;
    case "add":
    case "subtract":
      if (!(b!.shape.cols === cols && (b!.shape.rows === rows || b!.shape.rows === 1))) {
        badB(
          rows === 1
            ? `[1, ${cols}], the width of the first input ${name}`
            : `[${rows}, ${cols}] or [1, ${cols}] (added to every row) to match the first input ${name}`,
        );
      }
      return a.shape;
    case "cross":
      if (cols !== 3) bad("width 3: a 3-vector [1, 3] (or [R, 3], one per row)");
      if (b!.shape.rows !== 1 || b!.shape.cols !== 3) badB("[1, 3]: a 3-vector");
      return a.shape;
    case "dot":
      if (b!.shape.rows !== 1 || b!.shape.cols !== cols) {
        badB(`[1, ${cols}], the width of the first input ${name}`);
      }
      return matrixShape(rows, 1);
    case "matmul":
      return matmulShape(a, p.Matrix);
    case "integrate":
      return a.shape;
  }
}

export const VectorialFunction = defineBlock({
  type: "VectorialFunction",
  category: "Signal processing",
  summary:
    "Vector operations: rotation, L2 norm, wrench projection, add, subtract, cross, dot, matrix product, integration.",
  help:
    "Operations on whole vectors (paper III-F, Table 2), chosen by `Operation`. One input: " +
    "`rotate` applies R = Rz(Yaw)·Ry(Pitch)·Rx(Roll) (radians, right-handed, to column vectors " +
    "v′ = R·v: roll about x first, then pitch about y, then yaw about z, all about the fixed axes " +
    "— the aerospace/ROS rpy convention) to every consecutive x, y, z triple of a [1, 3k] vector " +
    "or every row of an [R, 3] matrix; `norm` gives the L2 norm ([1, C] → [1, 1], one per row of a " +
    "matrix → [R, 1]); `matmul` gives y = M·x with the K × C `Matrix` ([1, C] → [1, K], or per " +
    "row); `integrate` keeps a running integral per element by the trapezoidal rule, y += " +
    "(x[n] + x[n−1])/2 · Δt with Δt the difference of consecutive event timestamps (the first " +
    "event gives 0; timestamps that do not increase add nothing; NaN stays until `reset`, which " +
    "zeroes the integral). `wrench` takes a 6-vector [f; τ] (force, then torque) and gives " +
    "M·[f; τ − r × f], where r is the latest value of an optional second input (the point the " +
    "torque is taken about moves by r, as MOSAIC's wrench_projection did) and M the 6 × 6 " +
    "`Matrix` (default identity); to express a sensor's wrench in another frame use M = [[R, 0], " +
    "[[p]×·R, R]], with R the sensor-to-target rotation and p the sensor origin in the target " +
    "frame. Two inputs: `add` and `subtract` give first + second and first − second (a [1, C] " +
    "second input applies to every row), `cross` first × second (3-vectors), `dot` first · " +
    "second ([1, 1], or one per row). The second input is sampled and held: its latest value is " +
    "used, and the block emits only on the first input's events, once the second has produced a " +
    "value (until then its status says it is waiting). MOSAIC's positional form `[operation]` is " +
    "converted (`[rotation:roll;pitch;yaw]`, `absolute_value`, `wrench_projection`, `addVectors`, " +
    "`subtract`, `crossVector`, `scalarProduct`, `matrix_multiply`, `integrate`); its integrate " +
    "summed without Δt (`Integration: sum`), and its crossVector computed second × first " +
    "(a sign slip in its skew matrix): the conversion keeps the paper's first × second.",
  params,
  legacyParams(args) {
    const ops = args.filter((a) => a.trim() !== "");
    // No operation: zod then says that Operation is required.
    if (ops.length === 0) return {};
    // MOSAIC parsed every argument and kept the last one.
    const { key, value } = legacyPair(ops[ops.length - 1]!);
    const op = LEGACY_OPS[key] ?? (OPERATIONS as readonly string[]).find((o) => o === key);
    if (op === undefined) {
      const names = [...Object.keys(LEGACY_OPS), ...OPERATIONS];
      const s = closest(key, names);
      throw new LegacyParamsError(
        `unknown operation '${key}' (expected one of ${Object.keys(LEGACY_OPS).join(", ")})` +
          (s !== undefined ? `; did you mean '${s}'?` : ""),
        "Operation",
      );
    }
    if (op === "rotate") {
      const a = legacyVector(value, "rotation angles", "Roll");
      if (a.length !== 3) {
        throw new LegacyParamsError(
          `rotation needs three angles roll;pitch;yaw (radians), got ${a.length}`,
          "Roll",
        );
      }
      return { Operation: op, Roll: a[0], Pitch: a[1], Yaw: a[2] };
    }
    // MOSAIC's integrate added the inputs up without Δt.
    if (op === "integrate") return { Operation: op, Integration: "sum" };
    return { Operation: op };
  },
  legacyForm:
    "[operation]: rotation:roll;pitch;yaw (radians), absolute_value, wrench_projection, addVectors, " +
    "subtract, crossVector, scalarProduct, matrix_multiply (needs Matrix), integrate",
  inputs: { min: 1, max: 2, labels: ["signal", "operand"] },
  live: ["Roll", "Pitch", "Yaw", "Matrix"],
  views: ["scope", "spider"],
  panel: "Scope and spider plot of the result.",
  create(ctx, p) {
    const op: Operation = p.Operation;
    const a = signalInput(ctx, 0);
    const b = checkInputs(ctx, op, a);
    checkParamUse(op, p);
    const outShape = checkShapes(op, a, b, p);
    return new VectorialFunctionRun(ctx, p, a, b, outShape).instance();
  },
});
