/**
 * The Delsys Trigno link: a Trigno base station reached through the Trigno SDK's TCP server
 * (Trigno Control Utility: command port, EMG data port). The protocol is a later issue;
 * `delsysProtocol` returns the module that will speak it, undefined until then.
 */
import type { DeviceProtocol } from "./paced-device";

/** The Trigno Control Utility's command port (its EMG data come on another port). */
export const TRIGNO_COMMAND_PORT = 50040;
/** Sensors a Trigno base pairs. */
export const TRIGNO_SENSORS = 16;

/** The protocol module for `Sensors` EMG sensors; undefined: not implemented yet. */
export function delsysProtocol(_link: {
  Sensors: number;
  Host: string;
}): DeviceProtocol | undefined {
  return undefined;
}
