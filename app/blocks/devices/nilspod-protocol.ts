/**
 * The NilsPod's Bluetooth LE streaming protocol (Portabiles' IMU; docs/protocols.md, "NilsPod
 * (BLE)", cites a source for every fact): a Nordic UART-style service whose RX characteristic takes
 * one-byte commands (0xC2 start streaming, 0xC1 stop) and whose TX characteristic notifies 14-byte
 * samples — gyroscope x, y, z and accelerometer x, y, z as little-endian int16, then a 16-bit
 * sample counter — one or more per notification. Pure decoders and the counter's bookkeeping are
 * here, with no I/O; nilspod-link.ts drives the host's BLE bridge (`ctx.io.ble`) with them.
 */

/** Accelerometer x, y, z (m/s²) then gyroscope x, y, z (deg/s). */
export const NILSPOD_VALUES = 6;

/** Service and characteristics, in the bridge's form (32 lower-case hex digits). */
export const NILSPOD = {
  /** The streaming service (Nordic UART Service UUID). */
  service: "6e400001b5a3f393e0a9e50e24dcca9e",
  /** Commands (write): one byte each. */
  commands: "6e400002b5a3f393e0a9e50e24dcca9e",
  /** Samples (notify). */
  data: "6e400003b5a3f393e0a9e50e24dcca9e",
} as const;

export const NILSPOD_COMMAND = { stopStreaming: 0xc1, startStreaming: 0xc2 } as const;

/** Advertised names begin so ("NilsPod-…", "NilsPodX-…"): a scan without Address takes these. */
export const NILSPOD_NAME_PREFIX = "NilsPod";

/** One sample on the wire: 12 bytes of IMU values and a 2-byte counter. */
export const NILSPOD_SAMPLE_BYTES = 14;

/** g as the original MOSAIC and NilsPodLib convert it. */
export const NILSPOD_GRAVITY = 9.81;
/** Accelerometer ranges (±g) and gyroscope ranges (±deg/s) a NilsPod can be configured to. */
export const NILSPOD_ACC_RANGES = [2, 4, 8, 16] as const;
export const NILSPOD_GYRO_RANGES = [125, 250, 500, 1000, 2000] as const;
/** Sampling rates a NilsPod can be configured to (Hz; set on the device, not by this block). */
export const NILSPOD_RATES = [1024, 512, 256, 204.8, 102.4, 51.2, 25.6, 12.8, 6.4] as const;

/** Factors from raw int16 to m/s² and deg/s: full scale (±range) over 2^15. */
export interface NilsPodScales {
  acc: number;
  gyro: number;
}

/**
 * The scales of a NilsPod configured to ±`accRangeG` g and ±`gyroRangeDps` deg/s (the original's
 * fixed ±16 g and ±2000 deg/s by default): raw · range / 32768, times 9.81 for m/s².
 */
export function nilsPodScales(accRangeG = 16, gyroRangeDps = 2000): NilsPodScales {
  return { acc: (accRangeG / 32768) * NILSPOD_GRAVITY, gyro: gyroRangeDps / 32768 };
}

/**
 * Decodes one notification: for every 14-byte sample, fills `out` (6 values: accelerometer x, y,
 * z in m/s², gyroscope x, y, z in deg/s — the output's order; the wire has the gyroscope first)
 * and calls `onSample(out, counter)`. Returns undefined, or why the bytes are not whole samples
 * (then nothing is decoded).
 */
export function decodeNilsPod(
  data: Uint8Array,
  scales: NilsPodScales,
  out: Float64Array,
  onSample: (values: Float64Array, counter: number) => void,
): string | undefined {
  const n = data.length;
  if (n === 0 || n % NILSPOD_SAMPLE_BYTES !== 0) {
    return `${n} bytes, not a whole number of ${NILSPOD_SAMPLE_BYTES}-byte samples`;
  }
  const dv = new DataView(data.buffer, data.byteOffset, n);
  for (let at = 0; at < n; at += NILSPOD_SAMPLE_BYTES) {
    for (let a = 0; a < 3; a++) {
      out[3 + a] = dv.getInt16(at + 2 * a, true) * scales.gyro;
      out[a] = dv.getInt16(at + 6 + 2 * a, true) * scales.acc;
    }
    onSample(out, dv.getUint16(at + 12, true));
  }
  return undefined;
}

/**
 * Samples missing between counters. The counter is 16 bits and wraps: a step of d ≥ 1 (modulo
 * 2^16) means d − 1 samples were lost; a step of 0 or one backwards (≥ 2^15 modulo 2^16) is a
 * restart of the counter (or a reordering), counted apart, with no samples counted lost.
 */
export class NilsPodCounter {
  lost = 0;
  restarts = 0;
  private last = -1;

  /** The next sample's counter; returns the samples lost just before it. */
  next(counter: number): number {
    const last = this.last;
    this.last = counter;
    if (last < 0) return 0;
    const d = (counter - last) & 0xffff;
    if (d === 0 || d >= 0x8000) {
      this.restarts++;
      return 0;
    }
    this.lost += d - 1;
    return d - 1;
  }

  /** A new connection: the next counter starts again (no loss counted across it). */
  resync(): void {
    this.last = -1;
  }
}

/** "the NilsPod aa:bb:… over Bluetooth LE" (messages). */
export function nilsPodTarget(address: string | undefined): string {
  return `${address !== undefined ? `the NilsPod ${address}` : "the first NilsPod found"} over Bluetooth LE`;
}
