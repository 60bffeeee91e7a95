/**
 * `mosaic simulate DEVICE [options]`: runs a device simulator (app/devices/) on this machine so
 * that a pipeline can be demonstrated or tested without the hardware, e.g. the Trigno Control
 * Utility's SDK server for the Delsys block. Each simulator is one entry of `SIMULATORS` (its
 * options, its usage line and how to start it); it prints where it listens and what it streams,
 * and runs until Ctrl-C.
 */
import { parseArgs } from "node:util";
import {
  TCU_FRAME_INTERVAL,
  TCU_PORTS,
  TrignoSimulator,
  pairedSensors,
} from "../devices/trigno-simulator";
import { dlrAdcBtSimulatorOptions, startDlrAdcBtSimulator } from "../devices/dlr-adcbt-simulator";
import {
  hannesDongleSimulatorOptions,
  startHannesDongleSimulator,
} from "../devices/hannes-dongle-simulator";
import { HannesEmgSimulator, hannesEmgSimulatorOptions } from "../devices/hannes-emg-simulator";
import {
  hannesGuiSimulatorOptions,
  startHannesGuiSimulator,
} from "../devices/hannes-gui-simulator";
import {
  MuoviProbeSimulator,
  muoviProbeSimulatorOptions,
  SyncStationSimulator,
  syncStationSimulatorOptions,
} from "../devices/muovi-simulator";
import {
  QuattrocentoSimulator,
  quattrocentoSimulatorOptions,
} from "../devices/quattrocento-simulator";
import {
  SessantaquattroSimulator,
  sessantaquattroSimulatorOptions,
} from "../devices/sessantaquattro-simulator";

type OptionSpec = { type: "string" | "boolean"; default?: string | boolean };
type Values = Record<string, string | boolean | undefined>;

/** A running simulator: what to print, and how to stop it. */
interface Running {
  lines: string[];
  close(): Promise<void>;
}

interface DeviceSimulator {
  /** One line for the help. */
  summary: string;
  /** Its options as `mosaic simulate DEVICE` takes them (the help's usage line). */
  usage: string;
  options: Record<string, OptionSpec>;
  /** Starts it; throws an Error whose message says what is wrong (a taken port, a bad option). */
  start(v: Values, log: (line: string) => void): Promise<Running>;
}

/** A port option: 0…65535 (0: any free port). */
function portOption(v: Values, name: string, fallback: number): number {
  const raw = v[name];
  if (raw === undefined) return fallback;
  const n = Number(raw);
  if (typeof raw !== "string" || !/^\d+$/.test(raw) || n > 65535) {
    throw new Error(`--${name} must be a port number (0 for any free port), not '${String(raw)}'`);
  }
  return n;
}

/** `--sensors 8` (sensors 1…8) or `--sensors 1,3,5`. */
function sensorsOption(raw: string | boolean | undefined): number | number[] {
  if (raw === undefined) return 16;
  const text = String(raw).trim();
  const parts = text.split(",").map((s) => s.trim());
  if (parts.some((s) => !/^\d+$/.test(s))) {
    throw new Error(
      `--sensors takes a count (1…16) or sensor numbers such as 1,2,5; not '${text}'`,
    );
  }
  const nums = parts.map(Number);
  const sensors = parts.length === 1 ? nums[0]! : nums;
  pairedSensors(sensors); // throws with the reason
  return sensors;
}

const hz = (x: number): string => `${x.toFixed(3)} Hz`;

export const SIMULATORS: Record<string, DeviceSimulator> = {
  delsys: {
    summary:
      "Delsys Trigno Control Utility SDK server: command port, Avanti EMG (16 × float32, 1925.926 Hz) and AUX ports",
    usage:
      "[--sensors N|LIST] [--host ADDR] [--command-port P] [--emg-port P] [--aux-port P] [--seed S] [--verbose]",
    options: {
      sensors: { type: "string" },
      host: { type: "string", default: "127.0.0.1" },
      "command-port": { type: "string" },
      "emg-port": { type: "string" },
      "aux-port": { type: "string" },
      seed: { type: "string", default: "1" },
      verbose: { type: "boolean", default: false },
    },
    async start(v, log) {
      const sensors = sensorsOption(v.sensors);
      const seed = Number(v.seed);
      if (!Number.isInteger(seed))
        throw new Error(`--seed must be an integer, not '${String(v.seed)}'`);
      const sim = await TrignoSimulator.start({
        host: String(v.host),
        commandPort: portOption(v, "command-port", TCU_PORTS.command),
        emgPort: portOption(v, "emg-port", TCU_PORTS.emg),
        auxPort: portOption(v, "aux-port", TCU_PORTS.aux),
        sensors,
        seed,
        ...(v.verbose ? { log } : {}),
      });
      const ports = sim.ports;
      const paired = [...sim.paired].sort((a, b) => a - b);
      return {
        lines: [
          `Trigno simulator listening on ${sim.host}: command port ${ports.command}, EMG port ${ports.emg}, AUX port ${ports.aux}`,
          `${paired.length} Avanti sensor${paired.length === 1 ? "" : "s"} paired (${paired.join(", ")}); after START it streams ` +
            `EMG at ${hz(sim.rate)} (${sim.samplesPerFrame} samples × 16 float32 every ${TCU_FRAME_INTERVAL * 1000} ms; ` +
            `2000 Hz with BACKWARDS COMPATIBILITY ON) and AUX at ${hz(2 / TCU_FRAME_INTERVAL)}, seed ${seed}`,
          "Ctrl-C stops it.",
        ],
        close: () => sim.close(),
      };
    },
  },
  "dlr-adcbt": {
    summary:
      "DLR ADC/BT converter on a serial device (one end of a socat pty pair): answers the channel count and start, then streams frames of 12-bit channels",
    usage: "--port PATH [--channels N] [--rate HZ] [--seed S] [--faults N] [--verbose]",
    options: {
      port: { type: "string" },
      channels: { type: "string" },
      rate: { type: "string" },
      seed: { type: "string" },
      faults: { type: "string" },
      verbose: { type: "boolean", default: false },
    },
    async start(v, log) {
      const sim = await startDlrAdcBtSimulator({
        ...dlrAdcBtSimulatorOptions(v),
        ...(v.verbose ? { log } : {}),
      });
      return {
        lines: [
          `DLR ADC/BT simulator on ${sim.path}: waits for the channel count and start, then streams ` +
            `${sim.rate} frames/s (${sim.channels} channels until told otherwise), seed ${sim.seed}`,
          "Point DLR_ADCBT's Port at the other end of the pty pair. Ctrl-C stops it.",
        ],
        close: () => sim.close(),
      };
    },
  },
  hannes: {
    summary:
      "IIT Rehab Dongle with a Hannes hand on a serial device (one end of a socat pty pair): answers $$$, scan, con N and dct, ACKs the hand's packets and prints its hand, wrist and thumb references",
    usage: "--port PATH [--names NAME,NAME] [--verbose]",
    options: {
      port: { type: "string" },
      names: { type: "string" },
      verbose: { type: "boolean", default: false },
    },
    async start(v, log) {
      const sim = await startHannesDongleSimulator({ ...hannesDongleSimulatorOptions(v), log });
      return {
        lines: [
          `Hannes simulator on ${sim.path}: a Rehab Dongle listing ${sim.devices.map((d) => `${d.name} (con ${d.con})`).join(", ")}; ` +
            "it prints each step of the handshake and the hand's references as they change",
          "Point HannesHand's Port at the other end of the pty pair. Ctrl-C stops it.",
        ],
        close: () => sim.close(),
      };
    },
  },
  "hannes-gui": {
    summary:
      "IIT's Hannes GUI (virtual arm, UDP 8889): decodes HannesGUI's activation, raw-EMG and ARV datagrams and prints the arm's state as it changes",
    usage: "[--host ADDR] [--port P]",
    options: {
      host: { type: "string" },
      port: { type: "string" },
    },
    async start(v, log) {
      const sim = await startHannesGuiSimulator({ ...hannesGuiSimulatorOptions(v), log });
      return {
        lines: [
          `Hannes GUI simulator listening on UDP ${sim.host}:${sim.port}: prints hand, wrist P/S and wrist F/E activations, raw EMG and ARVs as they change`,
          "Point HannesGUI's Host and Port there. Ctrl-C stops it.",
        ],
        close: () => sim.close(),
      };
    },
  },
  "hannes-emg": {
    summary:
      "The Hannes's EMG stream: sends UDP datagrams of 16-bit values (deterministic) to a HannesReceiver's HOST:PORT",
    usage: "--to HOST:PORT [--rate HZ] [--channels N] [--count N]",
    options: {
      to: { type: "string" },
      rate: { type: "string" },
      channels: { type: "string" },
      count: { type: "string" },
    },
    async start(v, log) {
      const o = hannesEmgSimulatorOptions(v);
      const sim = new HannesEmgSimulator({ ...o, log });
      return {
        lines: [
          `Hannes EMG simulator sending to UDP ${sim.host}:${sim.port}: ${sim.channels} channels at ${sim.rate} Hz` +
            (o.count !== undefined ? `, ${o.count} datagrams` : ""),
          "Point HannesReceiver's Port there. Ctrl-C stops it.",
        ],
        close: () => sim.close(),
      };
    },
  },
  syncstation: {
    summary:
      "OT Bioelettronica SyncStation (TCP server, 54320): after a start command streams its Muovi probes (38 int16 each) and its own 6 channels at 2000 Hz",
    usage: "[--host ADDR] [--port P] [--seed S] [--verbose]",
    options: {
      host: { type: "string" },
      port: { type: "string" },
      seed: { type: "string" },
      verbose: { type: "boolean", default: false },
    },
    async start(v, log) {
      const sim = await SyncStationSimulator.start({
        ...syncStationSimulatorOptions(v),
        ...(v.verbose ? { log } : {}),
      });
      return {
        lines: [
          `SyncStation simulator listening on ${sim.host}:${sim.port}: waits for a start command (Muovi slots 0…3, CRC-8), then streams 38 channels per probe + 6 at 2000 Hz, seed ${sim.seed}`,
          "Point Muovi's Host and Port there. Ctrl-C stops it.",
        ],
        close: () => sim.close(),
      };
    },
  },
  muovi: {
    summary:
      "OT Bioelettronica Muovi probe (TCP client): connects to a MuoviSingleProbe block's port, streams 38 int16 channels at 2000 Hz after the command byte, reconnects when dropped",
    usage: "--connect HOST:PORT [--slot N] [--seed S] [--verbose]",
    options: {
      connect: { type: "string" },
      slot: { type: "string" },
      seed: { type: "string" },
      verbose: { type: "boolean", default: false },
    },
    async start(v, log) {
      const o = muoviProbeSimulatorOptions(v);
      const sim = new MuoviProbeSimulator({ ...o, ...(v.verbose ? { log } : {}) });
      return {
        lines: [
          `Muovi probe simulator connecting to ${o.host}:${o.port} (again every 0.5 s while not connected), seed ${sim.seed}`,
          "Ctrl-C stops it.",
        ],
        close: () => sim.close(),
      };
    },
  },
  quattrocento: {
    summary:
      "OT Bioelettronica Quattrocento (TCP server, 23456): after a 40-byte command with a good CRC-8 streams 120–408 int16 LE channels at 512–10240 Hz",
    usage: "[--host ADDR] [--port P] [--seed S] [--verbose]",
    options: {
      host: { type: "string" },
      port: { type: "string" },
      seed: { type: "string" },
      verbose: { type: "boolean", default: false },
    },
    async start(v, log) {
      const sim = await QuattrocentoSimulator.start({
        ...quattrocentoSimulatorOptions(v),
        ...(v.verbose ? { log } : {}),
      });
      return {
        lines: [
          `Quattrocento simulator listening on ${sim.host}:${sim.port}: waits for a configuration command (40 bytes, CRC-8), then streams the commanded channels (120, 216, 312 or 408) at the commanded rate (512…10240 Hz), seed ${sim.seed}`,
          "Point Quattrocento's Host and Port there. Ctrl-C stops it.",
        ],
        close: () => sim.close(),
      };
    },
  },
  sessantaquattro: {
    summary:
      "OT Bioelettronica Sessantaquattro(+) (TCP client): connects to a Sessantaquattro block's port, streams the channels its command word asks for (int16 or int24 BE, 500–4000 Hz), reconnects when dropped",
    usage: "--connect HOST:PORT [--model sessantaquattro|sessantaquattro+] [--seed S] [--verbose]",
    options: {
      connect: { type: "string" },
      model: { type: "string" },
      seed: { type: "string" },
      verbose: { type: "boolean", default: false },
    },
    async start(v, log) {
      const o = sessantaquattroSimulatorOptions(v);
      const sim = new SessantaquattroSimulator({ ...o, ...(v.verbose ? { log } : {}) });
      return {
        lines: [
          `${sim.model} simulator connecting to ${o.host}:${o.port} (again every 0.5 s while not connected), seed ${sim.seed}`,
          "Ctrl-C stops it.",
        ],
        close: () => sim.close(),
      };
    },
  },
};

/** The help's lines for `mosaic simulate`. */
export function simulateHelp(): string {
  return Object.entries(SIMULATORS)
    .map(([name, s]) => `  mosaic simulate ${name} ${s.usage}\n      ${s.summary}`)
    .join("\n");
}

/** `mosaic simulate DEVICE [options]`; resolves with the exit code after Ctrl-C. */
export async function cmdSimulate(
  args: string[],
  out: (s: string) => void,
  err: (s: string) => void,
): Promise<number> {
  const [device, ...rest] = args;
  const names = Object.keys(SIMULATORS).join(", ");
  const sim = device === undefined ? undefined : SIMULATORS[device];
  if (!sim) {
    err(
      device === undefined
        ? `usage: mosaic simulate DEVICE [options] (devices: ${names})`
        : `mosaic simulate: no simulator for '${device}' (devices: ${names})`,
    );
    return 2;
  }
  const { values, positionals } = parseArgs({
    args: rest,
    options: sim.options,
    allowPositionals: true,
  });
  if (positionals.length > 0) {
    err(
      `mosaic simulate ${device}: unexpected '${positionals[0]}' (usage: mosaic simulate ${device} ${sim.usage})`,
    );
    return 2;
  }
  let running: Running;
  try {
    running = await sim.start(values as Values, (l) => out(`  ${l}`));
  } catch (e) {
    err(`mosaic simulate ${device}: ${(e as Error).message}`);
    // A device or port that is not available (missing, busy) is 1; a bad option 2.
    const unavailable = (e as { exitCode?: unknown }).exitCode === 1;
    return unavailable || (e as Error).message.includes("in use") ? 1 : 2;
  }
  for (const l of running.lines) out(l);
  await new Promise<void>((r) => {
    process.once("SIGINT", r);
    process.once("SIGTERM", r);
  });
  await running.close();
  return 0;
}
