/**
 * The XdfRecorder in pipelines under the virtual clock, its files in memory and read back by our
 * reader (pyxdf reads real ones in tests/integration/xdf.test.ts): exact values and timestamps,
 * stream headers, markers, the 0.1-s write cadence (also when only markers arrive), file names,
 * start/stop, failures.
 */
import { beforeAll, describe, expect, test } from "vitest";
import { catalog } from "../catalog";
import {
  formatDiagnostic,
  loadPipeline,
  Runtime,
  runVirtual,
  VirtualClock,
  type FileWriteHandle,
  type Resources,
} from "../../engine";
import { noResources, runVirtualPipeline } from "../../engine/testing";
import { bytesSource, readXdf, xmlField, type XdfFile } from "./xdf-reader";
import { MemoryFile } from "./xdf-testing";
import { initDspForTests } from "../../../tests/support/wasm";

beforeAll(() => initDspForTests());

/** Files in memory; `openWrite` refuses an existing name as the Node host does. */
class MemoryFiles {
  readonly files = new Map<string, MemoryFile & { writes: number }>();
  failAfter = Infinity;

  resources(): Resources {
    return {
      ...noResources,
      openWrite: (path: string): FileWriteHandle => {
        if (this.files.has(path)) throw new Error(`${path} exists already: not overwritten`);
        const f = Object.assign(new MemoryFile(path), { writes: 0 });
        const write = f.write.bind(f);
        f.write = (b: Uint8Array) => {
          if (f.writes >= this.failAfter) throw new Error(`the disk is full: cannot write ${path}`);
          f.writes++;
          write(b);
        };
        this.files.set(path, f);
        return f;
      },
    };
  }

  read(path: string): XdfFile {
    const f = this.files.get(path);
    if (!f) throw new Error(`no file ${path} (have ${[...this.files.keys()].join(", ")})`);
    return readXdf(bytesSource(f.bytes));
  }
}

const START = 1_700_000_000;

async function create(yaml: string, files: MemoryFiles) {
  const loaded = loadPipeline(yaml, "test.yaml", catalog);
  if (!loaded.spec) throw new Error(loaded.diagnostics.map(formatDiagnostic).join("\n"));
  const clock = new VirtualClock(START);
  const created = await Runtime.create({
    spec: loaded.spec,
    catalog,
    clock,
    virtual: true,
    resources: files.resources(),
    ignorePlacement: true,
  });
  if (!created.runtime) throw new Error(created.diagnostics.map(formatDiagnostic).join("\n"));
  return { rt: created.runtime, clock };
}

async function loadError(yaml: string): Promise<string> {
  const loaded = loadPipeline(yaml, "test.yaml", catalog);
  if (!loaded.spec) return loaded.diagnostics.map(formatDiagnostic).join("\n");
  const created = await Runtime.create({
    spec: loaded.spec,
    catalog,
    clock: new VirtualClock(0),
    virtual: true,
    resources: new MemoryFiles().resources(),
    ignorePlacement: true,
  });
  created.runtime?.dispose();
  return created.diagnostics.map(formatDiagnostic).join("\n");
}

describe("XdfRecorder", () => {
  test("channel labels and unit come from the source's port meta, through same-shape blocks", async () => {
    const files = new MemoryFiles();
    await runVirtualPipeline(
      `
Amp: { Type: Quattrocento, Params: { Connectors: [IN1] } }
Abs: { Type: Function, Inputs: [Amp], Params: { Operation: abs } }
Rec: { Type: XdfRecorder, Inputs: [Abs], Params: { File: meta.xdf } }
`,
      { catalog, duration: 0.2, start: START, resources: files.resources() },
    );
    const [abs] = files.read("meta.xdf").streams;
    expect(abs!.header.labels.slice(0, 3)).toEqual(["IN1/1", "IN1/2", "IN1/3"]);
    expect(abs!.header.labels).toHaveLength(16);
    expect(xmlField(abs!.header.xml, "unit")).toBe("mV");
  });

  test("records signals (double64: exact) and Trigger markers with their timestamps", async () => {
    const files = new MemoryFiles();
    const run = await runVirtualPipeline(
      `
Timer: { Type: ScheduledTimer, DesiredRate: 100 }
Sin: { Type: SinGenerator, Inputs: [Timer], Params: { Components: 3, Frequency: 1.5 } }
Marks:
  Type: Trigger
  Params:
    Labels: { rest: [0, 0], fist: [1, 0.5] }
    Schedule: [{ Label: fist, At: 0.5, Seconds: 1 }]
Rec:
  Type: XdfRecorder
  Inputs: [Sin, Marks]
  Params:
    File: out/run.xdf
    Format: double64
    Streams: { Sin: { Type: EMG, Labels: [x, y, z], Unit: mV } }
`,
      { catalog, duration: 2.5, start: START, resources: files.resources() },
    );
    const x = files.read("out/run.xdf");
    expect(x.problem).toBe("");
    const [sin, marks] = x.streams;
    expect(sin!.header).toMatchObject({
      name: "Sin",
      type: "EMG",
      channelCount: 3,
      nominalRate: 100,
      format: "double64",
      sourceId: "MOSAIC/Rec/Sin",
      labels: ["x", "y", "z"],
    });
    expect(xmlField(sin!.header.xml, "unit")).toBe("mV");
    const want = run.outputs.get("Sin")!;
    expect(want.t.length).toBe(251);
    expect([...sin!.t]).toEqual(want.t);
    expect([...sin!.values!]).toEqual(want.v.flat());
    expect(marks!.header).toMatchObject({
      name: "Marks",
      type: "Markers",
      channelCount: 1,
      nominalRate: 0,
      format: "string",
    });
    const trig = run.outputs.get("Marks")!;
    expect([...marks!.t]).toEqual(trig.t);
    expect(marks!.strings).toEqual(["1,0.5", "NaN,NaN"]);
    // Footers (the pipeline stopped cleanly), clock offsets every 5 s from the start.
    expect(xmlField(sin!.footer!, "sample_count")).toBe("251");
    expect(xmlField(marks!.footer!, "sample_count")).toBe("2");
    expect(sin!.clockOffsets[0]).toEqual([START, 0]);
    const rec = run.telemetry.blocks.find((b) => b.name === "Rec")!;
    expect(rec.text).toMatch(/^recording out\/run\.xdf: \d\.\d s, [\d.]+ kB, [\d,]+ samples$/);
  });

  test("writes within 0.1 s, also when only markers arrive (its own timer flushes)", async () => {
    const files = new MemoryFiles();
    const { rt, clock } = await create(
      `
Marks:
  Type: Trigger
  Params:
    Labels: { a: [1] }
    Schedule: [{ Label: a, At: 0.5, Seconds: 0.05 }]
Rec: { Type: XdfRecorder, Inputs: [Marks], Params: { File: m.xdf } }
`,
      files,
    );
    rt.start();
    runVirtual(rt, clock, START + 0.45);
    expect(files.read("m.xdf").streams[0]!.t.length).toBe(0);
    // The start at 0.5 s, after a quiet spell, is written at once; the stop at 0.55 s waits for
    // the next write, 0.1 s after the previous one: the recorder's own timer, no event needed.
    runVirtual(rt, clock, START + 0.58);
    expect([...files.read("m.xdf").streams[0]!.t]).toEqual([START + 0.5]);
    runVirtual(rt, clock, START + 0.61);
    expect(files.read("m.xdf").streams[0]!.strings).toEqual(["1", "NaN"]);
    expect(files.read("m.xdf").streams[0]!.footer).toBeUndefined();
    rt.stop();
    rt.dispose();
    expect(files.read("m.xdf").streams[0]!.footer).toBeDefined();
  });

  test("a 1 kHz signal goes out as one Samples chunk per 0.1 s, one write each", async () => {
    const files = new MemoryFiles();
    const { rt, clock } = await create(
      `
Timer: { Type: ScheduledTimer, DesiredRate: 1000 }
Emg: { Type: SinGenerator, Inputs: [Timer], Params: { Components: 4 } }
Rec: { Type: XdfRecorder, Inputs: [Emg], Params: { File: e.xdf } }
`,
      files,
    );
    rt.start();
    runVirtual(rt, clock, START + 2);
    const f = files.files.get("e.xdf")!;
    // The header write, then one per 0.1 s (±1 for where the last one falls).
    expect(f.writes).toBeGreaterThanOrEqual(20);
    expect(f.writes).toBeLessThanOrEqual(22);
    const n = files.read("e.xdf").streams[0]!.t.length;
    expect(n).toBeGreaterThanOrEqual(1900);
    rt.stop();
    rt.dispose();
    expect(files.read("e.xdf").streams[0]!.t.length).toBe(2001);
  });

  test("never overwrites: {date}/{time} names, _2 for a taken name; stop closes, start opens a new file", async () => {
    const files = new MemoryFiles();
    files.resources().openWrite!("r.xdf"); // taken
    const { rt, clock } = await create(
      `
Timer: { Type: ScheduledTimer, DesiredRate: 10 }
Sin: { Type: SinGenerator, Inputs: [Timer] }
Rec: { Type: XdfRecorder, Inputs: [Sin], Params: { File: r.xdf } }
Dated: { Type: XdfRecorder, Inputs: [Sin], Params: { File: "d/{block}_{date}_{time}.xdf" } }
`,
      files,
    );
    rt.start();
    runVirtual(rt, clock, START + 1);
    expect(rt.invoke("Rec", "stop")).toBe("recording stopped: r_2.xdf closed");
    runVirtual(rt, clock, START + 2);
    expect(rt.invoke("Rec", "start")).toBe("recording to r_3.xdf");
    runVirtual(rt, clock, START + 3);
    expect(rt.setParam("Rec", "Recording", false)).toBeDefined();
    rt.stop();
    rt.dispose();
    const a = files.read("r_2.xdf").streams[0]!;
    const b = files.read("r_3.xdf").streams[0]!;
    expect(a.footer).toBeDefined();
    expect(b.footer).toBeDefined();
    expect(a.t[0]).toBe(START);
    expect(a.t.at(-1)).toBeCloseTo(START + 1, 9);
    expect(b.t[0]).toBeCloseTo(START + 2.1, 9);
    expect(b.t.at(-1)).toBeCloseTo(START + 3, 9);
    const dated = [...files.files.keys()].filter((k) => k.startsWith("d/"));
    expect(dated).toHaveLength(1);
    expect(dated[0]).toMatch(/^d\/Dated_\d{4}-\d\d-\d\d_\d\d-\d\d-\d\d\.xdf$/);
  });

  test("Overwrite: true replaces a file of the same name", async () => {
    const files = new MemoryFiles();
    const yaml = `
Timer: { Type: ScheduledTimer, DesiredRate: 10 }
Sin: { Type: SinGenerator, Inputs: [Timer] }
Rec: { Type: XdfRecorder, Inputs: [Sin], Params: { File: o.xdf, Overwrite: true } }
`;
    const overwriting = files.resources();
    const open = overwriting.openWrite!;
    const asked: (boolean | undefined)[] = [];
    overwriting.openWrite = (path, o) => {
      asked.push(o?.overwrite);
      files.files.delete(path); // what the host does with { overwrite: true }
      return open(path, o);
    };
    for (let k = 0; k < 2; k++) {
      await runVirtualPipeline(yaml, {
        catalog,
        duration: 0.5,
        start: START,
        resources: overwriting,
      });
    }
    expect(asked).toEqual([true, true]);
    expect([...files.files.keys()]).toEqual(["o.xdf"]);
    expect(files.read("o.xdf").streams[0]!.t.length).toBe(6);
  });

  test("a failed write is reported once and stops the recording; the pipeline runs on", async () => {
    const files = new MemoryFiles();
    files.failAfter = 3;
    const { rt, clock } = await create(
      `
Timer: { Type: ScheduledTimer, DesiredRate: 100 }
Sin: { Type: SinGenerator, Inputs: [Timer] }
Rec: { Type: XdfRecorder, Inputs: [Sin], Params: { File: full.xdf } }
`,
      files,
    );
    rt.start();
    runVirtual(rt, clock, START + 1);
    const t = rt.telemetry().blocks;
    const rec = t.find((b) => b.name === "Rec")!;
    expect(rec.errors).toBe(1);
    expect(rec.text).toMatch(/^not recording: the disk is full/);
    expect(t.find((b) => b.name === "Sin")!.events).toBe(101);
    rt.stop();
    rt.dispose();
  });

  test("where the runtime cannot write files it says so and records nothing", async () => {
    const run = await runVirtualPipeline(
      `
Timer: { Type: ScheduledTimer, DesiredRate: 10 }
Sin: { Type: SinGenerator, Inputs: [Timer] }
Rec: { Type: XdfRecorder, Inputs: [Sin] }
`,
      { catalog, duration: 0.5 },
    );
    const rec = run.telemetry.blocks.find((b) => b.name === "Rec")!;
    expect(rec.text).toMatch(/no file access in this runtime/);
    expect(rec.errors).toBe(0);
  });

  test("configuration errors name the input and the param", async () => {
    const base = `
Timer: { Type: ScheduledTimer, DesiredRate: 10 }
Sin: { Type: SinGenerator, Inputs: [Timer], Params: { Components: 2 } }
`;
    expect(
      await loadError(
        `${base}Rec: { Type: XdfRecorder, Inputs: [Sin], Params: { Streams: { Cos: {} } } }`,
      ),
    ).toMatch(/Streams names 'Cos', which is not one of the inputs \(Sin\)/);
    expect(
      await loadError(
        `${base}Rec: { Type: XdfRecorder, Inputs: [Sin], Params: { Streams: { Sin: { Labels: [a] } } } }`,
      ),
    ).toMatch(/Streams.Sin.Labels has 1 label, but the stream has 2 channels/);
    expect(await loadError(`${base}Rec: { Type: XdfRecorder, Inputs: [Timer] }`)).toMatch(
      /'Timer' is a timer/,
    );
    expect(await loadError(`${base}Rec: { Type: XdfRecorder, Inputs: [Sin, Sin] }`)).toMatch(
      /listed twice/,
    );
  });
});
