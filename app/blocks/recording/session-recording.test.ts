/**
 * Session recordings (the UI's Record button) through a real EngineSession under the virtual
 * clock: what the file holds is exactly what the outputs emitted, read back by our own readers.
 */
import { describe, expect, test } from "vitest";
import type { FileWriteHandle, Resources } from "../../engine";
import { VirtualClock } from "../../engine/clock";
import type { DataMessage, EngineMessage, RecordingStatus } from "../../engine/protocol";
import type { Runtime } from "../../engine/runtime/runtime";
import { runVirtual } from "../../engine/runtime/virtual";
import { EngineSession, type LoopHooks, type SessionPlatform } from "../../engine/session";
import { testCatalog } from "../../engine/test-blocks";
import { noResources } from "../../engine/testing";
import { parseEdfHeader } from "./edf-reader";
import { sessionRecordingFormats } from "./session-formats";
import { bytesSource, readXdf } from "./xdf-reader";
import { MemoryFile } from "./xdf-testing";

const PIPELINE = `
T: { Type: Tick, DesiredRate: 100 }
C: { Type: Counter, Inputs: [T], Params: { Channels: 2 } }
G: { Type: Gain, Inputs: [C], Params: { Gain: 0.1 } }
`;

/** A platform whose loop the test drives through the virtual clock (telemetry every 50 ms). */
function fakePlatform(resources: Resources) {
  const clock = new VirtualClock(1_700_000_000);
  const sent: EngineMessage[] = [];
  let running: { rt: Runtime; hooks: LoopHooks } | undefined;
  const platform: SessionPlatform = {
    engine: "test",
    sharedMemory: false,
    clock: () => clock,
    resources: () => resources,
    recordingFormats: sessionRecordingFormats,
    startLoop(rt, hooks) {
      running = { rt, hooks };
      return { stop: () => (running = undefined), wake: () => {} };
    },
    post: (m) => sent.push(m),
  };
  const advance = (seconds: number) => {
    const end = clock.t + seconds;
    while (running && clock.t < end - 1e-9) {
      runVirtual(running.rt, clock, Math.min(end, clock.t + running.hooks.telemetryIntervalS));
      running.hooks.onTelemetry();
    }
  };
  return { platform, sent, advance };
}

type Reply = Extract<EngineMessage, { type: "reply" }>;
const lastReply = (sent: EngineMessage[]): Reply =>
  sent.filter((m): m is Reply => m.type === "reply").at(-1)!;
const statuses = (sent: EngineMessage[]): RecordingStatus[] =>
  sent.flatMap((m) => (m.type === "recording" ? [m.recording] : []));
const downloads = (sent: EngineMessage[]) =>
  sent.flatMap((m) => (m.type === "download" ? [m] : []));

/** Every event of `block`'s watched output: times and values. */
function watched(sent: EngineMessage[], block: string): { t: number[]; v: number[] } {
  const t: number[] = [];
  const v: number[] = [];
  for (const m of sent) {
    if (m.type !== "data" || (m as DataMessage).block !== block) continue;
    t.push(...m.t);
    v.push(...m.v);
  }
  return { t, v };
}

async function runningSession(resources: Resources) {
  const f = fakePlatform(resources);
  const s = new EngineSession(testCatalog, f.platform);
  await s.handle({ type: "load", id: 1, file: "p.yaml", source: PIPELINE });
  await s.handle({ type: "start", id: 2 });
  f.advance(0.3);
  return { ...f, s };
}

describe("session recording", () => {
  test("XDF of two outputs in memory (browser build): downloaded on stop, read back exactly", async () => {
    const f = await runningSession(noResources);
    // Panel data of both outputs, undecimated: what the outputs emitted while recording.
    await f.s.handle({ type: "watch", id: 3, block: "C", maxRate: 1000 });
    await f.s.handle({ type: "watch", id: 4, block: "G", maxRate: 1000 });
    await f.s.handle({
      type: "record-start",
      id: 5,
      outputs: [{ block: "C" }, { block: "G", port: "out" }],
      format: "xdf",
    });
    expect(lastReply(f.sent)).toMatchObject({ id: 5, ok: true });
    expect(lastReply(f.sent).message).toMatch(
      /^recording C, G to \d{4}-\d\d-\d\d_\d\d-\d\d-\d\d\.xdf$/,
    );
    f.advance(2);
    const live = statuses(f.sent).at(-1)!;
    expect(live).toMatchObject({ state: "recording", format: "xdf", inMemory: true });
    expect(live.outputs).toEqual(["C", "G"]);
    expect(live.duration).toBeGreaterThan(1.5);
    expect(live.samples).toBeGreaterThan(0);
    await f.s.handle({ type: "unwatch", id: 6, block: "C" });
    await f.s.handle({ type: "unwatch", id: 7, block: "G" });
    await f.s.handle({ type: "record-stop", id: 8 });
    expect(lastReply(f.sent)).toMatchObject({ id: 8, ok: true });
    expect(lastReply(f.sent).message).toMatch(
      /^downloading .*\.xdf \(2\.0 s, \d+ bytes, 400 samples\)$/,
    );

    const [d] = downloads(f.sent);
    expect(d).toBeDefined();
    expect(d!.name).toMatch(/\.xdf$/);
    const done = statuses(f.sent).at(-1)!;
    expect(done).toMatchObject({ state: "finished", samples: 400, bytes: d!.bytes.length });

    const xdf = readXdf(bytesSource(d!.bytes));
    expect(xdf.problem).toBe("");
    expect(xdf.streams.map((s) => s.header.name)).toEqual(["C", "G"]);
    for (const [k, block] of ["C", "G"].entries()) {
      const s = xdf.streams[k]!;
      const want = watched(f.sent, block);
      expect(s.header).toMatchObject({ channelCount: 2, nominalRate: 100, format: "double64" });
      expect(s.footer).toBeDefined();
      expect(s.t.length).toBe(200);
      expect(Array.from(s.t)).toEqual(want.t);
      expect(Array.from(s.values!)).toEqual(want.v);
    }
    // Stopping the pipeline afterwards downloads nothing more.
    await f.s.handle({ type: "stop", id: 9 });
    expect(downloads(f.sent)).toHaveLength(1);
  });

  test("where the host writes files: recordings/<date>_<time>.edf, finished when the pipeline stops", async () => {
    const files: MemoryFile[] = [];
    const resources: Resources = {
      ...noResources,
      openWrite(path: string): FileWriteHandle {
        if (files.some((x) => x.path === path)) throw new Error(`${path} exists already`);
        const file = new MemoryFile(path);
        files.push(file);
        return file;
      },
    };
    const f = await runningSession(resources);
    const start = { type: "record-start", outputs: [{ block: "C" }], format: "edf", file: "rec" };
    await f.s.handle({ ...start, id: 3 });
    expect(lastReply(f.sent)).toMatchObject({
      ok: true,
      message: "recording C to recordings/rec.edf",
    });
    // One recording at a time.
    await f.s.handle({ ...start, id: 4 });
    expect(lastReply(f.sent)).toMatchObject({ ok: false, message: /running already/ });
    f.advance(1.5);
    await f.s.handle({ type: "stop", id: 5 });
    expect(statuses(f.sent).at(-1)).toMatchObject({ state: "finished", inMemory: false });
    expect(downloads(f.sent)).toHaveLength(0);
    expect(files[0]!.closed).toBe(true);
    const h = parseEdfHeader(files[0]!.bytes);
    expect(h.format).toBe("edf");
    expect(h.signals.map((s) => s.label)).toEqual(["C 1", "C 2", "EDF Annotations"]);
    expect(h.records).toBeGreaterThan(0);
    expect(h.records * h.recordDuration).toBeLessThanOrEqual(1.5);

    // A taken name gets a number; the file keeps going to recordings/.
    await f.s.handle({ type: "start", id: 6 });
    await f.s.handle({ ...start, id: 7, format: "bdf" });
    await f.s.handle({ ...start, id: 8 });
    expect(lastReply(f.sent)).toMatchObject({ ok: false });
    await f.s.handle({ type: "record-stop", id: 9 });
    await f.s.handle({ ...start, id: 10 });
    expect(lastReply(f.sent)).toMatchObject({ message: "recording C to recordings/rec_2.edf" });
  });

  test("a write that fails (disk full) ends the recording with an error; the pipeline goes on", async () => {
    let file: MemoryFile | undefined;
    const f = await runningSession({
      ...noResources,
      openWrite(path: string): FileWriteHandle {
        file = new MemoryFile(path);
        const write = file.write.bind(file);
        file.write = (bytes) => {
          if (file!.size + bytes.length > 4000) throw new Error("the disk is full");
          write(bytes);
        };
        return file;
      },
    });
    await f.s.handle({ type: "record-start", id: 3, outputs: [{ block: "G" }], format: "xdf" });
    expect(lastReply(f.sent)).toMatchObject({ ok: true });
    f.advance(2);
    const last = statuses(f.sent).at(-1)!;
    expect(last).toMatchObject({ state: "failed", error: "the disk is full" });
    expect(last.bytes).toBeLessThanOrEqual(4000);
    expect(file!.closed).toBe(true);
    const event = f.sent.find((m) => m.type === "event" && m.event.block === "recording");
    expect(event).toMatchObject({ event: { level: "error", message: /failed: the disk is full/ } });
    // What was written before the failure is whole chunks: it reads back without its footer.
    const xdf = readXdf(bytesSource(file!.bytes));
    expect(xdf.problem).toBe("");
    expect(xdf.streams[0]!.t.length).toBeGreaterThan(0);
    // The pipeline still runs, and a new recording can start.
    f.advance(0.5);
    expect(f.sent.filter((m) => m.type === "state").at(-1)).toMatchObject({ state: "running" });
    await f.s.handle({ type: "record-start", id: 4, outputs: [{ block: "G" }], format: "xdf" });
    expect(lastReply(f.sent)).toMatchObject({ id: 4, ok: true });
  });

  test("refusals say why and leave the pipeline running", async () => {
    const f = await runningSession(noResources);
    const tries = [
      { outputs: [{ block: "Nope" }], format: "xdf", why: /no block 'Nope'/ },
      { outputs: [{ block: "C", port: "x" }], format: "xdf", why: /no output 'x'.*\(it has out\)/ },
      { outputs: [{ block: "T" }], format: "xdf", why: /carries no values/ },
      { outputs: [{ block: "C" }, { block: "C" }], format: "xdf", why: /listed twice/ },
      { outputs: [{ block: "C" }], format: "xdf", file: "../x", why: /plain name/ },
    ];
    for (const [i, t] of tries.entries()) {
      const { why, ...req } = t;
      await f.s.handle({ type: "record-start", id: 10 + i, ...req });
      expect(lastReply(f.sent)).toMatchObject({ id: 10 + i, ok: false, message: why });
    }
    // A host that refuses the file (outside the allowed folders): said, nothing recorded.
    const refusing = await runningSession({
      ...noResources,
      openWrite: (path) => {
        throw new Error(`${path} is outside the folders this pipeline may write`);
      },
    });
    await refusing.s.handle({
      type: "record-start",
      id: 1,
      outputs: [{ block: "C" }],
      format: "bdf",
    });
    expect(lastReply(refusing.sent)).toMatchObject({
      ok: false,
      message: /^recordings\/\d{4}-.*\.bdf is outside the folders/,
    });
    expect(statuses(refusing.sent)).toEqual([]);
    await f.s.handle({ type: "record-stop", id: 20 });
    expect(lastReply(f.sent)).toMatchObject({ ok: false, message: "no recording is running" });
    await f.s.handle({ type: "stop", id: 21 });
    await f.s.handle({ type: "record-start", id: 22, outputs: [{ block: "C" }], format: "xdf" });
    expect(lastReply(f.sent)).toMatchObject({ ok: false, message: /start the pipeline first/ });
  });
});
