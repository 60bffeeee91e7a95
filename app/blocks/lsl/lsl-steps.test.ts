/**
 * LslOutlet and LslMarkers against a fake bridge that records what they push: the config
 * errors, each format's conversion, NaN handling, the status text, the counters and reset.
 */
import { describe, expect, test } from "vitest";
import {
  Frame,
  vectorShape,
  type AnyBlockDefinition,
  type LslBridge,
  type LslStreamInfo,
} from "../../engine";
import { BlockHarness } from "../../engine/testing";
import { LslMarkers } from "./lsl-markers";
import { LslOutlet } from "./lsl-outlet";

interface Pushed {
  values: number[] | string[];
  n: number;
  times: number[];
}

/** A bridge whose LSL clock is the pipeline's minus 1000 s; records outlets and their chunks. */
function fakeBridge(fail = false) {
  const infos: LslStreamInfo[] = [];
  const chunks: Pushed[] = [];
  let listening = false;
  const bridge: LslBridge = {
    version: "fake",
    localClock: () => 5,
    createOutlet(info) {
      if (fail) throw new Error("no network");
      infos.push(info);
      return {
        push(values, n, timestamps) {
          chunks.push({
            values: Array.from(values.subarray(0, (n * info.channels) as number)),
            n,
            times: Array.from(timestamps.subarray(0, n)),
          });
        },
        pushStrings(values, timestamps) {
          chunks.push({ values: [...values], n: timestamps.length, times: Array.from(timestamps) });
        },
        haveConsumers: () => listening,
        close() {},
      };
    },
    resolve() {
      throw new Error("not in this test");
    },
  };
  return { bridge, infos, chunks, listen: () => (listening = true) };
}

async function harness(
  def: AnyBlockDefinition,
  params: Record<string, unknown>,
  channels: number,
  lsl?: LslBridge,
) {
  return BlockHarness.create(def, params, {
    ...(lsl ? { io: { lsl } } : {}),
    now: 1005,
    virtual: true,
    inputs: [{ shape: vectorShape(channels), rate: 100 }],
  });
}

const frame = (t: number[], rows: number[][]) => Frame.from(vectorShape(rows[0]!.length), t, rows);

describe("LslOutlet", () => {
  test("refuses an unknown shape, no values and a wrong label count", async () => {
    await expect(BlockHarness.create(LslOutlet, {}, { inputs: [{ shape: null }] })).rejects.toThrow(
      /the input's shape is unknown \(a feedback cycle\?\)/,
    );
    await expect(harness(LslOutlet, {}, 0)).rejects.toThrow(
      /carries no values .*: use LslMarkers for events/,
    );
    await expect(harness(LslOutlet, { ChannelLabels: ["a"] }, 2)).rejects.toThrow(
      /^1 ChannelLabels for 2 channels \(input /,
    );
  });

  test("float32: the stream's metadata, chunks with mapped times, the status and reset", async () => {
    const { bridge, infos, chunks, listen } = fakeBridge();
    const h = await harness(LslOutlet, { Name: "E", NominalRate: 50 }, 2, bridge);
    h.start();
    expect(infos).toEqual([
      {
        name: "E",
        type: "EMG",
        channels: 2,
        rate: 50,
        format: "float32",
        sourceId: expect.stringMatching(/^mosaic:.*:E$/) as unknown as string,
        labels: ["Ch1", "Ch2"],
      },
    ]);
    expect(h.text).toBe(
      "streaming 'E' (2 ch float32 @ 50 Hz), 0 samples in 0 chunks, no inlet connected",
    );
    listen();
    h.push(
      frame(
        [1005, 1006],
        [
          [1.5, 2],
          [3, 4],
        ],
      ),
    );
    h.push(Frame.from(vectorShape(2), [], []));
    expect(chunks).toHaveLength(1);
    expect(chunks[0]!.values).toEqual([1.5, 2, 3, 4]);
    expect(chunks[0]!.n).toBe(2);
    expect(chunks[0]!.times[0]).toBeCloseTo(5, 6);
    expect(chunks[0]!.times[1]).toBeCloseTo(6, 6);
    h.instance.stop?.();
    expect(h.text).toBe(
      "streaming 'E' (2 ch float32 @ 50 Hz), 2 samples in 1 chunks, an inlet listens",
    );
    h.instance.reset?.();
    h.start();
    expect(h.text).toMatch(/0 samples in 0 chunks/);
  });

  test("int16 rounds and clamps (counted); string sends each value as text", async () => {
    const a = fakeBridge();
    const h = await harness(LslOutlet, { Name: "I", Format: "int16" }, 2, a.bridge);
    h.start();
    h.push(frame([1005], [[2.5, 40000]]));
    h.push(frame([1006], [[NaN, -1.5]]));
    expect(a.chunks.map((c) => c.values)).toEqual([
      [3, 32767],
      [0, -2],
    ]);
    h.instance.stop?.();
    expect(h.text).toMatch(/, 2 values clamped to int16$/);

    const b = fakeBridge();
    const s = await harness(LslOutlet, { Name: "S", Format: "string" }, 2, b.bridge);
    s.start();
    s.push(
      frame(
        [1005, 1006],
        [
          [1, 2.5],
          [NaN, 4],
        ],
      ),
    );
    s.push(frame([1007], [[7, 8]]));
    expect(b.chunks.map((c) => c.values)).toEqual([
      ["1", "2.5", "NaN", "4"],
      ["7", "8"],
    ]);
    expect(b.chunks[1]!.times[0]).toBeCloseTo(7, 6);
  });

  test("a failed outlet says why; frames without an outlet are counted, not sent", async () => {
    const { bridge } = fakeBridge(true);
    const h = await harness(LslOutlet, { Name: "F" }, 1, bridge);
    h.start();
    expect(h.errors).toEqual(["cannot open the LSL outlet 'F': no network"]);
    h.push(frame([1005, 1006], [[1], [2]]));
    h.instance.stop?.();
    expect(h.text).toBe("cannot open the LSL outlet 'F': no network");
    const u = await harness(LslOutlet, { Name: "N" }, 1, fakeBridge().bridge);
    u.push(frame([1005, 1006], [[1], [2]]));
    u.instance.stop?.();
    expect(u.text).toMatch(
      /0 samples in 0 chunks, no inlet connected, 2 samples not sent \(no outlet\)$/,
    );
  });
});

describe("LslMarkers", () => {
  test("refuses a Channel outside the input", async () => {
    await expect(harness(LslMarkers, { Channel: 2 }, 2)).rejects.toThrow(
      /^Channel 2 is not a value of input .* \(/,
    );
  });

  test("string markers: labels, numbers, NaN, SkipNaN, the status and reset", async () => {
    const { bridge, infos, chunks } = fakeBridge();
    const h = await harness(
      LslMarkers,
      { Name: "M", Channel: 1, Labels: ["go", "stop"] },
      2,
      bridge,
    );
    h.start();
    expect(infos).toEqual([
      {
        name: "M",
        type: "Markers",
        channels: 1,
        rate: 0,
        format: "string",
        sourceId: expect.stringMatching(/^mosaic:.*:M$/) as unknown as string,
      },
    ]);
    expect(h.text).toBe("markers 'M' (string): 0 sent");
    h.push(
      frame(
        [1005, 1006, 1007],
        [
          [9, 0],
          [9, 1.5],
          [9, NaN],
        ],
      ),
    );
    expect(chunks).toEqual([{ values: ["go", "1.5", "stop"], n: 3, times: chunks[0]!.times }]);
    expect(chunks[0]!.times[2]).toBeCloseTo(7, 6);
    h.instance.stop?.();
    expect(h.text).toBe("markers 'M' (string): 3 sent, last 'stop'");
    h.instance.reset?.();
    h.start();
    expect(h.text).toBe("markers 'M' (string): 0 sent");

    const b = fakeBridge();
    const s = await harness(LslMarkers, { Name: "K", SkipNaN: true }, 1, b.bridge);
    s.start();
    s.push(frame([1005, 1006], [[NaN], [NaN]]));
    s.push(frame([1007, 1008], [[NaN], [3]]));
    expect(b.chunks.map((c) => [c.values, c.n])).toEqual([[["3"], 1]]);
    expect(b.chunks[0]!.times[0]).toBeCloseTo(8, 6);
  });

  test("int32 codes: rounded, NaN as NanCode, clamped counted; no outlet: not sent", async () => {
    const { bridge, chunks } = fakeBridge();
    const h = await harness(LslMarkers, { Name: "C", Format: "int32", NanCode: -7 }, 1, bridge);
    h.start();
    h.push(frame([1005, 1006, 1007], [[2.4], [NaN], [1e10]]));
    expect(chunks.map((c) => [c.values, c.n])).toEqual([[[2, -7, 2147483647], 3]]);
    h.instance.stop?.();
    expect(h.text).toBe("markers 'C' (int32): 3 sent, last '2147483647', 1 clamped to int32");

    const f = fakeBridge(true);
    const u = await harness(LslMarkers, { Name: "U" }, 1, f.bridge);
    u.start();
    u.push(frame([1005, 1006], [[1], [2]]));
    u.instance.stop?.();
    expect(u.text).toBe("cannot open the LSL outlet 'U': no network");
    const n = await harness(LslMarkers, { Name: "N" }, 1, fakeBridge().bridge);
    n.push(frame([1005, 1006], [[1], [2]]));
    n.instance.stop?.();
    expect(n.text).toBe("markers 'N' (string): 0 sent, 2 not sent (no outlet)");
  });
});
