/**
 * IIT's Rehab Dongle with Hannes hands behind it, as a pure state machine: bytes from the
 * computer in, reply bytes out (docs/protocols.md, "Hannes": written from the protocol as the
 * original MOSAIC's HannesHand.cs used it, not from our block's code). The serial port around it
 * is hannes-dongle-simulator.ts.
 *
 * The dongle starts in data mode with no hand connected. `$$$` puts it in command mode, where it
 * reads text lines (ending LF, a CR before it dropped): `scan` answers a device table and
 * `Success`; `con N` connects to device N (`con N`, `Success`, `STREAM_MODE`) and goes back to
 * data mode; `dct` disconnects (`Success`, or `Command failed` with no hand); anything else is
 * `Command failed`. In data mode with a hand connected, bytes are packets to the hand: `%`,
 * command, payload, `&`, CR, LF. Each well-formed packet is answered `%` 0x02 `&` CR LF (ACK),
 * a refused one `%` 0x03 `&` CR LF (NACK). The hand starts in stream mode (the original's
 * initial EMGM mode); EnterCMDMode (0) and ExitCMDMode (1) switch it; RefControl (14) sets the
 * joint mask (option 0) and the control mode (option 5) in command mode, or one joint's
 * reference (options 1, 2, 3, 6); SimultRefControl (30) sets hand, wrist P/S, wrist F/E and
 * thumb in stream mode ("for streaming joint position commands the Stream Mode has to be
 * activated", the original's comment). Malformed input is counted by kind and never throws.
 */
import { FRAME_END, FRAME_START, hex, int8, logsFault } from "./hannes-simulator-common";

/** The hand's command bytes that the original sent (its enum CommandParsing). */
export const HAND_CMD = {
  EnterCMDMode: 0,
  ExitCMDMode: 1,
  ACK: 2,
  NACK: 3,
  RefControl: 14,
  SimultRefControl: 30,
} as const;

/** Payload bytes after the command byte, per command the simulator knows. */
const PAYLOAD: Readonly<Record<number, number>> = {
  [HAND_CMD.EnterCMDMode]: 0,
  [HAND_CMD.ExitCMDMode]: 0,
  [HAND_CMD.RefControl]: 2,
  [HAND_CMD.SimultRefControl]: 10,
};

/** RefControl's options (the original's enum RefTable). */
const REF_OPTION = ["JOINT_SET", "HAND", "WRIST_PS", "WRIST_FE", "ELBOW", "CONTROL_MODE", "THUMB"];
/** Control modes (enum ControlModality). */
export const CONTROL_MODES = ["EMG_CONTROL", "HMI_CONTROL", "EMC_TEST_CONTROL", "UNITY_CONTROL"];
/** Joint bits of RefControl JOINT_SET (enum JointsActivationIndex, bit 0 first). */
const JOINT_BITS = [
  "reserved",
  "3D digit",
  "thumb",
  "shoulder",
  "elbow",
  "wrist F/E",
  "wrist P/S",
  "hand",
];

/** One device of the dongle's scan table. */
export interface SimulatedHannes {
  con: number;
  rssi: number;
  address: string;
  name: string;
}

/** The references the hand holds: hand 0…100, wrist P/S −100…100, F/E 0…100, thumb −100…100. */
export interface HandReference {
  hand: number;
  ps: number;
  fe: number;
  thumb: number;
}

/** What arrived, in order (kept when `record` is on): a dongle command, a packet, or an error. */
export type DongleRecord = { text: string } | { packet: number[] } | { error: string };

/** Kinds of malformed input. */
export type DongleFault =
  | "unknownCommand"
  | "badEnd"
  | "badValue"
  | "wrongMode"
  | "strayBytes"
  | "noHand"
  | "unknownDongleCommand";

export const DONGLE_FAULTS: readonly DongleFault[] = [
  "unknownCommand",
  "badEnd",
  "badValue",
  "wrongMode",
  "strayBytes",
  "noHand",
  "unknownDongleCommand",
];

const FAULT_TEXT: Record<DongleFault, string> = {
  unknownCommand: "unknown command",
  badEnd: "bad end",
  badValue: "bad value",
  wrongMode: "wrong mode",
  strayBytes: "stray bytes",
  noHand: "bytes with no hand connected",
  unknownDongleCommand: "unknown dongle command",
};

export interface HannesHandMachineOptions {
  /** The devices the scan lists, connection numbers 1, 2, … (default one: "Hannes"). */
  names?: readonly string[];
  /** Keep every command received in `records` (tests). */
  record?: boolean;
  /** Log every command and packet received, too. */
  verbose?: boolean;
  /** Replies to the computer. */
  write: (bytes: Uint8Array) => void;
  /** One line per event (scan, connect, modes, joints, malformed input). */
  log?: (line: string) => void;
}

const ASCII = (s: string): Uint8Array => Uint8Array.from(s, (c) => c.charCodeAt(0) & 0xff);
const ACK = Uint8Array.of(FRAME_START, HAND_CMD.ACK, ...FRAME_END);
const NACK = Uint8Array.of(FRAME_START, HAND_CMD.NACK, ...FRAME_END);
const DOLLAR = 0x24;
const LF = 0x0a;
/** The longest text line the dongle keeps waiting for its end. */
const MAX_LINE = 256;

/** Bytes from `at` up to the next `%` or `$` after it (where a packet or `$$$` may start). */
function resync(b: Uint8Array, at: number): number {
  let end = at + 1;
  while (end < b.length && b[end] !== FRAME_START && b[end] !== DOLLAR) end++;
  return end - at;
}

/** The scan table's devices for these names: connection numbers from 1, made-up addresses. */
export function scanDevices(names: readonly string[]): SimulatedHannes[] {
  return names.map((name, i) => ({
    con: i + 1,
    rssi: -48 - 7 * i,
    address: `0CEC8000${(0x10 + i).toString(16).toUpperCase()}A`,
    name,
  }));
}

/** The dongle's reply to `scan`: a header, one line per device, `Success` (lines end CR LF). */
export function scanReply(devices: readonly SimulatedHannes[]): string {
  let s = " #  Con  RSSI  Address       Name\r\n";
  devices.forEach((d, i) => {
    s += ` ${i}  ${d.con}  ${d.rssi}  ${d.address}  ${d.name}\r\n`;
  });
  return s + "Success\r\n";
}

/** A joint mask in words: "thumb, wrist F/E, wrist P/S". */
export function jointNames(mask: number): string {
  const on = JOINT_BITS.filter((_, b) => (mask >> b) & 1);
  return on.length === 0 ? "none" : on.join(", ");
}

export class HannesHandMachine {
  readonly devices: readonly SimulatedHannes[];
  /** Everything received, in order, when `record` is on. */
  readonly records: DongleRecord[] = [];
  /** The references of every SimultRefControl applied, in order, when `record` is on. */
  readonly applied: HandReference[] = [];
  readonly malformed: Record<DongleFault, number> = {
    unknownCommand: 0,
    badEnd: 0,
    badValue: 0,
    wrongMode: 0,
    strayBytes: 0,
    noHand: 0,
    unknownDongleCommand: 0,
  };
  /** The dongle: reading its own commands, or passing bytes to the hand. */
  dongleMode: "data" | "command" = "data";
  /** The hand the dongle is connected to. */
  connected: SimulatedHannes | undefined;
  handMode: "stream" | "command" = "stream";
  jointMask: number | undefined;
  controlMode: number | undefined;
  readonly reference: HandReference = { hand: 0, ps: 0, fe: 0, thumb: 0 };
  /** SimultRefControl packets applied. */
  references = 0;
  /** Packets ACKed and NACKed. */
  acks = 0;
  nacks = 0;

  private buf = new Uint8Array(0);
  /** Malformed inputs seen (each stray run once), for the log's limit. */
  private faults = 0;
  private readonly log: (line: string) => void;

  constructor(private readonly o: HannesHandMachineOptions) {
    this.devices = scanDevices(o.names ?? ["Hannes"]);
    this.log = o.log ?? (() => {});
  }

  /** Malformed inputs in all. */
  get malformedTotal(): number {
    return DONGLE_FAULTS.reduce((s, k) => s + this.malformed[k], 0);
  }

  /** The malformed counts that are not zero, in words: "2 bad end, 5 stray bytes". */
  malformedText(): string {
    return DONGLE_FAULTS.filter((k) => this.malformed[k] > 0)
      .map((k) => `${this.malformed[k]} ${FAULT_TEXT[k]}`)
      .join(", ");
  }

  /** Bytes from the computer, in any chunks. */
  receive(bytes: Uint8Array): void {
    const joined = new Uint8Array(this.buf.length + bytes.length);
    joined.set(this.buf);
    joined.set(bytes, this.buf.length);
    let at = 0;
    for (;;) {
      const used = this.step(joined, at);
      if (used === 0) break;
      at += used;
    }
    this.buf = joined.slice(at);
  }

  /** Consumes one token at `at`; 0 when more bytes are needed. */
  private step(b: Uint8Array, at: number): number {
    const left = b.length - at;
    if (left === 0) return 0;
    if (b[at] === DOLLAR) {
      // Wait when what is there may still become `$$$`.
      if (left < 3 && b.subarray(at).every((x) => x === DOLLAR)) return 0;
      if (b[at + 1] === DOLLAR && b[at + 2] === DOLLAR) {
        this.commandMode();
        return 3;
      }
    }
    if (this.dongleMode === "command") return this.line(b, at);
    if (!this.connected) return this.noHand(b, at);
    if (b[at] === FRAME_START) return this.packet(b, at);
    return this.stray(b, at);
  }

  private commandMode(): void {
    this.keep({ text: "$$$" });
    if (this.dongleMode !== "command") this.log("dongle: command mode");
    this.dongleMode = "command";
  }

  /** A text line to the dongle (command mode). */
  private line(b: Uint8Array, at: number): number {
    const end = b.indexOf(LF, at);
    if (end < 0) {
      if (b.length - at <= MAX_LINE) return 0;
      this.fault(
        "unknownDongleCommand",
        `a line of over ${MAX_LINE} bytes without LF`,
        b.subarray(at, at + 16),
      );
      return b.length - at;
    }
    let text = String.fromCharCode(...b.subarray(at, end));
    if (text.endsWith("\r")) text = text.slice(0, -1);
    this.dongleCommand(text);
    return end + 1 - at;
  }

  private dongleCommand(text: string): void {
    const con = /^con (\d+)$/.exec(text);
    if (text === "scan") {
      this.keep({ text });
      this.reply(scanReply(this.devices));
      this.log(`scan: ${this.devices.map((d) => `${d.name} (con ${d.con})`).join(", ")}`);
    } else if (con) {
      this.keep({ text });
      this.connect(Number(con[1]), text);
    } else if (text === "dct") {
      this.keep({ text });
      this.disconnect();
    } else if (text === "") {
      // An empty line (a lone CR LF): nothing to do.
    } else {
      this.fault("unknownDongleCommand", `'${text.slice(0, 40)}'`);
      this.reply("Command failed\r\n");
    }
  }

  private connect(n: number, text: string): void {
    const d = this.devices.find((x) => x.con === n);
    if (!d) {
      this.log(`${text}: no device ${n} in the scan table`);
      this.reply("Command failed\r\n");
      return;
    }
    this.connected = d;
    this.dongleMode = "data";
    this.handMode = "stream";
    this.reply(`${text}\r\nSuccess\r\nSTREAM_MODE\r\n`);
    this.log(`${text}: connected to ${d.name} (${d.address})`);
  }

  private disconnect(): void {
    const d = this.connected;
    if (!d) {
      this.log("dct: no hand connected");
      this.reply("Command failed\r\n");
      return;
    }
    this.connected = undefined;
    this.reply("Success\r\n");
    this.log(`dct: disconnected from ${d.name}`);
  }

  /** Bytes in data mode with no hand: they go nowhere (counted), up to the next `$`. */
  private noHand(b: Uint8Array, at: number): number {
    let end = at + 1;
    while (end < b.length && b[end] !== DOLLAR) end++;
    this.fault("noHand", `${end - at} bytes`, b.subarray(at, end), end - at);
    return end - at;
  }

  /** Bytes between packets that start none: skipped up to the next `%` or `$`. */
  private stray(b: Uint8Array, at: number): number {
    const n = resync(b, at);
    this.fault("strayBytes", `${n} bytes between packets`, b.subarray(at, at + n), n);
    return n;
  }

  /** A packet to the hand at `at` (b[at] is `%`). */
  private packet(b: Uint8Array, at: number): number {
    if (b.length - at < 2) return 0;
    const cmd = b[at + 1]!;
    const n = PAYLOAD[cmd];
    if (n === undefined) {
      const skip = resync(b, at);
      this.fault("unknownCommand", `command ${cmd}`, b.subarray(at, at + skip));
      this.nack();
      return skip;
    }
    const size = 2 + n + FRAME_END.length;
    if (b.length - at < size) return 0;
    const tail = b.subarray(at + 2 + n, at + size);
    if (!FRAME_END.every((x, i) => tail[i] === x)) {
      const skip = resync(b, at);
      this.fault(
        "badEnd",
        `command ${cmd} ends ${hex(tail)}, not 26 0D 0A`,
        b.subarray(at, at + skip),
      );
      this.nack();
      return skip;
    }
    const body = [...b.subarray(at + 1, at + 2 + n)];
    this.keep({ packet: body });
    const refused = this.handCommand(body);
    if (refused) {
      this.fault(refused[0], refused[1], body);
      this.nack();
    } else this.ack();
    return size;
  }

  /** Applies one packet; a refusal's kind and reason, or undefined when done. */
  private handCommand(p: number[]): [DongleFault, string] | undefined {
    const name = this.connected!.name;
    switch (p[0]) {
      case HAND_CMD.EnterCMDMode:
        if (this.handMode !== "command") this.log(`${name}: command mode`);
        this.handMode = "command";
        return undefined;
      case HAND_CMD.ExitCMDMode:
        if (this.handMode !== "stream") this.log(`${name}: stream mode`);
        this.handMode = "stream";
        return undefined;
      case HAND_CMD.RefControl:
        return this.refControl(p[1]!, p[2]!);
      default:
        return this.simultRef(p);
    }
  }

  private refControl(option: number, value: number): [DongleFault, string] | undefined {
    const what = REF_OPTION[option];
    if (what === undefined) return ["badValue", `RefControl option ${option} (0…6 known)`];
    const setup = option === 0 || option === 5;
    if (setup && this.handMode !== "command") {
      return ["wrongMode", `RefControl ${what} in stream mode (needs command mode)`];
    }
    if (option === 0) {
      this.jointMask = value;
      this.log(`joints activated: ${jointNames(value)} (0x${hex([value])})`);
    } else if (option === 5) {
      if (value >= CONTROL_MODES.length) return ["badValue", `control mode ${value} (0…3 known)`];
      this.controlMode = value;
      this.log(`control mode ${value} (${CONTROL_MODES[value]})`);
    } else {
      const r = this.reference;
      const v = option === 2 || option === 6 ? int8(value) : value;
      const bad = option === 2 || option === 6 ? v < -100 || v > 100 : v > 100;
      if (bad) return ["badValue", `RefControl ${what} ${v} out of range`];
      if (option === 1) r.hand = v;
      else if (option === 2) r.ps = v;
      else if (option === 3) r.fe = v;
      else if (option === 6) r.thumb = v;
    }
    return undefined;
  }

  /** SimultRefControl: 0x00, hand, P/S, F/E, elbow, 0x03, thumb, 3D digit, shoulder, 0x00. */
  private simultRef(p: number[]): [DongleFault, string] | undefined {
    if (this.handMode !== "stream") {
      return ["wrongMode", "SimultRefControl in command mode (needs stream mode)"];
    }
    if (p[1] !== 0 || (p[6] !== 3 && p[6] !== 0) || p[10] !== 0) {
      return [
        "badValue",
        `SimultRefControl fixed bytes ${hex([p[1]!, p[6]!, p[10]!])}, not 00 03 00`,
      ];
    }
    const hand = p[2]!;
    const ps = int8(p[3]!);
    const fe = p[4]!;
    const thumb = int8(p[7]!);
    if (hand > 100 || fe > 100 || ps < -100 || ps > 100 || thumb < -100 || thumb > 100) {
      return [
        "badValue",
        `SimultRefControl out of range: hand ${hand}, P/S ${ps}, F/E ${fe}, thumb ${thumb}`,
      ];
    }
    Object.assign(this.reference, { hand, ps, fe, thumb });
    this.references++;
    if (this.o.record) this.applied.push({ hand, ps, fe, thumb });
    return undefined;
  }

  /** The hand's state in one line. */
  stateText(): string {
    const d = this.connected;
    const r = this.reference;
    const head = d ? `${d.name} (${this.handMode} mode)` : "no hand connected";
    let s = `${head}: hand ${r.hand} · wrist P/S ${r.ps} · wrist F/E ${r.fe} · thumb ${r.thumb} · ${this.references} references`;
    if (this.nacks > 0) s += ` · ${this.nacks} NACKed`;
    const bad = this.malformedText();
    if (bad !== "") s += ` · malformed: ${bad}`;
    return s;
  }

  private keep(r: DongleRecord): void {
    if (this.o.record) this.records.push(r);
    if (this.o.verbose && "packet" in r) this.log(`packet ${hex(r.packet)}`);
    else if (this.o.verbose && "text" in r) this.log(`command '${r.text}'`);
  }

  private fault(kind: DongleFault, why: string, bytes?: ArrayLike<number>, count = 1): void {
    this.malformed[kind] += count;
    const error = `${FAULT_TEXT[kind]}: ${why}${bytes ? ` (${hex(bytes, 16)})` : ""}`;
    this.keep({ error });
    this.faults++;
    if (logsFault(this.faults)) this.log(`${error} [malformed input ${this.faults}]`);
  }

  private reply(s: string): void {
    this.o.write(ASCII(s));
  }

  private ack(): void {
    this.acks++;
    this.o.write(ACK);
  }

  private nack(): void {
    this.nacks++;
    this.o.write(NACK);
  }
}
