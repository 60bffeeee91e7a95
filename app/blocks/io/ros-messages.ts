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
  const size = o.size;
  switch (type) {
    case "std_msgs/Float64MultiArray":
    case "std_msgs/Float32MultiArray": {
      const f32 = type === "std_msgs/Float32MultiArray";
      const data = new Array<number>(size).fill(0);
      const msg = { layout: multiArrayLayout(o), data };
      return {
        encode(v, off) {
          for (let i = 0; i < size; i++) data[i] = f32 ? Math.fround(v[off + i]!) : v[off + i]!;
          return msg;
        },
      };
    }
    case "std_msgs/Float64": {
      const msg = { data: 0 };
      return {
        encode(v, off) {
          msg.data = v[off]!;
          return msg;
        },
      };
    }
    case "geometry_msgs/Vector3": {
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
    case "geometry_msgs/Twist": {
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
    case "sensor_msgs/JointState": {
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
  }
}

export function rosDecoder(type: RosMessageType, o: RosCodecOptions): RosDecoder {
  const size = o.size;
  switch (type) {
    case "std_msgs/Float64MultiArray":
    case "std_msgs/Float32MultiArray":
      return {
        decode(msg, out) {
          if (!isObj(msg)) return "not a message object";
          const data = msg.data;
          if (!isList(data)) return data === undefined ? "no data" : "data is not a list";
          let offset = 0;
          const layout = msg.layout;
          if (isObj(layout) && layout.data_offset !== undefined) {
            const d = layout.data_offset;
            if (typeof d !== "number" || !Number.isInteger(d) || d < 0 || d > data.length) {
              return `layout.data_offset ${JSON.stringify(d)} does not fit ${data.length} values`;
            }
            offset = d;
          }
          const n = data.length - offset;
          if (n !== size) return expected(n, size);
          return copyNumbers(data, offset, n, out, "data");
        },
      };
    case "std_msgs/Float64":
      return { decode: (msg, out) => readFields(msg, ["data"], out) };
    case "geometry_msgs/Vector3":
      return { decode: (msg, out) => readFields(msg, VECTOR3, out) };
    case "geometry_msgs/Twist":
      return { decode: (msg, out) => readFields(msg, TWIST, out) };
    case "sensor_msgs/JointState": {
      const names = o.jointNames;
      // The order of `name` seldom changes: the index of each wanted joint is kept until it does.
      let lastNames: string[] = [];
      let index: number[] = [];
      return {
        decode(msg, out) {
          if (!isObj(msg)) return "not a message object";
          const position = msg.position;
          if (!isList(position)) {
            return position === undefined ? "no position" : "position is not a list";
          }
          if (!names) {
            if (position.length !== size) return expected(position.length, size);
            return copyNumbers(position, 0, size, out, "position");
          }
          const got = msg.name;
          if (!Array.isArray(got)) return "no name list to find the joints in";
          if (got.length !== lastNames.length || got.some((g, i) => g !== lastNames[i])) {
            const at = new Map<unknown, number>();
            got.forEach((g, i) => {
              if (!at.has(g)) at.set(g, i);
            });
            const missing = names.filter((n) => !at.has(n));
            if (missing.length > 0) {
              return `no joint ${missing.map((m) => `'${m}'`).join(", ")} in name`;
            }
            lastNames = got.map(String);
            index = names.map((n) => at.get(n)!);
          }
          for (let i = 0; i < size; i++) {
            const k = index[i]!;
            if (k >= position.length) {
              return `position has ${position.length} values, joint '${names[i]}' is number ${k + 1} in name`;
            }
            const x = num(position[k]);
            if (x === undefined) return `position[${k}] is not a number`;
            out[i] = x;
          }
          return undefined;
        },
      };
    }
  }
}
