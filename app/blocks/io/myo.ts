import { z } from "zod";
import { BlockConfigError, defineBlock, vectorShape, type BlockContext } from "../../engine";
import {
  CLASSIFIER_MODE,
  EMG_CHANNELS,
  EMG_MODE,
  EMG_RATE,
  IMU_MODE,
  IMU_VALUES,
  setModeCommand,
} from "./myo-protocol";
import { MyoRun } from "./myo-run";

const ADDRESS =
  /^(?:[0-9a-f]{2}[:-]){5}[0-9a-f]{2}$|^[0-9a-f]{32}$|^[0-9a-f]{8}(?:-[0-9a-f]{4}){3}-[0-9a-f]{12}$/i;

const params = z.strictObject({
  Address: z
    .string()
    .regex(ADDRESS, "a Bluetooth address aa:bb:cc:dd:ee:ff, or the device id macOS gives")
    .optional()
    .describe(
      "The armband's Bluetooth address (aa:bb:cc:dd:ee:ff; on macOS the device id noble " +
        "reports). Omitted: the first Myo found that no other Myo block of this worker uses",
    ),
  EMG: z
    .enum(["filtered", "raw"])
    .default("filtered")
    .describe(
      "EMG mode written to the armband: filtered (myohw send_emg, what MOSAIC asked for) or raw " +
        "(send_emg_raw: unfiltered)",
    ),
  IMU: z
    .boolean()
    .default(true)
    .describe("Stream the IMU (orientation, accelerometer, gyroscope at 50 Hz) on the imu output"),
  Vibrate: z
    .boolean()
    .default(true)
    .describe("Vibrate briefly once streaming starts, so the wearer knows the armband is live"),
  Reconnect: z
    .number()
    .min(0)
    .max(3600)
    .default(1)
    .describe(
      "Seconds to wait before searching again after a lost link or a failed connection (0: never)",
    ),
  MaxDelay: z
    .number()
    .int()
    .min(1)
    .max(10_000)
    .default(15)
    .describe(
      "With a timer input only: EMG samples kept waiting for ticks; older ones are dropped " +
        "(MOSAIC's _maxDelay, 15 samples = 75 ms)",
    ),
});

type Params = z.output<typeof params>;

/**
 * Whether a timer input paces the EMG output (MOSAIC's form); any other input is a config
 * error.
 */
function pacedByTimer(ctx: BlockContext): boolean {
  const timer = ctx.inputs[0];
  if (timer && !timer.isTimer) {
    throw new BlockConfigError(
      `the input ${timer.source} is not a timer: a Myo's input only paces its EMG output (MOSAIC's form); leave Inputs out to emit every sample as it arrives`,
    );
  }
  return timer !== undefined;
}

/** The set-mode command that starts the armband streaming as the params ask. */
function modeCommand(p: Params): Uint8Array {
  return setModeCommand(
    p.EMG === "raw" ? EMG_MODE.raw : EMG_MODE.filtered,
    p.IMU ? IMU_MODE.data : IMU_MODE.none,
    CLASSIFIER_MODE.disabled,
  );
}

export const Myo = defineBlock({
  type: "Myo",
  aliases: ["MYO"],
  category: "Devices",
  summary: "Streams EMG (8 ch @ 200 Hz) and IMU (50 Hz) from a Thalmic Labs Myo armband over BLE.",
  help:
    "The Myo armband (Thalmic Labs) over Bluetooth LE, as MOSAIC's Myo block, " +
    "without Thalmic's SDK or dongle: the block scans for the armband's control service, " +
    "connects (to `Address`, or to the first Myo found), tells it never to sleep and to stream " +
    "EMG (`EMG`: filtered or raw) and the IMU with the on-board classifier off, and subscribes " +
    "to its four EMG characteristics and the IMU characteristic. Each EMG notification holds two " +
    "8-channel int8 samples; `emg` emits them as two events [1, 8] stamped 5 ms apart (200 Hz), " +
    "each value int8 / 128 as MOSAIC emitted it (in [−1, 0.992]; a UdpSender fed by this block " +
    "picks the myo serializer, which multiplies by 128 again and sends the original bytes). " +
    "`imu` emits [1, 10] at 50 Hz: orientation quaternion w, x, y, z (int16 / 16384), " +
    "accelerometer x, y, z in g (/ 2048) and gyroscope x, y, z in deg/s (/ 16). With a timer " +
    "input (MOSAIC's form, `Inputs: [timer]`, `Params: [address]`) each tick emits the oldest " +
    "waiting EMG sample instead (the newest `MaxDelay` are kept), repeats the last one when none " +
    "came, and zeros while not streaming. A lost link is reported in the status and the armband " +
    "is searched for again after `Reconnect` seconds. Needs the desktop app or `mosaic run` with " +
    "a Bluetooth LE adapter (on Linux, node needs the CAP_NET_RAW capability); without one the " +
    "status says why and the rest of the pipeline runs. Protocol: Thalmic Labs' `myohw.h` " +
    "(github.com/thalmiclabs/myo-bluetooth, modified BSD licence) and MOSAIC's `Myo.cs` " +
    "(AIROB-Lab/MOSAIC); details in docs/protocols.md, section Myo (BLE).",
  params,
  legacyParams(args) {
    const a = (args[0] ?? "").trim();
    return a === "" ? {} : { Address: a };
  },
  legacyForm: "[address] (optional: the first Myo found)",
  inputs: { min: 0, max: 1, labels: ["timer"] },
  outputs: ["emg", "imu"],
  eventLoop: true,
  views: ["scope", "spider"],
  panel: "Scope of the 8 EMG channels; the link's state, samples received, disconnections.",
  create(ctx, p: Params) {
    const paced = pacedByTimer(ctx);
    if (!paced && ctx.declaredRate === undefined) ctx.setDesiredRate(EMG_RATE);
    const emgOut = ctx.output(vectorShape(EMG_CHANNELS), "emg");
    const imuOut = ctx.output(vectorShape(IMU_VALUES), "imu");
    return new MyoRun(ctx, p, paced, modeCommand(p), emgOut, imuOut).instance();
  },
});
