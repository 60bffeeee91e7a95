import { describe, expect, test } from "vitest";
import { vectorShape } from "../../engine";
import { BlockHarness, runVirtualPipeline } from "../../engine/testing";
import { convertLegacy, vectors } from "../../../tests/support/blocks";
import { memoryResources } from "../../../tests/support/fs-resources";
import { catalog } from "../catalog";
import { BufferBlock } from "./buffer";

const STOP = [NaN, NaN];

async function buffer(params: object = {}, t = 2, d = 3, files?: Record<string, string>) {
  const h = await BlockHarness.create(BufferBlock, params, {
    inputs: [{ shape: vectorShape(t) }, { shape: vectorShape(d), rate: 25 }],
    ...(files ? { resources: memoryResources(files) } : {}),
  });
  h.start();
  return h;
}

const data = (t0: number, n: number, d = 3) =>
  vectors(
    Array.from({ length: n }, (_, i) => t0 + i * 0.04),
    Array.from({ length: n }, (_, i) => Array.from({ length: d }, (_, k) => t0 * 10 + i + k / 10)),
  );

const run = (h: BlockHarness, action: string, arg?: unknown) =>
  h.instance.actions![action]!.run(arg);

describe("Buffer", () => {
  test("a target starts a cluster, another target switches, all-NaN stops; data outside is ignored", async () => {
    const h = await buffer();
    expect(h.text).toBe("empty");
    h.push(data(0, 2), 1); // not recording yet
    h.push(vectors([1], [[1, 0]]), 0);
    expect(h.text).toBe("recording [1, 0] (0 rows)");
    h.push(data(1, 3), 1);
    h.push(
      vectors(
        [2, 2.1],
        [
          [1, 0],
          [0, 1],
        ],
      ),
      0,
    ); // the same target continues, then a new one
    h.push(data(2, 2), 1);
    h.push(vectors([3], [STOP]), 0);
    h.push(data(3, 4), 1); // stopped: ignored
    expect(h.text).toBe("2 clusters, 5 rows");
    expect(run(h, "inspect")).toBe(
      "2 clusters, 5 rows — [1, 0]: 1 cluster, 3 rows; [0, 1]: 1 cluster, 2 rows",
    );
    expect(h.output("pairs").v).toEqual([]); // Stream is off
    expect(run(h, "emit")).toBe("emitted 5 rows of 2 + 3 values");
    const out = h.output("pairs");
    expect(out.frames).toEqual([5]); // all at once, one frame
    expect(out.t).toEqual([1, 1.04, 1.08, 2, 2.04]);
    expect(out.v[0]).toEqual([1, 0, 10, 10.1, 10.2]);
    expect(out.v[3]).toEqual([0, 1, 20, 20.1, 20.2]);
  });

  test("Stream: true sends rows as they are recorded; a start/stop without data keeps no cluster", async () => {
    const h = await buffer({ Stream: true });
    h.push(vectors([0, 0.5], [[1, 1], STOP]), 0);
    expect(h.text).toBe("empty");
    h.push(vectors([1], [[0, 2]]), 0);
    h.push(data(1, 2), 1);
    expect(h.output("pairs").v).toEqual([
      [0, 2, 10, 10.1, 10.2],
      [0, 2, 11, 11.1, 11.2],
    ]);
    h.instance.setParam!("Stream", false);
    h.push(data(2, 1), 1);
    expect(h.output("pairs").v).toHaveLength(2);
  });

  test("a trigger event with some NaN is ignored with a warning", async () => {
    const h = await buffer();
    h.push(vectors([0], [[1, NaN]]), 0);
    expect(h.warnings[0]).toContain("ignored a trigger event with 1 NaN of 2 values");
    expect(h.text).toBe("empty");
  });

  test("actions start (target or label index), stop, clear", async () => {
    const h = await buffer({}, 3);
    expect(run(h, "start", 1)).toBe("recording [0, 1, 0]");
    h.push(data(0, 2), 1);
    expect(run(h, "start", [0.5, 0, 0])).toBe("recording [0.5, 0, 0]");
    h.push(data(1, 1), 1);
    expect(run(h, "start", "0;0;1")).toBe("recording [0, 0, 1]");
    expect(run(h, "stop")).toBe("stopped: 2 clusters, 3 rows");
    expect(() => run(h, "start", 3)).toThrow("a whole number from 0 to 2");
    expect(() => run(h, "start", [1, 2])).toThrow(
      "expected a target of 3 values: 3 finite numbers",
    );
    expect(run(h, "clear")).toBe("cleared 3 rows");
    expect(h.text).toBe("empty");
    const one = await buffer({}, 1);
    expect(run(one, "start", 2)).toBe("recording [2]");
  });

  test("MaxRows bounds the memory; the status says it is full and how many rows were dropped", async () => {
    const h = await buffer({ MaxRows: 4 });
    h.push(vectors([0], [[1, 0]]), 0);
    h.push(data(0, 3), 1);
    h.push(data(1, 3), 1);
    expect(h.text).toBe("full: 4 rows (MaxRows), 2 dropped; save, emit or clear to record more");
    expect(h.warnings).toHaveLength(1);
    expect(run(h, "inspect")).toContain("2 rows dropped (full)");
    run(h, "clear");
    h.push(data(2, 1), 1);
    expect(h.text).toBe("recording [1, 0] (1 row)");
  });

  test("thousands are grouped in the status: '2 clusters, 3,400 rows'", async () => {
    const h = await buffer({}, 1, 1);
    for (const [label, n] of [
      [0, 1700],
      [1, 1700],
    ] as const) {
      h.push(vectors([label], [[label]]), 0);
      h.push(
        vectors(
          Array.from({ length: n }, (_, i) => label * 100 + i / 1000),
          Array.from({ length: n }, (_, i) => [i]),
        ),
        1,
      );
    }
    h.push(vectors([500], [[NaN]]), 0);
    expect(h.text).toBe("2 clusters, 3,400 rows");
  });

  test("save writes one CSV line target…,data… per row", async () => {
    const files: Record<string, string> = {};
    const h = await buffer({}, 2, 2, files);
    expect(run(h, "save", "x.csv")).toBe("the buffer is empty: nothing saved");
    h.push(vectors([0], [[1, 0]]), 0);
    h.push(
      vectors(
        [0, 0.1],
        [
          [0.5, -2],
          [1e-7, 3],
        ],
      ),
      1,
    );
    h.push(vectors([1], [[0, 1]]), 0);
    h.push(vectors([1.1], [[4, 5]]), 1);
    expect(run(h, "save", "data/set.csv")).toBe("saving 3 rows to data/set.csv");
    await new Promise((r) => setTimeout(r, 0));
    expect(files["data/set.csv"]).toBe("1,0,0.5,-2\n1,0,1e-7,3\n0,1,4,5\n");
    expect(h.text).toBe("recording [0, 1] (1 row)");
    run(h, "stop");
    expect(h.text).toBe("2 clusters, 3 rows (saved 3 rows to data/set.csv)");
    run(h, "save");
    await new Promise((r) => setTimeout(r, 0));
    expect(files["block.csv"]).toBe(files["data/set.csv"]);
  });

  test("a failed save is reported as a warning", async () => {
    const h = await BlockHarness.create(
      BufferBlock,
      {},
      {
        inputs: [{ shape: vectorShape(1) }, { shape: vectorShape(1) }],
      },
    ); // no file access
    h.start();
    run(h, "start", 0);
    h.push(vectors([0], [[1]]), 1);
    run(h, "save", "a.csv");
    await new Promise((r) => setTimeout(r, 0));
    expect(h.warnings[0]).toContain("cannot save the buffer to a.csv");
  });

  test("reset forgets everything", async () => {
    const h = await buffer();
    h.push(vectors([0], [[1, 0]]), 0);
    h.push(data(0, 2), 1);
    h.instance.reset!();
    expect(h.text).toBe("empty");
    h.push(data(1, 2), 1);
    expect(run(h, "inspect")).toBe("empty");
  });

  test("MaxRows × (T + D) is bounded at load (1 GiB)", async () => {
    await expect(buffer({}, 2, 6400)).rejects.toThrow(
      "MaxRows 100,000 rows of 2 + 6400 values would take up to 4.8 GiB; the Buffer keeps at " +
        "most 134,217,728 values (1 GiB): set MaxRows to 20,964 or less",
    );
  });

  test("the trigger must be a vector and the data a signal", async () => {
    await expect(
      BlockHarness.create(
        BufferBlock,
        {},
        {
          inputs: [{ shape: vectorShape(0), isTimer: true }, { shape: vectorShape(2) }],
        },
      ),
    ).rejects.toThrow("input 'in0' is a timer");
  });

  test("in a pipeline: MOSAIC's [Trigger, -Data] subscribes the data only while recording", async () => {
    const yaml =
      "T: { Type: ScheduledTimer, DesiredRate: 100 }\n" +
      "Label: { Type: SinGenerator, Inputs: [T], Params: { Components: 1, Amplitude: 0 } }\n" +
      "Emg: { Type: SinGenerator, Inputs: [T], Params: { Components: 2 } }\n" +
      "Buf: { Type: Buffer, Inputs: [Label, -Emg], Params: { Stream: true } }\n";
    const r = await runVirtualPipeline(yaml, { catalog, duration: 0.1, record: ["Buf"] });
    const pairs = r.outputs.get("Buf")!;
    // The first label event subscribes Emg; from then on every Emg event is recorded.
    expect(pairs.v.length).toBeGreaterThanOrEqual(9);
    for (const row of pairs.v) {
      expect(row).toHaveLength(3);
      expect(row[0]).toBe(0);
    }
    expect(r.telemetry.edges.find((e) => e.to === "Buf" && e.from === "Emg")!.subscribed).toBe(
      true,
    );
    expect(r.telemetry.blocks.find((b) => b.name === "Buf")!.text).toMatch(
      /^recording \[0\] \(\d+ rows\)$/,
    );
    const h = await BlockHarness.create(
      BufferBlock,
      {},
      { inputs: [{ shape: vectorShape(1) }, { shape: vectorShape(2), subscribed: false }] },
    );
    h.push(vectors([0], [[1]]), 0);
    expect(h.subscribed).toEqual({ 1: true });
    h.push(vectors([1], [[NaN]]), 0);
    expect(h.subscribed).toEqual({ 1: false });
  });

  test("legacy: no params", () => {
    expect(
      convertLegacy(
        "T: { Type: ScheduledTimer, DesiredRate: 10 }\n" +
          "L: { Type: SinGenerator, Inputs: [T] }\n" +
          "B: { Type: Buffer, Inputs: [L, -L], Params: [''] }\n",
        "B",
      ),
    ).toEqual({ Stream: false, MaxRows: 100_000 });
  });
});
