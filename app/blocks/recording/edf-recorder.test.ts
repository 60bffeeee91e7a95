import { describe, expect, test } from "vitest";
import { z } from "zod";
import { BLOCKS, catalog } from "../catalog";
import {
  createCatalog,
  defineBlock,
  vectorShape,
  type FileWriteHandle,
  type Resources,
} from "../../engine";
import { BlockHarness, noResources, runVirtualPipeline } from "../../engine/testing";
import { vectors } from "../../../tests/support/blocks";
import { EdfRecorder } from "./edf-recorder";
import {
  annotationBytes,
  decodeRecord,
  digitalSample,
  headerSize,
  parseEdfHeader,
  parseTals,
  type EdfHeader,
} from "./edf-reader";
import { planEdfFileRepair, repairEdf } from "./edf-repair";
import { autoRange } from "./edf-stream";

/** Files in memory, written through the same FileWriteHandle interface as the Node host's. */
function memoryFiles() {
  const files = new Map<string, { buf: Uint8Array; size: number; syncs: number }>();
  const resources: Resources = {
    ...noResources,
    openWrite(path: string, o?: { overwrite?: boolean }): FileWriteHandle {
      if (files.has(path) && o?.overwrite !== true) {
        throw new Error(`${path} exists already: not overwritten`);
      }
      const f = { buf: new Uint8Array(4096), size: 0, syncs: 0 };
      files.set(path, f);
      const grow = (to: number) => {
        if (to <= f.buf.length) return;
        const b = new Uint8Array(Math.max(to, f.buf.length * 2));
        b.set(f.buf);
        f.buf = b;
      };
      return {
        path,
        get size() {
          return f.size;
        },
        write(b) {
          grow(f.size + b.length);
          f.buf.set(b, f.size);
          f.size += b.length;
        },
        writeAt(b, pos) {
          if (pos + b.length > f.size) throw new Error("past the end");
          f.buf.set(b, pos);
        },
        sync() {
          f.syncs++;
        },
        close() {},
      };
    },
  };
  const bytes = (path: string) => {
    const f = files.get(path);
    if (!f) throw new Error(`no file ${path}; files: ${[...files.keys()].join(", ")}`);
    return f.buf.slice(0, f.size);
  };
  return { resources, files, bytes };
}

interface Read {
  header: EdfHeader;
  records: Uint8Array[];
  signals: number[][];
  annotations: { onset: number; text: string }[];
}

/** Our reader over a whole file (the independent readers are in tests/integration/edf_check.py). */
function readWhole(b: Uint8Array): Read {
  const header = parseEdfHeader(b.subarray(0, headerSize(b)));
  const records: Uint8Array[] = [];
  for (let r = 0; r < header.records; r++) {
    const at = header.headerBytes + r * header.recordBytes;
    records.push(b.subarray(at, at + header.recordBytes));
  }
  const signals = header.signals.map(() => [] as number[]);
  const annotations: { onset: number; text: string }[] = [];
  for (const rec of records) {
    const out = header.signals.map((s) => new Float64Array(s.samples));
    decodeRecord(header, rec, out);
    header.signals.forEach((s, k) => {
      if (!s.annotations) signals[k]!.push(...out[k]!);
    });
    for (const a of annotationBytes(header, rec)) {
      for (const t of parseTals(a)) annotations.push({ onset: t.onset, text: t.text });
    }
  }
  return { header, records, signals, annotations };
}

const T0 = Date.UTC(2026, 10, 24, 10, 0, 0) / 1000 + 0.25;

/** A source that names its channels and their unit (PortMeta), as a device block does. */
const Named = defineBlock({
  type: "NamedSource",
  category: "Testing",
  summary: "Test source with channel names.",
  help: "Emits [1, 2] per tick with labelled channels.",
  params: z.strictObject({}),
  inputs: { min: 1, max: 1 },
  create(ctx) {
    const out = ctx.output(vectorShape(2), undefined, {
      labels: ["Biceps", "Triceps long head (EMG)"],
      unit: "mV",
    });
    return {
      process(f) {
        const o = out.frame(f.n);
        for (let i = 0; i < f.n; i++) {
          o.t[i] = f.t[i]!;
          o.v[2 * i] = 1;
          o.v[2 * i + 1] = 2;
        }
        out.emit(o);
      },
    };
  },
});

describe("EdfRecorder", () => {
  test("two inputs of different rates: exact digital values, labels, rates, time-keeping TALs", async () => {
    const m = memoryFiles();
    const h = await BlockHarness.create(
      EdfRecorder,
      { File: "out/rec", PhysicalRange: [-3276.8, 3276.7], RecordDuration: 0.027 },
      {
        inputs: [
          { shape: vectorShape(3), rate: 2000 },
          { shape: vectorShape(2), rate: 1925.926 },
        ],
        resources: m.resources,
        now: T0,
      },
    );
    h.start();
    // 0.27 s: 10 records of 54 + 52 samples; value k/10 is digital k exactly (step 0.1).
    const a = Array.from({ length: 540 }, (_, i) => [
      i / 10,
      -i / 10,
      ((i * 7) % 65535) / 10 - 3276.8,
    ]);
    const b = Array.from({ length: 520 }, (_, i) => [i, 3276.7 - i / 10]);
    // Delivered in uneven frames, interleaved.
    for (let i = 0, j = 0; i < 540 || j < 520;) {
      const na = Math.min(37, 540 - i);
      if (na > 0)
        h.push(
          vectors(
            a.slice(i, i + na).map((_, k) => T0 + (i + k) / 2000),
            a.slice(i, i + na),
          ),
          0,
        );
      i += na;
      const nb = Math.min(23, 520 - j);
      if (nb > 0)
        h.push(
          vectors(
            b.slice(j, j + nb).map((_, k) => T0 + ((j + k) * 27) / 52000),
            b.slice(j, j + nb),
          ),
          1,
        );
      j += nb;
    }
    h.instance.stop!();
    const r = readWhole(m.bytes("out/rec.edf"));
    expect(r.header.records).toBe(10);
    expect(r.header.format).toBe("edf");
    expect(r.header.reserved).toBe("EDF+C");
    expect(r.header.recordDuration).toBe(0.027);
    expect(r.header.signals.map((s) => [s.label, s.samples, s.dimension])).toEqual([
      ["in0 1", 54, "uV"],
      ["in0 2", 54, "uV"],
      ["in0 3", 54, "uV"],
      ["in1 1", 52, "uV"],
      ["in1 2", 52, "uV"],
      ["EDF Annotations", r.header.signals[5]!.samples, ""],
    ]);
    for (let i = 0; i < 540; i++) {
      const rec = r.records[Math.floor(i / 54)]!;
      const s = i % 54;
      expect(digitalSample(r.header, rec, 0, s)).toBe(i);
      expect(digitalSample(r.header, rec, 1, s)).toBe(0 - i);
      expect(digitalSample(r.header, rec, 2, s)).toBe(((i * 7) % 65535) - 32768);
    }
    for (let j = 0; j < 520; j++) {
      const rec = r.records[Math.floor(j / 52)]!;
      expect(digitalSample(r.header, rec, 3, j % 52)).toBe(10 * j);
      expect(digitalSample(r.header, rec, 4, j % 52)).toBe(32767 - j);
    }
    r.signals[0]!.forEach((x, i) => expect(Math.abs(x - i / 10)).toBeLessThan(1e-9));
    // The start is the first sample's time: whole seconds in the header, the fraction in the first TAL.
    expect(r.header.start).toBe(T0 - 0.25);
    expect(r.annotations.map((x) => x.onset)).toEqual(
      Array.from({ length: 10 }, (_, k) => Number((0.25 + k * 0.027).toFixed(6))),
    );
    expect(r.annotations.every((x) => x.text === "")).toBe(true);
    expect(h.text).toBe("stopped: out/rec.edf: 0.3 s, 7.3 KiB, 10 records, 0 clipped");
    expect(m.files.get("out/rec.edf")!.syncs).toBe(1);
  });

  test("BDF+: 24-bit samples, clipping and NaN counted, auto range from the first record", async () => {
    const m = memoryFiles();
    const h = await BlockHarness.create(
      EdfRecorder,
      { File: "x.bdf", RecordDuration: 0.01 },
      { inputs: [{ shape: vectorShape(1), rate: 1000 }], resources: m.resources, now: T0 },
    );
    h.start();
    const v = Array.from({ length: 30 }, (_, i) => [
      i < 10 ? 0.3 * (i % 2 ? 1 : -1) : i === 15 ? NaN : i === 20 ? 99 : 1,
    ]);
    h.push(
      vectors(
        v.map((_, i) => T0 + i / 1000),
        v,
      ),
      0,
    );
    h.instance.stop!();
    const r = readWhole(m.bytes("x.bdf"));
    expect(r.header.format).toBe("bdf");
    expect(r.header.signals[1]!.label).toBe("BDF Annotations");
    // ±10 × 0.3 = 3 → rounded up to 5.
    expect([r.header.signals[0]!.physicalMin, r.header.signals[0]!.physicalMax]).toEqual([-5, 5]);
    expect(r.header.signals[0]!.digitalMax).toBe(8388607);
    expect(r.signals[0]![20]).toBe(5); // 99 clipped to the maximum
    expect(r.signals[0]![15]).toBe(-5); // NaN written as the digital minimum
    expect(Math.abs(r.signals[0]![1]! - 0.3)).toBeLessThan(10 / 16777215);
    expect(h.text).toMatch(/3 records, 1 clipped, 1 NaN$/);
    expect(autoRange(Float64Array.of(0, 0), 0, 2)).toEqual([-1, 1]);
    expect(autoRange(Float64Array.of(-0.011), 0, 1)).toEqual([-0.2, 0.2]);
    expect(autoRange(Float64Array.of(1200), 0, 1)).toEqual([-20000, 20000]);
  });

  test("Trigger markers become annotations at their times; the header count is kept current", async () => {
    const m = memoryFiles();
    const start = 1_790_000_000;
    const run = await runVirtualPipeline(
      `
Timer: { Type: ScheduledTimer, DesiredRate: 500 }
Sin: { Type: SinGenerator, Inputs: [Timer], Params: { Components: 2, Frequency: 3, Amplitude: 100 } }
Trig: { Type: Trigger, Params: { Labels: { rest: [0], fist: [1] }, Schedule: [ { Label: fist, At: 0.5, Seconds: 0.3 } ] } }
Rec: { Type: EdfRecorder, Inputs: [Sin, Trig.label], Params: { File: "{block}-{date}-{time}", PhysicalRange: [-200, 200] } }
`,
      { catalog, duration: 2, start, resources: m.resources },
    );
    const name = "Rec-20260921-141320.edf";
    const r = readWhole(m.bytes(name));
    expect(r.header.recordDuration).toBe(0.5);
    expect(r.header.records).toBe(4); // the fifth record (from 2.0 s) is incomplete at the stop
    const marks = r.annotations.filter((a) => a.text !== "");
    expect(marks).toEqual([
      { onset: 0.5, text: "Trig.label=1" },
      { onset: 0.8, text: "Trig.label=NaN" },
    ]);
    expect(r.signals[0]!.length).toBe(1000);
    expect(r.signals[0]![125]).toBeCloseTo(100 * Math.sin(2 * Math.PI * 3 * 0.25), 2);
    const rec = run.telemetry.blocks.find((b) => b.name === "Rec")!;
    // The status while running (refreshed every 0.25 s of pipeline time).
    expect(rec.text).toMatch(
      /^Rec-20260921-141320\.edf: 1\.5 s, 4\.\d KiB, 3 records, 0 clipped, 2 annotations$/,
    );
  });

  test("labels and dimension from the channel names and unit the source block gives", async () => {
    const m = memoryFiles();
    await runVirtualPipeline(
      `
Timer: { Type: ScheduledTimer, DesiredRate: 100 }
Arm: { Type: NamedSource, Inputs: [Timer] }
Sin: { Type: SinGenerator, Inputs: [Timer] }
Rec: { Type: EdfRecorder, Inputs: [Arm, Sin], Params: { File: named, RecordDuration: 0.1 } }
`,
      {
        catalog: createCatalog([...BLOCKS, Named]),
        duration: 0.5,
        start: T0,
        resources: m.resources,
      },
    );
    const r = readWhole(m.bytes("named.edf"));
    expect(r.header.signals.map((s) => [s.label, s.dimension])).toEqual([
      ["Biceps", "mV"],
      ["Triceps long hea", "mV"],
      ["Sin", "uV"],
      ["EDF Annotations", ""],
    ]);
  });

  test("the File pattern never overwrites: -2, -3; start/stop make new files", async () => {
    const m = memoryFiles();
    m.resources.openWrite!("r/a.edf").close();
    const h = await BlockHarness.create(
      EdfRecorder,
      { File: "r/a.edf", RecordDuration: 0.1 },
      { inputs: [{ shape: vectorShape(1), rate: 100 }], resources: m.resources, now: T0 },
    );
    h.start();
    h.push(vectors([T0, T0 + 0.01], [[1], [2]]), 0);
    expect(h.instance.actions!.stop!.run()).toBe("recording stopped (r/a-2.edf)");
    expect(h.instance.actions!.start!.run()).toBe("recording to r/a-3.edf");
    h.instance.setParam!("Recording", false);
    expect([...m.files.keys()]).toEqual(["r/a.edf", "r/a-2.edf", "r/a-3.edf"]);
    // Nothing complete: the files are empty (the header goes out with the first record).
    expect(m.files.get("r/a-2.edf")!.size).toBe(0);
  });

  test("an input that stalls is padded to keep the file going; its late samples are dropped", async () => {
    const m = memoryFiles();
    const h = await BlockHarness.create(
      EdfRecorder,
      { File: "p", RecordDuration: 0.5, PhysicalRange: [-100, 100] },
      {
        inputs: [
          { shape: vectorShape(1), rate: 100 },
          { shape: vectorShape(1), rate: 10 },
        ],
        resources: m.resources,
        now: T0,
      },
    );
    h.start();
    h.push(vectors([T0], [[7]]), 1);
    const a = Array.from({ length: 600 }, (_, i) => [i % 50]);
    h.push(
      vectors(
        a.map((_, i) => T0 + i / 100),
        a,
      ),
      0,
    );
    // 2 s of lag allowed (4 records): the fast input's queue holds 5 records (250 samples); each
    // sample past that forces a record with the slow input padded: 7 records, 4 + 6 × 5 padded.
    expect(m.files.get("p.edf")!.size).toBeGreaterThan(0);
    const late = Array.from({ length: 40 }, (_, i) => [i]);
    h.push(
      vectors(
        late.map((_, i) => T0 + i / 10),
        late,
      ),
      1,
    );
    h.instance.stop!();
    const r = readWhole(m.bytes("p.edf"));
    expect(r.header.records).toBe(8);
    expect(h.text).toMatch(/8 records, 0 clipped, 34 padded, 34 dropped$/);
    // The slow input: its one real sample, held, then (after dropping 34 late ones) samples 34…38.
    expect(r.signals[1]!.slice(0, 35).every((x) => Math.abs(x - 7) < 0.01)).toBe(true);
    expect(r.signals[1]!.slice(35, 40).map(Math.round)).toEqual([34, 35, 36, 37, 38]);
    expect(r.signals[0]!.slice(0, 400).map(Math.round)).toEqual(a.slice(0, 400).map((x) => x[0]));
  });

  test("no file access (browser): says so and records nothing", async () => {
    const h = await BlockHarness.create(
      EdfRecorder,
      {},
      { inputs: [{ shape: vectorShape(1), rate: 100 }] },
    );
    h.start();
    h.push(vectors([1], [[1]]), 0);
    expect(h.text).toBe("no file access in this runtime: nothing is recorded");
  });

  test("load errors name the param and say what is wrong", async () => {
    const make = (params: unknown, inputs = [{ shape: vectorShape(2), rate: 2000 }]) =>
      BlockHarness.create(EdfRecorder, params, { inputs });
    await expect(make({ Labels: ["a"] })).rejects.toThrow(
      /Labels has 1 names but the signal inputs have 2 channels/,
    );
    await expect(make({ File: "x.edf", Format: "bdf" })).rejects.toThrow(
      /File ends in .edf but Format is bdf/,
    );
    await expect(make({ RecordDuration: 0.0003 })).rejects.toThrow(
      /gives 0.600 samples per 0.0003 s record/,
    );
    await expect(make({ PhysicalRange: [[0, 1]] })).rejects.toThrow(/PhysicalRange has 1 ranges/);
    await expect(make({ PhysicalRange: [1, 0] })).rejects.toThrow(/min < max/);
    await expect(make({}, [{ shape: vectorShape(1), rate: 0 }])).rejects.toThrow(
      /needs at least one periodic signal input/,
    );
    await expect(
      make({}, [
        { shape: vectorShape(1), rate: 2000 },
        { shape: vectorShape(1), rate: Math.PI },
      ]),
    ).rejects.toThrow(/no record duration of at most 60 s/);
  });
});

describe("edf repair", () => {
  test("a torn last record is cut and the record count set from the size", async () => {
    const m = memoryFiles();
    const h = await BlockHarness.create(
      EdfRecorder,
      { File: "t", RecordDuration: 0.1, PhysicalRange: [-10, 10] },
      { inputs: [{ shape: vectorShape(2), rate: 100 }], resources: m.resources, now: T0 },
    );
    h.start();
    const v = Array.from({ length: 55 }, (_, i) => [i / 10, -i / 10]);
    h.push(
      vectors(
        v.map((_, i) => T0 + i / 100),
        v,
      ),
      0,
    );
    const whole = m.bytes("t.edf");
    const hdr = parseEdfHeader(whole.subarray(0, headerSize(whole)));
    // An older recorder's file: count -1, half a record more.
    expect(whole.length).toBe(hdr.headerBytes + 5 * hdr.recordBytes);
    const damaged = new Uint8Array(whole.length + 17);
    damaged.set(whole);
    damaged.set(new TextEncoder().encode("-1      "), 236);
    let size = damaged.length;
    const file = {
      get size() {
        return size;
      },
      read: (into: Uint8Array, pos: number) => {
        const n = Math.max(0, Math.min(into.length, size - pos));
        into.set(damaged.subarray(pos, pos + n));
        return n;
      },
      writeAt: (b: Uint8Array, pos: number) => damaged.set(b, pos),
      truncate: (len: number) => {
        size = len;
      },
    };
    // What mosaic repair writes: the whole records kept, the count patched.
    const plan = planEdfFileRepair(file);
    expect(plan.keep).toBe(hdr.headerBytes + 5 * hdr.recordBytes);
    expect(plan.append.length).toBe(0);
    expect(plan.patches).toEqual([{ at: 236, bytes: new TextEncoder().encode("5       ") }]);
    expect(plan.changed).toBe(true);
    expect(plan.messages).toEqual([
      "EDF+ with 3 signals: 5 whole data records of 0.1 s (0.500 s)",
      "drops a torn last record (17 bytes)",
      "sets the header's number of data records from -1 to 5",
    ]);
    expect(repairEdf(file)).toBe(
      "repaired: cut a torn last record (17 bytes), set the number of data records from -1 to 5; 5 data records (0.500 s)",
    );
    const r = readWhole(damaged.subarray(0, size));
    expect(r.header.records).toBe(5);
    expect(r.signals[0]!.map((x) => Math.round(x * 10))).toEqual(
      Array.from({ length: 50 }, (_, i) => i),
    );
    expect(repairEdf(file)).toBe("intact: 5 data records (0.500 s)");
    expect(planEdfFileRepair(file).changed).toBe(false);
    expect(() => repairEdf({ ...file, size: 10 })).toThrow(/too short for an EDF\/BDF header/);
  });
});
