/**
 * `mosaic bench`: replay throughput — a generated recording played through the replay pipeline
 * on the virtual clock (`mosaic run COPY --json --clock virtual --duration V`), V picked by a short
 * calibration run so the measured run lasts about `targetWall` seconds.
 */
import { join, relative } from "node:path";
import { writeEmgCsv, writeReplayPipeline } from "./bench-data";
import { runChild, type ChildRun } from "./bench-proc";
import type { ReplayResult } from "./bench-types";
import { loadAvg, progress, round } from "./bench-util";
import type { ReplayDef } from "./bench-workloads";

/** The replay throughput target, channel-samples per second (DESIGN.md §6). */
const REPLAY_TARGET = 20e6;

export interface ReplayOptions {
  cli: string;
  root: string;
  /** Where the recording and the pipeline copy are written. */
  tmp: string;
  quick: boolean;
  /** Wall seconds the measured run should last. */
  targetWall: number;
}

/** The recording and the pipeline copy that plays it. */
interface Recording {
  bytes: number;
  template: string;
  pipe: string;
}

/** One replay run. */
interface Attempt {
  run: ChildRun;
  args: string[];
  virtualSeconds: number;
  wall: number;
  frames: number;
  /** Channel-samples per wall second. */
  rate: number;
  error: string | undefined;
}

export async function runReplay(def: ReplayDef, o: ReplayOptions): Promise<ReplayResult> {
  const rec = await writeRecording(def, o);
  const before = loadAvg();
  const { virtualSeconds, calibration } = await calibrate(def, o, rec);
  progress(`${def.id}: ${virtualSeconds} virtual s`);
  const m = await attempt(def, o, rec, virtualSeconds);
  const after = loadAvg();
  return {
    kind: "replay",
    id: def.id,
    title: def.title,
    file: relative(o.root, rec.template),
    args: m.args.map((a) => (a === rec.pipe ? `<tmp>/replay-${def.channels}.yaml` : a)),
    ok: !m.error,
    ...(m.error ? { error: m.error } : {}),
    channels: def.channels,
    rate: def.rate,
    recordingSeconds: def.recordingSeconds,
    recordingBytes: rec.bytes,
    virtualSeconds,
    wallSeconds: round(m.wall, 4),
    loadSeconds: round(m.run.loadSeconds),
    channelSamplesPerSecond: Math.round(m.rate),
    framesPerSecond: Math.round(m.frames / m.wall),
    ...(calibration ? { calibration } : {}),
    peakRssMiB: round(m.run.peakRssKiB / 1024, 1),
    loadAvgBefore: before,
    loadAvgAfter: after,
    lingerSeconds: round(m.run.lingerSeconds),
    killedAfterSummary: m.run.killedAfterSummary,
  };
}

async function writeRecording(def: ReplayDef, o: ReplayOptions): Promise<Recording> {
  const csvName = `rec-${def.channels}ch-${def.rate}hz.csv`;
  progress(
    `${def.id}: generating a ${def.channels}-channel ${def.recordingSeconds}-s recording at ${def.rate} Hz`,
  );
  const { bytes } = await writeEmgCsv(
    join(o.tmp, csvName),
    def.channels,
    def.rate,
    def.recordingSeconds,
    def.channels,
  );
  const template = join(o.root, "pipelines", "bench", "replay.yaml");
  const pipe = writeReplayPipeline(
    template,
    o.tmp,
    `replay-${def.channels}.yaml`,
    csvName,
    def.rate,
  );
  return { bytes, template, pipe };
}

/**
 * The virtual seconds for the measured run: from the target rate with `--quick`, else from a
 * calibration run of about half a second at the target rate.
 */
async function calibrate(
  def: ReplayDef,
  o: ReplayOptions,
  rec: Recording,
): Promise<{ virtualSeconds: number; calibration?: ReplayResult["calibration"] }> {
  const perVirtualSecond = def.channels * def.rate;
  const v = Math.max(5, Math.round((REPLAY_TARGET * o.targetWall) / perVirtualSecond));
  if (o.quick) return { virtualSeconds: v };
  const cal = Math.max(5, Math.round((REPLAY_TARGET * 0.5) / perVirtualSecond));
  progress(`${def.id}: calibration, ${cal} virtual s`);
  const c = await attempt(def, o, rec, cal);
  if (c.error) return { virtualSeconds: v };
  return {
    virtualSeconds: Math.min(
      1e6,
      Math.max(cal, Math.round((c.rate * o.targetWall) / perVirtualSecond)),
    ),
    calibration: {
      virtualSeconds: cal,
      wallSeconds: round(c.wall),
      channelSamplesPerSecond: Math.round(c.rate),
    },
  };
}

async function attempt(
  def: ReplayDef,
  o: ReplayOptions,
  rec: Recording,
  virtualSeconds: number,
): Promise<Attempt> {
  const args = [
    "run",
    rec.pipe,
    "--json",
    "--clock",
    "virtual",
    "--duration",
    String(virtualSeconds),
  ];
  const run = await runChild({
    cli: o.cli,
    args,
    cwd: o.root,
    steadySeconds: 1e6,
    warmup: false,
    timeoutSeconds: 180,
  });
  const s = run.summary;
  const source = s?.blocks.find((b) => b.type === "FilePlayer");
  const samples = (source?.events ?? 0) * def.channels;
  const wall = s?.wallSeconds ?? NaN;
  let error = run.error;
  if (!error && s && s.reason !== "finished") error = `run stopped: ${s.reason}`;
  if (!error && !(samples > 0)) error = "the FilePlayer emitted nothing";
  return {
    run,
    args,
    virtualSeconds,
    wall,
    frames: source?.events ?? 0,
    rate: samples / wall,
    error,
  };
}
