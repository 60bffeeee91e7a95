/**
 * IIT's Rehab Dongle with Hannes hands behind it on a serial device: one end of a socat pty pair
 * (`socat pty,raw,echo=0,link=/tmp/hannes pty,raw,echo=0,link=/tmp/hannes-dongle`: the pipeline's
 * HannesHand opens /tmp/hannes, the simulator /tmp/hannes-dongle), or a real serial port wired to
 * the computer running the pipeline. The protocol is the state machine of hannes-hand-simulator.ts
 * (docs/protocols.md, "Hannes"); this file opens the port (115200 Bd, the `serialport` package
 * on the main thread), passes bytes both ways and reports the hand's state: one line per event
 * (scan, connect, modes, joints, malformed input) and the references whenever they change, at
 * most four lines a second. Used by the tests and by `mosaic simulate hannes`.
 */
import { SerialPort } from "serialport";
import {
  HannesHandMachine,
  type DongleRecord,
  type HandReference,
  type SimulatedHannes,
} from "./hannes-hand-simulator";
import {
  DeviceUnavailableError,
  errorText,
  StateReporter,
  type SimulatorValues,
} from "./hannes-simulator-common";

/** The dongle's serial settings, as the original opened the port. */
export const HANNES_BAUD_RATE = 115200;

export interface HannesDongleSimulatorOptions {
  /** The serial device to open (a pty end, /dev/ttyUSB0, COM7). */
  path: string;
  /** The Hannes devices the scan lists, connection numbers 1, 2, … (default: one, "Hannes"). */
  names?: readonly string[];
  /** Keep every command received in `records` (tests). */
  record?: boolean;
  /** Events and the hand's state, one line each (the CLI prints them). */
  log?: (line: string) => void;
  /** Also every packet received (`--verbose`). */
  verbose?: boolean;
}

export interface HannesDongleSimulator {
  readonly path: string;
  readonly devices: readonly SimulatedHannes[];
  /** Everything received, in order, when `record` is on. */
  readonly records: readonly DongleRecord[];
  /** The references of every SimultRefControl applied, in order, when `record` is on. */
  readonly applied: readonly HandReference[];
  /** Packets NACKed. */
  readonly nacks: number;
  /** The hand connected now, if any. */
  readonly connected: SimulatedHannes | undefined;
  readonly handMode: "stream" | "command";
  readonly jointMask: number | undefined;
  readonly controlMode: number | undefined;
  /** The references the hand holds now. */
  readonly reference: Readonly<HandReference>;
  /** SimultRefControl packets applied. */
  readonly references: number;
  /** Malformed inputs in all. */
  readonly malformedTotal: number;
  /** Resolves when `cond` holds (checked every 10 ms); rejects after `timeoutMs` saying `what`. */
  waitFor(cond: () => boolean, what: string, timeoutMs?: number): Promise<void>;
  /** Closes the port (after what was written went out). */
  close(): Promise<void>;
}

/** Opens the port and plays the dongle and the hand (see the file comment). */
export async function startHannesDongleSimulator(
  o: HannesDongleSimulatorOptions,
): Promise<HannesDongleSimulator> {
  checkNames(o.names);
  const port = new SerialPort({ path: o.path, baudRate: HANNES_BAUD_RATE, autoOpen: false });
  await new Promise<void>((resolve, reject) =>
    port.open((err) => (err ? reject(openError(o.path, err)) : resolve())),
  );
  return new Dongle(port, o);
}

/** Why a port did not open, in words; a missing or busy device exits `mosaic simulate` with 1. */
function openError(path: string, err: Error): Error {
  const m = errorText(err);
  if (/ENOENT|No such file/i.test(m)) {
    return new DeviceUnavailableError(`cannot open ${path}: no such device (is socat running?)`);
  }
  if (/EBUSY|busy|Cannot lock|temporarily unavailable/i.test(m)) {
    return new DeviceUnavailableError(`cannot open ${path}: it is in use by another program`);
  }
  if (/EACCES|Permission denied/i.test(m)) {
    return new DeviceUnavailableError(`cannot open ${path}: permission denied`);
  }
  return new DeviceUnavailableError(`cannot open ${path}: ${m}`);
}

function checkNames(names: readonly string[] | undefined): void {
  if (names === undefined) return;
  if (names.length < 1 || names.length > 9) {
    throw new Error(`between 1 and 9 Hannes names, not ${names.length}`);
  }
  for (const n of names) {
    if (!/^[A-Za-z0-9_.-]{1,32}$/.test(n)) {
      throw new Error(
        `a Hannes name is 1…32 letters, digits, '_', '.' or '-' (the scan table splits on spaces), not '${n}'`,
      );
    }
  }
}

class Dongle implements HannesDongleSimulator {
  readonly path: string;
  private readonly machine: HannesHandMachine;
  private readonly state: StateReporter;
  private closed = false;

  constructor(
    private readonly port: SerialPort,
    o: HannesDongleSimulatorOptions,
  ) {
    this.path = o.path;
    const log = o.log ?? (() => {});
    this.state = new StateReporter(log);
    this.machine = new HannesHandMachine({
      ...(o.names ? { names: o.names } : {}),
      ...(o.record ? { record: true } : {}),
      ...(o.verbose ? { verbose: true } : {}),
      write: (b) => {
        if (this.port.isOpen) this.port.write(Buffer.from(b));
      },
      log,
    });
    port.on("data", (d: Buffer) => {
      this.machine.receive(d);
      this.state.update(this.machine.stateText());
    });
    port.on("error", (e: Error) => log(`${this.path}: ${errorText(e)}`));
    port.on("close", () => {
      if (!this.closed) log(`${this.path} closed (the pty pair is gone?)`);
    });
  }

  get devices(): readonly SimulatedHannes[] {
    return this.machine.devices;
  }
  get records(): readonly DongleRecord[] {
    return this.machine.records;
  }
  get applied(): readonly HandReference[] {
    return this.machine.applied;
  }
  get nacks(): number {
    return this.machine.nacks;
  }
  get connected(): SimulatedHannes | undefined {
    return this.machine.connected;
  }
  get handMode(): "stream" | "command" {
    return this.machine.handMode;
  }
  get jointMask(): number | undefined {
    return this.machine.jointMask;
  }
  get controlMode(): number | undefined {
    return this.machine.controlMode;
  }
  get reference(): Readonly<HandReference> {
    return this.machine.reference;
  }
  get references(): number {
    return this.machine.references;
  }
  get malformedTotal(): number {
    return this.machine.malformedTotal;
  }

  async waitFor(cond: () => boolean, what: string, timeoutMs = 10_000): Promise<void> {
    const end = Date.now() + timeoutMs;
    while (!cond()) {
      if (Date.now() > end) throw new Error(`the Hannes simulator: no ${what} in ${timeoutMs} ms`);
      await new Promise((r) => setTimeout(r, 10));
    }
  }

  async close(): Promise<void> {
    if (this.closed) return;
    this.closed = true;
    this.state.flush();
    if (!this.port.isOpen) return;
    await new Promise<void>((resolve) => this.port.drain(() => resolve()));
    await new Promise<void>((resolve) => this.port.close(() => resolve()));
  }
}

/**
 * The simulator's options from `mosaic simulate hannes`'s (`--port PATH [--names A,B] [--verbose]`); throws
 * an Error saying what is wrong.
 */
export function hannesDongleSimulatorOptions(v: SimulatorValues): HannesDongleSimulatorOptions {
  const path = v.port;
  if (typeof path !== "string" || path.trim() === "") {
    throw new Error(
      "--port PATH is required: the serial device the dongle is on, e.g. one end of a pty pair " +
        "made by `socat pty,raw,echo=0,link=/tmp/hannes pty,raw,echo=0,link=/tmp/hannes-dongle` " +
        "(then --port /tmp/hannes-dongle here and Port: /tmp/hannes in the pipeline)",
    );
  }
  const o: HannesDongleSimulatorOptions = {
    path,
    ...(v.verbose === true ? { verbose: true } : {}),
  };
  if (v.names !== undefined) {
    const names = String(v.names)
      .split(",")
      .map((s) => s.trim());
    try {
      checkNames(names);
    } catch (e) {
      throw new Error(`--names: ${errorText(e)}`);
    }
    o.names = names;
  }
  return o;
}
