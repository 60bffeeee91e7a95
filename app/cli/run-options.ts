/**
 * `mosaic run`'s options: the command line read and checked (the first wrong value is said, in
 * the words `mosaic run` has always used, exit 2), and the host's options made from it. Also the
 * `--simulate-devices [--keep-network]` pair that `mosaic validate` shares.
 */
import { resolve } from "node:path";
import { parseArgs } from "node:util";
import { NilsPodSimulator } from "../devices/nilspod-simulator";
import type { BleBridge } from "../engine/io";
import type { SimulateOptions } from "../engine/pipeline/simulate";
import type { HostOptions } from "../host/host";
import { DEFAULT_TELEMETRY_HZ } from "../host/worker-protocol";

export const SIMULATE_ARGS = {
  "simulate-devices": { type: "boolean", default: false },
  "keep-network": { type: "boolean", default: false },
} as const;

/** `--simulate-devices [--keep-network]` as the host's option (undefined: off). */
export function simulateOption(v: {
  "simulate-devices"?: boolean;
  "keep-network"?: boolean;
}): SimulateOptions | undefined | string {
  if (v["keep-network"] && !v["simulate-devices"]) {
    return "--keep-network only applies with --simulate-devices";
  }
  return v["simulate-devices"] ? { keepNetwork: v["keep-network"] === true } : undefined;
}

/** A simulated Bluetooth LE peripheral, closed when the run ends. */
export type SimulatedBle = BleBridge & { close(): void };

/** Peripherals `--simulate-ble` can play behind the host's Bluetooth LE bridge. */
const SIMULATED_BLE: Record<string, () => SimulatedBle> = {
  nilspod: () => new NilsPodSimulator({ realtime: true }),
};

/**
 * `--simulate-ble NAME`: what starts the simulated peripheral (once every option is checked, so a
 * refused command line leaves none running), or why not (undefined: off).
 */
function bleOption(name: string | undefined): (() => SimulatedBle) | undefined | string {
  if (name === undefined) return undefined;
  return (
    SIMULATED_BLE[name] ??
    `--simulate-ble: no simulated peripheral '${name}' (peripherals: ${Object.keys(SIMULATED_BLE).join(", ")})`
  );
}

export interface RunOptions {
  file: string;
  mode: "realtime" | "virtual";
  /** Seconds (virtual ones under the virtual clock); undefined: until the input ends. */
  duration: number | undefined;
  /** The virtual clock's start, UNIX seconds. */
  start: number;
  /** Seconds after which the timing statistics are reset (0: never). */
  warmup: number;
  telemetryHz: number;
  batchingMs: number | undefined;
  json: boolean;
  precision: boolean;
  logDir: string | undefined;
  simulate: SimulateOptions | undefined;
  ble: SimulatedBle | undefined;
}

/** The command line as parseArgs reads it (unknown options and missing values throw). */
function readArgs(args: string[]) {
  return parseArgs({
    args,
    allowPositionals: true,
    options: {
      duration: { type: "string" },
      clock: { type: "string", default: "realtime" },
      json: { type: "boolean", default: false },
      precision: { type: "boolean", default: false },
      "batching-ms": { type: "string" },
      "log-dir": { type: "string" },
      start: { type: "string" },
      warmup: { type: "string" },
      "telemetry-hz": { type: "string" },
      "simulate-ble": { type: "string" },
      ...SIMULATE_ARGS,
    },
  });
}

type RunValues = ReturnType<typeof readArgs>["values"];

/** The numbers `mosaic run` takes, each checked in turn: the values, or the first one wrong. */
function runNumbers(
  values: RunValues,
): Pick<RunOptions, "duration" | "start" | "warmup" | "telemetryHz" | "batchingMs"> | string {
  const duration = values.duration !== undefined ? Number(values.duration) : undefined;
  if (duration !== undefined && !(duration > 0)) {
    return `mosaic run: --duration must be a positive number of seconds, not '${values.duration}'`;
  }
  const start = values.start !== undefined ? Number(values.start) : 0;
  if (!Number.isFinite(start)) {
    return `mosaic run: --start must be a number of seconds, not '${values.start}'`;
  }
  const warmup = values.warmup !== undefined ? Number(values.warmup) : 0;
  if (!(warmup >= 0)) {
    return `mosaic run: --warmup must be a number of seconds, not '${values.warmup}'`;
  }
  const telemetryHz =
    values["telemetry-hz"] !== undefined ? Number(values["telemetry-hz"]) : DEFAULT_TELEMETRY_HZ;
  if (!(telemetryHz > 0 && telemetryHz <= 100)) {
    return `mosaic run: --telemetry-hz must be between 0 and 100, not '${values["telemetry-hz"]}'`;
  }
  const batchingMs =
    values["batching-ms"] !== undefined ? Number(values["batching-ms"]) : undefined;
  if (batchingMs !== undefined && !(batchingMs >= 0 && batchingMs <= 1000)) {
    return `mosaic run: --batching-ms must be between 0 and 1000 milliseconds, not '${values["batching-ms"]}'`;
  }
  return { duration, start, warmup, telemetryHz, batchingMs };
}

/**
 * `mosaic run`'s options, or the line that says what is wrong with them (exit 2). The checks go
 * in this order: the simulation options, `--simulate-ble`, one FILE, `--clock`, the numbers; the
 * simulated peripheral starts once they all passed.
 */
export function parseRunOptions(args: string[]): RunOptions | string {
  const { values, positionals } = readArgs(args);
  const simulate = simulateOption(values);
  if (typeof simulate === "string") return `mosaic run: ${simulate}`;
  const ble = bleOption(values["simulate-ble"]);
  if (typeof ble === "string") return `mosaic run: ${ble}`;
  const file = positionals[0];
  if (!file || positionals.length > 1) {
    return "usage: mosaic run FILE [--duration S] [--clock realtime|virtual] [--json]";
  }
  const mode = values.clock;
  if (mode !== "realtime" && mode !== "virtual") {
    return `mosaic run: --clock must be realtime or virtual, not '${mode}'`;
  }
  const numbers = runNumbers(values);
  if (typeof numbers === "string") return numbers;
  return {
    file,
    mode,
    ...numbers,
    json: values.json,
    precision: values.precision,
    logDir: values["log-dir"],
    simulate,
    ble: ble?.(),
  };
}

/** The host's options for the run (only those the command line set, besides the defaults). */
export function hostOptions(o: RunOptions): HostOptions {
  return {
    mode: o.mode,
    precision: o.precision,
    ...(o.batchingMs !== undefined ? { batchingS: o.batchingMs / 1000 } : {}),
    ...(o.logDir !== undefined ? { logDir: resolve(o.logDir) } : {}),
    virtualStart: o.start,
    telemetryHz: o.telemetryHz,
    ...(o.mode === "virtual" && o.duration !== undefined ? { virtualDuration: o.duration } : {}),
    ...(o.simulate ? { simulateDevices: o.simulate } : {}),
    ...(o.ble ? { ble: o.ble } : {}),
  };
}
