import { z } from "zod";
import {
  BlockConfigError,
  defineBlock,
  vectorShape,
  type BleAdapterState,
  type BleBridge,
  type BleConnection,
  type BlePeripheral,
  type Frame,
} from "../../engine";
import { plural, TextThrottle } from "../shared/text";
import {
  CLASSIFIER_MODE,
  decodeEmg,
  decodeImu,
  EMG_CHANNELS,
  EMG_MODE,
  EMG_RATE,
  EmgTimestamps,
  IMU_MODE,
  IMU_VALUES,
  MYO,
  normalizeUuid,
  sameAddress,
  setModeCommand,
  SLEEP_MODE,
  sleepModeCommand,
  VIBRATION,
  vibrateCommand,
} from "./myo-protocol";

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

type Phase =
  | "unavailable"
  | "adapter"
  | "scanning"
  | "connecting"
  | "configuring"
  | "streaming"
  | "lost"
  | "stopped";

/** Armbands in use by a Myo block, per bridge: a block without Address skips them. */
const claimed = new WeakMap<BleBridge, Set<string>>();
const claimsOf = (b: BleBridge): Set<string> => {
  let s = claimed.get(b);
  if (!s) claimed.set(b, (s = new Set()));
  return s;
};
const addressKey = (a: string): string => a.replace(/[:-]/g, "").toLowerCase();

const ADAPTER_TEXT: Record<Exclude<BleAdapterState, "poweredOn">, string> = {
  unknown: "waiting for the Bluetooth adapter…",
  resetting: "the Bluetooth adapter is resetting…",
  unsupported: "the Bluetooth adapter does not support Bluetooth LE",
  unauthorized: "not allowed to use the Bluetooth adapter",
  poweredOff: "Bluetooth is off (switch it on; on Linux: bluetoothctl power on)",
  unavailable: "no Bluetooth adapter",
};

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
    const timer = ctx.inputs[0];
    if (timer && !timer.isTimer) {
      throw new BlockConfigError(
        `the input ${timer.source} is not a timer: a Myo's input only paces its EMG output (MOSAIC's form); leave Inputs out to emit every sample as it arrives`,
      );
    }
    const paced = timer !== undefined;
    if (!paced && ctx.declaredRate === undefined) ctx.setDesiredRate(EMG_RATE);
    const emgOut = ctx.output(vectorShape(EMG_CHANNELS), "emg");
    const imuOut = ctx.output(vectorShape(IMU_VALUES), "imu");
    const emgCommand = setModeCommand(
      p.EMG === "raw" ? EMG_MODE.raw : EMG_MODE.filtered,
      p.IMU ? IMU_MODE.data : IMU_MODE.none,
      CLASSIFIER_MODE.disabled,
    );

    const scratch = new Float64Array(2 * EMG_CHANNELS);
    const imuScratch = new Float64Array(IMU_VALUES);
    const stamps = new Float64Array(2);
    const clock = new EmgTimestamps();
    // Timer mode: a FIFO of EMG samples (MaxDelay × 8) and the sample held between them.
    const queue = new Float64Array(paced ? p.MaxDelay * EMG_CHANNELS : 0);
    let qHead = 0;
    let qLen = 0;
    const held = new Float64Array(EMG_CHANNELS);

    let bridge: BleBridge | undefined;
    let watch: { close(): void } | undefined;
    let scan: { stop(): void } | undefined;
    let conn: BleConnection | undefined;
    let address: string | undefined;
    let gen = 0;
    let phase: Phase = "stopped";
    let adapter: BleAdapterState = "unknown";
    let adapterMessage = "";
    let problem = "";
    let emgSamples = 0;
    let imuSamples = 0;
    let malformed = 0;
    let lastMalformed = "";
    let dropped = 0;
    let disconnections = 0;
    const throttle = new TextThrottle(0.5);
    let lastText = "";

    const name = (): string => address ?? p.Address ?? "a Myo";

    const refresh = (): void => {
      let text: string;
      switch (phase) {
        case "unavailable":
          text =
            "Bluetooth LE is not available here (browser build): run the pipeline with mosaic run or the desktop app";
          break;
        case "adapter":
          text =
            adapter === "poweredOn"
              ? "Bluetooth adapter on"
              : adapterMessage !== ""
                ? adapterMessage
                : ADAPTER_TEXT[adapter];
          break;
        case "scanning":
          text = `searching for ${p.Address ?? "a Myo armband"}…`;
          break;
        case "connecting":
          text = `connecting to ${name()}…`;
          break;
        case "configuring":
          text = `setting up ${name()}…`;
          break;
        case "streaming":
          text = `${name()} streaming · ${plural(emgSamples, "EMG sample")}`;
          if (p.IMU) text += ` · ${imuSamples} IMU`;
          break;
        case "lost":
          text =
            `${name()}: ${problem}; ` +
            (p.Reconnect > 0
              ? `searching again in ${p.Reconnect} s`
              : "not reconnecting (Reconnect 0)");
          break;
        case "stopped":
          text = address ? `${address} disconnected` : "stopped";
          break;
      }
      if (disconnections > 0) text += ` · ${plural(disconnections, "disconnection")}`;
      if (dropped > 0) text += ` · ${dropped} EMG samples dropped (MaxDelay)`;
      if (malformed > 0) text += ` · ${malformed} malformed (last: ${lastMalformed})`;
      if (text !== lastText) {
        lastText = text;
        ctx.setText(text);
      }
    };

    const release = (): void => {
      if (bridge && address) claimsOf(bridge).delete(addressKey(address));
    };

    const stopScan = (): void => {
      scan?.stop();
      scan = undefined;
    };

    const beginScan = (): void => {
      if (!bridge || scan || conn || phase === "connecting" || phase === "configuring") return;
      if (adapter !== "poweredOn") return;
      phase = "scanning";
      refresh();
      const g = gen;
      const handle = bridge.scan({
        services: [MYO.controlService],
        onFound,
        onError: (m) => {
          if (g === gen) fail(m);
        },
      });
      // An error reported (or an armband found) before `scan` returned has moved on already.
      if (g === gen && phase === "scanning") scan = handle;
      else handle.stop();
    };

    const retryLater = (): void => {
      if (p.Reconnect <= 0) return;
      const g = gen;
      ctx.at(ctx.now() + p.Reconnect, () => {
        if (g !== gen || phase !== "lost") return;
        beginScan();
      });
    };

    /** The attempt (or the link) failed: say why, clean up, search again later. */
    const fail = (reason: string): void => {
      gen++;
      stopScan();
      conn?.disconnect();
      conn = undefined;
      release();
      problem = reason;
      phase = "lost";
      ctx.warn(`${name()}: ${reason}`);
      refresh();
      retryLater();
    };

    const onFound = (found: BlePeripheral): void => {
      if (!bridge || phase !== "scanning") return;
      if (p.Address !== undefined) {
        if (!sameAddress(found.address, p.Address)) return;
      } else if (claimsOf(bridge).has(addressKey(found.address))) {
        return;
      }
      stopScan();
      void connect(bridge, found.address);
    };

    const connect = async (b: BleBridge, to: string): Promise<void> => {
      const g = ++gen;
      address = to;
      claimsOf(b).add(addressKey(to));
      phase = "connecting";
      refresh();
      let c: BleConnection;
      try {
        c = await b.connect(to, (reason) => {
          if (g !== gen) return;
          conn = undefined;
          disconnections++;
          fail(`disconnected (${reason})`);
        });
      } catch (e) {
        if (g === gen) fail(`connection failed: ${(e as Error)?.message ?? String(e)}`);
        return;
      }
      if (g !== gen) {
        c.disconnect();
        return;
      }
      conn = c;
      phase = "configuring";
      refresh();
      try {
        const found = new Set(
          (await c.discover([MYO.controlService, MYO.emgService, MYO.imuService])).map(
            (x) => `${normalizeUuid(x.service)}/${normalizeUuid(x.uuid)}`,
          ),
        );
        if (g !== gen) return;
        const need: [string, string][] = [
          [MYO.controlService, MYO.commandCharacteristic],
          ...MYO.emgCharacteristics.map((u): [string, string] => [MYO.emgService, u]),
          ...(p.IMU ? [[MYO.imuService, MYO.imuCharacteristic] as [string, string]] : []),
        ];
        const missing = need.filter(([s, u]) => !found.has(`${s}/${u}`));
        if (missing.length > 0) {
          fail(`not a Myo armband (missing characteristic ${missing[0]![1]})`);
          return;
        }
        const command = (bytes: Uint8Array): Promise<void> =>
          c.write(MYO.controlService, MYO.commandCharacteristic, bytes);
        await command(sleepModeCommand(SLEEP_MODE.neverSleep));
        for (const u of MYO.emgCharacteristics) {
          await c.subscribe(MYO.emgService, u, (d) => {
            if (g === gen) onEmg(d);
          });
        }
        if (p.IMU) {
          await c.subscribe(MYO.imuService, MYO.imuCharacteristic, (d) => {
            if (g === gen) onImu(d);
          });
        }
        await command(emgCommand);
        if (p.Vibrate) await command(vibrateCommand(VIBRATION.short));
        if (g !== gen) return;
        clock.reset();
        phase = "streaming";
        problem = "";
        refresh();
      } catch (e) {
        if (g === gen) fail(`setting up failed: ${(e as Error)?.message ?? String(e)}`);
      }
    };

    const bad = (why: string): void => {
      malformed++;
      lastMalformed = why;
      refresh();
    };

    const onEmg = (data: Uint8Array): void => {
      const err = decodeEmg(data, scratch);
      if (err !== undefined) return bad(err);
      emgSamples += 2;
      const now = ctx.now();
      if (paced) {
        for (let s = 0; s < 2; s++) {
          if (qLen === p.MaxDelay) {
            qHead = (qHead + 1) % p.MaxDelay;
            qLen--;
            dropped++;
          }
          queue.set(
            scratch.subarray(s * EMG_CHANNELS, (s + 1) * EMG_CHANNELS),
            ((qHead + qLen) % p.MaxDelay) * EMG_CHANNELS,
          );
          qLen++;
        }
      } else {
        clock.stamp(now, stamps);
        const f = emgOut.frame(2);
        f.t[0] = stamps[0]!;
        f.t[1] = stamps[1]!;
        f.v.set(scratch);
        emgOut.emit(f);
      }
      if (throttle.due(now)) refresh();
    };

    const onImu = (data: Uint8Array): void => {
      const err = decodeImu(data, imuScratch);
      if (err !== undefined) return bad(err);
      imuSamples++;
      const f = imuOut.frame(1);
      f.t[0] = ctx.now();
      f.v.set(imuScratch);
      imuOut.emit(f);
    };

    const onState = (s: BleAdapterState, message?: string): void => {
      adapter = s;
      adapterMessage = message ?? "";
      if (s === "poweredOn") {
        if (phase === "adapter" || phase === "stopped") beginScan();
        else refresh();
        return;
      }
      // The adapter went away: the link (if any) is gone with it.
      gen++;
      stopScan();
      conn?.disconnect();
      conn = undefined;
      release();
      phase = "adapter";
      refresh();
    };

    const resetQueue = (): void => {
      qHead = 0;
      qLen = 0;
      held.fill(0);
    };

    return {
      start() {
        bridge = ctx.io.ble;
        if (!bridge) {
          phase = "unavailable";
          refresh();
          return;
        }
        phase = "adapter";
        watch = bridge.watchState(onState);
      },
      stop() {
        gen++;
        watch?.close();
        watch = undefined;
        stopScan();
        const c = conn;
        conn = undefined;
        release();
        if (c) {
          // MOSAIC's end commands: stop streaming, let the armband sleep again; then disconnect.
          const writes = [
            c.write(MYO.controlService, MYO.commandCharacteristic, setModeCommand(0, 0, 0)),
            c.write(
              MYO.controlService,
              MYO.commandCharacteristic,
              sleepModeCommand(SLEEP_MODE.normal),
            ),
          ];
          void Promise.allSettled(writes).then(() => c.disconnect());
        }
        if (phase !== "unavailable") phase = "stopped";
        refresh();
      },
      process(frame: Frame) {
        // Timer mode (MOSAIC): one EMG event per tick.
        const out = emgOut.frame(frame.n);
        for (let e = 0; e < frame.n; e++) {
          if (phase !== "streaming") {
            held.fill(0);
          } else if (qLen > 0) {
            held.set(queue.subarray(qHead * EMG_CHANNELS, (qHead + 1) * EMG_CHANNELS));
            qHead = (qHead + 1) % p.MaxDelay;
            qLen--;
          }
          out.t[e] = frame.t[e]!;
          out.v.set(held, e * EMG_CHANNELS);
        }
        emgOut.emit(out);
      },
      reset() {
        resetQueue();
        clock.reset();
        emgSamples = 0;
        imuSamples = 0;
        malformed = 0;
        dropped = 0;
        disconnections = 0;
        refresh();
      },
      dispose() {
        gen++;
        watch?.close();
        watch = undefined;
        stopScan();
        conn?.disconnect();
        conn = undefined;
        release();
      },
      actions: {
        vibrate: {
          label: "Vibrate",
          description: "Makes the armband vibrate briefly (to find which one is which)",
          run: () => {
            if (!conn || phase !== "streaming") return `${name()} is not connected`;
            void conn
              .write(
                MYO.controlService,
                MYO.commandCharacteristic,
                vibrateCommand(VIBRATION.medium),
              )
              .catch(() => {});
            return `${name()} vibrates`;
          },
        },
      },
    };
  },
});
