/**
 * ROS messages ↔ flat vectors, for the Ros block (docs/protocols.md, "ROS (rosbridge)"). A message
 * is the JSON object rosbridge carries in `msg`; a vector is the block's event, values in the
 * order below. Decoding never throws: a message that does not fit gives a one-line reason.
 *
 * | type                         | values                                                     |
 * | ---------------------------- | ---------------------------------------------------------- |
 * | std_msgs/Float64MultiArray   | `data` (after `layout.data_offset`), any length            |
 * | std_msgs/Float32MultiArray   | the same; published values are rounded to float32          |
 * | std_msgs/Float64             | `[data]`                                                   |
 * | geometry_msgs/Vector3        | `[x, y, z]`                                                |
 * | geometry_msgs/Twist          | `[linear.x, linear.y, linear.z, angular.x, angular.y, angular.z]` |
 * | sensor_msgs/JointState       | `position` (by `name` when joint names are given)          |
 */

export const ROS_MESSAGE_TYPES = [
  "std_msgs/Float64MultiArray",
  "std_msgs/Float32MultiArray",
  "std_msgs/Float64",
  "geometry_msgs/Vector3",
  "geometry_msgs/Twist",
  "sensor_msgs/JointState",
] as const;

export type RosMessageType = (typeof ROS_MESSAGE_TYPES)[number];

/** Values per message of the fixed-size types; undefined for the arrays (any length). */
export function fixedSizeOf(type: RosMessageType): number | undefined {
  switch (type) {
    case "std_msgs/Float64":
      return 1;
    case "geometry_msgs/Vector3":
      return 3;
    case "geometry_msgs/Twist":
      return 6;
    default:
      return undefined;
  }
}

export interface RosCodecOptions {
  /** Values per vector. */
  size: number;
  /** MultiArray: the vector is a `rows × cols` matrix, row-major (layout with two dims). */
  rows?: number;
  cols?: number;
  /** JointState: the joints' names, one per value (published in `name`, matched when decoding). */
  jointNames?: readonly string[];
}

export interface RosEncoder {
  /**
   * The message for the values `v[off] … v[off + size - 1]`. The object is reused by the next
   * call: send (serialise) it first.
   */
  encode(v: ArrayLike<number>, off: number): object;
}

export interface RosDecoder {
  /** Writes the message's `size` values to `out`; returns why not, when the message does not fit. */
  decode(msg: unknown, out: Float64Array): string | undefined;
}

type Obj = Record<string, unknown>;

const isObj = (x: unknown): x is Obj => typeof x === "object" && x !== null && !Array.isArray(x);

/** A number, or JSON null (what JSON makes of NaN and ±∞) as NaN; undefined otherwise. */
function num(x: unknown): number | undefined {
  if (typeof x === "number") return x;
  if (x === null) return NaN;
  return undefined;
}

/** Arrays arrive as JSON arrays (or typed arrays, from a CBOR-speaking bridge). */
function isList(x: unknown): x is ArrayLike<unknown> {
  return Array.isArray(x) || (ArrayBuffer.isView(x) && !(x instanceof DataView));
}

const expected = (n: number, size: number): string =>
  `${n} value${n === 1 ? "" : "s"}, expected ${size}`;

/** Copies `n` numbers of `list` from `from` into `out`, or says which one is not a number. */
function copyNumbers(
  list: ArrayLike<unknown>,
  from: number,
  n: number,
  out: Float64Array,
  field: string,
): string | undefined {
  for (let i = 0; i < n; i++) {
    const x = num(list[from + i]);
    if (x === undefined) return `${field}[${from + i}] is not a number`;
    out[i] = x;
  }
  return undefined;
}

/** Reads `obj[keys[0]]`, `obj[keys[1]]`, … (nested objects by dotted name) into `out`. */
function readFields(msg: unknown, keys: readonly string[], out: Float64Array): string | undefined {
  if (!isObj(msg)) return "not a message object";
  for (let i = 0; i < keys.length; i++) {
    const path = keys[i]!.split(".");
    let x: unknown = msg;
    for (const k of path) x = isObj(x) ? x[k] : undefined;
    const v = num(x);
    if (v === undefined) return x === undefined ? `no ${keys[i]}` : `${keys[i]} is not a number`;
    out[i] = v;
  }
  return undefined;
}

const FLOAT64 = ["data"] as const;
const VECTOR3 = ["x", "y", "z"] as const;
const TWIST = ["linear.x", "linear.y", "linear.z", "angular.x", "angular.y", "angular.z"] as const;

function multiArrayLayout(o: RosCodecOptions): object {
  const { size, rows, cols } = o;
  if (rows !== undefined && cols !== undefined && rows > 1) {
    return {
      dim: [
        { label: "rows", size: rows, stride: rows * cols },
        { label: "cols", size: cols, stride: cols },
      ],
      data_offset: 0,
    };
  }
  return { dim: [{ label: "values", size, stride: size }], data_offset: 0 };
}

export function rosEncoder(type: RosMessageType, o: RosCodecOptions): RosEncoder {
  switch (type) {
    case "std_msgs/Float64MultiArray":
      return multiArrayEncoder(o, false);
    case "std_msgs/Float32MultiArray":
      return multiArrayEncoder(o, true);
    case "std_msgs/Float64":
      return float64Encoder();
    case "geometry_msgs/Vector3":
      return vector3Encoder();
    case "geometry_msgs/Twist":
      return twistEncoder();
    case "sensor_msgs/JointState":
      return jointStateEncoder(o);
  }
}

/** Float64MultiArray, or Float32MultiArray (`f32`: the values rounded to float32). */
function multiArrayEncoder(o: RosCodecOptions, f32: boolean): RosEncoder {
  const size = o.size;
  const data = new Array<number>(size).fill(0);
  const msg = { layout: multiArrayLayout(o), data };
  return {
    encode(v, off) {
      for (let i = 0; i < size; i++) data[i] = f32 ? Math.fround(v[off + i]!) : v[off + i]!;
      return msg;
    },
  };
}

function float64Encoder(): RosEncoder {
  const msg = { data: 0 };
  return {
    encode(v, off) {
      msg.data = v[off]!;
      return msg;
    },
  };
}

function vector3Encoder(): RosEncoder {
  const msg = { x: 0, y: 0, z: 0 };
  return {
    encode(v, off) {
      msg.x = v[off]!;
      msg.y = v[off + 1]!;
      msg.z = v[off + 2]!;
      return msg;
    },
  };
}

function twistEncoder(): RosEncoder {
  const linear = { x: 0, y: 0, z: 0 };
  const angular = { x: 0, y: 0, z: 0 };
  const msg = { linear, angular };
  return {
    encode(v, off) {
      linear.x = v[off]!;
      linear.y = v[off + 1]!;
      linear.z = v[off + 2]!;
      angular.x = v[off + 3]!;
      angular.y = v[off + 4]!;
      angular.z = v[off + 5]!;
      return msg;
    },
  };
}

/** JointState: the joints' names (as given) and their positions. */
function jointStateEncoder(o: RosCodecOptions): RosEncoder {
  const size = o.size;
  // No header: rosbridge fills it in (frame_id "", stamp = the time it publishes).
  const position = new Array<number>(size).fill(0);
  const msg = { name: [...(o.jointNames ?? [])], position, velocity: [], effort: [] };
  return {
    encode(v, off) {
      for (let i = 0; i < size; i++) position[i] = v[off + i]!;
      return msg;
    },
  };
}

export function rosDecoder(type: RosMessageType, o: RosCodecOptions): RosDecoder {
  const size = o.size;
  switch (type) {
    case "std_msgs/Float64MultiArray":
    case "std_msgs/Float32MultiArray":
      return { decode: (msg, out) => decodeMultiArray(msg, size, out) };
    case "std_msgs/Float64":
      return { decode: (msg, out) => readFields(msg, FLOAT64, out) };
    case "geometry_msgs/Vector3":
      return { decode: (msg, out) => readFields(msg, VECTOR3, out) };
    case "geometry_msgs/Twist":
      return { decode: (msg, out) => readFields(msg, TWIST, out) };
    case "sensor_msgs/JointState":
      return new JointStateDecoder(size, o.jointNames);
  }
}

/** A MultiArray's `size` values: `data` after `layout.data_offset`. */
function decodeMultiArray(msg: unknown, size: number, out: Float64Array): string | undefined {
  if (!isObj(msg)) return "not a message object";
  const data = msg.data;
  if (!isList(data)) return data === undefined ? "no data" : "data is not a list";
  const offset = dataOffset(msg.layout, data.length);
  if (typeof offset === "string") return offset;
  const n = data.length - offset;
  if (n !== size) return expected(n, size);
  return copyNumbers(data, offset, n, out, "data");
}

/** Where the values start in `data` (`layout.data_offset`, else 0), or why it does not fit. */
function dataOffset(layout: unknown, length: number): number | string {
  if (!isObj(layout) || layout.data_offset === undefined) return 0;
  const d = layout.data_offset;
  if (typeof d !== "number" || !Number.isInteger(d) || d < 0 || d > length) {
    return `layout.data_offset ${JSON.stringify(d)} does not fit ${length} values`;
  }
  return d;
}

/** JointState: `position`, in order, or the positions of the named joints found in `name`. */
class JointStateDecoder implements RosDecoder {
  // The order of `name` seldom changes: the index of each wanted joint is kept until it does.
  private lastNames: string[] = [];
  /** Where each wanted joint is in `name` (and so in `position`). */
  private index: number[] = [];

  constructor(
    private readonly size: number,
    private readonly names: readonly string[] | undefined,
  ) {}

  decode(msg: unknown, out: Float64Array): string | undefined {
    if (!isObj(msg)) return "not a message object";
    const position = msg.position;
    if (!isList(position)) {
      return position === undefined ? "no position" : "position is not a list";
    }
    const { size, names } = this;
    if (!names) {
      if (position.length !== size) return expected(position.length, size);
      return copyNumbers(position, 0, size, out, "position");
    }
    const got = msg.name;
    if (!Array.isArray(got)) return "no name list to find the joints in";
    if (got.length !== this.lastNames.length || got.some((g, i) => g !== this.lastNames[i])) {
      const missing = this.findJoints(got, names);
      if (missing !== undefined) return missing;
    }
    return this.readJoints(position, names, out);
  }

  /** Finds each wanted joint in the new name list `got`; says which are missing. */
  private findJoints(got: unknown[], names: readonly string[]): string | undefined {
    const at = new Map<unknown, number>();
    got.forEach((g, i) => {
      if (!at.has(g)) at.set(g, i);
    });
    const missing = names.filter((n) => !at.has(n));
    if (missing.length > 0) {
      return `no joint ${missing.map((m) => `'${m}'`).join(", ")} in name`;
    }
    this.lastNames = got.map(String);
    this.index = names.map((n) => at.get(n)!);
    return undefined;
  }

  /** Copies the wanted joints' positions into `out`, or says which is missing or not a number. */
  private readJoints(
    position: ArrayLike<unknown>,
    names: readonly string[],
    out: Float64Array,
  ): string | undefined {
    const index = this.index;
    for (let i = 0; i < this.size; i++) {
      const k = index[i]!;
      if (k >= position.length) {
        return `position has ${position.length} values, joint '${names[i]}' is number ${k + 1} in name`;
      }
      const x = num(position[k]);
      if (x === undefined) return `position[${k}] is not a number`;
      out[i] = x;
    }
    return undefined;
  }
}
