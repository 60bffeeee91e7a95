/**
 * OT Bioelettronica's Sessantaquattro and Sessantaquattro+ on the wire (docs/protocols.md,
 * "OT Bioelettronica Sessantaquattro"):
 *
 * - The PC listens (TCP port 45454) and the device connects to it. The PC sends the 16-bit
 *   command word, big-endian (CONTROL BYTE 0, then CONTROL BYTE 1): bit 15 GETSET (0: set),
 *   14-13 FSAMP (500, 1000, 2000, 4000 Hz), 12-11 NCH (8, 16, 32, 64 bioelectrical channels),
 *   10-8 MODE (0 monopolar, 1 bipolar: half the channels, 2 differential, …), 7 HRES (24-bit
 *   samples), 6 HPF (the firmware's high-pass), 5-4 GAIN/EXTEN (0: 286.1 nV per bit), 3-2 TRIG
 *   (0: GO/STOP controls the transfer), 1 REC (SD card), 0 GO/STOP (1: stream; 0: stop and close
 *   the socket).
 * - Then, per sample, every channel as a big-endian two's-complement integer of 2 bytes (3 with
 *   HRES): the bioelectrical channels, 2 AUX, on the Sessantaquattro+ 4 IMU quaternion channels
 *   (W, X, Y, Z), then the 2 accessory channels (buffer/trigger, and a sample counter, +1 per
 *   sample).
 *
 * `SessantaquattroStreamParser` keeps the alignment by that counter (its 16 low bits, which count
 * whether the device wraps it at 16 or 24 bits), finds it again after malformed bytes and counts
 * samples the device skipped.
 */
import { CounterAlignedParser, type CounterFraming, u16be } from "./counter-aligned-parser";

/** The TCP port the device connects to (the manual's default). */
export const SESSANTAQUATTRO_PORT = 45454;
/** The models: the Sessantaquattro+ adds 4 IMU channels. */
export const SESSANTAQUATTRO_MODELS = ["Sessantaquattro", "Sessantaquattro+"] as const;
export type SessantaquattroModel = (typeof SESSANTAQUATTRO_MODELS)[number];
/** FSAMP 0…3 in the modes offered here (the accelerometer mode has other rates). */
export const SESSANTAQUATTRO_RATES = [500, 1000, 2000, 4000] as const;
export type SessantaquattroRate = (typeof SESSANTAQUATTRO_RATES)[number];
/** NCH 0…3: bioelectrical channels (halved in bipolar mode). */
export const SESSANTAQUATTRO_CHANNELS = [8, 16, 32, 64] as const;
export type SessantaquattroChannels = (typeof SESSANTAQUATTRO_CHANNELS)[number];
/** MODE 0…2, the detection modes offered here. */
export const SESSANTAQUATTRO_MODES = ["monopolar", "bipolar", "differential"] as const;
export type SessantaquattroMode = (typeof SESSANTAQUATTRO_MODES)[number];

/** Bioelectrical channels, mV per bit: 286.1 nV (OTB's readers use 0.000286 mV). */
export const EMG_MV_PER_BIT = 0.000286;
/** AUX channels, mV per bit: 146.48 µV at 16 bits (the 16 high bits), 572.2 nV at 24. */
export const AUX_MV_PER_BIT_16 = 0.14648;
export const AUX_MV_PER_BIT_24 = 0.0005722;

export interface SessantaquattroConfig {
  model: SessantaquattroModel;
  mode: SessantaquattroMode;
  /** NCH as bioelectrical channels in monopolar mode. */
  channels: SessantaquattroChannels;
  rate: SessantaquattroRate;
  highRes: boolean;
  hpf: boolean;
}

/** What a command word says, field by field. */
export interface CommandFields {
  getset: number;
  fsamp: number;
  nch: number;
  mode: number;
  hres: number;
  hpf: number;
  gain: number;
  trig: number;
  rec: number;
  go: number;
}

/** The command word for `cfg`, streaming (`go`) or stopping. */
export function commandWord(cfg: SessantaquattroConfig, go: boolean): number {
  const fsamp = SESSANTAQUATTRO_RATES.indexOf(cfg.rate);
  const nch = SESSANTAQUATTRO_CHANNELS.indexOf(cfg.channels);
  const mode = SESSANTAQUATTRO_MODES.indexOf(cfg.mode);
  if (fsamp < 0) throw new Error(`${cfg.rate} Hz is not a Sessantaquattro rate (500…4000)`);
  if (nch < 0) throw new Error(`${cfg.channels} is not a channel count (8, 16, 32, 64)`);
  if (mode < 0) throw new Error(`'${cfg.mode}' is not a detection mode offered here`);
  return (
    (fsamp << 13) |
    (nch << 11) |
    (mode << 8) |
    ((cfg.highRes ? 1 : 0) << 7) |
    ((cfg.hpf ? 1 : 0) << 6) |
    (go ? 1 : 0)
  );
}

/** The two bytes on the wire, big-endian (CONTROL BYTE 0 first). */
export function encodeCommand(word: number): Uint8Array {
  return Uint8Array.of((word >> 8) & 0xff, word & 0xff);
}

/** The fields of a command word. */
export function readCommand(word: number): CommandFields {
  return {
    getset: (word >> 15) & 1,
    fsamp: (word >> 13) & 3,
    nch: (word >> 11) & 3,
    mode: (word >> 8) & 7,
    hres: (word >> 7) & 1,
    hpf: (word >> 6) & 1,
    gain: (word >> 4) & 3,
    trig: (word >> 2) & 3,
    rec: (word >> 1) & 1,
    go: word & 1,
  };
}

/** What each channel on the wire carries. */
export type ChannelKind = "bio" | "aux" | "imu" | "buffer" | "counter";

/** The channels of one sample, in order on the wire. */
export interface WireChannel {
  kind: ChannelKind;
  /** "EMG 12", "AUX 1", "IMU W", "buffer", "counter". */
  name: string;
}

/** Bioelectrical channels streamed: NCH's count, halved in bipolar mode. */
export function bioChannels(cfg: Pick<SessantaquattroConfig, "mode" | "channels">): number {
  return cfg.mode === "bipolar" ? cfg.channels / 2 : cfg.channels;
}

/** Every channel of one sample on the wire, in order. */
export function wireLayout(
  cfg: Pick<SessantaquattroConfig, "model" | "mode" | "channels">,
): WireChannel[] {
  const out: WireChannel[] = [];
  for (let i = 1; i <= bioChannels(cfg); i++) out.push({ kind: "bio", name: `EMG ${i}` });
  out.push({ kind: "aux", name: "AUX 1" }, { kind: "aux", name: "AUX 2" });
  if (cfg.model === "Sessantaquattro+") {
    for (const q of ["W", "X", "Y", "Z"]) out.push({ kind: "imu", name: `IMU ${q}` });
  }
  out.push({ kind: "buffer", name: "buffer" }, { kind: "counter", name: "counter" });
  return out;
}

/** The mV per bit of a channel (1 for the IMU and accessory channels, which have no unit). */
export function mvPerBit(kind: ChannelKind, highRes: boolean): number {
  if (kind === "bio") return EMG_MV_PER_BIT;
  if (kind === "aux") return highRes ? AUX_MV_PER_BIT_24 : AUX_MV_PER_BIT_16;
  return 1;
}

export { LOCK_SAMPLES } from "./counter-aligned-parser";
/** The largest jump of the counter taken for samples the device skipped (1 s at 4 kHz). */
export const MAX_GAP = 4000;

/** Big-endian integers of `bytes` bytes, signed but the two accessory channels (the last two). */
function sessantaquattroFraming(channels: number, bytes: 2 | 3): CounterFraming<Int32Array> {
  const sampleBytes = channels * bytes;
  const accessoryMask = bytes === 2 ? 0xffff : 0xffffff;
  return {
    sampleBytes,
    maxGap: MAX_GAP,
    noCounter: `no sample counter (the last of ${channels} channels, +1 per sample) in the data: not a Sessantaquattro stream of these settings, or misaligned`,
    counter: (b, at) => u16be(b, at + sampleBytes - 2),
    decode(b, at, raw) {
      if (bytes === 2) {
        for (let ch = 0; ch < channels; ch++) raw[ch] = (u16be(b, at + 2 * ch) << 16) >> 16;
      } else {
        for (let ch = 0, i = at; ch < channels; ch++, i += 3) {
          raw[ch] = (((b[i]! << 16) | (b[i + 1]! << 8) | b[i + 2]!) << 8) >> 8;
        }
      }
      raw[channels - 2] = raw[channels - 2]! & accessoryMask;
      raw[channels - 1] = raw[channels - 1]! & accessoryMask;
    },
  };
}

/**
 * Splits the stream into samples of `channels` big-endian integers of `bytes` bytes (2 or 3),
 * aligned by the last channel (a counter, +1 per sample; its 16 low bits are compared).
 * `onSample(raw)` gets each sample's values (reused: copy what you keep): signed, but the two
 * accessory channels (the last two) unsigned. Gaps, restarts and misalignment: see
 * CounterAlignedParser.
 */
export class SessantaquattroStreamParser extends CounterAlignedParser<Int32Array> {
  constructor(
    readonly channels: number,
    readonly bytes: 2 | 3,
    onSample: (raw: Int32Array) => void,
  ) {
    if (!Number.isInteger(channels) || channels < 3) {
      throw new Error(`a Sessantaquattro sample has at least 3 channels, not ${channels}`);
    }
    super(sessantaquattroFraming(channels, bytes), new Int32Array(channels), onSample);
  }
}
