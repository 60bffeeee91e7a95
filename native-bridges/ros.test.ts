/**
 * The Node ROS bridge (roslib on a `ws` transport) against the rosbridge v2 test server
 * (tests/support/rosbridge-server.ts): advertise/publish/subscribe/unsubscribe/unadvertise on the
 * wire, connection states, refused and lost connections, and that nothing is queued while the
 * connection is down.
 */
import { afterEach, describe, expect, test } from "vitest";
import type { RosConnection, RosConnectionState } from "../app/engine/io";
import { RosbridgeTestServer } from "../tests/support/rosbridge-server";
import { describeRosError, nodeRosBridge } from "./ros";

const cleanup: (() => unknown)[] = [];
afterEach(async () => {
  for (const c of cleanup.splice(0).reverse()) await c();
});

const until = async (cond: () => boolean, what: string, ms = 5000): Promise<void> => {
  const end = Date.now() + ms;
  while (!cond()) {
    if (Date.now() > end) throw new Error(`timed out waiting for ${what}`);
    await new Promise((r) => setTimeout(r, 5));
  }
};

async function server(port = 0): Promise<RosbridgeTestServer> {
  const s = await RosbridgeTestServer.start(port);
  cleanup.push(() => s.stop());
  return s;
}

function connect(url: string) {
  const states: [RosConnectionState, string | undefined][] = [];
  const notices: string[] = [];
  const conn: RosConnection = nodeRosBridge().connect({
    url,
    onState: (s, m) => states.push([s, m]),
    onNotice: (m) => notices.push(m),
  });
  cleanup.push(() => conn.close());
  const last = (): RosConnectionState | undefined => states.at(-1)?.[0];
  return { conn, states, notices, last };
}

describe("nodeRosBridge", () => {
  test("advertise + publish reach the server; server messages reach the subscriber", async () => {
    const s = await server();
    const c = connect(s.url);
    expect(c.states[0]![0]).toBe("connecting");
    const got: unknown[] = [];
    const sub = c.conn.subscribe({
      topic: "/in",
      type: "geometry_msgs/Vector3",
      throttleMs: 20,
      queueLength: 3,
      onMessage: (m) => got.push(m),
    });
    const pub = c.conn.advertise({ topic: "/out", type: "std_msgs/Float64", latch: true });
    await until(() => c.last() === "connected", "the connection");
    await until(() => s.subscribers("/in") === 1 && s.publishers("/out") === 1, "registration");
    expect(s.typeOf("/out")).toBe("std_msgs/Float64");
    expect(s.subscriptionOptions("/in")).toEqual([{ throttleRate: 20, queueLength: 3 }]);
    const adv = s.ops.find((o) => o.op === "advertise")!;
    expect(adv).toMatchObject({ topic: "/out", type: "std_msgs/Float64", latch: true });

    expect(pub.publish({ data: 0.1 })).toBe(true);
    expect(pub.publish({ data: -1e-300 })).toBe(true);
    await until(() => s.published("/out").length === 2, "two publishes");
    expect(s.published("/out")).toEqual([{ data: 0.1 }, { data: -1e-300 }]);

    s.publish("/in", { x: 1, y: 2, z: 1 / 3 });
    await until(() => got.length === 1, "a message");
    expect(got).toEqual([{ x: 1, y: 2, z: 1 / 3 }]);

    sub.unsubscribe();
    pub.unadvertise();
    await until(() => s.subscribers("/in") === 0 && s.publishers("/out") === 0, "unregistering");
    s.publish("/in", { x: 9, y: 9, z: 9 });
    await new Promise((r) => setTimeout(r, 50));
    expect(got).toHaveLength(1);
    expect(c.notices).toEqual([]);

    c.conn.close();
    await until(() => s.clients === 0, "the close");
    expect(c.states.map((x) => x[0])).toEqual(["connecting", "connected"]);
  });

  test("server status errors come back as notices", async () => {
    const s = await server();
    s.publish("/typed", {}, "std_msgs/String");
    const c = connect(s.url);
    c.conn.advertise({ topic: "/typed", type: "std_msgs/Float64" });
    await until(() => c.notices.length > 0, "a notice");
    expect(c.notices[0]).toMatch(/^error: advertise: topic \/typed already established/);
    // A status about one published message (its own id) comes back as well.
    const pub = c.conn.advertise({ topic: "/list", type: "std_msgs/Float64" });
    await until(() => c.last() === "connected" && s.publishers("/list") === 1, "advertise");
    expect(pub.publish([1, 2] as unknown as object)).toBe(true);
    await until(() => c.notices.length > 1, "a second notice");
    expect(c.notices[1]).toBe("error: publish: msg is not a message object");
  });

  test("refused: one disconnected with the reason; publish returns false meanwhile", async () => {
    const s = await server();
    const port = s.port;
    await s.stop();
    const c = connect(`ws://127.0.0.1:${port}`);
    const pub = c.conn.advertise({ topic: "/x", type: "std_msgs/Float64" });
    expect(pub.publish({ data: 1 })).toBe(false);
    await until(() => c.last() === "disconnected", "the refusal");
    expect(c.states.map((x) => x[0])).toEqual(["connecting", "disconnected"]);
    expect(c.states[1]![1]).toMatch(/nothing is listening at 127\.0\.0\.1:\d+ \(ECONNREFUSED\)/);
    expect(pub.publish({ data: 1 })).toBe(false);
  });

  test("a lost connection is reported once; nothing published meanwhile is queued", async () => {
    const s = await server();
    const c = connect(s.url);
    const pub = c.conn.advertise({ topic: "/y", type: "std_msgs/Float64" });
    await until(() => c.last() === "connected" && s.publishers("/y") === 1, "the connection");
    await s.stop();
    await until(() => c.last() === "disconnected", "the loss");
    expect(c.states.at(-1)![1]).toMatch(/^connection lost: the connection was closed, code 1006/);
    expect(pub.publish({ data: 5 })).toBe(false);
    await s.start();
    await new Promise((r) => setTimeout(r, 100));
    // One attempt per connect: nothing reconnects by itself, nothing queued is sent later.
    expect(s.clients).toBe(0);
    expect(s.published("/y")).toEqual([]);
    expect(c.states.filter((x) => x[0] === "disconnected")).toHaveLength(1);
  });

  test("a bad URL or a non-rosbridge server is a disconnected state, not a throw", async () => {
    const c = connect("ws://exa mple");
    await until(() => c.last() === "disconnected", "the refusal");
    expect(c.states.at(-1)![1]).toMatch(/invalid|URL/i);
  });

  test("close before the socket opens: no callbacks after it", async () => {
    const s = await server();
    const c = connect(s.url);
    c.conn.close();
    await new Promise((r) => setTimeout(r, 150));
    expect(c.states.map((x) => x[0])).toEqual(["connecting"]);
    expect(s.clients).toBe(0);
  });

  test("error texts name the cause", () => {
    const e = Object.assign(new Error("getaddrinfo ENOTFOUND robot"), { code: "ENOTFOUND" });
    expect(describeRosError(e, "ws://robot:9090")).toBe(
      "cannot resolve the host of ws://robot:9090 (ENOTFOUND): check Url",
    );
  });
});
