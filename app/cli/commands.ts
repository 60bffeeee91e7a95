/**
 * `mosaic`: run and check pipelines headless.
 *
 *   mosaic validate FILE...            exit 0 when valid, 2 with file:line:col messages otherwise
 *   mosaic format FILE... [--check]    canonical round trip through the editor's document model
 *   mosaic test-block FILE...          the block contract on a user's block module
 *   mosaic run FILE [options]          live per-block table (or --json lines); Ctrl-C stops cleanly
 *   mosaic bench [options]             the standard performance suite (see `mosaic bench --help`)
 *   mosaic simulate DEVICE [options]   a device simulator (app/devices/) until Ctrl-C
 *   mosaic repair FILE...              makes an interrupted recording (XDF) whole again
 *   mosaic new-block --rust NAME [DIR] a block written in Rust, from templates/rust-block
 */
import { readFileSync, statSync, writeFileSync } from "node:fs";
import { dirname, join, resolve } from "node:path";
import { parseArgs } from "node:util";
import { formatDiagnostic, type Diagnostic } from "../engine/diagnostics";
import type { SimulateOptions } from "../engine/pipeline/simulate";
import { Host, webRoot } from "../host/host";
import type { Served } from "../host/serve";
import { serveStatic } from "../host/web-server";
import { RunConsole, type RunEnd } from "./run-console";
import {
  hostOptions,
  parseRunOptions,
  SIMULATE_ARGS,
  simulateOption,
  type RunOptions,
} from "./run-options";

const VERSION = "0.1.0";

/**
 * The whole help. The commands' modules give their own lines; they are loaded only here and when
 * their command runs, so that `mosaic run` keeps the block catalog, the YAML and schema libraries
 * and the bench out of the main thread (less memory, faster start).
 */
async function helpText(): Promise<string> {
  const [{ testBlockHelp }, { simulateHelp }, { repairHelp }, { newBlockHelp }] = await Promise.all(
    [import("./test-block"), import("./simulate"), import("./repair"), import("./new-block")],
  );
  return `mosaic ${VERSION} — run MOSAIC pipelines headless

Usage:
  mosaic validate FILE... [--simulate-devices [--keep-network]]
      Checks pipeline files (YAML syntax, block types, params, wiring, shapes, files they read).
      Exit 0 when every file is valid, 2 otherwise; messages are file:line:col. With
      --simulate-devices, checks the pipeline as \`mosaic run --simulate-devices\` would run it.
${testBlockHelp()}
  mosaic format FILE... [--check]
      Loads each pipeline through the editor's document model (the code the visual editor saves
      with) and writes it back in canonical form: a no-op on a valid file except that a missing
      final line break is added (comments, key order and styles are kept). An invalid file is
      never written: its messages are printed (file:line:col) and the exit code is 2. --check
      writes nothing and lists the files that would change (exit 1).
  mosaic run FILE [--duration S] [--clock realtime|virtual] [--json] [--precision]
                  [--batching-ms MS] [--log-dir DIR] [--start T] [--warmup S]
                  [--simulate-devices [--keep-network]] [--simulate-ble nilspod]
      Runs a pipeline and shows a live per-block table: desired and actual rate, status
      (on time, lagging, stumbling, idle), compute time and drops. --json prints one JSON object
      per line instead (telemetry at 20 Hz, events, a final summary). Ctrl-C stops cleanly and
      flushes every log. Exit 0 on success, 1 on a runtime failure, 2 on an invalid file.
        --duration S   stop after S seconds (virtual seconds with --clock virtual)
        --clock        realtime (default) or virtual (as fast as possible, deterministic)
        --precision    spin the last ~0.3 ms before each tick (less jitter, more CPU)
        --batching-ms MS  how long timer ticks may wait to go out together (default: the
                       file's Pipeline: { BatchingMs }, else 5); 0 wakes for every tick.
                       Blocks with their own BatchingMs keep it.
        --log-dir DIR  base folder for relative Path logs (default: the pipeline's folder)
        --start T      virtual clock start time, UNIX seconds (default 0)
        --warmup S     reset the timing statistics (ΔT, lateness) after S seconds
        --telemetry-hz N  telemetry (status, rates) per second, default 20 (as the UI);
                       the engine hands it over a quarter second at a time (--json lines
                       come in groups, each report with its own time)
        --simulate-devices  run without hardware: every device block becomes a simulator
                       of the same output shape and rate (EmgSimulator for EMG armbands and
                       probes, ImuSimulator for IMUs), every output device (BlenderArm, Hannes,
                       UdpSender, ROS, a serial port that only writes) a SimulatedOutput that
                       counts what it would have sent; one info line per block says what it
                       became (docs/mosaic-compatibility.md lists them)
        --keep-network  with --simulate-devices: keep the blocks that talk over UDP and ROS
                       (BlenderArm, HannesGUI, UdpSender, ROS), so local receivers get the data
        --simulate-ble nilspod  a simulated NilsPod behind the Bluetooth LE bridge (no adapter
                       needed): the NilsPod block finds it and speaks its protocol to it
  mosaic web [--port N] [--host ADDR] [--pipeline FILE]
      Serves the browser build (dist/web: the UI with the engine in the page's Web Worker, on
      simulated signals) and prints its URL; --pipeline preselects one of pipelines/ (default
      the demo). Ctrl-C stops it.
  mosaic serve [FILE] [--port N] [--host ADDR] [--no-start] [--simulate-devices]
               [--data-dir DIR]
      Runs the engine here (with UDP, serial and the other device bridges) and serves the UI
      for it: the same page as \`mosaic web\`, connected over a WebSocket that needs the token
      in the printed URL. FILE is loaded and started (--no-start: only loaded); several tabs
      may watch the same engine. Binds 127.0.0.1 unless --host says otherwise.
      --simulate-devices loads FILE with simulated devices (the page's switch does the same).
      Pipelines loaded from the page read and write only in pipelines/, FILE's folder and
      --data-dir DIR (data and model files, Path logs, Python modules).
  mosaic bench [--duration S] [--warmup S] [--only NAME[,NAME]] [--out DIR] [--quick]
      Runs the standard benchmarks and writes bench/results/*.json and *.md.
  mosaic simulate DEVICE [options]
      Runs a device's simulator on this machine, written from its protocol, so that a pipeline
      can be demonstrated without the hardware; prints where it listens, runs until Ctrl-C.
${simulateHelp()}
${repairHelp()}
${newBlockHelp()}
  mosaic --help | --version
`;
}

function out(s: string): void {
  process.stdout.write(s + "\n");
}
function err(s: string): void {
  process.stderr.write(s + "\n");
}

async function cmdValidate(args: string[]): Promise<number> {
  let files: string[];
  let simulate: SimulateOptions | undefined;
  try {
    const r = parseArgs({ args, allowPositionals: true, options: SIMULATE_ARGS });
    files = r.positionals;
    const s = simulateOption(r.values);
    if (typeof s === "string") throw new Error(s);
    simulate = s;
  } catch (e) {
    err(`mosaic validate: ${(e as Error).message}`);
    return 2;
  }
  if (files.length === 0) {
    err("mosaic validate: give at least one pipeline file");
    return 2;
  }
  // Loaded on demand: `mosaic run` keeps the block catalog out of the main thread.
  const { loadDspFromDisk, validatePipelineFile } = await import("../host/validate");
  loadDspFromDisk();
  let bad = false;
  for (const f of files) {
    const ds = await validatePipelineFile(f, simulate);
    for (const d of ds) err(formatDiagnostic(d));
    const errors = ds.filter((d) => d.severity === "error").length;
    if (errors > 0) {
      bad = true;
      err(`${f}: invalid (${errors} error${errors === 1 ? "" : "s"})`);
    } else {
      out(`${f}: ok`);
    }
  }
  return bad ? 2 : 0;
}

async function cmdFormat(args: string[]): Promise<number> {
  const parsed = parseFormatArgs(args);
  if (typeof parsed === "number") return parsed;
  const { check, files } = parsed;
  // The same full check as `mosaic validate` (loader, then every block instantiated).
  const { loadDspFromDisk, validatePipelineFile } = await import("../host/validate");
  const { PipelineDocument } = await import("../engine/pipeline/document");
  loadDspFromDisk();
  const tools: FormatTools = { validate: validatePipelineFile, Document: PipelineDocument };
  let invalid = false;
  let changed = 0;
  for (const f of files) {
    const outcome = await formatFile(f, check, tools);
    if (outcome === "invalid") invalid = true;
    else if (outcome === "changed") changed++;
  }
  if (invalid) return 2;
  return check && changed > 0 ? 1 : 0;
}

/** What `mosaic format` uses, loaded on demand: validatePipelineFile and PipelineDocument. */
interface FormatTools {
  validate(file: string): Promise<Diagnostic[]>;
  Document: { parse(text: string, file: string): { normalize(): void; toString(): string } };
}

/** What came of one file: invalid (or unreadable, unwritable), unchanged, changed (or would be). */
type FormatOutcome = "invalid" | "unchanged" | "changed";

/** `mosaic format`'s `--check` and files, or the exit status after a usage error. */
function parseFormatArgs(args: string[]): { check: boolean; files: string[] } | number {
  let check: boolean;
  let files: string[];
  try {
    const r = parseArgs({
      args,
      allowPositionals: true,
      options: { check: { type: "boolean", default: false } },
    });
    check = r.values.check;
    files = r.positionals;
  } catch (e) {
    err(`mosaic format: ${(e as Error).message}`);
    return 2;
  }
  if (files.length === 0) {
    err("usage: mosaic format FILE... [--check]");
    return 2;
  }
  return { check, files };
}

/** Validates, formats and (unless `check`) rewrites one file, saying so on stdout or stderr. */
async function formatFile(f: string, check: boolean, tools: FormatTools): Promise<FormatOutcome> {
  if (!(await validForFormat(f, tools.validate))) return "invalid";
  const r = formatSource(f, tools.Document);
  if (!r) return "invalid";
  if (r.formatted === r.source) {
    out(`${f}: unchanged`);
    return "unchanged";
  }
  if (check) {
    out(`${f}: would change`);
    return "changed";
  }
  try {
    writeFileSync(f, r.formatted);
  } catch (e) {
    err(`${f}: cannot write: ${(e as Error).message}`);
    return "invalid";
  }
  out(`${f}: formatted`);
  return "changed";
}

/** True when the file has no errors; otherwise prints them and says it is not formatted. */
async function validForFormat(f: string, validate: FormatTools["validate"]): Promise<boolean> {
  const errors = (await validate(f)).filter((d) => d.severity === "error");
  if (errors.length === 0) return true;
  for (const d of errors) err(formatDiagnostic(d));
  err(`${f}: invalid (${errors.length} error${errors.length === 1 ? "" : "s"}), not formatted`);
  return false;
}

/** The file's text and its canonical form; undefined (after saying why) when it cannot be read. */
function formatSource(
  f: string,
  Document: FormatTools["Document"],
): { source: string; formatted: string } | undefined {
  try {
    const source = readFileSync(f, "utf8");
    const doc = Document.parse(source, f);
    doc.normalize();
    return { source, formatted: doc.toString() };
  } catch (e) {
    err(`${f}: ${(e as Error).message}`);
    return undefined;
  }
}

/**
 * `mosaic run FILE [options]`: loads the pipeline, runs it until its input ends, its duration,
 * Ctrl-C or a fatal error, and shows it as it goes (RunConsole). Exit 0 on success, 1 on a
 * runtime failure, 2 on wrong options or an invalid file.
 */
async function cmdRun(args: string[]): Promise<number> {
  const o = parseRunOptions(args);
  if (typeof o === "string") {
    err(o);
    return 2;
  }
  const view = new RunConsole(o.json, out, err);
  const { host, diagnostics } = await Host.load(o.file, hostOptions(o), view.events());
  for (const d of diagnostics) err(formatDiagnostic(d));
  if (!host) {
    err(`${o.file}: invalid pipeline, not started`);
    return 2;
  }
  if (
    o.mode === "virtual" &&
    o.duration === undefined &&
    !host.plan?.blocks.some((b) => b.finite)
  ) {
    err(
      "note: under the virtual clock without --duration and without a finite source (a FilePlayer " +
        "without Loop), the run goes on until Ctrl-C",
    );
  }
  const run = await runUntilStopped(host, o, view);
  const final = await host.stop();
  o.ble?.close();
  return view.finish(final, {
    ...run,
    logs: host.logFiles,
    virtualDuration: o.mode === "virtual" && o.duration !== undefined,
  });
}

/**
 * Starts the host and waits for the run to stop: Ctrl-C (SIGINT, SIGTERM), the realtime
 * `--duration`, or the view's own reasons (input ended, fatal error). After `--warmup` the
 * timing statistics are reset and the measured time starts again.
 */
async function runUntilStopped(
  host: Host,
  o: RunOptions,
  view: RunConsole,
): Promise<Pick<RunEnd, "reason" | "wallSeconds" | "measuredSeconds">> {
  const onSig = (): void => view.stop("interrupted");
  process.once("SIGINT", onSig);
  process.once("SIGTERM", onSig);
  const redraw = view.startRedrawing();
  const timer =
    o.mode === "realtime" && o.duration !== undefined
      ? setTimeout(() => view.stop("duration"), o.duration * 1000)
      : undefined;
  const t0 = performance.now();
  let measuredFrom = t0;
  const warm =
    o.warmup > 0
      ? setTimeout(() => {
          measuredFrom = performance.now();
          void host.control({ op: "resetTiming" });
          view.warmupDone();
        }, o.warmup * 1000)
      : undefined;
  host.start();
  const reason = await view.stopped;
  const wallSeconds = (performance.now() - t0) / 1000;
  const measuredSeconds = (performance.now() - measuredFrom) / 1000;
  if (warm) clearTimeout(warm);
  if (timer) clearTimeout(timer);
  if (redraw) clearInterval(redraw);
  process.off("SIGINT", onSig);
  process.off("SIGTERM", onSig);
  return { reason, wallSeconds, measuredSeconds };
}

async function cmdWeb(args: string[]): Promise<number> {
  const { values } = parseArgs({
    args,
    options: {
      port: { type: "string", default: "8321" },
      host: { type: "string", default: "127.0.0.1" },
      pipeline: { type: "string" },
    },
  });
  const port = portNumber("web", values.port);
  if (port === undefined) return 2;
  const root = webRoot();
  if (!root) {
    err("mosaic web: the browser build is missing (dist/web): run `npm run build` first");
    return 1;
  }
  let server;
  try {
    server = await serveStatic(root, port, values.host);
  } catch (e) {
    err(`mosaic web: ${(e as Error).message}`);
    return 1;
  }
  const url =
    server.url + (values.pipeline ? `?pipeline=${encodeURIComponent(values.pipeline)}` : "");
  out(`MOSAIC is at ${url}`);
  out("(the pipeline runs in the page; Ctrl-C stops this server)");
  await untilInterrupted();
  await server.close();
  return 0;
}

/** `--port` as a port number; undefined (after saying why) when it is not one. */
function portNumber(cmd: string, value: string): number | undefined {
  const port = Number(value);
  if (Number.isInteger(port) && port >= 0 && port <= 65535) return port;
  err(`mosaic ${cmd}: --port must be a port number, not '${value}'`);
  return undefined;
}

/** Resolves on Ctrl-C (SIGINT) or SIGTERM. */
function untilInterrupted(): Promise<void> {
  return new Promise<void>((r) => {
    process.once("SIGINT", r);
    process.once("SIGTERM", r);
  });
}

/** What `mosaic serve` was asked to do, its options checked. */
interface ServeArgs {
  port: number;
  host: string;
  root: string;
  dataDir: string | undefined;
  /** The pipeline to load at start, and its text. */
  file: string | undefined;
  source: string | undefined;
  start: boolean;
  simulateDevices: boolean;
}

/** Parses and checks `mosaic serve`'s arguments; an exit code (after saying why) when they fail. */
function parseServeArgs(args: string[]): ServeArgs | number {
  const { values, positionals } = parseArgs({
    args,
    allowPositionals: true,
    options: {
      port: { type: "string", default: "8321" },
      host: { type: "string", default: "127.0.0.1" },
      "no-start": { type: "boolean", default: false },
      "simulate-devices": { type: "boolean", default: false },
      "data-dir": { type: "string" },
    },
  });
  const dataDir = values["data-dir"] !== undefined ? resolve(values["data-dir"]) : undefined;
  if (dataDir !== undefined && !statSync(dataDir, { throwIfNoEntry: false })?.isDirectory()) {
    err(`mosaic serve: --data-dir ${dataDir} is not a folder`);
    return 2;
  }
  const port = portNumber("serve", values.port);
  if (port === undefined) return 2;
  if (positionals.length > 1) {
    err("mosaic serve: give at most one pipeline file");
    return 2;
  }
  const root = webRoot();
  if (!root) {
    err("mosaic serve: the browser build is missing (dist/web): run `npm run build` first");
    return 1;
  }
  const file = positionals[0] ? resolve(positionals[0]) : undefined;
  let source: string | undefined;
  if (file) {
    try {
      source = readFileSync(file, "utf8");
    } catch (e) {
      err(`mosaic serve: cannot read ${file}: ${(e as Error).message}`);
      return 2;
    }
  }
  return {
    port,
    host: values.host,
    root,
    dataDir,
    file,
    source,
    start: !values["no-start"],
    simulateDevices: values["simulate-devices"],
  };
}

async function cmdServe(args: string[]): Promise<number> {
  const a = parseServeArgs(args);
  if (typeof a === "number") return a;
  const { serve } = await import("../host/serve");
  let served;
  try {
    served = await serve({
      webRoot: a.root,
      port: a.port,
      host: a.host,
      // The UI names its examples "pipelines/x.yaml", relative to the repository (= the web root).
      pipelinesDir: join(dirname(a.root), ".."),
      ...(a.dataDir !== undefined ? { dataDir: a.dataDir } : {}),
      onProblem: (m) => err(`mosaic serve: ${m}`),
    });
  } catch (e) {
    err(`mosaic serve: ${(e as Error).message}`);
    return 1;
  }
  if (!(await loadFirstPipeline(served.hub, a))) {
    await served.close();
    return 2;
  }
  out(`MOSAIC is at ${served.url}`);
  out("(the engine runs in this process; open the URL, token included; Ctrl-C stops it)");
  await untilInterrupted();
  await served.close();
  return 0;
}

/** Loads (and unless --no-start starts) the pipeline given on the command line; false if invalid. */
async function loadFirstPipeline(hub: Served["hub"], a: ServeArgs): Promise<boolean> {
  if (!a.file || a.source === undefined) return true;
  const r = await hub.request({
    type: "load",
    file: a.file,
    source: a.source,
    ...(a.simulateDevices ? { simulateDevices: true } : {}),
  });
  for (const d of r.diagnostics ?? []) err(formatDiagnostic(d));
  if (!r.ok) return false;
  if (a.start) await hub.request({ type: "start" });
  return true;
}

/** A command's arguments that parseArgs refused (unknown option, missing value): its message, exit 2. */
function isArgsError(e: unknown): e is Error {
  return e instanceof Error && String((e as { code?: unknown }).code).startsWith("ERR_PARSE_ARGS");
}

export async function main(argv: string[]): Promise<number> {
  const [cmd, ...rest] = argv;
  if (cmd !== undefined && (rest.includes("--help") || rest.includes("-h"))) {
    out(await helpText());
    return 0;
  }
  try {
    return await dispatch(cmd, rest);
  } catch (e) {
    if (!isArgsError(e)) throw e;
    err(`mosaic ${cmd}: ${e.message.split(". To specify a positional")[0]} (see mosaic --help)`);
    return 2;
  }
}

async function dispatch(cmd: string | undefined, rest: string[]): Promise<number> {
  switch (cmd) {
    case undefined:
    case "-h":
    case "--help":
    case "help":
      out(await helpText());
      return cmd === undefined ? 2 : 0;
    case "-v":
    case "--version":
      out(VERSION);
      return 0;
    case "validate":
      return cmdValidate(rest);
    case "test-block":
      return (await import("./test-block")).cmdTestBlock(rest, out, err);
    case "format":
      return cmdFormat(rest);
    case "run":
      return cmdRun(rest);
    case "bench":
      return (await import("./bench")).runBench(rest);
    case "web":
      return cmdWeb(rest);
    case "serve":
      return cmdServe(rest);
    case "simulate":
      return (await import("./simulate")).cmdSimulate(rest, out, err);
    case "repair":
      return (await import("./repair")).cmdRepair(rest, out, err);
    case "new-block":
      return (await import("./new-block")).cmdNewBlock(rest, out, err);
    default:
      err(
        `mosaic: unknown command '${cmd}' (commands: validate, format, run, web, serve, bench, simulate, repair, new-block; see mosaic --help)`,
      );
      return 2;
  }
}
