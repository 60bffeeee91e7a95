/**
 * OT Bioelettronica's Quattrocento on the wire (docs/protocols.md, "OT Bioelettronica
 * Quattrocento"): the 40-byte configuration command the PC sends and the sample stream it gets.
 *
 * - **Command** (the PC is a TCP client of 169.254.1.10:23456): `ACQ_SETT` (bit 7 = 1, DECIM,
 *   REC_ON, FSAMP<1:0>, NCH<1:0>, ACQ_ON), `AN_OUT_IN_SEL` (gain, source input), `AN_OUT_CH_SEL`
 *   (channel), three bytes per input for IN1…IN8 and MULTIPLE IN1…IN4 (`CONF0`: muscle; `CONF1`:
 *   sensor · 8 + adapter; `CONF2`: side, high-pass, low-pass, detection mode) and the CRC-8 of
 *   the 39 bytes before it (CRC-8/MAXIM, the SyncStation's: `crc8` of muovi-protocol.ts). Stop is
 *   the same command with `ACQ_SETT` = 0x80 (acquisition off), as OTB's example sends it.
 * - **Stream**: per sample, NCH int16 little-endian values: the active INs (16 channels each),
 *   the active MULTIPLE INs (64 each), 16 AUX IN, then 8 accessory channels, the first of which
 *   is an unsigned 16-bit sample counter (+1 per sample, from an unpredictable value, wrapping).
 *
 * `QuattrocentoStreamParser` keeps the alignment by that counter: it trusts an alignment once
 * LOCK_SAMPLES samples in a row count up, finds it again after malformed bytes and counts the
 * samples the device skipped.
 */
import { CounterAlignedParser, type CounterFraming, u16le } from "./counter-aligned-parser";
import { crc8 } from "./muovi-protocol";

/** The Quattrocento's default address (link-local, on its Ethernet port) and TCP port. */
export const QUATTROCENTO_HOST = "169.254.1.10";
export const QUATTROCENTO_PORT = 23456;
/** Bytes of a configuration command (39 and the CRC-8). */
export const COMMAND_BYTES = 40;
/** Sampling rates by FSAMP<1:0> (Hz). */
export const QUATTROCENTO_RATES = [512, 2048, 5120, 10240] as const;
export type QuattrocentoRate = (typeof QUATTROCENTO_RATES)[number];
/** Channels per sample by NCH<1:0>. */
export const QUATTROCENTO_CHANNEL_COUNTS = [120, 216, 312, 408] as const;
export type QuattrocentoChannelCount = (typeof QUATTROCENTO_CHANNEL_COUNTS)[number];
/** AUX IN channels and accessory channels, in every sample after the inputs'. */
export const AUX_CHANNELS = 16;
export const ACCESSORY_CHANNELS = 8;
/** EMG inputs: 5 V ADC swing, 16 bits, gain 150, in mV per bit. */
export const EMG_MV_PER_BIT = (5 / 2 ** 16 / 150) * 1000;
/** AUX IN: 5 V swing, 16 bits, gain 0.5, in mV per bit. */
export const AUX_MV_PER_BIT = (5 / 2 ** 16 / 0.5) * 1000;

/** The front-panel inputs and the rear AUX IN, as the block's params name them. */
export const CONNECTORS = [
  "IN1",
  "IN2",
  "IN3",
  "IN4",
  "IN5",
  "IN6",
  "IN7",
  "IN8",
  "MULTIPLE IN1",
  "MULTIPLE IN2",
  "MULTIPLE IN3",
  "MULTIPLE IN4",
  "AUX IN",
] as const;
export type Connector = (typeof CONNECTORS)[number];
/** The inputs with a configuration (all but AUX IN), in command order. */
export const CONFIGURED_INPUTS = CONNECTORS.slice(0, 12) as readonly Connector[];

/** Channels of one connector: 16 per IN and for AUX IN, 64 per MULTIPLE IN. */
export const connectorChannels = (c: Connector): number => (c.startsWith("MULTIPLE") ? 64 : 16);

/** NCH<1:0> (0…3): 2·(n+1) INs and n+1 MULTIPLE INs active. */
export function activeInputs(nch: number): { ins: number; multiples: number } {
  return { ins: 2 * (nch + 1), multiples: nch + 1 };
}

/** The smallest NCH code (0…3) whose stream carries every connector listed. */
export function nchFor(connectors: readonly Connector[]): number {
  let nch = 0;
  for (const c of connectors) {
    const i = CONNECTORS.indexOf(c);
    if (i < 8) nch = Math.max(nch, Math.floor(i / 2));
    else if (i < 12) nch = Math.max(nch, i - 8);
  }
  return nch;
}

/** Where a connector's channels start in a sample of NCH code `nch`; -1 when not streamed. */
export function connectorOffset(c: Connector, nch: number): number {
  const { ins, multiples } = activeInputs(nch);
  const i = CONNECTORS.indexOf(c);
  if (i < 8) return i < ins ? 16 * i : -1;
  if (i < 12) return i - 8 < multiples ? 16 * ins + 64 * (i - 8) : -1;
  return 16 * ins + 64 * multiples;
}

/** Where the accessory channels start (the sample counter is the first). */
export const counterChannel = (channels: number): number => channels - ACCESSORY_CHANNELS;

export const HIGH_PASS = [0.7, 10, 100, 200] as const;
export const LOW_PASS = [130, 500, 900, 4400] as const;
export const DETECTION = ["monopolar", "differential", "bipolar"] as const;
export const SIDES = ["undefined", "left", "right", "none"] as const;
export const ANALOG_OUT_GAINS = [1, 2, 4, 16] as const;

/** One input's three configuration bytes, as values (see `inputBytes`). */
export interface InputSettings {
  /** Muscle index, 0…64 (0: not defined). */
  muscle: number;
  /** Sensor index, 0…23 (0: not defined). */
  sensor: number;
  /** Adapter index, 0…6 (0: not defined). */
  adapter: number;
  side: (typeof SIDES)[number];
  highPass: (typeof HIGH_PASS)[number];
  lowPass: (typeof LOW_PASS)[number];
  mode: (typeof DETECTION)[number];
}

/** OTB's example's setting of every input: 10 Hz high-pass, 500 Hz low-pass, monopolar. */
export const DEFAULT_INPUT: InputSettings = {
  muscle: 0,
  sensor: 0,
  adapter: 0,
  side: "undefined",
  highPass: 10,
  lowPass: 500,
  mode: "monopolar",
};

export interface QuattrocentoConfig {
  rate: QuattrocentoRate;
  /** NCH code, 0…3 (120, 216, 312, 408 channels). */
  nch: number;
  /** DECIM: sample at 10240 Hz and send one sample in 2, 5 or 20. */
  decimator: boolean;
  /** REC_ON: the acquisition is marked on the Trigger OUT. */
  recording: boolean;
  analogOut: { source: Connector; channel: number; gain: (typeof ANALOG_OUT_GAINS)[number] };
  /** The 12 inputs' settings, in command order (IN1…IN8, MULTIPLE IN1…IN4). */
  inputs: readonly InputSettings[];
}

/** `INx_CONF0/1/2` of one input. */
export function inputBytes(s: InputSettings): [number, number, number] {
  return [
    s.muscle & 0x7f,
    ((s.sensor & 0x1f) << 3) | (s.adapter & 0x07),
    (SIDES.indexOf(s.side) << 6) |
      (HIGH_PASS.indexOf(s.highPass) << 4) |
      (LOW_PASS.indexOf(s.lowPass) << 2) |
      DETECTION.indexOf(s.mode),
  ];
}

/** `ACQ_SETT`: 1, DECIM, REC_ON, FSAMP<1:0>, NCH<1:0>, ACQ_ON (bit 7 first). */
export function acqSettByte(c: QuattrocentoConfig, acquire: boolean): number {
  return (
    0x80 |
    (c.decimator ? 0x40 : 0) |
    (c.recording ? 0x20 : 0) |
    (QUATTROCENTO_RATES.indexOf(c.rate) << 3) |
    (c.nch << 1) |
    (acquire ? 1 : 0)
  );
}

/** The 40-byte command: acquisition on (`acquire`) with `c`, or the stop command. */
export function quattrocentoCommand(c: QuattrocentoConfig, acquire: boolean): Uint8Array {
  if (c.inputs.length !== CONFIGURED_INPUTS.length) {
    throw new Error(`a Quattrocento command configures 12 inputs, not ${c.inputs.length}`);
  }
  if (!Number.isInteger(c.nch) || c.nch < 0 || c.nch > 3) {
    throw new Error(`NCH code ${c.nch} is not 0…3`);
  }
  const cmd = new Uint8Array(COMMAND_BYTES);
  cmd[0] = acquire ? acqSettByte(c, true) : 0x80;
  cmd[1] =
    (ANALOG_OUT_GAINS.indexOf(c.analogOut.gain) << 4) | CONNECTORS.indexOf(c.analogOut.source);
  cmd[2] = c.analogOut.channel & 0x3f;
  c.inputs.forEach((s, i) => cmd.set(inputBytes(s), 3 + 3 * i));
  cmd[COMMAND_BYTES - 1] = crc8(cmd, COMMAND_BYTES - 1);
  return cmd;
}

/** Whether this machine stores an int16 little-endian, as the wire does (then samples are copied). */
const LITTLE_ENDIAN = new Uint8Array(Uint16Array.of(1).buffer)[0] === 1;

export { LOCK_SAMPLES } from "./counter-aligned-parser";
/** The largest jump of the counter taken for samples the device skipped (1 s at 10240 Hz). */
export const MAX_GAP = 10240;

/**
 * Int16 little-endian values, the sample counter at accessory channel 1 (`channels − 8`). A sample
 * at an even offset is copied through an int16 view of the buffer where the machine is
 * little-endian too.
 */
function quattrocentoFraming(channels: number): CounterFraming<Int16Array> {
  const counterAt = 2 * counterChannel(channels);
  let words: Int16Array<ArrayBufferLike> = new Int16Array(0);
  return {
    sampleBytes: channels * 2,
    maxGap: MAX_GAP,
    noCounter: `no sample counter (channel ${counterChannel(channels) + 1} of ${channels}, +1 per sample) in the data: not a Quattrocento stream of ${channels} channels, or misaligned`,
    counter: (b, at) => u16le(b, at + counterAt),
    decode(b, at, raw) {
      if (LITTLE_ENDIAN && (at & 1) === 0 && (b.byteOffset & 1) === 0) {
        if (words.buffer !== b.buffer)
          words = new Int16Array(b.buffer, b.byteOffset, b.length >> 1);
        raw.set(words.subarray(at >> 1, (at >> 1) + raw.length));
      } else for (let ch = 0, i = at; ch < raw.length; ch++, i += 2) raw[ch] = u16le(b, i);
    },
  };
}

/**
 * Splits an int16 little-endian stream of `channels` values per sample into samples, aligned by
 * the sample counter (accessory channel 1, at `channels − 8`, +1 per sample): see
 * CounterAlignedParser for gaps, restarts and misalignment.
 */
export class QuattrocentoStreamParser extends CounterAlignedParser<Int16Array> {
  constructor(
    readonly channels: number,
    onSample: (raw: Int16Array) => void,
  ) {
    if (!Number.isInteger(channels) || channels <= ACCESSORY_CHANNELS) {
      throw new Error(
        `a Quattrocento sample has more than ${ACCESSORY_CHANNELS} channels, not ${channels}`,
      );
    }
    super(quattrocentoFraming(channels), new Int16Array(channels), onSample);
  }
}
