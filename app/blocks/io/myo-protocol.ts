/**
 * The Thalmic Labs Myo armband's Bluetooth LE protocol, as published by Thalmic Labs in
 * `myohw.h` (github.com/thalmiclabs/myo-bluetooth): service and characteristic UUIDs, the command
 * bytes that start streaming, and pure decoders of EMG and IMU notifications. No I/O here: the
 * Myo block (myo.ts) drives a `BleBridge` with these.
 *
 * Byte order: `myohw.h` says "all values are big-endian", but the armband sends its int16 fields
 * little-endian, as BLE attribute values are; every working decoder reads them so (e.g.
 * dzhu/myo-raw unpacks with `'<'`), and so do we. docs/protocols.md, "Myo (BLE)", has the tables.
 */

/**
 * A Myo UUID from its 16-bit short id: myohw.h's base UUID d506xxxx-a904-deb9-4748-2c7f4a124842
 * with the short id in place of xxxx, in the bridge's form (32 lower-case hex digits).
 */
export function myoUuid(short: number): string {
  return `d506${short.toString(16).padStart(4, "0")}a904deb947482c7f4a124842`;
}

/** Services and characteristics (myohw.h `myohw_services`). */
export const MYO = {
  controlService: myoUuid(0x0001),
  infoCharacteristic: myoUuid(0x0101),
  firmwareCharacteristic: myoUuid(0x0201),
  commandCharacteristic: myoUuid(0x0401),
  imuService: myoUuid(0x0002),
  imuCharacteristic: myoUuid(0x0402),
  emgService: myoUuid(0x0005),
  /** EmgData0…3Characteristic: each notifies two 8-channel samples; together 200 Hz. */
  emgCharacteristics: [0x0105, 0x0205, 0x0305, 0x0405].map(myoUuid),
} as const;

/** A UUID in the bridge's form: lower case, no dashes. */
export function normalizeUuid(uuid: string): string {
  return uuid.replace(/-/g, "").toLowerCase();
}

/** The same device address, whatever the case and separators ("AA:BB…" = "aa-bb…" = "aabb…"). */
export function sameAddress(a: string, b: string): boolean {
  const n = (s: string): string => s.replace(/[:-]/g, "").toLowerCase();
  return n(a) === n(b);
}

/** myohw_emg_mode_t. */
export const EMG_MODE = { none: 0x00, filtered: 0x02, raw: 0x03 } as const;
/** myohw_imu_mode_t (data: orientation, accelerometer and gyroscope streams). */
export const IMU_MODE = { none: 0x00, data: 0x01 } as const;
/** myohw_classifier_mode_t. */
export const CLASSIFIER_MODE = { disabled: 0x00, enabled: 0x01 } as const;
/** myohw_sleep_mode_t. */
export const SLEEP_MODE = { normal: 0x00, neverSleep: 0x01 } as const;
/** myohw_vibration_type_t. */
export const VIBRATION = { none: 0x00, short: 0x01, medium: 0x02, long: 0x03 } as const;

/** Command ids (myohw_command_t). */
const COMMAND = { setMode: 0x01, vibrate: 0x03, setSleepMode: 0x09 } as const;

/** `myohw_command_set_mode_t`: header (command, payload size 3), EMG, IMU and classifier modes. */
export function setModeCommand(emg: number, imu: number, classifier: number): Uint8Array {
  return Uint8Array.of(COMMAND.setMode, 3, emg, imu, classifier);
}

/** `myohw_command_set_sleep_mode_t`: header (command, payload size 1), sleep mode. */
export function sleepModeCommand(mode: number): Uint8Array {
  return Uint8Array.of(COMMAND.setSleepMode, 1, mode);
}

/** `myohw_command_vibrate_t`: header (command, payload size 1), vibration type. */
export function vibrateCommand(type: number): Uint8Array {
  return Uint8Array.of(COMMAND.vibrate, 1, type);
}

export const EMG_CHANNELS = 8;
/** Samples per EMG notification (`myohw_emg_data_t`: sample1[8], sample2[8], int8). */
export const EMG_SAMPLES_PER_NOTIFICATION = 2;
/** MYOHW_EMG_DEFAULT_STREAMING_RATE. */
export const EMG_RATE = 200;
/** MYOHW_DEFAULT_IMU_SAMPLE_RATE. */
export const IMU_RATE = 50;
/** MOSAIC's Myo divided the int8 EMG by 128 (`_myoHwEmgScale`): values in [−1, 127/128]. */
export const EMG_SCALE = 1 / 128;
/** MYOHW_ORIENTATION_SCALE, MYOHW_ACCELEROMETER_SCALE (→ g), MYOHW_GYROSCOPE_SCALE (→ deg/s). */
export const ORIENTATION_SCALE = 16384;
export const ACCELEROMETER_SCALE = 2048;
export const GYROSCOPE_SCALE = 16;
/** Values of one IMU event: quaternion w, x, y, z; accelerometer x, y, z; gyroscope x, y, z. */
export const IMU_VALUES = 10;

const EMG_BYTES = EMG_CHANNELS * EMG_SAMPLES_PER_NOTIFICATION;
const IMU_BYTES = 2 * IMU_VALUES;

/**
 * Decodes an EMG notification into `out` (16 values: the first sample's 8 channels, then the
 * second's), each int8 times `scale`. Returns undefined, or why the bytes are not one.
 */
export function decodeEmg(
  data: Uint8Array,
  out: Float64Array,
  scale = EMG_SCALE,
): string | undefined {
  if (data.length !== EMG_BYTES)
    return `${data.length} bytes, an EMG notification has ${EMG_BYTES}`;
  for (let i = 0; i < EMG_BYTES; i++) {
    const b = data[i]!;
    out[i] = (b < 128 ? b : b - 256) * scale;
  }
  return undefined;
}

/**
 * Decodes an IMU notification (`myohw_imu_data_t`, ten little-endian int16) into `out`:
 * quaternion w, x, y, z (/16384), accelerometer in g (/2048), gyroscope in deg/s (/16).
 * Returns undefined, or why the bytes are not one.
 */
export function decodeImu(data: Uint8Array, out: Float64Array): string | undefined {
  if (data.length !== IMU_BYTES)
    return `${data.length} bytes, an IMU notification has ${IMU_BYTES}`;
  const dv = new DataView(data.buffer, data.byteOffset, data.byteLength);
  for (let i = 0; i < IMU_VALUES; i++) {
    const raw = dv.getInt16(2 * i, true);
    out[i] = raw / (i < 4 ? ORIENTATION_SCALE : i < 7 ? ACCELEROMETER_SCALE : GYROSCOPE_SCALE);
  }
  return undefined;
}

/**
 * Timestamps for EMG samples, which the armband sends without any: two per notification, 5 ms
 * apart. Consecutive notifications continue the sample clock (last + 5 ms), so BLE's bursty
 * delivery does not show as jitter. The clock is pulled back towards the arrival time when it
 * runs ahead of it (never more than half a period per notification, never before the previous
 * sample) and re-synchronised to the arrival time when it falls more than `maxLag` behind
 * (notifications lost, a stalled link, a reconnection).
 */
export class EmgTimestamps {
  private last = NaN;
  /** Times the clock was re-synchronised (after the first notification). */
  resyncs = 0;

  constructor(
    readonly period = 1 / EMG_RATE,
    readonly maxLag = 0.05,
  ) {}

  /** Fills `t[0..n)` for `n` samples that arrived at `now`; the last one gets ≤ `now`. */
  stamp(now: number, t: Float64Array | number[], n = EMG_SAMPLES_PER_NOTIFICATION): void {
    const p = this.period;
    const span = (n - 1) * p;
    let first: number;
    if (this.last !== this.last) {
      first = now - span;
    } else {
      const ideal = this.last + p;
      if (ideal + span < now - this.maxLag) {
        first = now - span;
        this.resyncs++;
      } else if (ideal + span > now) {
        first = Math.max(now - span, ideal - p / 2);
      } else {
        first = ideal;
      }
    }
    for (let i = 0; i < n; i++) t[i] = first + i * p;
    this.last = first + span;
  }

  /** Forget the clock: the next notification starts it again (after a reconnection). */
  reset(): void {
    this.last = NaN;
  }
}
