/**
 * The Lab Streaming Layer blocks against an independent pylsl process (tests/reference's pylsl
 * 1.18, tests/integration/lsl_peer.py) and against each other, through the real liblsl bridge
 * (native-bridges/lsl.ts). Discovery is confined to this machine by an lsl_api.cfg of our own
 * (ResolveScope machine, IPv6 off, KnownPeers 127.0.0.1, a SessionID no other run shares),
 * given to both sides through LSLAPICFG: nothing is broadcast on the network.
 *
 * The long test streams 10 s at 2 kHz × 32 channels each way at once, in real time (LSL needs
 * it): MOSAIC's LslOutlet → pylsl and pylsl → MOSAIC's LslInlet, every value exact, no sample
 * lost or repeated, every timestamp within 1 ms of the time it was given (mapped between the
 * pipeline clock and LSL's clock by an offset this test measures on its own). About 13 s.
 * The others: markers both ways, blocks to blocks in this process (int32 markers, a refused
 * channel count, a lost stream recovered), no bridge, a missing library, and `mosaic run` of
 * pipelines/examples/lsl-outlet.yaml read by pylsl, and the paper's Myo pipeline split across two
 * `mosaic run` processes (lsl-split-acquire.yaml → lsl-split-process.yaml): every sample the
 * second logs is the first's, exact, at the same time (1 ms), and its blocks keep up (these two
 * need dist/). The whole file: about 45 s.
 */
import { spawn, type ChildProcess } from "node:child_process";
import { existsSync, mkdirSync, readFileSync, writeFileSync } from "node:fs";
import { join } from "node:path";
import { createInterface } from "node:readline";
import { afterEach, describe, expect, test } from "vitest";
import { parse, stringify } from "yaml";
import { LslInlet } from "../../app/blocks/lsl/lsl-inlet";
import { LslMarkerInlet } from "../../app/blocks/lsl/lsl-marker-inlet";
import { LslMarkers } from "../../app/blocks/lsl/lsl-markers";
import { LslOutlet } from "../../app/blocks/lsl/lsl-outlet";
import { measureOffset } from "../../app/blocks/lsl/clock-map";
import { Frame, vectorShape, type AnyBlockDefinition } from "../../app/engine";
import { BlockHarness } from "../../app/engine/testing";
import { liblslCandidates, liblslMissing, nodeLslBridge } from "../../native-bridges/lsl";
import { CLI, jsonLines, KEEPING_UP, requireBuild, ROOT, tempDir } from "./helpers";

const PYTHON = join(ROOT, "tests", "reference", ".venv", "bin", "python");
const PEER = join(ROOT, "tests", "integration", "lsl_peer.py");
const RATE = 2000;
const CHANNELS = 32;
const SECONDS = 10;
const N = RATE * SECONDS;

// liblsl reads its configuration once, at its first call: set it before any.
const cfgDir = tempDir("mosaic-lsl-");
const CFG = join(cfgDir, "lsl_api.cfg");
writeFileSync(
  CFG,
  [
    "[ports]",
    "IPv6 = disable",
    "[multicast]",
    "ResolveScope = machine",
    "[lab]",
    "KnownPeers = {127.0.0.1}",
    `SessionID = mosaic-test-${process.pid}-${Date.now()}`,
    "[log]",
    "level = -2",
    "",
  ].join("\n"),
);
process.env.LSLAPICFG = CFG;
const lsl = nodeLslBridge();

const wall = (): number => (performance.timeOrigin + performance.now()) / 1000;
const sleep = (ms: number) => new Promise((r) => setTimeout(r, ms));

async function until(ok: () => boolean, what: string, ms = 10_000): Promise<void> {
  const t0 = Date.now();
  while (!ok()) {
    if (Date.now() - t0 > ms) throw new Error(`timed out waiting for ${what}`);
    await sleep(5);
  }
}

const cleanup: (() => void | Promise<void>)[] = [];
afterEach(async () => {
  for (const c of cleanup.splice(0).reverse()) await c();
});

/** A block in a harness on the wall clock (read at every `now()`), with the real bridge. */
async function harness(
  def: AnyBlockDefinition,
  params: Record<string, unknown>,
  input?: { channels: number; rate: number },
  io = true,
) {
  const h = await BlockHarness.create(def, params, {
    ...(io ? { io: { lsl } } : {}),
    now: wall(),
    virtual: false,
    ...(input ? { inputs: [{ shape: vectorShape(input.channels), rate: input.rate }] } : {}),
  });
  Object.defineProperty(h, "clock", { get: wall, set: () => {} });
  cleanup.push(() => {
    h.instance.stop?.();
    h.instance.dispose?.();
  });
  return h;
}

/** Polls the harnesses' timers (the inlets' PollRate) every 2 ms. */
function poll(...hs: BlockHarness[]): void {
  const timer = setInterval(() => {
    for (const h of hs) h.tick(wall());
  }, 2);
  cleanup.push(() => clearInterval(timer));
}

interface Peer {
  proc: ChildProcess;
  events: Record<string, unknown>[];
  next(event: string, ms?: number): Promise<Record<string, unknown>>;
}

function peer(...args: string[]): Peer {
  const proc = spawn(PYTHON, [PEER, ...args], {
    env: { ...process.env, LSLAPICFG: CFG },
    stdio: ["pipe", "pipe", "pipe"],
  });
  const events: Record<string, unknown>[] = [];
  let stderr = "";
  proc.stderr!.on("data", (d: Buffer) => (stderr += d.toString()));
  createInterface({ input: proc.stdout! }).on("line", (l) => {
    if (l.startsWith("{")) events.push(JSON.parse(l) as Record<string, unknown>);
  });
  cleanup.push(() => {
    proc.stdin!.end();
    if (proc.exitCode === null) proc.kill();
  });
  return {
    proc,
    events,
    async next(event, ms = 30_000) {
      await until(
        () => events.some((e) => e.event === event) || proc.exitCode !== null,
        `the pylsl peer's ${event}`,
        ms,
      );
      const e = events.find((x) => x.event === event);
      if (!e) throw new Error(`the pylsl peer ended without ${event}: ${stderr.slice(-2000)}`);
      return e;
    },
  };
}

const ourValue = (k: number, c: number): number => (k * 32 + c) / 8 - 5000.5;
const peerValue = (k: number, c: number): number => -(k * 32 + c) / 4 + 0.125;

/** Feeds `h` the events of the test signal whose time has come, as frames of what is due. */
function feedRealTime(h: BlockHarness, t0: number, n: number): { sent: () => number } {
  let k = 0;
  const timer = setInterval(() => {
    const due = Math.min(n, Math.floor((wall() - t0) * RATE) + 1);
    if (due <= k) return;
    const f = new Frame(vectorShape(CHANNELS), due - k);
    f.n = due - k;
    for (let i = 0; i < f.n; i++) {
      f.t[i] = t0 + (k + i) / RATE;
      for (let c = 0; c < CHANNELS; c++) f.v[i * CHANNELS + c] = ourValue(k + i, c);
    }
    h.push(f);
    k = due;
  }, 3);
  cleanup.push(() => clearInterval(timer));
  return { sent: () => k };
}

const available = existsSync(PYTHON) && liblslCandidates().some((p) => existsSync(p));

describe.runIf(available)("Lab Streaming Layer with an independent pylsl process", () => {
  test(
    "10 s at 2 kHz x 32 channels each way: exact values, no sample lost, timestamps within 1 ms",
    { timeout: 90_000 },
    async () => {
      const labels = Array.from({ length: CHANNELS }, (_, c) => `EMG${c + 1}`);
      const outlet = await harness(
        LslOutlet,
        {
          Name: "MosaicOut",
          Type: "EMG",
          Format: "double64",
          ChannelLabels: labels,
          SourceId: "mosaic-test-out",
        },
        { channels: CHANNELS, rate: RATE },
      );
      const inlet = await harness(LslInlet, { Name: "PyOut", Channels: CHANNELS });
      outlet.start();
      inlet.start();
      poll(inlet);
      const py = peer("stream", String(N));

      const ready = await py.next("inlet-ready");
      expect(ready).toMatchObject({
        name: "MosaicOut",
        type: "EMG",
        channels: CHANNELS,
        rate: RATE,
        format: 2, // pylsl's cf_double64
        source_id: "mosaic-test-out",
        labels,
      });
      const t0 = wall() + 0.05;
      const feed = feedRealTime(outlet, t0, N);
      const start = (await py.next("outlet-start")) as { t0: number };

      const rec = inlet.output();
      await until(() => feed.sent() === N && rec.t.length >= N, "both streams", 40_000);
      const done = (await py.next("inlet-done")) as {
        samples: number;
        bad: number;
        timestamps: number[];
      };
      await sleep(100);

      // The test's own map between the two clocks: lsl = wall + offset.
      const offset = measureOffset(wall, () => lsl.localClock(), 21)!.offset;

      // MOSAIC → pylsl.
      expect(done.samples).toBe(N);
      expect(done.bad).toBe(0);
      let worst = 0;
      done.timestamps.forEach((ts, k) => {
        worst = Math.max(worst, Math.abs(ts - (t0 + k / RATE + offset)));
      });
      expect(worst).toBeLessThan(0.001);

      // pylsl → MOSAIC.
      expect(rec.t.length).toBe(N);
      let wrong = 0;
      let late = 0;
      for (let k = 0; k < N; k++) {
        const v = rec.v[k]!;
        for (let c = 0; c < CHANNELS; c++) if (v[c] !== peerValue(k, c)) wrong++;
        late = Math.max(late, Math.abs(rec.t[k]! - (start.t0 + k / RATE - offset)));
      }
      expect(wrong).toBe(0);
      expect(late).toBeLessThan(0.001);
      inlet.tick(wall() + 0.5);
      expect(inlet.text).toMatch(/'PyOut' .*32 ch double64 @ 2000 Hz.*20,000 samples/);
      outlet.instance.stop?.();
      expect(outlet.text).toMatch(/streaming 'MosaicOut' .*20,000 samples in .* chunks/);
    },
  );

  test("markers: string markers out to pylsl, string markers in, at their own times", async () => {
    const labels = ["rest", "power"];
    const markers = await harness(
      LslMarkers,
      { Name: "MosaicMarkers", Format: "string", Labels: labels },
      { channels: 1, rate: 0 },
    );
    const inlet = await harness(LslMarkerInlet, { Name: "PyMarkers", Labels: labels });
    markers.start();
    inlet.start();
    poll(inlet);
    const py = peer("markers");
    expect(await py.next("markers-ready")).toMatchObject({ format: 3, type: "Markers" });
    const t = wall();
    markers.push(Frame.from(vectorShape(1), [t, t + 0.5, t + 1, t + 1.5], [[0], [1], [NaN], [5]]));
    py.proc.stdin!.write("4\n");
    const got = (await py.next("markers-received")) as { markers: [string, number][] };
    const sent = (await py.next("markers-sent")) as { t0: number };
    await until(() => inlet.output().t.length >= 5, "5 markers in");
    const offset = measureOffset(wall, () => lsl.localClock(), 21)!.offset;

    expect(got.markers.map((m) => m[0])).toEqual(["rest", "power", "stop", "5"]);
    got.markers.forEach((m, i) => {
      expect(Math.abs(m[1] - (t + i * 0.5 + offset))).toBeLessThan(0.001);
    });
    const rec = inlet.output();
    expect(rec.v.map((v) => v[0])).toEqual([0, 1, 7, NaN, 1]);
    rec.t.forEach((ti, i) =>
      expect(Math.abs(ti - (sent.t0 + i * 0.1 - offset))).toBeLessThan(0.001),
    );
    inlet.tick(wall() + 1);
    expect(inlet.text).toMatch(/5 samples.*last 'power'.*1 not a label or number/);
  });
});

describe.runIf(available)(
  "Lab Streaming Layer between MOSAIC blocks (liblsl in this process)",
  () => {
    test("int32 markers: rounded codes, NaN as NanCode, clamped values counted", async () => {
      const markers = await harness(
        LslMarkers,
        { Name: "Codes", Format: "int32", SourceId: "codes-1" },
        { channels: 2, rate: 0 },
      );
      const inlet = await harness(LslMarkerInlet, { Name: "Codes", Type: "" });
      markers.start();
      inlet.start();
      poll(inlet);
      await until(() => /receiving 'Codes'/.test(inlet.text), "the inlet to open", 15_000);
      await sleep(300);
      const t = wall();
      markers.push(
        Frame.from(
          vectorShape(2),
          [t, t + 0.01, t + 0.02],
          [
            [3.4, 0],
            [NaN, 0],
            [1e12, 0],
          ],
        ),
      );
      await until(() => inlet.output().t.length >= 3, "3 codes");
      expect(inlet.output().v.map((v) => v[0])).toEqual([3, -1, 2147483647]);
      markers.push(Frame.from(vectorShape(2), [wall()], [[1, 0]]));
      markers.instance.stop?.();
      expect(markers.text).toMatch(/4 sent, last '1', 1 clamped to int32/);
    });

    test("a stream of another channel count is refused with the reason; a lost stream recovers", async () => {
      const params = { Name: "Four", Format: "float32", SourceId: "four-1" };
      let outlet = await harness(LslOutlet, params, { channels: 4, rate: 100 });
      const wrong = await harness(LslInlet, { Name: "Four", Channels: 3 });
      const inlet = await harness(LslInlet, { Name: "Four", Channels: 4 });
      outlet.start();
      wrong.start();
      inlet.start();
      poll(wrong, inlet);
      await until(() => /has 4 channels; Channels is 3/.test(wrong.text), "the refusal", 15_000);
      await until(() => /receiving 'Four'/.test(inlet.text), "the inlet to open", 15_000);
      await sleep(300);
      const send = (h: BlockHarness, k: number) =>
        h.push(Frame.from(vectorShape(4), [wall()], [[k, k + 0.5, -k, 1 / 4]]));
      send(outlet, 1);
      await until(() => inlet.output().t.length === 1, "one sample");
      expect(inlet.output().v[0]).toEqual([1, 1.5, -1, 0.25]);
      // The source goes away: after 1 s of silence the stream reads lost.
      outlet.instance.stop?.();
      await until(() => /^lost 'Four'.*lost 1×, recovered 0×/.test(inlet.text), "lost", 10_000);
      // The same source id comes back: liblsl reconnects and samples flow again.
      outlet = await harness(LslOutlet, params, { channels: 4, rate: 100 });
      outlet.start();
      const feeder = setInterval(() => send(outlet, 2), 20);
      cleanup.push(() => clearInterval(feeder));
      await until(() => /recovered 1×/.test(inlet.text), "recovered", 20_000);
      expect(inlet.output().v.at(-1)).toEqual([2, 2.5, -2, 0.25]);
    });

    test("two streams match: the inlet says which it reads and how to choose", async () => {
      const one = await harness(
        LslOutlet,
        { Name: "Twin", SourceId: "twin-1" },
        { channels: 1, rate: 10 },
      );
      const two = await harness(
        LslOutlet,
        { Name: "Twin", SourceId: "twin-2" },
        { channels: 1, rate: 10 },
      );
      one.start();
      two.start();
      await sleep(500);
      const inlet = await harness(LslInlet, { Name: "Twin", Channels: 1 });
      inlet.start();
      poll(inlet);
      await until(() => inlet.warnings.length > 0, "the warning", 15_000);
      expect(inlet.warnings[0]).toMatch(
        /^2 streams match name='Twin': reading the one on .* \(source id 'twin-[12]'\); narrow it with SourceId or a Predicate$/,
      );
    });

    test("without the bridge (the browser build) the blocks say so and nothing breaks", async () => {
      for (const [def, params, input] of [
        [LslOutlet, { Name: "X" }, { channels: 2, rate: 10 }],
        [LslMarkers, {}, { channels: 1, rate: 0 }],
        [LslInlet, { Name: "X", Channels: 2 }, undefined],
        [LslMarkerInlet, {}, undefined],
      ] as const) {
        const h = await harness(def, params, input, false);
        h.start();
        if (input)
          h.push(
            Frame.from(vectorShape(input.channels), [wall()], [new Array(input.channels).fill(1)]),
          );
        expect(h.text).toMatch(/Lab Streaming Layer is unavailable here \(the browser build/);
        expect(h.errors).toEqual([]);
      }
    });
  },
);

describe.runIf(available)("mosaic run of pipelines/examples/lsl-outlet.yaml", () => {
  test("pylsl reads its EMG stream (32 ch, 2 kHz, 1/2000 s apart) and the Stimulus's markers", async () => {
    requireBuild();
    const run = spawn(
      process.execPath,
      [CLI, "run", join(ROOT, "pipelines", "examples", "lsl-outlet.yaml"), "--duration", "8"],
      { cwd: ROOT, env: { ...process.env, LSLAPICFG: CFG, NO_COLOR: "1" } },
    );
    let out = "";
    run.stdout.on("data", (d: Buffer) => (out += d.toString()));
    run.stderr.on("data", (d: Buffer) => (out += d.toString()));
    cleanup.push(() => {
      if (run.exitCode === null) run.kill();
    });
    const py = peer("example", "5");
    const got = await py.next("example-read", 40_000);
    expect(got).toMatchObject({
      channels: 32,
      rate: 2000,
      format: 1, // pylsl's cf_float32
      labels: Array.from({ length: 32 }, (_, c) => `Ch${c + 1}`),
    });
    // A loaded machine may start late or pause; a healthy one gets ~10,000 samples in 5 s.
    expect(got.samples as number).toBeGreaterThan(2000);
    expect(got.step_min as number).toBeCloseTo(1 / 2000, 6);
    expect(got.step_max as number).toBeCloseTo(1 / 2000, 6);
    // The capture of the first task (fist) starts 2 s after the start and ends 1 s later.
    expect((got.markers as string[]).slice(0, 2)).toEqual(["fist", "stop"]);
    const code = await new Promise<number | null>((r) => run.on("exit", (c) => r(c)));
    expect(code, out).toBe(0);
    expect(out).toMatch(/LslOutlet .*streaming 'MosaicEMG' \(32 ch float32 @ 2000 Hz\)/);
  });
});

/** `mosaic run FILE --json` with the test's LSL configuration; resolves with its exit and output. */
function runJson(file: string, seconds: number): Promise<{ code: number | null; out: string }> {
  const run = spawn(process.execPath, [CLI, "run", file, "--duration", String(seconds), "--json"], {
    cwd: ROOT,
    env: { ...process.env, LSLAPICFG: CFG, NO_COLOR: "1" },
  });
  let out = "";
  run.stdout.on("data", (d: Buffer) => (out += d.toString()));
  cleanup.push(() => {
    if (run.exitCode === null) run.kill();
  });
  return new Promise((r) => run.on("exit", (code) => r({ code, out })));
}

/** A copy of an example in `dir` whose `blocks` log to `dir/logs/` (their Path). */
function withLogs(example: string, dir: string, blocks: readonly string[]): string {
  const doc = parse(readFileSync(join(ROOT, "pipelines", "examples", example), "utf8")) as Record<
    string,
    Record<string, unknown>
  >;
  for (const b of blocks) doc[b]!.Path = "logs/";
  mkdirSync(dir, { recursive: true });
  const file = join(dir, example);
  writeFileSync(file, stringify(doc));
  return file;
}

const logLines = (file: string): { t: number; v: string }[] =>
  readFileSync(file, "utf8")
    .trim()
    .split("\n")
    .map((l) => {
      const i = l.indexOf(",");
      return { t: Number(l.slice(0, i)), v: l.slice(i + 1) };
    });

/** Every line `got` has is `sent`'s, in order and without a gap, at the same time (1 ms). */
function expectSameSamples(
  sent: { t: number; v: string }[],
  got: { t: number; v: string }[],
): void {
  expect(got.length).toBeGreaterThan(0);
  const j = sent.findIndex((s) => Math.abs(s.t - got[0]!.t) < 0.001);
  expect(j).toBeGreaterThanOrEqual(0);
  let wrong = 0;
  let late = 0;
  got.forEach((g, i) => {
    const s = sent[j + i];
    if (!s || s.v !== g.v) wrong++;
    else late = Math.max(late, Math.abs(s.t - g.t));
  });
  expect(wrong).toBe(0);
  expect(late).toBeLessThan(0.001);
}

describe.runIf(available)("two MOSAIC processes connected by LSL", () => {
  test(
    "the Myo bench pipeline split across them: every sample arrives exact and the blocks keep up",
    { timeout: 90_000 },
    async () => {
      requireBuild();
      const dir = tempDir("mosaic-lsl-split-");
      const acquire = withLogs("lsl-split-acquire.yaml", join(dir, "a"), ["Myo", "Cues"]);
      const processing = withLogs("lsl-split-process.yaml", join(dir, "b"), ["Myo", "Cues"]);
      const a = runJson(acquire, 14);
      await sleep(1000);
      const b = await runJson(processing, 10);
      const ra = await a;
      expect(ra.code, ra.out.slice(-2000)).toBe(0);
      expect(b.code, b.out.slice(-2000)).toBe(0);

      // No sample lost or changed between the processes (double64: values exact as logged).
      const emg = logLines(join(dir, "b", "logs", "Myo.txt"));
      expectSameSamples(logLines(join(dir, "a", "logs", "Myo.txt")), emg);
      expectSameSamples(
        logLines(join(dir, "a", "logs", "Cues.txt")),
        logLines(join(dir, "b", "logs", "Cues.txt")),
      );
      // Resolving and the first clock offset take about a second; then 200 Hz.
      expect(emg.length).toBeGreaterThan(200 * 6);

      // Every block of the processing side runs at its rate and keeps up (shares over the run,
      // after the first 2 s; 96-100 % here under a load average of 7 on 2 cores).
      const lines = jsonLines(b.out);
      const summary = lines.find((l) => l.type === "summary") as unknown as {
        blocks: { name: string; rate: number; desiredRate: number }[];
      };
      for (const blk of summary.blocks)
        expect(blk.rate, blk.name).toBeGreaterThan(0.95 * blk.desiredRate);
      const snaps = lines.filter((l) => l.type === "telemetry");
      const t0 = snaps[0]!.t as number;
      const later = snaps
        .filter((l) => (l.t as number) > t0 + 2)
        .map(
          (l) =>
            (typeof l.blocks === "string" ? JSON.parse(l.blocks) : l.blocks) as {
              name: string;
              status: string;
            }[],
        );
      for (const blk of summary.blocks) {
        const keeping = later.filter((bl) =>
          KEEPING_UP.includes(bl.find((x) => x.name === blk.name)!.status),
        ).length;
        expect(keeping / later.length, blk.name).toBeGreaterThan(0.8);
      }
    },
  );
});

test("a missing liblsl is reported with where it was looked for and what to do", () => {
  expect(liblslCandidates({ MOSAIC_LIBLSL: "/nowhere/liblsl.so" })).toEqual(["/nowhere/liblsl.so"]);
  const tried = liblslCandidates({});
  expect(tried.some((p) => p.includes(join("native-bridges", "python", ".venv")))).toBe(true);
  const msg = liblslMissing(["/a/liblsl.so", "/b/liblsl.so"]);
  expect(msg).toContain("/a/liblsl.so, /b/liblsl.so");
  expect(msg).toContain("MOSAIC_LIBLSL");
  expect(msg).toContain("npm run setup");
});
