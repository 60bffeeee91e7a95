import { z } from "zod";
import {
  BlockConfigError,
  defineBlock,
  vectorShape,
  type BlockContext,
  type OutputPort,
  type PortMeta,
} from "../../engine";
import { plural, TextThrottle } from "../shared/text";
import {
  DeviceClock,
  hzText,
  TRIGNO_AUX_PORT,
  TRIGNO_COMMAND_PORT,
  TRIGNO_EMG_PORT,
  TRIGNO_NATIVE_RATE,
  TRIGNO_NATIVE_SAMPLES,
  TRIGNO_SENSORS,
} from "./delsys-protocol";
import { delsysProtocol, TrignoLink, trignoWidth, type TrignoLinkOptions } from "./delsys-link";
import { noTcpMessage } from "./stream-link";
import { pacedDevice, pacingTimer } from "./paced-device";

const sensorNumber = z.number().int().min(1).max(TRIGNO_SENSORS);

const params = z.strictObject({
  Sensors: z
    .union([
      sensorNumber,
      z
        .array(sensorNumber)
        .min(1)
        .max(TRIGNO_SENSORS)
        .refine((a) => new Set(a).size === a.length, {
          message: "a sensor is listed twice",
        }),
    ])
    .default(TRIGNO_SENSORS)
    .describe(
      "EMG sensors streamed, one channel each: a count N (sensors 1…N) or the sensor numbers " +
        "(1…16, the TCU's pairing slots) in the order of the output's channels, e.g. " +
        "[1, 2, 3, 4, 9, 10, 11, 12]",
    ),
  Host: z
    .string()
    .trim()
    .min(1)
    .max(253)
    .regex(/^[A-Za-z0-9.:_%-]+$/, "expected an IP address or a host name")
    .default("127.0.0.1")
    .describe("The computer running Delsys' Trigno Control Utility (its SDK server)"),
  Port: z
    .number()
    .int()
    .min(1)
    .max(65535)
    .optional()
    .describe(`The TCU's command port (default ${TRIGNO_COMMAND_PORT})`),
  EmgPort: z
    .number()
    .int()
    .min(1)
    .max(65535)
    .optional()
    .describe(`The TCU's Avanti EMG data port (default ${TRIGNO_EMG_PORT})`),
  Aux: z
    .enum(["none", "acc", "imu"])
    .default("none")
    .describe(
      "IMU channels joined after each sensor's EMG channel, from the TCU's AUX port at 148.148 " +
        "Hz, each value held for the 13 EMG samples it spans: none; acc (accelerometer x, y, z " +
        "in g: 4 channels per sensor, the paper's 8 sensors × 4 = 32); imu (accelerometer, " +
        "gyroscope in °/s, magnetometer in µT: 10 per sensor)",
    ),
  AuxPort: z
    .number()
    .int()
    .min(1)
    .max(65535)
    .optional()
    .describe(`The TCU's Avanti AUX (IMU) data port (default ${TRIGNO_AUX_PORT})`),
});

/** AUX values per sensor for each `Aux` choice. */
const AUX_VALUES = { none: 0, acc: 3, imu: 9 } as const;
const AUX_NAMES = [
  "acc x",
  "acc y",
  "acc z",
  "gyro x",
  "gyro y",
  "gyro z",
  "mag x",
  "mag y",
  "mag z",
];
const AUX_UNITS = ["g", "g", "g", "°/s", "°/s", "°/s", "µT", "µT", "µT"];

type Params = z.output<typeof params>;

/** The selected sensor numbers, in output order. */
export function selectedSensors(s: Params["Sensors"]): number[] {
  return typeof s === "number" ? Array.from({ length: s }, (_, i) => i + 1) : [...s];
}

/** What each output channel carries: "sensor 3 EMG (V)", "sensor 3 acc x (g)". */
function channelLabels(sensors: readonly number[], aux: number): string[] {
  const names: string[] = [];
  for (const s of sensors) {
    names.push(`sensor ${s} EMG (V)`);
    for (let j = 0; j < aux; j++) names.push(`sensor ${s} ${AUX_NAMES[j]} (${AUX_UNITS[j]})`);
  }
  return names;
}

/** The output's PortMeta: the labels, and the unit when every channel is EMG. */
function outputMeta(link: TrignoLinkOptions): PortMeta {
  const aux = link.aux ?? 0;
  return { labels: channelLabels(link.sensors, aux), ...(aux === 0 ? { unit: "V" } : {}) };
}

export const Delsys = defineBlock({
  type: "Delsys",
  category: "Devices",
  summary:
    "EMG from a Delsys Trigno system over the Trigno SDK (TCP): native 1925.926 Hz, or paced by a timer.",
  help:
    "A Delsys Trigno wireless EMG system through the Trigno Control Utility's SDK server (TCP, " +
    `command port ${TRIGNO_COMMAND_PORT}, Avanti EMG data port ${TRIGNO_EMG_PORT}; protocol and ` +
    "sources in docs/protocols.md, section Delsys Trigno). The block connects, switches the " +
    "TCU's backwards compatibility and upsampling off, asks which of the selected `Sensors` are " +
    "paired (an unpaired one is reported and its channel stays 0), sends START and parses the " +
    "float32 stream (16 sensor slots per sample, volts), one channel per selected sensor in the " +
    "order listed. With `Aux: acc` (or `imu`) it also reads the AUX port (IMU, 148.148 Hz) and " +
    "joins each sensor's accelerometer (or all nine IMU values) after its EMG channel, each AUX " +
    "sample held for the 13 EMG samples of its half frame: 8 sensors give the paper's 32 " +
    "channels. **Without an input** it is its own source at the device's rate (" +
    `${hzText(TRIGNO_NATIVE_RATE)}, ${TRIGNO_NATIVE_SAMPLES} samples every 13.5 ms): what arrives ` +
    "is emitted at once as one frame, stamped on the device's sample clock (the first batch's " +
    "last sample at its arrival, then 1 / rate apart, at most one 13.5 ms frame ahead of " +
    "arrival; re-anchored after a reconnection, the gap counted). **With a timer input** (MOSAIC's form: `Inputs: [timer]`, no Params) each tick " +
    "emits the oldest waiting sample, repeats the last when none came and zeros while not " +
    "streaming, as the original. A lost connection is reported and retried (0.5 s, doubling to " +
    "5 s); STOP is sent when the pipeline stops. Malformed or misaligned data (not finite, " +
    "beyond ±0.1 V, non-zero in an unpaired slot) is counted and skipped to the next whole " +
    "sample, a sample cut short by a disconnection is counted as truncated. The original MOSAIC " +
    "used Delsys' licensed .NET API instead (RF base, its own sensor scan); this block needs " +
    "only the TCU. Never run against real hardware here: tested against the simulator " +
    "(`mosaic simulate delsys`). `mosaic run --simulate-devices` replaces it by an EmgSimulator " +
    "of the same shape and rate. Unavailable in the browser build (no TCP): the status says so.",
  params,
  legacyParams: () => ({}),
  legacyForm: "no Params (16 sensors)",
  inputs: { min: 0, max: 1, labels: ["timer"] },
  outputs: ["emg"],
  eventLoop: true,
  views: ["scope", "spider"],
  panel:
    "Scope of the sensors; the link's state, samples, reconnections, malformed and truncated data.",
  create(ctx, p) {
    const sensors = selectedSensors(p.Sensors);
    const link: TrignoLinkOptions = {
      host: p.Host,
      commandPort: p.Port ?? TRIGNO_COMMAND_PORT,
      emgPort: p.EmgPort ?? TRIGNO_EMG_PORT,
      sensors,
      aux: AUX_VALUES[p.Aux],
      auxPort: p.AuxPort ?? TRIGNO_AUX_PORT,
    };
    checkPorts(p, link);
    const target = `the Trigno Control Utility at ${p.Host}:${link.commandPort}`;
    let current: TrignoLink | undefined;
    const actions = {
      channels: {
        label: "Channels",
        description: "Which sensor each output channel carries",
        run: () =>
          channelLabels(sensors, link.aux ?? 0)
            .map((n, i) => `channel ${i + 1}: ${n}`)
            .join("; "),
      },
      counts: {
        label: "Counts",
        description: "Samples, reconnections, malformed and truncated data, the TCU's banner",
        run: () => countsText(current),
      },
    };
    if (ctx.inputs.length > 0) {
      pacingTimer(ctx);
      const instance = pacedDevice(ctx, {
        device: "Delsys Trigno",
        target: `${target} (Trigno SDK, TCP)`,
        shape: vectorShape(trignoWidth(link)),
        meta: outputMeta(link),
        port: "emg",
        // Two TCU frames: a 1926 Hz timer drains each 13.5 ms frame before the next comes.
        maxQueue: 2 * (TRIGNO_NATIVE_SAMPLES + 1),
        protocol: delsysProtocol(link, (l) => (current = l)),
      });
      return { ...instance, actions };
    }
    return { ...nativeSource(ctx, link, target, (l) => (current = l)), actions };
  },
});

/** The command, EMG and AUX ports must differ (the TCU serves each kind on its own port). */
function checkPorts(p: Params, link: TrignoLinkOptions): void {
  const used: [string, number][] = [
    ["Port", link.commandPort],
    ["EmgPort", link.emgPort],
  ];
  if ((link.aux ?? 0) > 0) used.push(["AuxPort", link.auxPort ?? TRIGNO_AUX_PORT]);
  for (let i = 0; i < used.length; i++) {
    for (let j = 0; j < i; j++) {
      if (used[i]![1] !== used[j]![1]) continue;
      const [a, b] = [used[j]!, used[i]!];
      const key = p[b[0] as keyof Params] !== undefined ? b[0] : a[0];
      throw new BlockConfigError(
        `${b[0]} ${b[1]} is the ${a[0]} too: the TCU serves commands, EMG and AUX data on different ports`,
        key,
      );
    }
  }
}

/** One line of counts, for the action. */
function countsText(link: TrignoLink | undefined): string {
  if (!link) return "not started";
  const c = link.counts;
  return (
    `${c.samples} samples at ${hzText(c.rate)}, ${c.reconnections} reconnections, ` +
    `${c.malformed} malformed (${c.skippedBytes} bytes skipped${c.lastProblem ? `, last: ${c.lastProblem}` : ""}), ` +
    `${c.truncated} truncated (${c.truncatedBytes} bytes)` +
    (c.unpaired.length > 0 ? `, not paired: ${c.unpaired.join(", ")}` : "") +
    ((link.options.aux ?? 0) > 0
      ? `; AUX: ${c.aux.samples} samples, ${c.aux.malformed} malformed, ${c.aux.held} EMG samples with held AUX values, ${c.aux.dropped} AUX samples dropped`
      : "") +
    (c.banner ? `; TCU: ${c.banner}` : "")
  );
}

/** The block without an input: its own source at the device's rate. */
function nativeSource(
  ctx: BlockContext,
  o: TrignoLinkOptions,
  target: string,
  onLink: (l: TrignoLink) => void,
) {
  return new DelsysNativeRun(ctx, o, target, onLink).instance();
}

/** The state of the native form: the link, the device's sample clock and the status. */
class DelsysNativeRun {
  private readonly k: number;
  private readonly out: OutputPort;
  private readonly clock: DeviceClock;
  private readonly throttle = new TextThrottle(0.5);
  private link: TrignoLink | undefined;
  private phase = "stopped";
  private lastText = "";
  private shownGaps = 0;

  constructor(
    private readonly ctx: BlockContext,
    private readonly o: TrignoLinkOptions,
    private readonly target: string,
    private readonly onLink: (l: TrignoLink) => void,
  ) {
    if (ctx.declaredRate === undefined) ctx.setDesiredRate(TRIGNO_NATIVE_RATE);
    this.k = trignoWidth(o);
    this.out = ctx.output(vectorShape(this.k), "emg", outputMeta(o));
    this.clock = new DeviceClock(TRIGNO_NATIVE_RATE);
    this.refresh();
  }

  /** The block instance the engine drives. */
  instance() {
    return {
      start: () => this.start(),
      stop: () => this.stop(),
      reset: () => this.reset(),
      dispose: () => this.dispose(),
    };
  }

  /** The status: the link's phase and its counts, when it changed. */
  private refresh(): void {
    const text = this.statusText();
    if (text !== this.lastText) {
      this.lastText = text;
      this.ctx.setText(text);
    }
  }

  /** The link's phase, then each count that is not zero. */
  private statusText(): string {
    let text = this.phase;
    const c = this.link?.counts;
    const clock = this.clock;
    if (c) {
      if (c.samples > 0) text += ` · ${plural(c.samples, "sample")}`;
      if (c.reconnections > 0) text += ` · ${plural(c.reconnections, "reconnection")}`;
      if (clock.gapSamples > 0) text += ` · ${clock.gapSamples} samples lost in gaps`;
      if (c.malformed > 0) text += ` · ${c.malformed} malformed (${c.skippedBytes} bytes skipped)`;
      if (c.truncated > 0) text += ` · ${c.truncated} truncated`;
      if (c.aux.malformed > 0) text += ` · ${c.aux.malformed} malformed AUX`;
      if (c.aux.held > 0) text += ` · ${c.aux.held} samples with held AUX`;
      if (clock.reanchors > 0) text += ` · re-anchored ${clock.reanchors}×`;
    }
    return text;
  }

  /** The samples of one batch from the link go out as one frame on the device's clock. */
  private onSamples(values: Float64Array, n: number): void {
    const f = this.out.frame(n);
    this.clock.stamp(this.ctx.now(), f.t, n);
    f.v.set(values.subarray(0, n * this.k));
    this.out.emit(f);
    // A gap (after a reconnection) shows at once; the counts every half second.
    if (this.clock.gaps !== this.shownGaps) {
      this.shownGaps = this.clock.gaps;
      this.refresh();
    } else if (this.throttle.due(this.ctx.now())) this.refresh();
  }

  /** Opens the link to the TCU, or says that this host has no TCP. */
  private start(): void {
    const ctx = this.ctx;
    const tcp = ctx.io.tcp;
    if (!tcp) {
      this.phase = "TCP not available in the browser build; use --simulate-devices";
      this.refresh();
      ctx.warn(noTcpMessage(this.target));
      return;
    }
    const clock = this.clock;
    this.link = new TrignoLink(ctx, tcp, this.o, {
      samples: (values, n) => this.onSamples(values, n),
      state: (_phase, text) => {
        this.phase = text;
        this.refresh();
      },
      warn: (m) => ctx.warn(`Delsys Trigno: ${m}`),
      started(rate) {
        clock.setRate(rate);
      },
      broke() {
        clock.restart();
      },
    });
    this.onLink(this.link);
    this.link.open();
  }

  /** Closes the link (it sends STOP) and says so. */
  private stop(): void {
    this.link?.close();
    this.phase = "stopped";
    this.refresh();
  }

  /** Forgets the clock and the gaps shown. */
  private reset(): void {
    this.clock.reset();
    this.shownGaps = 0;
    this.throttle.reset();
    this.refresh();
  }

  /** Closes the link and lets it go. */
  private dispose(): void {
    this.link?.close();
    this.link = undefined;
  }
}
