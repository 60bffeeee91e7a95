import { describe, expect, test } from "vitest";
import {
  createCatalog,
  loadPipeline,
  matrixShape,
  vectorShape,
  type RosBridge,
  type RosConnectionState,
  type RosConnectOptions,
} from "../../engine";
import { BlockHarness } from "../../engine/testing";
import { vectors } from "../../../tests/support/blocks";
import { Ros } from "./ros";

interface FakeConnection {
  options: RosConnectOptions;
  advertised: { topic: string; type: string; latch?: boolean }[];
  subscribed: { topic: string; type: string; throttleMs?: number; queueLength?: number }[];
  onMessage?: (msg: unknown) => void;
  closed: boolean;
  unsubscribed: boolean;
  unadvertised: boolean;
  state(s: RosConnectionState, message?: string): void;
}

/** A rosbridge without sockets: the test opens and drops connections and delivers messages. */
function fakeRos(opts: { refuseAtOnce?: boolean } = {}) {
  const connections: FakeConnection[] = [];
  const published: string[] = [];
  let connected = false;
  const bridge: RosBridge = {
    connect(options) {
      const c: FakeConnection = {
        options,
        advertised: [],
        subscribed: [],
        closed: false,
        unsubscribed: false,
        unadvertised: false,
        state(s, m) {
          connected = s === "connected";
          options.onState(s, m);
        },
      };
      connections.push(c);
      options.onState("connecting");
      if (opts.refuseAtOnce) options.onState("disconnected", "bad URL");
      return {
        advertise(o) {
          c.advertised.push(o);
          return {
            publish(msg) {
              if (!connected || c.closed) return false;
              published.push(JSON.stringify(msg));
              return true;
            },
            unadvertise: () => void (c.unadvertised = true),
          };
        },
        subscribe(o) {
          const { onMessage, ...rest } = o;
          c.subscribed.push(rest);
          c.onMessage = onMessage;
          return { unsubscribe: () => void (c.unsubscribed = true) };
        },
        close() {
          c.closed = true;
          connected = false;
        },
      };
    },
  };
  return {
    bridge,
    connections,
    published,
    get last() {
      return connections.at(-1)!;
    },
  };
}

const pub = (shape = vectorShape(3)) => ({
  inputs: [{ shape, rate: 50 }],
});

describe("ROS block", () => {
  test("publish: every input event is one message; dropped (not queued) while disconnected", async () => {
    const ros = fakeRos();
    const h = await BlockHarness.create(
      Ros,
      { Topic: "/mosaic/out", Latch: true },
      { ...pub(), io: { ros: ros.bridge } },
    );
    expect(h.text).toBe(
      "ws://127.0.0.1:9090 · publishing /mosaic/out (std_msgs/Float64MultiArray) · 0 out",
    );
    h.start();
    expect(ros.connections).toHaveLength(1);
    expect(ros.last.options.url).toBe("ws://127.0.0.1:9090");
    expect(ros.last.advertised).toEqual([
      { topic: "/mosaic/out", type: "std_msgs/Float64MultiArray", latch: true },
    ]);
    expect(h.text).toMatch(/^connecting to ws:\/\/127\.0\.0\.1:9090… · publishing/);
    h.push(vectors([0.01], [[1, 2, 3]]));
    expect(ros.published).toEqual([]);
    ros.last.state("connected");
    expect(h.text).toMatch(
      /^connected to ws:\/\/127\.0\.0\.1:9090 · publishing .* · 0 out · 1 dropped while disconnected$/,
    );
    h.push(
      vectors(
        [0.3, 0.31],
        [
          [0.5, -1, 1e-300],
          [4, 5, 6],
        ],
      ),
    );
    expect(ros.published.map((m) => JSON.parse(m).data)).toEqual([
      [0.5, -1, 1e-300],
      [4, 5, 6],
    ]);
    expect(h.text).toMatch(/ · 2 out · 1 dropped while disconnected$/);
    // NaN cannot travel in JSON: such events are counted, not sent.
    h.push(vectors([0.7], [[NaN, 0, 0]]));
    expect(ros.published).toHaveLength(2);
    expect(h.text).toMatch(/1 not sent \(NaN or ±∞\)/);
    h.instance.stop?.();
    expect(ros.last.closed).toBe(true);
    expect(ros.last.unadvertised).toBe(true);
    expect(h.text).toMatch(/^stopped · publishing/);
    h.instance.dispose?.();
    h.instance.dispose?.();
  });

  test("subscribe: each message is an event [1, Channels] at arrival; wrong lengths counted", async () => {
    const ros = fakeRos();
    const h = await BlockHarness.create(
      Ros,
      { Topic: "/in", Direction: "subscribe", Channels: 2, ThrottleMs: 10, QueueLength: 2 },
      { io: { ros: ros.bridge } },
    );
    h.start();
    expect(ros.last.subscribed).toEqual([
      { topic: "/in", type: "std_msgs/Float64MultiArray", throttleMs: 10, queueLength: 2 },
    ]);
    ros.last.state("connected");
    h.clock = 1.25;
    ros.last.onMessage!({ data: [1, 2] });
    h.clock = 1.5;
    ros.last.onMessage!({ data: [1, 2, 3] });
    ros.last.onMessage!("garbage");
    h.clock = 1.75;
    ros.last.onMessage!({ layout: { dim: [], data_offset: 0 }, data: [-0.5, 1 / 3] });
    expect(h.output().t).toEqual([1.25, 1.75]);
    expect(h.output().v).toEqual([
      [1, 2],
      [-0.5, 1 / 3],
    ]);
    expect(h.text).toMatch(
      /^connected to .* · subscribed to \/in \(std_msgs\/Float64MultiArray\) · 2 in · 2 malformed \(last: not a message object\)$/,
    );
    expect(h.warnings[0]).toMatch(
      /malformed std_msgs\/Float64MultiArray message on \/in: 3 values, expected 2/,
    );
  });

  test("reconnects with exponential backoff, counting down in the status", async () => {
    const ros = fakeRos();
    const h = await BlockHarness.create(
      Ros,
      {
        Topic: "/x",
        Direction: "subscribe",
        MessageType: "geometry_msgs/Vector3",
        ReconnectSeconds: 1,
        ReconnectMaxSeconds: 4,
      },
      { io: { ros: ros.bridge }, now: 100 },
    );
    h.start();
    ros.last.state("connected");
    ros.last.onMessage!({ x: 1, y: 2, z: 3 });
    h.clock = 101;
    ros.last.state("disconnected", "connection lost: code 1006");
    expect(ros.last.closed).toBe(true);
    expect(h.text).toBe(
      "disconnected from ws://127.0.0.1:9090: connection lost: code 1006; reconnecting in 1 s (attempt 2) · subscribed to /x (geometry_msgs/Vector3) · 1 in",
    );
    expect(h.warnings.at(-1)).toMatch(
      /lost the connection to rosbridge at ws:\/\/127\.0\.0\.1:9090/,
    );
    // Attempts at +1, +2, +4, +4 s (doubling, capped at ReconnectMaxSeconds).
    const waits: number[] = [];
    for (let k = 0; k < 4; k++) {
      const before = h.clock;
      const connections = ros.connections.length;
      while (ros.connections.length === connections) {
        expect(h.fireOneShot()).toBe(true);
        if (ros.connections.length === connections) expect(h.text).toMatch(/reconnecting in \d s/);
      }
      waits.push(h.clock - before);
      expect(h.text).toMatch(/^connecting to .* \(attempt \d\)…/);
      ros.last.state("disconnected", "nothing is listening (ECONNREFUSED)");
    }
    expect(waits).toEqual([1, 2, 4, 4]);
    expect(h.text).toMatch(
      /nothing is listening \(ECONNREFUSED\); reconnecting in 4 s \(attempt 6\)/,
    );
    // A success resets the backoff and counts a reconnect.
    while (ros.connections.length === 5) h.fireOneShot();
    ros.last.state("connected");
    expect(h.text).toMatch(/^connected to .* · 1 in · 1 reconnect$/);
    ros.last.onMessage!({ x: 4, y: 5, z: 6 });
    expect(h.output().v).toEqual([
      [1, 2, 3],
      [4, 5, 6],
    ]);
    const t = h.clock;
    ros.last.state("disconnected", "again");
    h.fireOneShot();
    expect(h.clock - t).toBe(1);
    // Stopped: a pending countdown does nothing.
    h.instance.stop?.();
    const n = ros.connections.length;
    h.fireOneShot();
    expect(ros.connections).toHaveLength(n);
  });

  test("ReconnectSeconds 0: stays disconnected; a bridge that refuses at once is handled", async () => {
    const ros = fakeRos({ refuseAtOnce: true });
    const h = await BlockHarness.create(
      Ros,
      { Topic: "/x", ReconnectSeconds: 0 },
      { ...pub(), io: { ros: ros.bridge } },
    );
    h.start();
    expect(ros.last.closed).toBe(true);
    expect(ros.last.advertised).toEqual([]);
    expect(h.text).toMatch(
      /disconnected from .*: bad URL; not reconnecting \(ReconnectSeconds 0\)/,
    );
    expect(h.fireOneShot()).toBe(false);
    h.push(vectors([1], [[1, 2, 3]]));
    expect(h.text).toMatch(/1 dropped while disconnected/);
  });

  test("without a bridge (browser build) the status says ROS is unavailable", async () => {
    const h = await BlockHarness.create(Ros, { Topic: "/x" }, pub());
    expect(h.text).toMatch(/^ROS is unavailable here \(the browser build/);
    h.start();
    h.push(vectors([1], [[1, 2, 3]]));
    expect(h.warnings).toHaveLength(1);
    h.instance.stop?.();
    expect(h.text).toMatch(/^ROS is unavailable here/);
  });

  test("a matrix input goes as a rows × cols MultiArray; Twist and JointState map", async () => {
    const ros = fakeRos();
    const h = await BlockHarness.create(
      Ros,
      { Topic: "/m" },
      { inputs: [{ shape: matrixShape(2, 2), rate: 10 }], io: { ros: ros.bridge } },
    );
    h.start();
    ros.last.state("connected");
    h.push(vectors([0], [[1, 2, 3, 4]]));
    expect(JSON.parse(ros.published[0]!).layout.dim.map((d: { size: number }) => d.size)).toEqual([
      2, 2,
    ]);

    const j = fakeRos();
    const hj = await BlockHarness.create(
      Ros,
      { Topic: "/joints", MessageType: "sensor_msgs/JointState", JointNames: ["a", "b"] },
      { inputs: [{ shape: vectorShape(2), rate: 10 }], io: { ros: j.bridge } },
    );
    hj.start();
    j.last.state("connected");
    hj.push(vectors([0], [[0.1, 0.2]]));
    expect(JSON.parse(j.published[0]!)).toEqual({
      name: ["a", "b"],
      position: [0.1, 0.2],
      velocity: [],
      effort: [],
    });
  });

  test("params are checked with the parameter named", async () => {
    const bad = async (params: object, opts: object, re: RegExp) =>
      expect(BlockHarness.create(Ros, params, opts)).rejects.toThrow(re);
    await bad({ Topic: "/x" }, {}, /Direction publish needs an input/);
    await bad({ Topic: "/x", Direction: "subscribe" }, {}, /Channels is needed to subscribe/);
    await bad({ Topic: "/x", Direction: "subscribe", Channels: 2 }, pub(), /takes no input/);
    await bad(
      { Topic: "/x", MessageType: "geometry_msgs/Twist" },
      pub(),
      /geometry_msgs\/Twist message carries 6 values, but the input 'in0' has 3/,
    );
    await bad({ Topic: "/x", Channels: 4 }, pub(), /Channels is 4 but the input/);
    await bad({ Topic: "/x", ThrottleMs: 5 }, pub(), /ThrottleMs applies to Direction subscribe/);
    await bad(
      { Topic: "/x", Direction: "subscribe", Channels: 1, Latch: true },
      {},
      /Latch applies to Direction publish/,
    );
    await bad({ Topic: "/x", JointNames: ["a"] }, pub(), /JointNames apply to sensor_msgs/);
    await bad(
      { Topic: "/x", MessageType: "sensor_msgs/JointState", JointNames: ["a", "b"] },
      pub(),
      /JointNames lists 2 joints for 3 values/,
    );
    await bad(
      { Topic: "/x", ReconnectSeconds: 10, ReconnectMaxSeconds: 5 },
      pub(),
      /ReconnectSeconds \(10\) is longer/,
    );
    await bad({ Topic: "no spaces" }, pub(), /ROS topic name/);
    await bad({ Topic: "/x", Url: "http://x:9090" }, pub(), /WebSocket URL/);
    // JointState subscribe takes its width from JointNames.
    const h = await BlockHarness.create(Ros, {
      Topic: "joint_states",
      Direction: "subscribe",
      MessageType: "sensor_msgs/JointState",
      JointNames: ["a", "b", "c"],
    });
    expect(h.ports[0]!.shape).toEqual(vectorShape(3));
  });

  test("MOSAIC's positional form [host, publish|subscribe, topic, type, channels]", () => {
    const catalog = createCatalog([Ros]);
    const r = loadPipeline(
      `P: { Type: ROS, Inputs: [ S ], Params: [ "localhost", "publish", "example_topic1", "std_msgs/Float64MultiArray", 10 ] }
S: { Type: ROS, Inputs: [], Params: [ "10.0.0.2", "Subscribe", "example_topic3", "std_msgs/Float64MultiArray", 4 ] }
`,
      "p.yaml",
      catalog,
    );
    expect(r.diagnostics.filter((d) => d.severity === "error")).toEqual([]);
    expect(r.spec!.blocks.map((b) => b.params)).toEqual([
      expect.objectContaining({
        Url: "ws://localhost:9090",
        Direction: "publish",
        Topic: "/example_topic1",
        MessageType: "std_msgs/Float64MultiArray",
      }),
      expect.objectContaining({
        Url: "ws://10.0.0.2:9090",
        Direction: "subscribe",
        Topic: "/example_topic3",
        Channels: 4,
      }),
    ]);
    expect(r.spec!.blocks[0]!.params).not.toHaveProperty("Channels");
    const bad = loadPipeline(
      `S: { Type: ROS, Inputs: [], Params: [ localhost, listen, t, std_msgs/Float64MultiArray, 4 ] }
T: { Type: ROS, Inputs: [], Params: [ localhost, subscribe, t, std_msgs/Float64MultiArray ] }
`,
      "p.yaml",
      catalog,
    );
    expect(bad.diagnostics.filter((d) => d.severity === "error").map((d) => d.message)).toEqual([
      expect.stringMatching(/'listen' is neither publish nor subscribe/),
      expect.stringMatching(/a subscriber needs the number of channels/),
    ]);
  });
});
