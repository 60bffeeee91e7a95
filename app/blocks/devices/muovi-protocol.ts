/**
 * OT Bioelettronica's Muovi probes and SyncStation on the wire (docs/protocols.md, "OT
 * Bioelettronica Muovi and SyncStation"): the commands the PC sends and the sample stream it gets.
 *
 * - **SyncStation** (the PC is a TCP client of 192.168.76.1:54320): one configuration command,
 *   `[count·2 + GO, probe bytes…, CRC-8]`, a probe byte being `slot·16 + EMG·8 + mode·2 + enable`;
 *   stop is `[0, CRC-8 of it]`. Then, per sample at 2 kHz, the enabled slots' channels in slot order
 *   (38 int16 big-endian per Muovi: 32 EMG, 4 IMU quaternion, buffer/trigger, sample counter)
 *   followed by the SyncStation's own 6 channels, the last of them its sample counter.
 * - **Muovi alone** (the probe is a TCP client of the PC's port 54321): one command byte,
 *   `EMG·8 + mode·2 + GO` (9: EMG at 2 kHz, 32 monopolar channels, start; 8: stop), then 38 int16
 *   big-endian channels per sample, the last the probe's sample counter.
 *
 * Nothing in the stream marks where a sample starts: `MuoviStreamParser` keeps the alignment by the
 * last channel, which counts samples (+1 per sample, wrapping at 16 bits), finds it again after
 * malformed bytes and counts samples the device skipped.
 */
import { CounterAlignedParser, type CounterFraming, u16be } from "./counter-aligned-parser";

/** The SyncStation's address on its own Wi-Fi network and its TCP port (the original's). */
export const MUOVI_HOST = "192.168.76.1";
export const MUOVI_PORT = 54320;
/** EMG channels per probe, and the probes' EMG sampling rate (Hz). */
export const MUOVI_CHANNELS = 32;
export const MUOVI_RATE = 2000;
/** The local TCP port a single probe connects to (the original's MuoviSingleProbe listened here). */
export const MUOVI_PROBE_PORT = 54321;
/** Channels a Muovi sends per sample in EMG mode (32 EMG + 4 quaternion + buffer + counter). */
export const MUOVI_WIRE_CHANNELS = 38;
/** The SyncStation's own channels after the probes' (3 AUX, load cell, buffer, counter). */
export const SYNCSTATION_CHANNELS = 6;
/** Muovi slots on a SyncStation (0-based 0…3; 4-5 are Muovi+/Sessantaquattro+, 6… Due+/Quattro+). */
export const SYNCSTATION_MUOVI_SLOTS = 4;
/** Muovi EMG mode, 32 monopolar channels with preamp gain 8: 286.1 nV per bit, in mV. */
export const MUOVI_MV_PER_BIT = 0.000286;
/** The original Muovi block's unit: raw / 32768. */
export const MUOVI_FULL_SCALE = 32768;

/**
 * CRC-8 of `bytes[0…len)` as OT Bioelettronica's examples compute it: least significant bit
 * first, 0x8C (the reflected polynomial x⁸ + x⁵ + x⁴ + 1, 0x31) xored in when the bit out differs,
 * initial value 0: the CRC-8/MAXIM (Dallas 1-Wire) checksum.
 */
export function crc8(bytes: ArrayLike<number>, len = bytes.length): number {
  let crc = 0;
  for (let i = 0; i < len; i++) {
    let b = bytes[i]! & 0xff;
    for (let k = 0; k < 8; k++) {
      const out = (crc ^ b) & 1;
      crc >>= 1;
      if (out) crc ^= 0x8c;
      b >>= 1;
    }
  }
  return crc;
}

/** The probe byte of one SyncStation slot (EMG mode, 32 monopolar channels, enabled). */
export function syncStationProbeByte(slot: number): number {
  return slot * 16 + 1 * 8 + 0 * 2 + 1;
}

/** The SyncStation's start command for these Muovi slots (0…3, any order): sorted, CRC-8 last. */
export function syncStationStart(slots: readonly number[]): Uint8Array {
  const sorted = [...slots].sort((a, b) => a - b);
  for (const s of sorted) {
    if (!Number.isInteger(s) || s < 0 || s >= SYNCSTATION_MUOVI_SLOTS) {
      throw new Error(
        `SyncStation slot ${s} is not a Muovi slot (0…${SYNCSTATION_MUOVI_SLOTS - 1})`,
      );
    }
  }
  const cmd = new Uint8Array(sorted.length + 2);
  cmd[0] = sorted.length * 2 + 1;
  sorted.forEach((s, i) => (cmd[i + 1] = syncStationProbeByte(s)));
  cmd[cmd.length - 1] = crc8(cmd, cmd.length - 1);
  return cmd;
}

/** The SyncStation's stop command: a header of 0 (no probes, GO off) and its CRC-8. */
export function syncStationStop(): Uint8Array {
  return Uint8Array.of(0, crc8([0]));
}

/** A single Muovi's command byte: EMG mode, 32 monopolar channels, GO (start) or not (stop). */
export function probeCommand(go: boolean): number {
  return 1 * 8 + 0 * 2 + (go ? 1 : 0);
}

/** Channels per sample of a SyncStation streaming `probes` Muovi probes. */
export const syncStationChannels = (probes: number): number =>
  probes * MUOVI_WIRE_CHANNELS + SYNCSTATION_CHANNELS;

export { LOCK_SAMPLES } from "./counter-aligned-parser";
/** The largest jump of the counter taken for samples the device skipped (1 s at 2 kHz). */
export const MAX_GAP = 2000;

/** Int16 big-endian values, the last one a counter (+1 per sample). */
function muoviFraming(channels: number): CounterFraming<Int16Array> {
  const sampleBytes = channels * 2;
  return {
    sampleBytes,
    maxGap: MAX_GAP,
    noCounter: `no sample counter (the last of ${channels} channels, +1 per sample) in the data: not a Muovi stream, or misaligned`,
    counter: (b, at) => u16be(b, at + sampleBytes - 2),
    decode(b, at, raw) {
      for (let ch = 0; ch < channels; ch++) raw[ch] = u16be(b, at + 2 * ch);
    },
  };
}

/**
 * Splits an int16 big-endian stream of `channels` values per sample into samples, aligned by the
 * last channel (a counter, +1 per sample): see CounterAlignedParser for gaps, restarts and
 * misalignment.
 */
export class MuoviStreamParser extends CounterAlignedParser<Int16Array> {
  constructor(
    readonly channels: number,
    onSample: (raw: Int16Array) => void,
  ) {
    if (!Number.isInteger(channels) || channels < 2) {
      throw new Error(`a Muovi stream has at least 2 channels per sample, not ${channels}`);
    }
    super(muoviFraming(channels), new Int16Array(channels), onSample);
  }
}

/** Where each requested slot's channels start in a SyncStation sample (slots stream in slot order). */
export function slotOffsets(slots: readonly number[]): number[] {
  const sorted = [...slots].sort((a, b) => a - b);
  return slots.map((s) => sorted.indexOf(s) * MUOVI_WIRE_CHANNELS);
}
