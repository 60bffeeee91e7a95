/**
 * The DLR ADC/BT link: an analog-to-digital converter behind a serial port (Bluetooth SPP or
 * USB) at 115200 Bd 8N1, configured with the number of channels and streaming fixed-size frames
 * (a two-byte start, the frame's length, big-endian 16-bit values, an end mark). The protocol is
 * a later issue (the host's serial bridge, `ctx.io.serial`, is what it will use);
 * `dlrAdcBtProtocol` returns the module that will speak it, undefined until then.
 */
import type { DeviceProtocol } from "./paced-device";

export const DLR_BAUD_RATE = 115200;
/** Channels when the file does not say (the original's default). */
export const DLR_DEFAULT_CHANNELS = 10;
/** A frame's length is one byte: 4 + 2 · channels + 4 ≤ 255. */
export const DLR_MAX_CHANNELS = 123;

/** The protocol module; undefined: not implemented yet. */
export function dlrAdcBtProtocol(_link: {
  Port?: string | undefined;
  Channels: number;
}): DeviceProtocol | undefined {
  return undefined;
}
