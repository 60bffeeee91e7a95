import { z } from "zod";
import {
  BlockConfigError,
  closest,
  defineBlock,
  formatShape,
  legacyPair,
  LegacyParamsError,
  legacyVector,
  matrixShape,
  type Shape,
} from "../../engine";
import { flattenRows, matrixParam, rotationRPY } from "../shared/linalg";
import { inputName, signalInput, type SignalInput } from "../shared/inputs";

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
type Operation = (typeof OPERATIONS)[number];

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

type Params = z.output<typeof params>;

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
      if (p.Matrix && (p.Matrix.length !== 6 || p.Matrix[0]!.length !== 6)) {
        throw new BlockConfigError(
          `Matrix is ${p.Matrix.length} × ${p.Matrix[0]!.length}; wrench needs a 6 × 6 matrix`,
          "Matrix",
        );
      }
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
    case "matmul": {
      const m = p.Matrix;
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
    const b = n === 2 ? signalInput(ctx, 1) : null;
    if (p.Matrix !== undefined && op !== "matmul" && op !== "wrench") {
      throw new BlockConfigError(
        `Matrix is used only by matmul and wrench, not by ${op}`,
        "Matrix",
      );
    }
    if (op !== "rotate") {
      for (const k of ["Roll", "Pitch", "Yaw"] as const) {
        if (p[k] !== 0) throw new BlockConfigError(`${k} is used only by rotate, not by ${op}`, k);
      }
    }
    const outShape = checkShapes(op, a, b, p);
    const out = ctx.output(outShape);
    const { rows, cols } = a.shape;
    const size = a.size;
    const outStride = outShape.rows * outShape.cols;

    // Second input: sample and hold.
    const bSize = b?.size ?? 0;
    const held = new Float64Array(bSize);
    let seen = b === null;
    const waiting = b ? `waiting for ${b.info.source}` : "";
    ctx.setText(waiting);

    // Rotation matrix / projection matrix.
    const rot = new Float64Array(9);
    const angles = { Roll: p.Roll, Pitch: p.Pitch, Yaw: p.Yaw };
    rotationRPY(angles.Roll, angles.Pitch, angles.Yaw, rot);
    const k = op === "matmul" ? outShape.cols : 6;
    let mat = p.Matrix
      ? flattenRows(p.Matrix)
      : op === "wrench"
        ? flattenRows([0, 1, 2, 3, 4, 5].map((i) => [0, 1, 2, 3, 4, 5].map((j) => +(i === j))))
        : new Float64Array(0);
    const w = new Float64Array(6);

    // Integrator state.
    const sum = op === "integrate";
    const acc = new Float64Array(sum ? size : 0);
    const prev = new Float64Array(sum ? size : 0);
    let prevT = NaN;
    const trapezoid = p.Integration === "trapezoid";

    const compute = (v: Float64Array, src: number, t: number, o: Float64Array, dst: number) => {
      switch (op) {
        case "rotate":
          for (let i = 0; i < size; i += 3) {
            const x = v[src + i]!;
            const y = v[src + i + 1]!;
            const z = v[src + i + 2]!;
            o[dst + i] = rot[0]! * x + rot[1]! * y + rot[2]! * z;
            o[dst + i + 1] = rot[3]! * x + rot[4]! * y + rot[5]! * z;
            o[dst + i + 2] = rot[6]! * x + rot[7]! * y + rot[8]! * z;
          }
          break;
        case "norm":
          for (let r = 0; r < rows; r++) {
            let s = 0;
            const off = src + r * cols;
            for (let c = 0; c < cols; c++) s += v[off + c]! * v[off + c]!;
            o[dst + r] = Math.sqrt(s);
          }
          break;
        case "wrench":
          for (let r = 0; r < rows; r++) {
            const off = src + r * 6;
            for (let i = 0; i < 6; i++) w[i] = v[off + i]!;
            if (b) {
              // τ − r × f
              const fx = w[0]!;
              const fy = w[1]!;
              const fz = w[2]!;
              w[3] = w[3]! - (held[1]! * fz - held[2]! * fy);
              w[4] = w[4]! - (held[2]! * fx - held[0]! * fz);
              w[5] = w[5]! - (held[0]! * fy - held[1]! * fx);
            }
            for (let i = 0; i < 6; i++) {
              let s = 0;
              for (let j = 0; j < 6; j++) s += mat[i * 6 + j]! * w[j]!;
              o[dst + r * 6 + i] = s;
            }
          }
          break;
        case "add":
        case "subtract": {
          const sign = op === "add" ? 1 : -1;
          const bStride = bSize === size ? 0 : cols; // 0: same shape; cols: one row for all
          for (let r = 0; r < rows; r++) {
            const off = r * cols;
            const boff = bStride === 0 ? off : 0;
            for (let c = 0; c < cols; c++) {
              o[dst + off + c] = v[src + off + c]! + sign * held[boff + c]!;
            }
          }
          break;
        }
        case "cross":
          for (let r = 0; r < rows; r++) {
            const off = src + r * 3;
            const x = v[off]!;
            const y = v[off + 1]!;
            const z = v[off + 2]!;
            o[dst + r * 3] = y * held[2]! - z * held[1]!;
            o[dst + r * 3 + 1] = z * held[0]! - x * held[2]!;
            o[dst + r * 3 + 2] = x * held[1]! - y * held[0]!;
          }
          break;
        case "dot":
          for (let r = 0; r < rows; r++) {
            let s = 0;
            const off = src + r * cols;
            for (let c = 0; c < cols; c++) s += v[off + c]! * held[c]!;
            o[dst + r] = s;
          }
          break;
        case "matmul":
          for (let r = 0; r < rows; r++) {
            const off = src + r * cols;
            for (let i = 0; i < k; i++) {
              let s = 0;
              const m = i * cols;
              for (let c = 0; c < cols; c++) s += mat[m + c]! * v[off + c]!;
              o[dst + r * k + i] = s;
            }
          }
          break;
        case "integrate": {
          const first = Number.isNaN(prevT);
          const dt = first ? 0 : t - prevT;
          for (let i = 0; i < size; i++) {
            const x = v[src + i]!;
            if (!trapezoid) acc[i] = acc[i]! + x;
            else if (dt > 0) acc[i] = acc[i]! + 0.5 * (x + prev[i]!) * dt;
            prev[i] = x;
            o[dst + i] = acc[i]!;
          }
          if (first || dt > 0) prevT = t;
          break;
        }
      }
    };

    const setMatrix = (m: unknown): void => {
      if (op !== "matmul" && op !== "wrench") {
        throw new Error(`Matrix is used only by matmul and wrench, not by ${op}`);
      }
      const rowsM = m as number[][];
      const want = op === "matmul" ? `${k} × ${cols}` : "6 × 6";
      const wantCols = op === "matmul" ? cols : 6;
      if (rowsM.length !== k || rowsM[0]!.length !== wantCols) {
        throw new Error(
          `Matrix must stay ${want} (the output width is fixed while running); got ` +
            `${rowsM.length} × ${rowsM[0]!.length}`,
        );
      }
      mat = flattenRows(rowsM);
    };

    return {
      process(f, port) {
        const nEv = f.n;
        if (nEv === 0) return;
        const v = f.v;
        if (port === 1) {
          const last = (nEv - 1) * bSize;
          for (let i = 0; i < bSize; i++) held[i] = v[last + i]!;
          if (!seen) {
            seen = true;
            ctx.setText("");
          }
          return;
        }
        if (!seen) return;
        const o = out.frame(nEv);
        const ft = f.t;
        const ov = o.v;
        for (let e = 0; e < nEv; e++) {
          o.t[e] = ft[e]!;
          compute(v, e * size, ft[e]!, ov, e * outStride);
        }
        out.emit(o);
      },
      reset() {
        held.fill(0);
        seen = b === null;
        ctx.setText(waiting);
        acc.fill(0);
        prev.fill(0);
        prevT = NaN;
      },
      setParam(name, value) {
        if (name === "Matrix") {
          setMatrix(value);
          return;
        }
        if (name === "Roll" || name === "Pitch" || name === "Yaw") {
          if (op !== "rotate") throw new Error(`${name} is used only by rotate, not by ${op}`);
          angles[name] = value as number;
          rotationRPY(angles.Roll, angles.Pitch, angles.Yaw, rot);
        }
      },
    };
  },
});
