import { describe, expect, test } from "vitest";
import {
  createCatalog,
  Frame,
  loadPipeline,
  vectorShape,
  type Endpoint,
  type IoBridges,
  type UdpOpenOptions,
} from "../../engine";
import { BlockHarness } from "../../engine/testing";
import { BLOCKS } from "../catalog";
import { decodeStreamlined, newHeader, StreamlinedEncoder } from "./udp-format";
import { UdpReceiver } from "./udp-receiver";
import { serializerFor, UdpSender } from "./udp-sender";

/** A UDP bridge without sockets: keeps what is sent and lets the test deliver datagrams. */
function fakeUdp() {
  const sent: Uint8Array[] = [];
  const opened: UdpOpenOptions[] = [];
  let closed = 0;
  const io: IoBridges = {
    udp: {
      open(o) {
        opened.push(o);
        return {
          send: (d) => sent.push(d.slice()),
          close: () => void closed++,
        };
      },
    },
  };
  return {
    io,
    sent,
    opened,
    get closed() {
      return closed;
    },
    deliver(d: Uint8Array, from: Endpoint = { host: "127.0.0.1", port: 40000 }) {
      opened.at(-1)!.onMessage!(d, from);
    },
  };
}

const decode = (d: Uint8Array) => {
  const h = newHeader();
  const v = new Float64Array(255);
  const err = decodeStreamlined(d, h, v, 0, 255);
  if (err) throw new Error(err);
  return { ...h, values: Array.from(v.subarray(0, h.count)) };
};

describe("UdpSender", () => {
  test("serializer by the input block's type, as MOSAIC chose", () => {
    expect(serializerFor("ControlAlgorithm")).toBe("control");
    expect(serializerFor("Myo")).toBe("myo");
    expect(serializerFor("Filter")).toBe("vector");
    expect(serializerFor(undefined)).toBe("vector");
  });

  test("vector: one streamlined f64 datagram per event, event timestamps, counter +1", async () => {
    const udp = fakeUdp();
    const h = await BlockHarness.create(
      UdpSender,
      { Port: 5005, Category: 0, Subcategory: 1 },
      { inputs: [{ shape: vectorShape(3), rate: 100 }], io: udp.io },
    );
    h.start();
    expect(udp.opened[0]!.remote).toEqual({ host: "127.0.0.1", port: 5005 });
    h.push(
      Frame.from(
        vectorShape(3),
        [10, 10.01],
        [
          [1, 2, 3],
          [-4, 0.5, NaN],
        ],
      ),
    );
    expect(udp.sent.map(decode)).toEqual([
      {
        count: 3,
        type: "f64",
        category: 0,
        subcategory: 1,
        timestamp: 10,
        counter: 0,
        values: [1, 2, 3],
      },
      {
        count: 3,
        type: "f64",
        category: 0,
        subcategory: 1,
        timestamp: 10.01,
        counter: 1,
        values: [-4, 0.5, NaN],
      },
    ]);
    expect(h.text).toMatch(
      /→ 127\.0\.0\.1:5005 \(vector serializer, f64, category 0\): 2 datagrams sent/,
    );
    h.instance.stop?.();
    expect(udp.closed).toBe(1);
  });

  test("a ControlAlgorithm's MOSAIC mapping goes out with its DOAs codes as subcategories", async () => {
    const udp = fakeUdp();
    const h = await BlockHarness.create(
      UdpSender,
      { Port: 5005 },
      { inputs: [{ shape: vectorShape(11), type: "ControlAlgorithm" }], io: udp.io },
    );
    h.start();
    h.push(Frame.from(vectorShape(11), [1], [[0, 1, 2, 3, 4, 5, 50, 50, 50, 9, 10]]));
    const sent = udp.sent.map(decode);
    // 0 ThumbFlexion … 8 WristPronationSupination; the enum's 9 (OpenHand) was never sent.
    expect(sent.map((d) => d.subcategory)).toEqual([0, 1, 2, 3, 4, 5, 6, 7, 8, 10, 11]);
    expect(sent.map((d) => d.values[0])).toEqual([0, 1, 2, 3, 4, 5, 50, 50, 50, 9, 10]);
  });

  test("control: one datagram per value (count 1, f64, category 1, subcategory per DoF)", async () => {
    const udp = fakeUdp();
    const h = await BlockHarness.create(
      UdpSender,
      { Port: 5005, Serializer: "control", Subcategories: [6, 8] },
      { inputs: [{ shape: vectorShape(2) }], io: udp.io },
    );
    h.start();
    h.push(Frame.from(vectorShape(2), [1], [[50, 75.5]]));
    expect(udp.sent.map(decode)).toEqual([
      {
        count: 1,
        type: "f64",
        category: 1,
        subcategory: 6,
        timestamp: 1,
        counter: 0,
        values: [50],
      },
      {
        count: 1,
        type: "f64",
        category: 1,
        subcategory: 8,
        timestamp: 1,
        counter: 1,
        values: [75.5],
      },
    ]);
  });

  test("auto: after a ControlAlgorithm (the engine reports the input's type) it sends per DoF", async () => {
    const udp = fakeUdp();
    const h = await BlockHarness.create(
      UdpSender,
      { Port: 5005 },
      { inputs: [{ shape: vectorShape(2), type: "ControlAlgorithm" }], io: udp.io },
    );
    h.start();
    expect(h.text).toMatch(/\(control serializer/);
    h.push(Frame.from(vectorShape(2), [1], [[0.25, -0.5]]));
    expect(udp.sent.map(decode).map((d) => [d.count, d.category, d.values[0]])).toEqual([
      [1, 1, 0.25],
      [1, 1, -0.5],
    ]);
  });

  test("several inputs (MOSAIC's sender subscribed to all): each with its own serializer, one counter", async () => {
    const udp = fakeUdp();
    const h = await BlockHarness.create(
      UdpSender,
      { Port: 11000 },
      {
        inputs: [
          { shape: vectorShape(2), type: "ControlAlgorithm" },
          { shape: vectorShape(3), type: "Joiner" },
          { shape: vectorShape(1), type: "Resampler" },
        ],
        io: udp.io,
      },
    );
    h.start();
    h.push(Frame.from(vectorShape(2), [1], [[50, 75]]), 0);
    h.push(Frame.from(vectorShape(3), [1.005], [[0.1, 0.2, 0.3]]), 1);
    h.push(Frame.from(vectorShape(1), [1.04], [[0.7]]), 2);
    expect(udp.sent.map(decode)).toEqual([
      {
        count: 1,
        type: "f64",
        category: 1,
        subcategory: 0,
        timestamp: 1,
        counter: 0,
        values: [50],
      },
      {
        count: 1,
        type: "f64",
        category: 1,
        subcategory: 1,
        timestamp: 1,
        counter: 1,
        values: [75],
      },
      {
        count: 3,
        type: "f64",
        category: 0,
        subcategory: 1,
        timestamp: 1.005,
        counter: 2,
        values: [0.1, 0.2, 0.3],
      },
      {
        count: 1,
        type: "f64",
        category: 0,
        subcategory: 2,
        timestamp: 1.04,
        counter: 3,
        values: [0.7],
      },
    ]);
    h.instance.stop?.();
    expect(h.text).toMatch(/in0: control serializer.*in1: vector serializer.*4 datagrams sent/);
  });

  test("the original's cfg13 form loads: UDP_StreamlinedSender with three inputs", () => {
    const src = `
t: { Type: ScheduledTimer, DesiredRate: 100 }
a: { Type: SinGenerator, Inputs: [t], Params: [2] }
b: { Type: SinGenerator, Inputs: [t], Params: [3] }
UDP_sender: { Type: UDP_StreamlinedSender, Inputs: [ a, b, t ], Params: [ localhost, 11000 ] }
`;
    const r = loadPipeline(src, "cfg13.yaml", createCatalog(BLOCKS));
    expect(r.diagnostics.filter((d) => d.severity === "error")).toEqual([]);
    expect(r.spec!.byName.get("UDP_sender")!.inputs.map((i) => i.block)).toEqual(["a", "b", "t"]);
  });

  test("myo: signed bytes, value · 128, category 1, subcategory 1", async () => {
    const udp = fakeUdp();
    const h = await BlockHarness.create(
      UdpSender,
      { Port: 5005, Serializer: "myo" },
      { inputs: [{ shape: vectorShape(3) }], io: udp.io },
    );
    h.start();
    h.push(Frame.from(vectorShape(3), [1], [[0.5, -1, 1]]));
    const d = udp.sent[0]!;
    expect(d[1]).toBe(0x11);
    expect(decode(d)).toMatchObject({ category: 1, subcategory: 1, values: [64, -128, 127] });
  });

  test("raw f32: bare little-endian vectors (a matrix row-major)", async () => {
    const udp = fakeUdp();
    const h = await BlockHarness.create(
      UdpSender,
      { Port: 5005, Format: "f32" },
      { inputs: [{ shape: { rows: 2, cols: 2 } }], io: udp.io },
    );
    h.start();
    h.push(Frame.from({ rows: 2, cols: 2 }, [1], [[1, 2, 3, 0.1]]));
    expect(Array.from(new Float32Array(udp.sent[0]!.buffer))).toEqual([1, 2, 3, Math.fround(0.1)]);
  });

  test("send errors are counted and shown, never thrown", async () => {
    const udp = fakeUdp();
    const h = await BlockHarness.create(
      UdpSender,
      { Port: 5005 },
      { inputs: [{ shape: vectorShape(1) }], io: udp.io },
    );
    h.start();
    h.push(Frame.from(vectorShape(1), [1, 2, 3], [[1], [2], [3]]));
    // The bridge calls onError once per datagram it did not send.
    udp.opened[0]!.onError("nothing is listening at 127.0.0.1:5005 (ECONNREFUSED)");
    udp.opened[0]!.onError("nothing is listening at 127.0.0.1:5005 (ECONNREFUSED)");
    await Promise.resolve(); // the text is rebuilt once after a burst of errors
    expect(h.text).toMatch(/: 1 datagram sent, 2 not sent \(nothing is listening/);
    expect(h.warnings[0]).toMatch(
      /UDP to 127\.0\.0\.1:5005: nothing is listening.*\(1 datagram not sent so far\)$/,
    );
  });

  test("without a UDP bridge (browser build) the status says so and counts what was not sent", async () => {
    const h = await BlockHarness.create(
      UdpSender,
      { Port: 5005 },
      { inputs: [{ shape: vectorShape(1) }] },
    );
    h.start();
    expect(h.warnings[0]).toMatch(/UDP is unavailable here/);
    h.push(Frame.from(vectorShape(1), [1, 2], [[1], [2]]));
    expect(h.text).toMatch(/UDP is unavailable here .*: 2 events not sent/);
  });

  test("config errors name the param", async () => {
    const mk = (params: object, size: number) =>
      BlockHarness.create(UdpSender, params, {
        inputs: [{ shape: vectorShape(size) }],
        io: fakeUdp().io,
      });
    await expect(mk({ Port: 1, Serializer: "control", Subcategories: [1] }, 2)).rejects.toThrow(
      /Subcategories lists 1 values but the input has 2/,
    );
    await expect(mk({ Port: 1 }, 256)).rejects.toThrow(/at most 255/);
    await expect(mk({ Port: 1, Format: "f64", Category: 2 }, 2)).rejects.toThrow(
      /Category applies to the streamlined format/,
    );
    await expect(mk({ Port: 1, Serializer: "control", Subcategory: 250 }, 8)).rejects.toThrow(
      /past 255/,
    );
  });

  test("MOSAIC's positional form [hostIP, port] and class name load", () => {
    const r = loadPipeline(
      "T: { Type: ScheduledTimer, DesiredRate: 25 }\n" +
        "S: { Type: SinGenerator, Inputs: [T] }\n" +
        "U: { Type: UDP_StreamlinedSender, Inputs: [S], Params: [192.168.0.10, '5005'] }\n",
      "legacy.yaml",
      createCatalog(BLOCKS),
    );
    expect(r.spec, JSON.stringify(r.diagnostics)).toBeDefined();
    const u = r.spec!.blocks.find((b) => b.name === "U")!;
    expect(u.type).toBe("UdpSender");
    expect(u.params).toMatchObject({ Host: "192.168.0.10", Port: 5005, Format: "streamlined" });
    const bad = loadPipeline(
      "T: { Type: ScheduledTimer, DesiredRate: 25 }\n" +
        "S: { Type: SinGenerator, Inputs: [T] }\n" +
        "U: { Type: UDP_StreamlinedSender, Inputs: [S], Params: [localhost] }\n",
      "legacy.yaml",
      createCatalog(BLOCKS),
    );
    expect(bad.spec).toBeUndefined();
    expect(bad.diagnostics.map((d) => d.message).join("\n")).toMatch(/\[hostIP, port\]/);
  });
});

describe("UdpReceiver", () => {
  const datagram = (values: number[], counter: number, opts: { t?: number; cat?: number } = {}) => {
    const enc = new StreamlinedEncoder(values.length, "f32");
    enc.counter = counter;
    return enc.encode(opts.t ?? 99, opts.cat ?? 0, 0, values, 0).slice();
  };

  test("binds Host:Port and emits one event per streamlined datagram, at arrival time", async () => {
    const udp = fakeUdp();
    const h = await BlockHarness.create(
      UdpReceiver,
      { Port: 6000, Channels: 2 },
      { io: udp.io, virtual: false },
    );
    h.start();
    expect(udp.opened[0]!.bind).toEqual({ host: "127.0.0.1", port: 6000 });
    udp.opened[0]!.onReady!({ host: "127.0.0.1", port: 6000 });
    h.clock = 5;
    udp.deliver(datagram([1, 2], 0));
    h.clock = 5.5;
    udp.deliver(datagram([3, 0.25], 1));
    expect(h.output()).toMatchObject({
      t: [5, 5.5],
      v: [
        [1, 2],
        [3, 0.25],
      ],
      frames: [1, 1],
    });
    expect(h.text).toMatch(/listening on 127\.0\.0\.1:6000, 2 datagrams/);
    h.instance.stop?.();
    expect(udp.closed).toBe(1);
    expect(h.text).toMatch(/^closed 127\.0\.0\.1:6000, 2 datagrams/);
  });

  test("sender timestamps; lost datagrams counted from the counter (wrapping)", async () => {
    const udp = fakeUdp();
    const h = await BlockHarness.create(
      UdpReceiver,
      { Port: 6000, Channels: 1, Timestamps: "sender" },
      { io: udp.io },
    );
    h.start();
    udp.deliver(datagram([1], 65534, { t: 1 }));
    udp.deliver(datagram([2], 1, { t: 2 })); // 65535 and 0 lost
    udp.deliver(datagram([3], 0, { t: 3 })); // late
    expect(h.output().t).toEqual([1, 2, 3]);
    expect(h.instance.actions!.counts!.run()).toMatch(
      /3 datagrams, 3 events, 2 lost, 1 out of order/,
    );
  });

  test("malformed datagrams and other channel counts are counted and reported, not thrown", async () => {
    const udp = fakeUdp();
    const h = await BlockHarness.create(UdpReceiver, { Port: 6000, Channels: 2 }, { io: udp.io });
    h.start();
    udp.deliver(new Uint8Array([1, 2, 3]), { host: "10.0.0.7", port: 1234 });
    udp.deliver(datagram([1, 2, 3], 0));
    const bad = datagram([1, 2], 1);
    bad[1] = 0x33;
    udp.deliver(bad);
    udp.deliver(datagram([1, 2], 2));
    expect(h.output().v).toEqual([[1, 2]]);
    expect(h.warnings[0]).toMatch(
      /malformed datagram from 10\.0\.0\.7:1234 on 127\.0\.0\.1:6000: 3 bytes is shorter than the 14-byte header/,
    );
    expect(h.text).toMatch(/3 malformed \(last: unknown type byte 0x33/);
    expect(h.instance.actions!.counts!.run()).toMatch(/4 datagrams, 1 events, .*3 malformed/);
  });

  test("Category / Subcategory filter: other datagrams are ignored", async () => {
    const udp = fakeUdp();
    const h = await BlockHarness.create(
      UdpReceiver,
      { Port: 6000, Channels: 1, Category: 1 },
      { io: udp.io },
    );
    h.start();
    udp.deliver(datagram([1, 2, 3], 0, { cat: 0 })); // another stream, another count: ignored
    udp.deliver(datagram([7], 1, { cat: 1 }));
    expect(h.output().v).toEqual([[7]]);
    expect(h.text).toMatch(/1 ignored \(other category\)/);
  });

  test("raw f64: several vectors in one datagram, spaced by 1/DesiredRate", async () => {
    const udp = fakeUdp();
    const h = await BlockHarness.create(
      UdpReceiver,
      { Port: 6000, Channels: 2, Format: "f64" },
      { io: udp.io, desiredRate: 100 },
    );
    h.start();
    h.clock = 10;
    udp.deliver(new Uint8Array(new Float64Array([1, 2, 3, 4, 5, 6]).buffer));
    const o = h.output();
    expect(o.frames).toEqual([3]);
    expect(o.v).toEqual([
      [1, 2],
      [3, 4],
      [5, 6],
    ]);
    expect(o.t.map((t) => Math.round(t * 1000) / 1000)).toEqual([9.98, 9.99, 10]);
    udp.deliver(new Uint8Array(20));
    expect(h.text).toMatch(
      /1 malformed \(last: 20 bytes is not a whole number of 2-value f64 vectors/,
    );
  });

  test("a port in use: the status names the port, the block stays silent, nothing throws", async () => {
    const udp = fakeUdp();
    const h = await BlockHarness.create(UdpReceiver, { Port: 6000, Channels: 2 }, { io: udp.io });
    h.start();
    udp.opened[0]!.onError(
      "port 6000 is already in use on 127.0.0.1 (EADDRINUSE): another program ...",
    );
    expect(udp.closed).toBe(1);
    expect(h.text).toMatch(/^cannot listen on UDP 127\.0\.0\.1:6000: port 6000 is already in use/);
    expect(h.warnings[0]).toBe(h.text);
  });

  test("without a UDP bridge (browser build) the status says so", async () => {
    const h = await BlockHarness.create(UdpReceiver, { Port: 6000, Channels: 2 });
    expect(h.text).toMatch(/UDP is unavailable here \(the browser build has no network sockets\)/);
    h.start();
    expect(h.warnings[0]).toMatch(/receives nothing/);
  });

  test("config errors", async () => {
    await expect(BlockHarness.create(UdpReceiver, { Port: 1, Channels: 300 })).rejects.toThrow(
      /at most 255/,
    );
    await expect(
      BlockHarness.create(UdpReceiver, {
        Port: 1,
        Channels: 3,
        Format: "f32",
        Timestamps: "sender",
      }),
    ).rejects.toThrow(/carry no timestamp/);
  });
});
