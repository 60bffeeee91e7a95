/**
 * The NilsPod link (Portabiles' IMU over Bluetooth LE, a Nordic UART-style service): 14-byte
 * samples of gyroscope and accelerometer int16 values and a counter. The protocol is a later issue
 * (the host's BLE bridge, `ctx.io.ble`, is what it will use); `nilsPodProtocol` returns the
 * module that will speak it, undefined until then.
 */
import type { DeviceProtocol } from "./paced-device";

/** Accelerometer x, y, z (m/s²) then gyroscope x, y, z (deg/s). */
export const NILSPOD_VALUES = 6;

/** The protocol module; undefined: not implemented yet. */
export function nilsPodProtocol(_link: {
  Address?: string | undefined;
}): DeviceProtocol | undefined {
  return undefined;
}
