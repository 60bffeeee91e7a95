import { z } from "zod";
import { defineBlock, vectorShape } from "../../engine";
import { nilsPodProtocol } from "./nilspod-link";
import {
  NILSPOD_ACC_RANGES,
  NILSPOD_GYRO_RANGES,
  NILSPOD_VALUES,
  nilsPodTarget,
} from "./nilspod-protocol";
import { pacedDevice, pacingTimer } from "./paced-device";

const ADDRESS =
  /^(?:[0-9a-f]{2}[:-]){5}[0-9a-f]{2}$|^[0-9a-f]{32}$|^[0-9a-f]{8}(?:-[0-9a-f]{4}){3}-[0-9a-f]{12}$/i;

const params = z.strictObject({
  Address: z
    .string()
    .regex(ADDRESS, "a Bluetooth address aa:bb:cc:dd:ee:ff, or the device id macOS gives")
    .optional()
    .describe(
      "The NilsPod's Bluetooth address (aa:bb:cc:dd:ee:ff; on macOS the device id noble " +
        "reports). Omitted: the first NilsPod found (advertised name NilsPod…) that no other " +
        "NilsPod block of this worker uses",
    ),
  AccRange: z
    .literal(NILSPOD_ACC_RANGES)
    .optional()
    .describe(
      "The accelerometer range the NilsPod is configured to, ±g; unset: 16, as the original " +
        "assumed (raw · range / 32768 · 9.81 gives m/s²)",
    ),
  GyroRange: z
    .literal(NILSPOD_GYRO_RANGES)
    .optional()
    .describe(
      "The gyroscope range the NilsPod is configured to, ±deg/s; unset: 2000, as the original " +
        "assumed (raw · range / 32768 gives deg/s)",
    ),
});

export const NilsPod = defineBlock({
  type: "NilsPod",
  category: "Devices",
  summary:
    "A NilsPod inertial sensor over Bluetooth LE: accelerometer and gyroscope, paced by a timer.",
  help:
    "A NilsPod IMU (Portabiles) over Bluetooth LE, as MOSAIC's NilsPod block, without any " +
    "vendor software: the block scans for `Address` (or the first peripheral whose name begins " +
    "NilsPod), connects, subscribes to the sample characteristic of its streaming service " +
    "(6e400003-…, Nordic UART) and writes the start command 0xC2; at close it writes the stop " +
    "command 0xC1 and disconnects. Each notification holds one or more 14-byte samples " +
    "(gyroscope x, y, z and accelerometer x, y, z as little-endian int16, then a 16-bit " +
    "counter). Paced by one timer input: every tick emits one vector [1, 6], accelerometer x, y, " +
    "z in m/s² (raw · AccRange / 32768 · 9.81) and gyroscope x, y, z in deg/s (raw · GyroRange / " +
    "32768), with the oldest sample waiting (the newest 15 are kept), the last one again when " +
    "none came, zeros while not streaming, as the original. The device's own rate (up to 1024 " +
    "Hz, configured on the NilsPod) should match the timer's. The status counts samples, " +
    "samples lost (gaps in the counter), malformed notifications (dropped, never fatal) and " +
    "disconnections; a lost link (or 2 s without data) is reported and the NilsPod searched for " +
    "again after 0.5, 1, 2, 4, then every 5 s. MOSAIC's positional form is `[MAC]` (optional: " +
    "`''` or no Params takes the first NilsPod found). Needs the desktop app or `mosaic run` " +
    "with a Bluetooth LE adapter (on Linux, node needs the CAP_NET_RAW capability); without one " +
    "the status says why and the rest of the pipeline runs. Tested only against a simulated " +
    "NilsPod (app/devices/nilspod-simulator.ts), never a real one; `mosaic run " +
    "--simulate-devices` (or the app's Simulate devices switch) replaces the block by an " +
    "ImuSimulator of the same shape and rate. Protocol: docs/protocols.md, section NilsPod (BLE).",
  params,
  legacyParams(args) {
    const a = (args[0] ?? "").trim();
    return a === "" ? {} : { Address: a };
  },
  legacyForm: "[address] (optional: the first NilsPod found)",
  inputs: { min: 1, max: 1, labels: ["timer"] },
  outputs: ["imu"],
  eventLoop: true,
  views: ["scope"],
  panel:
    "Scope of the six axes; the link's state, samples received and lost, malformed notifications, disconnections.",
  create(ctx, p) {
    pacingTimer(ctx);
    return pacedDevice(ctx, {
      device: "NilsPod",
      target: nilsPodTarget(p.Address),
      shape: vectorShape(NILSPOD_VALUES),
      port: "imu",
      protocol: nilsPodProtocol(p),
    });
  },
});
