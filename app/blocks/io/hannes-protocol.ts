/**
 * The IIT Hannes formats as the original MOSAIC spoke them (docs/protocols.md, "Hannes"; public
 * sources: AIROB-Lab/MOSAIC at bbacbd2, MosaicLibary/Blocks/Devices/HannesHand.cs, HannesGUI.cs
 * and HannesReceiver.cs). Pure functions: the blocks do the I/O.
 *
 * - HannesHand: the hand's serial protocol through IIT's Bluetooth "Rehab Dongle": text commands
 *   to the dongle, then packets `%` + command + payload + `&` CR LF to the hand.
 * - HannesGUI: UDP datagrams to IIT's virtual Hannes arm (`%` + kind + payload + `&` CR LF).
 * - HannesReceiver: UDP datagrams with six 16-bit EMG values.
 */
import { A } from "../control/actuation";

export const START = 0x25; // '%'
export const END = 0x26; // '&'
export const CR = 0x0d;
export const LF = 0x0a;

/** The hand's command bytes (HannesHand.cs, enum CommandParsing: the index is the byte). */
export const CMD = {
  EnterCMDMode: 0,
  ExitCMDMode: 1,
  ACK: 2,
  NACK: 3,
  RefControl: 14,
  SimultRefControl: 30,
} as const;

/** Options of RefControl (enum RefTable). */
export const REF = { JOINT_SET: 0, CONTROL_MODE: 5 } as const;

/** Control modes (enum ControlModality); the original used UNITY_CONTROL, "the one it responds to". */
export const UNITY_CONTROL = 3;

/**
 * The joints the original activated (SetDefaultJointmask): bits of enum JointsActivationIndex,
 * bit 0 first (.NET BitArray.CopyTo): thumb (2), wrist flexion/extension (5), wrist
 * pronation/supination (6). Bit 7 (hand) is never set there (a BitArray starts false), though
 * the hand joint is driven; 0x64.
 */
export const DEFAULT_JOINT_MASK = (1 << 2) | (1 << 5) | (1 << 6);

/** Dongle commands (text): command mode, scan, connect, disconnect. */
export const DONGLE = {
  commandMode: "$$$",
  // SerialPort.WriteLine appends "\n" to the "\r" the original put after each command.
  scan: "scan\r\n",
  connect: (con: number): string => `con ${con}\r\n`,
  disconnect: "dct\r\n",
} as const;

/** The dongle's line that ends a successful command, and the hand's ACK / NACK lines. */
export const SUCCESS_LINE = "Success\r";
export const ACK_LINE = `%${String.fromCharCode(CMD.ACK)}&\r`;
export const NACK_LINE = `%${String.fromCharCode(CMD.NACK)}&\r`;

/**
 * C#'s unchecked `(byte)` cast of a double, on the values the original sent: the value truncated
 * toward zero, as a two's-complement byte (−50 → 206). Values are clamped to [lo, hi] first (the
 * original sent whatever the dictionary held; its strategies kept it within 0..100).
 */
export function toByte(x: number, lo: number, hi: number): number {
  const v = x !== x ? 0 : Math.trunc(Math.min(hi, Math.max(lo, x)));
  return v & 0xff;
}

/** `%` + bytes + `&` CR LF (WriteCommandPacketToHannesEMGEM). */
export function packet(payload: ArrayLike<number>): Uint8Array {
  const b = new Uint8Array(payload.length + 4);
  b[0] = START;
  for (let i = 0; i < payload.length; i++) b[1 + i] = payload[i]! & 0xff;
  b[payload.length + 1] = END;
  b[payload.length + 2] = CR;
  b[payload.length + 3] = LF;
  return b;
}

/** The four references the hand gets: hand, wrist P/S, wrist F/E, thumb (the original's order). */
export interface HannesReference {
  /** Hand open (0) … closed (100): the Middle finger's actuation. */
  hand: number;
  /** Wrist pronation/supination −100…100: −(PS − 50)·2. */
  ps: number;
  /** Wrist flexion/extension 0…100: the actuation as it is. */
  fe: number;
  /** Thumb rotation −100…100: −(ThumbRotation − 50)·2. */
  thumb: number;
}

/** sendControlValues: actuation (11 values 0..100, actuation.ts order) → the hand's references. */
export function handReference(act: ArrayLike<number>, out: Float64Array): void {
  out[0] = act[A.Middle]!;
  out[1] = -(act[A.WristPronationSupination]! - 50) * 2 + 0; // + 0: no −0
  out[2] = act[A.WristFlexionExtension]!;
  out[3] = -(act[A.ThumbRotation]! - 50) * 2 + 0;
}

/**
 * SimultRefControl payload (11 bytes): command 30, 0x00, hand, wrist P/S, wrist F/E, elbow 0,
 * 0x03, thumb, 3D digit 0, shoulder 0, 0x00 (the original's comments: B2, B7 and B11 "have to be"
 * fixed; it sent 0x03 in B7 although the comment says 0x00). `ref` is hand, ps, fe, thumb.
 */
export function simultRefPayload(ref: ArrayLike<number>): number[] {
  return [
    CMD.SimultRefControl,
    0x00,
    toByte(ref[0]!, 0, 100),
    toByte(ref[1]!, -100, 100),
    toByte(ref[2]!, 0, 100),
    0x00,
    0x03,
    toByte(ref[3]!, -100, 100),
    0x00,
    0x00,
    0x00,
  ];
}

/**
 * The pose the original sent before disconnecting ("neutral position", so that the
 * pronation/supination joint stops turning): Middle 0, wrist F/E 80, thumb rotation 50, P/S 50,
 * i.e. references hand 0, P/S 0, F/E 80, thumb 0.
 */
export const NEUTRAL_REFERENCE: readonly number[] = [0, 0, 80, 0];

/** One device of the dongle's scan table. */
export interface ScannedDevice {
  con: number;
  rssi: number;
  address: string;
  name: string;
}

/**
 * A line of the dongle's scan reply, as the original read it: split on spaces; a line with at
 * least 5 fields and no "RSSI" (the header) is a device: fields 1–4 are connection number, RSSI,
 * address and name, or 2–5 when field 1 holds a '#'. Anything else: null.
 */
export function parseScanLine(line: string): ScannedDevice | null {
  const f = line.split(" ").filter((x) => x !== "");
  if (f.length < 5 || f.includes("RSSI")) return null;
  const at = f[1]!.includes("#") ? 2 : 1;
  if (f.length < at + 4) return null;
  const con = Number.parseInt(f[at]!, 10);
  const rssi = Number.parseInt(f[at + 1]!, 10);
  if (!Number.isInteger(con) || !Number.isInteger(rssi)) return null;
  return { con, rssi, address: f[at + 2]!, name: f[at + 3]!.replace(/\r$/, "") };
}

/** Splits serial input into lines on LF (SerialPort.ReadLine), keeping a CR before it. */
export class LineSplitter {
  private partial = "";

  push(bytes: Uint8Array, onLine: (line: string) => void): void {
    for (let i = 0; i < bytes.length; i++) {
      const c = bytes[i]!;
      if (c === LF) {
        const l = this.partial;
        this.partial = "";
        onLine(l);
      } else if (this.partial.length < 4096) {
        this.partial += String.fromCharCode(c);
      }
    }
  }

  reset(): void {
    this.partial = "";
  }
}

/** ASCII bytes of a dongle command. */
export function ascii(s: string): Uint8Array {
  const b = new Uint8Array(s.length);
  for (let i = 0; i < s.length; i++) b[i] = s.charCodeAt(i) & 0xff;
  return b;
}

// ---------------------------------------------------------------------------------------------
// HannesGUI (UDP to IIT's virtual arm)

/** Datagram kinds (byte 1). */
export const GUI = { ACTIVATION: 15, RAW_EMG: 16, ARV: 32 } as const;
/** Joint ids of an activation datagram (byte 2). */
export const GUI_JOINT = { HAND: 0, WRIST_PS: 1, WRIST_FE: 2 } as const;

/** An activation datagram: `%`, 15, joint, value, `&`, CR, LF (7 bytes). */
export function guiActivation(joint: number, value: number): Uint8Array {
  return packet([GUI.ACTIVATION, joint, toByte(value, 0, 100)]);
}

/**
 * The three activation datagrams of one control event (in the original's order): hand ←
 * ThumbFlexion, wrist P/S ← WristPronationSupination, wrist F/E ← WristFlexionExtension, each the
 * actuation value 0..100 as a byte.
 */
export function guiActivations(act: ArrayLike<number>): Uint8Array[] {
  return [
    guiActivation(GUI_JOINT.HAND, act[A.ThumbFlexion]!),
    guiActivation(GUI_JOINT.WRIST_PS, act[A.WristPronationSupination]!),
    guiActivation(GUI_JOINT.WRIST_FE, act[A.WristFlexionExtension]!),
  ];
}

/**
 * A raw-EMG datagram of `nBytes` data bytes: `%`, 16, one byte per value (128·x truncated toward
 * zero, clamped to −128…127, two's complement), zeros after the last value, `&`, CR, LF. The
 * original wrapped 1.0 to −128 (it did not clamp).
 */
export function guiRawEmg(
  values: ArrayLike<number>,
  off: number,
  n: number,
  nBytes: number,
): Uint8Array {
  const b = new Uint8Array(nBytes + 5);
  b[0] = START;
  b[1] = GUI.RAW_EMG;
  for (let i = 0; i < n && i < nBytes; i++) b[2 + i] = toByte(128 * values[off + i]!, -128, 127);
  b[nBytes + 2] = END;
  b[nBytes + 3] = CR;
  b[nBytes + 4] = LF;
  return b;
}

/**
 * An ARV datagram of `nBytes` data bytes: `%`, 32, each value as a little-endian float64 (8 bytes),
 * zeros after the last value, `&`, CR, LF.
 */
export function guiArv(
  values: ArrayLike<number>,
  off: number,
  n: number,
  nBytes: number,
): Uint8Array {
  const b = new Uint8Array(nBytes + 5);
  const dv = new DataView(b.buffer);
  b[0] = START;
  b[1] = GUI.ARV;
  for (let i = 0; i < n && 8 * (i + 1) <= nBytes; i++)
    dv.setFloat64(2 + 8 * i, values[off + i]!, true);
  b[nBytes + 2] = END;
  b[nBytes + 3] = CR;
  b[nBytes + 4] = LF;
  return b;
}

// ---------------------------------------------------------------------------------------------
// HannesReceiver (UDP from the Hannes EMG board)

/**
 * A datagram of the Hannes EMG stream, as the original read it: bytes 0 and 1 a header it did not
 * check (byte 1 "cmd"), then little-endian unsigned 16-bit values from byte 2, each divided by
 * 2¹⁶. Reads `channels` values into `out`; false when the datagram is too short.
 */
export function decodeHannesEmg(data: Uint8Array, channels: number, out: Float64Array): boolean {
  if (data.length < 2 + 2 * channels) return false;
  for (let i = 0; i < channels; i++) out[i] = (data[2 + 2 * i]! | (data[3 + 2 * i]! << 8)) / 65536;
  return true;
}
