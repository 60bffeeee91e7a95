/**
 * The BodyRig block's chain, resolved against its inputs (`compileRig`, at create: every error a
 * BlockConfigError naming the link and the param), and its state at run time (`RigState`: the
 * latest good orientation of every link, and the pose computed from them).
 */
import { BlockConfigError, errorMessage, type BlockContext } from "../../engine";
import { findInput, inputName, vectorInput } from "../shared/inputs";
import type { BodyRigParams, LinkParams } from "./body-rig";
import { computeOrder, parentIndices } from "./chain";
import {
  canonicalize,
  eulerInto,
  IDENTITY,
  multiplyConjugate,
  normalizeInto,
  parseEulerSequence,
  refusalReason,
  rotateVector,
  type EulerSequence,
} from "./quaternion";

/** Unit vector of each Axis value. */
const AXIS_VECTORS: Record<string, readonly [number, number, number]> = {
  x: [1, 0, 0],
  "-x": [-1, 0, 0],
  y: [0, 1, 0],
  "-y": [0, -1, 0],
  z: [0, 0, 1],
  "-z": [0, 0, -1],
};

export interface RigPlan {
  /** Link names, in the order of Links (the order of the outputs). */
  readonly names: readonly string[];
  /** Each input as written in Inputs, by port. */
  readonly inputNames: readonly string[];
  /** Parent of each link, -1 for a root. */
  readonly parent: Int32Array;
  /** Link indices, parents before children. */
  readonly order: Int32Array;
  /** The distal end relative to the proximal one, in the segment's frame: 3 per link. */
  readonly offset: Float64Array;
  /** Unit quaternion sensor → segment: 4 per link. */
  readonly sensorToSegment: Float64Array;
  /** Input port of each link. */
  readonly input: Int32Array;
  /** First channel of each link's orientation in its input's event. */
  readonly channel: Int32Array;
  /** The links each input port feeds. */
  readonly linksOf: readonly Int32Array[];
  /** The port whose events make the block emit. */
  readonly trigger: number;
  readonly origin: Float64Array;
  /** Values per orientation: 4 (quaternion) or 3 (Euler angles). */
  readonly valuesPer: 3 | 4;
  /** The Euler sequence, when the inputs carry Euler angles. */
  readonly euler: EulerSequence | null;
}

/** Why the orientation at `v[at…]` was refused. */
export function describeRefusal(plan: RigPlan, v: ArrayLike<number>, at: number): string {
  return plan.euler ? "an angle is not a finite number" : refusalReason(v, at);
}

/** Runs `fn`; a BlockConfigError it throws is rethrown naming link `i` and positioned at `key`. */
function atLink<T>(i: number, l: LinkParams, key: keyof LinkParams, fn: () => T): T {
  try {
    return fn();
  } catch (e) {
    if (!(e instanceof BlockConfigError)) throw e;
    throw new BlockConfigError(`link '${l.Name}': ${errorMessage(e)}`, `Links[${i}].${key}`);
  }
}

/** The rotation sensor → segment of every link, unit quaternions. */
function sensorToSegment(p: BodyRigParams, seq: EulerSequence): Float64Array {
  const out = new Float64Array(4 * p.Links.length);
  const scratch = new Float64Array(8);
  const q = new Float64Array(4);
  p.Links.forEach((l, i) => {
    if (l.SensorToSegmentEuler !== undefined)
      eulerInto(seq, l.SensorToSegmentEuler, 0, q, 0, scratch);
    else q.set(l.SensorToSegment ?? IDENTITY);
    // The schema refused zero-norm and non-finite values: this cannot fail.
    normalizeInto(q, 0, out, 4 * i);
  });
  return out;
}

/** The distal end of every link relative to its proximal end, in the segment's frame. */
function offsets(p: BodyRigParams): Float64Array {
  const out = new Float64Array(3 * p.Links.length);
  p.Links.forEach((l, i) => {
    if (l.Offset !== undefined) out.set(l.Offset, 3 * i);
    else {
      const a = AXIS_VECTORS[l.Axis ?? p.Axis]!;
      const len = l.Length ?? 0;
      out.set([a[0] * len, a[1] * len, a[2] * len], 3 * i);
    }
  });
  return out;
}

/** Input port and first channel of every link, checked against the inputs' widths. */
function sources(
  ctx: BlockContext,
  p: BodyRigParams,
  valuesPer: number,
): { input: Int32Array; channel: Int32Array } {
  const n = p.Links.length;
  const input = new Int32Array(n);
  const channel = new Int32Array(n);
  const next = new Map<number, number>();
  p.Links.forEach((l, i) => {
    const port =
      l.Input === undefined
        ? 0
        : atLink(i, l, "Input", () => findInput(ctx, l.Input!, "Input").index);
    const s = atLink(i, l, "Input", () => vectorInput(ctx, port, "Input"));
    const first = l.Channel ?? next.get(port) ?? 0;
    const last = first + valuesPer - 1;
    if (last >= s.size) {
      const what = valuesPer === 4 ? "a quaternion w, x, y, z" : "3 Euler angles";
      throw new BlockConfigError(
        `link '${l.Name}': channels ${first}–${last} (${what}) are out of range for input ` +
          `${inputName(s.info)} with ${s.size} channel${s.size === 1 ? "" : "s"} (valid: 0–${s.size - 1})` +
          (l.Channel === undefined
            ? "; by default a link reads the channels after the previous link's on the same input (set Channel)"
            : ""),
        `Links[${i}].Channel`,
      );
    }
    input[i] = port;
    channel[i] = first;
    next.set(port, first + valuesPer);
  });
  return { input, channel };
}

/** Every input must feed a link or be the Trigger. */
function checkInputsUsed(ctx: BlockContext, input: Int32Array, trigger: number): void {
  for (const info of ctx.inputs) {
    if (info.index === trigger || input.includes(info.index)) continue;
    throw new BlockConfigError(
      `input ${inputName(info)} feeds no link and is not the Trigger; name it in a link's Input, or remove it`,
      "Links",
    );
  }
}

/** Resolves the chain against the block's inputs; throws a BlockConfigError on what does not fit. */
export function compileRig(ctx: BlockContext, p: BodyRigParams): RigPlan {
  const valuesPer = p.Orientation === "euler" ? 3 : 4;
  const seq = parseEulerSequence(p.EulerSequence);
  const { input, channel } = sources(ctx, p, valuesPer);
  const trigger = p.Trigger === undefined ? 0 : findInput(ctx, p.Trigger, "Trigger").index;
  checkInputsUsed(ctx, input, trigger);
  const parent = parentIndices(p.Links);
  const linksOf = ctx.inputs.map((info) => {
    const mine: number[] = [];
    input.forEach((port, i) => {
      if (port === info.index) mine.push(i);
    });
    return Int32Array.from(mine);
  });
  return {
    names: p.Links.map((l) => l.Name),
    inputNames: ctx.inputs.map((i) => i.source),
    parent,
    order: computeOrder(parent),
    offset: offsets(p),
    sensorToSegment: sensorToSegment(p, seq),
    input,
    channel,
    linksOf,
    trigger,
    origin: Float64Array.from(p.Origin),
    valuesPer,
    euler: valuesPer === 3 ? seq : null,
  };
}

/** Told about every orientation a link refused (read at `v[at…]`, event time `t`). */
export interface RefusalListener {
  refused(link: number, v: ArrayLike<number>, at: number, t: number): void;
}

/** The latest good orientation of every link, and the pose they give. */
export class RigState {
  /** World ← sensor of each link, unit quaternions (valid where `valid` is 1). */
  private readonly imu: Float64Array;
  private readonly valid: Uint8Array;
  private readonly segment = new Float64Array(4);
  private readonly raw = new Float64Array(4);
  private readonly scratch = new Float64Array(8);
  private readonly end = new Float64Array(3);

  constructor(private readonly plan: RigPlan) {
    this.imu = new Float64Array(4 * plan.names.length);
    this.valid = new Uint8Array(plan.names.length);
  }

  /** Reads the orientations that input `port` carries in `v[base…]` (one event). */
  update(
    port: number,
    v: ArrayLike<number>,
    base: number,
    t: number,
    listener: RefusalListener,
  ): void {
    const plan = this.plan;
    const links = plan.linksOf[port]!;
    for (let k = 0; k < links.length; k++) {
      const i = links[k]!;
      const at = base + plan.channel[i]!;
      const ok = plan.euler
        ? eulerInto(plan.euler, v, at, this.raw, 0, this.scratch) &&
          normalizeInto(this.raw, 0, this.imu, 4 * i)
        : normalizeInto(v, at, this.imu, 4 * i);
      if (ok) this.valid[i] = 1;
      else listener.refused(i, v, at, t);
    }
  }

  /**
   * Writes the pose: positions (base, then every link's distal end, 3 values each) at
   * `pos[po…]`, segment orientations (4 values per link, w ≥ 0) at `ori[oo…]`.
   */
  pose(pos: Float64Array, po: number, ori: Float64Array, oo: number): void {
    const plan = this.plan;
    const q = this.segment;
    const end = this.end;
    pos[po] = plan.origin[0]!;
    pos[po + 1] = plan.origin[1]!;
    pos[po + 2] = plan.origin[2]!;
    for (let k = 0; k < plan.order.length; k++) {
      const i = plan.order[k]!;
      const at = po + 3 * (i + 1);
      const from = po + 3 * (plan.parent[i]! + 1); // the base for a root (-1)
      if (this.valid[i] === 0) {
        ori.fill(NaN, oo + 4 * i, oo + 4 * i + 4);
        pos.fill(NaN, at, at + 3);
        continue;
      }
      multiplyConjugate(this.imu, 4 * i, plan.sensorToSegment, 4 * i, q, 0);
      canonicalize(q, 0);
      ori.set(q, oo + 4 * i);
      const d = 3 * i;
      rotateVector(q, 0, plan.offset[d]!, plan.offset[d + 1]!, plan.offset[d + 2]!, end, 0);
      pos[at] = pos[from]! + end[0]!;
      pos[at + 1] = pos[from + 1]! + end[1]!;
      pos[at + 2] = pos[from + 2]! + end[2]!;
    }
  }

  reset(): void {
    this.valid.fill(0);
    this.imu.fill(0);
  }
}
