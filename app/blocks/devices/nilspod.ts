import { z } from "zod";
import { defineBlock, vectorShape } from "../../engine";
import { NILSPOD_VALUES, nilsPodProtocol } from "./nilspod-protocol";
import { pacedDevice, pacingTimer } from "./paced-device";

const ADDRESS =
  /^(?:[0-9a-f]{2}[:-]){5}[0-9a-f]{2}$|^[0-9a-f]{32}$|^[0-9a-f]{8}(?:-[0-9a-f]{4}){3}-[0-9a-f]{12}$/i;

const params = z.strictObject({
  Address: z
    .string()
    .regex(ADDRESS, "a Bluetooth address aa:bb:cc:dd:ee:ff, or the device id macOS gives")
    .optional()
    .describe("The NilsPod's Bluetooth address; omitted: the first NilsPod found"),
});

export const NilsPod = defineBlock({
  type: "NilsPod",
  category: "Devices",
  summary:
    "A NilsPod inertial sensor over Bluetooth LE: accelerometer and gyroscope, paced by a timer.",
  help:
    "A NilsPod IMU (Portabiles) over Bluetooth LE, as MOSAIC's NilsPod block: paced by one timer " +
    "input, every tick emits one vector [1, 6]: accelerometer x, y, z in m/s² and gyroscope x, " +
    "y, z in deg/s (the oldest sample waiting, the last one again when none came, zeros while " +
    "not streaming, as the original). MOSAIC's positional form is `[MAC]` (optional: `''` or " +
    "no Params takes the first NilsPod found). The NilsPod's protocol comes in a later release: " +
    "until then the block says that the device is not reachable and sends zeros, and `mosaic " +
    "run --simulate-devices` (or the app's Simulate devices switch) replaces it by an " +
    "ImuSimulator of the same shape and rate.",
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
  panel: "Scope of the six axes; the link's state and samples received.",
  create(ctx, p) {
    pacingTimer(ctx);
    return pacedDevice(ctx, {
      device: "NilsPod",
      target: `${p.Address !== undefined ? `the NilsPod ${p.Address}` : "the first NilsPod found"} over Bluetooth LE`,
      shape: vectorShape(NILSPOD_VALUES),
      port: "imu",
      protocol: nilsPodProtocol(p),
    });
  },
});
