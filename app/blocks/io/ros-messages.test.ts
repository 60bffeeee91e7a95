import { describe, expect, test } from "vitest";
import {
  fixedSizeOf,
  ROS_MESSAGE_TYPES,
  rosDecoder,
  rosEncoder,
  type RosMessageType,
} from "./ros-messages";

/** The JSON rosbridge would carry (what roslib sends), parsed back. */
const wire = (o: object): unknown => JSON.parse(JSON.stringify(o));

const decode = (type: RosMessageType, size: number, msg: unknown, names?: string[]) => {
  const out = new Float64Array(size);
  const err = rosDecoder(type, { size, ...(names ? { jointNames: names } : {}) }).decode(msg, out);
  return err ?? Array.from(out);
};

describe("ROS message mapping", () => {
  test("fixed sizes", () => {
    expect(ROS_MESSAGE_TYPES.map((t) => fixedSizeOf(t))).toEqual([
      undefined,
      undefined,
      1,
      3,
      6,
      undefined,
    ]);
  });

  test("Float64MultiArray: data with a one-dim layout; a matrix gets rows × cols", () => {
    const enc = rosEncoder("std_msgs/Float64MultiArray", { size: 3 });
    expect(wire(enc.encode([9, 0.1, -2, 1e-300], 1))).toEqual({
      layout: { dim: [{ label: "values", size: 3, stride: 3 }], data_offset: 0 },
      data: [0.1, -2, 1e-300],
    });
    const m = rosEncoder("std_msgs/Float64MultiArray", { size: 6, rows: 2, cols: 3 });
    expect(wire(m.encode([1, 2, 3, 4, 5, 6], 0))).toEqual({
      layout: {
        dim: [
          { label: "rows", size: 2, stride: 6 },
          { label: "cols", size: 3, stride: 3 },
        ],
        data_offset: 0,
      },
      data: [1, 2, 3, 4, 5, 6],
    });
  });

  test("Float64MultiArray round trip is exact; data_offset is honoured", () => {
    const v = [Math.PI, -1 / 3, 5e-324, 1.7976931348623157e308];
    const enc = rosEncoder("std_msgs/Float64MultiArray", { size: 4 });
    expect(decode("std_msgs/Float64MultiArray", 4, wire(enc.encode(v, 0)))).toEqual(v);
    expect(
      decode("std_msgs/Float64MultiArray", 2, {
        layout: { dim: [], data_offset: 1 },
        data: [99, 1, 2],
      }),
    ).toEqual([1, 2]);
    // A publisher that leaves the layout out (or empty) is fine.
    expect(decode("std_msgs/Float64MultiArray", 2, { data: [3, 4] })).toEqual([3, 4]);
  });

  test("Float32MultiArray: published values are rounded to float32", () => {
    const enc = rosEncoder("std_msgs/Float32MultiArray", { size: 2 });
    const msg = wire(enc.encode([0.1, 1 / 3], 0)) as { data: number[] };
    expect(msg.data).toEqual([Math.fround(0.1), Math.fround(1 / 3)]);
    expect(decode("std_msgs/Float32MultiArray", 2, msg)).toEqual(msg.data);
  });

  test("Float64, Vector3, Twist", () => {
    expect(wire(rosEncoder("std_msgs/Float64", { size: 1 }).encode([2.5], 0))).toEqual({
      data: 2.5,
    });
    expect(wire(rosEncoder("geometry_msgs/Vector3", { size: 3 }).encode([1, 2, 3], 0))).toEqual({
      x: 1,
      y: 2,
      z: 3,
    });
    const twist = wire(
      rosEncoder("geometry_msgs/Twist", { size: 6 }).encode([1, 2, 3, 4, 5, 6], 0),
    );
    expect(twist).toEqual({ linear: { x: 1, y: 2, z: 3 }, angular: { x: 4, y: 5, z: 6 } });
    expect(decode("geometry_msgs/Twist", 6, twist)).toEqual([1, 2, 3, 4, 5, 6]);
    expect(decode("std_msgs/Float64", 1, { data: -0.5 })).toEqual([-0.5]);
    expect(decode("geometry_msgs/Vector3", 3, { x: 1, y: 2, z: 3 })).toEqual([1, 2, 3]);
  });

  test("JointState: position, names sent; picked by name when names are given", () => {
    const enc = rosEncoder("sensor_msgs/JointState", { size: 2, jointNames: ["elbow", "wrist"] });
    expect(wire(enc.encode([0.5, -0.25], 0))).toEqual({
      name: ["elbow", "wrist"],
      position: [0.5, -0.25],
      velocity: [],
      effort: [],
    });
    const msg = { name: ["wrist", "thumb", "elbow"], position: [1, 2, 3], velocity: [] };
    expect(decode("sensor_msgs/JointState", 2, msg, ["elbow", "wrist"])).toEqual([3, 1]);
    // The order of `name` may change from one message to the next.
    const d = rosDecoder("sensor_msgs/JointState", { size: 2, jointNames: ["elbow", "wrist"] });
    const out = new Float64Array(2);
    expect(d.decode(msg, out)).toBeUndefined();
    expect(d.decode({ name: ["elbow", "wrist"], position: [7, 8] }, out)).toBeUndefined();
    expect(Array.from(out)).toEqual([7, 8]);
    expect(d.decode({ name: ["elbow"], position: [7] }, out)).toBe("no joint 'wrist' in name");
    expect(decode("sensor_msgs/JointState", 3, msg)).toEqual([1, 2, 3]);
  });

  test("JSON null (what JSON makes of NaN) decodes as NaN", () => {
    expect(decode("std_msgs/Float64MultiArray", 2, { data: [null, 1] })).toEqual([NaN, 1]);
    expect(decode("geometry_msgs/Vector3", 3, { x: null, y: 0, z: 0 })).toEqual([NaN, 0, 0]);
  });

  test("messages that do not fit give a reason, never throw", () => {
    const cases: [RosMessageType, number, unknown, string][] = [
      ["std_msgs/Float64MultiArray", 2, { data: [1, 2, 3] }, "3 values, expected 2"],
      ["std_msgs/Float64MultiArray", 2, { data: [1] }, "1 value, expected 2"],
      ["std_msgs/Float64MultiArray", 2, { data: [1, "x"] }, "data[1] is not a number"],
      ["std_msgs/Float64MultiArray", 2, {}, "no data"],
      ["std_msgs/Float64MultiArray", 2, { data: 5 }, "data is not a list"],
      [
        "std_msgs/Float64MultiArray",
        2,
        { layout: { data_offset: 9 }, data: [1, 2] },
        "layout.data_offset 9 does not fit 2 values",
      ],
      ["std_msgs/Float64MultiArray", 2, null, "not a message object"],
      ["std_msgs/Float64MultiArray", 2, [1, 2], "not a message object"],
      ["std_msgs/Float64", 1, { data: "1" }, "data is not a number"],
      ["geometry_msgs/Vector3", 3, { x: 1, y: 2 }, "no z"],
      ["geometry_msgs/Twist", 6, { linear: { x: 1, y: 2, z: 3 } }, "no angular.x"],
      ["geometry_msgs/Twist", 6, "twist", "not a message object"],
      ["sensor_msgs/JointState", 2, { position: [1] }, "1 value, expected 2"],
      ["sensor_msgs/JointState", 2, { name: [] }, "no position"],
    ];
    for (const [type, size, msg, reason] of cases) {
      expect(decode(type, size, msg), `${type} ${JSON.stringify(msg)}`).toBe(reason);
    }
  });
});
