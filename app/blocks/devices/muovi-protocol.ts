/**
 * The Muovi SyncStation link (OT Bioelettronica): where it is and what the data looks like. The
 * protocol itself (a configuration command over TCP, then frames of int16 samples of every enabled
 * probe, 38 values per Muovi probe of which the first 32 are EMG, at 2 kHz) is a later issue;
 * `muoviProtocol` returns the module that will speak it, undefined until then.
 */
import type { DeviceProtocol } from "./paced-device";

/** The SyncStation's address on its own Wi-Fi network and its TCP port (the original's). */
export const MUOVI_HOST = "192.168.76.1";
export const MUOVI_PORT = 54320;
/** EMG channels per probe, and the probes' sampling rate (Hz). */
export const MUOVI_CHANNELS = 32;
export const MUOVI_RATE = 2000;

/**
 * The protocol module for these probes, averaging `averageOver` raw samples per tick; undefined:
 * not implemented yet.
 */
export function muoviProtocol(
  _link: { Probes: readonly number[]; Host: string; Port: number },
  _averageOver: number,
): DeviceProtocol | undefined {
  return undefined;
}

/** The local TCP port a single probe connects to (the original's MuoviSingleProbe listened here). */
export const MUOVI_PROBE_PORT = 54321;

/** The protocol module of a single probe delivering `rows` raw samples per tick; undefined: not yet. */
export function muoviProbeProtocol(
  _link: { Probes: readonly number[]; Port: number },
  _rows: number,
): DeviceProtocol | undefined {
  return undefined;
}
