/**
 * One VectorialFunction at run time (vectorial-function.ts): the operation applied to every event
 * of the first input, the second input's sample-and-hold value, the rotation and projection
 * matrices (changeable while running) and the integrator's state.
 */
import type { BlockContext, BlockInstance, Frame, OutputPort, Shape } from "../../engine";
import { flattenRows, rotationRPY } from "../shared/linalg";
import type { SignalInput } from "../shared/inputs";
import type { Operation, VectorialFunctionParams } from "./vectorial-function";

/** The 6 × 6 identity, row by row (wrench's default Matrix). */
function identity6(): Float64Array {
  return flattenRows([0, 1, 2, 3, 4, 5].map((i) => [0, 1, 2, 3, 4, 5].map((j) => +(i === j))));
}

export class VectorialFunctionRun {
  private readonly op: Operation;
  private readonly out: OutputPort;
  private readonly rows: number;
  private readonly cols: number;
  /** Values per event of the first input. */
  private readonly size: number;
  /** Values per event of the output. */
  private readonly outStride: number;

  // Second input: sample and hold.
  private readonly hasB: boolean;
  private readonly bSize: number;
  private readonly held: Float64Array;
  private seen: boolean;
  private readonly waiting: string;

  // Rotation matrix / projection matrix.
  private readonly rot = new Float64Array(9);
  private readonly angles: { Roll: number; Pitch: number; Yaw: number };
  /** Rows of the projection matrix (matmul: the output width; wrench: 6). */
  private readonly k: number;
  private mat: Float64Array;
  private readonly w = new Float64Array(6);

  // Integrator state.
  private readonly acc: Float64Array;
  private readonly prev: Float64Array;
  private prevT = NaN;
  private readonly trapezoid: boolean;

  constructor(
    private readonly ctx: BlockContext,
    p: VectorialFunctionParams,
    a: SignalInput,
    b: SignalInput | null,
    outShape: Shape,
  ) {
    const op = p.Operation;
    this.op = op;
    this.out = ctx.output(outShape);
    this.rows = a.shape.rows;
    this.cols = a.shape.cols;
    this.size = a.size;
    this.outStride = outShape.rows * outShape.cols;

    this.hasB = b !== null;
    this.bSize = b?.size ?? 0;
    this.held = new Float64Array(this.bSize);
    this.seen = b === null;
    this.waiting = b ? `waiting for ${b.info.source}` : "";
    ctx.setText(this.waiting);

    this.angles = { Roll: p.Roll, Pitch: p.Pitch, Yaw: p.Yaw };
    rotationRPY(p.Roll, p.Pitch, p.Yaw, this.rot);
    this.k = op === "matmul" ? outShape.cols : 6;
    this.mat = p.Matrix
      ? flattenRows(p.Matrix)
      : op === "wrench"
        ? identity6()
        : new Float64Array(0);

    const integrate = op === "integrate";
    this.acc = new Float64Array(integrate ? this.size : 0);
    this.prev = new Float64Array(integrate ? this.size : 0);
    this.trapezoid = p.Integration === "trapezoid";
  }

  instance(): BlockInstance {
    return {
      process: (f, port) => {
        if (f.n === 0) return;
        if (port === 1) this.hold(f);
        else if (this.seen) this.emit(f);
      },
      reset: () => this.reset(),
      setParam: (name, value) => this.setParam(name, value),
    };
  }

  /** Second input: keeps its latest value; the first one ends the wait. */
  private hold(f: Frame): void {
    const { held, bSize } = this;
    const v = f.v;
    const last = (f.n - 1) * bSize;
    for (let i = 0; i < bSize; i++) held[i] = v[last + i]!;
    if (!this.seen) {
      this.seen = true;
      this.ctx.setText("");
    }
  }

  /** First input: one output event per input event. */
  private emit(f: Frame): void {
    const nEv = f.n;
    const { out, size, outStride } = this;
    const v = f.v;
    const o = out.frame(nEv);
    const ft = f.t;
    const ov = o.v;
    for (let e = 0; e < nEv; e++) {
      o.t[e] = ft[e]!;
      this.compute(v, e * size, ft[e]!, ov, e * outStride);
    }
    out.emit(o);
  }

  private reset(): void {
    this.held.fill(0);
    this.seen = !this.hasB;
    this.ctx.setText(this.waiting);
    this.acc.fill(0);
    this.prev.fill(0);
    this.prevT = NaN;
  }

  private setParam(name: string, value: unknown): void {
    if (name === "Matrix") {
      this.setMatrix(value);
      return;
    }
    if (name === "Roll" || name === "Pitch" || name === "Yaw") {
      const op = this.op;
      if (op !== "rotate") throw new Error(`${name} is used only by rotate, not by ${op}`);
      const angles = this.angles;
      angles[name] = value as number;
      rotationRPY(angles.Roll, angles.Pitch, angles.Yaw, this.rot);
    }
  }

  private setMatrix(m: unknown): void {
    const { op, k, cols } = this;
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
    this.mat = flattenRows(rowsM);
  }

  /** One event: the values of `v` from `src` (timestamp `t`) → `o` from `dst`. */
  private compute(v: Float64Array, src: number, t: number, o: Float64Array, dst: number): void {
    switch (this.op) {
      case "rotate":
        return this.rotate(v, src, o, dst);
      case "norm":
        return this.norm(v, src, o, dst);
      case "wrench":
        return this.wrench(v, src, o, dst);
      case "add":
        return this.addHeld(v, src, o, dst, 1);
      case "subtract":
        return this.addHeld(v, src, o, dst, -1);
      case "cross":
        return this.cross(v, src, o, dst);
      case "dot":
        return this.dot(v, src, o, dst);
      case "matmul":
        return this.matmul(v, src, o, dst);
      case "integrate":
        return this.integrate(v, src, t, o, dst);
    }
  }

  /** R·v for every x, y, z triple. */
  private rotate(v: Float64Array, src: number, o: Float64Array, dst: number): void {
    const { rot, size } = this;
    for (let i = 0; i < size; i += 3) {
      const x = v[src + i]!;
      const y = v[src + i + 1]!;
      const z = v[src + i + 2]!;
      o[dst + i] = rot[0]! * x + rot[1]! * y + rot[2]! * z;
      o[dst + i + 1] = rot[3]! * x + rot[4]! * y + rot[5]! * z;
      o[dst + i + 2] = rot[6]! * x + rot[7]! * y + rot[8]! * z;
    }
  }

  /** L2 norm of every row. */
  private norm(v: Float64Array, src: number, o: Float64Array, dst: number): void {
    const { rows, cols } = this;
    for (let r = 0; r < rows; r++) {
      let s = 0;
      const off = src + r * cols;
      for (let c = 0; c < cols; c++) s += v[off + c]! * v[off + c]!;
      o[dst + r] = Math.sqrt(s);
    }
  }

  /** Matrix · [f; τ − r × f] for every row's wrench (r: the held second input, if any). */
  private wrench(v: Float64Array, src: number, o: Float64Array, dst: number): void {
    const { rows, w, held, mat } = this;
    for (let r = 0; r < rows; r++) {
      const off = src + r * 6;
      for (let i = 0; i < 6; i++) w[i] = v[off + i]!;
      if (this.hasB) {
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
  }

  /** add (sign 1) / subtract (sign −1): first ± the held second input. */
  private addHeld(v: Float64Array, src: number, o: Float64Array, dst: number, sign: number): void {
    const { rows, cols, held } = this;
    const bStride = this.bSize === this.size ? 0 : cols; // 0: same shape; cols: one row for all
    for (let r = 0; r < rows; r++) {
      const off = r * cols;
      const boff = bStride === 0 ? off : 0;
      for (let c = 0; c < cols; c++) {
        o[dst + off + c] = v[src + off + c]! + sign * held[boff + c]!;
      }
    }
  }

  /** Every row × the held 3-vector. */
  private cross(v: Float64Array, src: number, o: Float64Array, dst: number): void {
    const { rows, held } = this;
    for (let r = 0; r < rows; r++) {
      const off = src + r * 3;
      const x = v[off]!;
      const y = v[off + 1]!;
      const z = v[off + 2]!;
      o[dst + r * 3] = y * held[2]! - z * held[1]!;
      o[dst + r * 3 + 1] = z * held[0]! - x * held[2]!;
      o[dst + r * 3 + 2] = x * held[1]! - y * held[0]!;
    }
  }

  /** Every row · the held vector. */
  private dot(v: Float64Array, src: number, o: Float64Array, dst: number): void {
    const { rows, cols, held } = this;
    for (let r = 0; r < rows; r++) {
      let s = 0;
      const off = src + r * cols;
      for (let c = 0; c < cols; c++) s += v[off + c]! * held[c]!;
      o[dst + r] = s;
    }
  }

  /** Matrix · every row. */
  private matmul(v: Float64Array, src: number, o: Float64Array, dst: number): void {
    const { rows, cols, k, mat } = this;
    for (let r = 0; r < rows; r++) {
      const off = src + r * cols;
      for (let i = 0; i < k; i++) {
        let s = 0;
        const m = i * cols;
        for (let c = 0; c < cols; c++) s += mat[m + c]! * v[off + c]!;
        o[dst + r * k + i] = s;
      }
    }
  }

  /** Running integral per element: trapezoid over the timestamps, or a plain sum. */
  private integrate(v: Float64Array, src: number, t: number, o: Float64Array, dst: number): void {
    const { acc, prev, size, trapezoid } = this;
    const first = Number.isNaN(this.prevT);
    const dt = first ? 0 : t - this.prevT;
    for (let i = 0; i < size; i++) {
      const x = v[src + i]!;
      if (!trapezoid) acc[i] = acc[i]! + x;
      else if (dt > 0) acc[i] = acc[i]! + 0.5 * (x + prev[i]!) * dt;
      prev[i] = x;
      o[dst + i] = acc[i]!;
    }
    if (first || dt > 0) this.prevT = t;
  }
}
