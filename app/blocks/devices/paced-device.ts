/**
 * What the original MOSAIC's timer-paced acquisition devices (Muovi, MuoviSingleProbe, Delsys,
 * DLR_ADCBT, NilsPod) share: one timer input that sets the output rate, an output of a shape fixed
 * at load, and a link to the device that a **protocol module** beside each block provides
 * (`DeviceProtocol`). The link delivers samples into a queue; every tick emits the oldest waiting
 * sample (the newest `maxQueue` are kept, older ones are dropped and counted), repeats the last one
 * when none came and emits zeros while the device is not streaming, as the original's NilsPod,
 * DLR_ADCBT and Myo did on every tick.
 *
 * The protocols themselves are a later issue: a block without one says, when the pipeline starts,
 * that its device is not reachable, what it would have tried and what to do (run with
 * `--simulate-devices`), and the rest of the pipeline keeps running.
 */
import {
  BlockConfigError,
  shapeSize,
  type BlockContext,
  type BlockInstance,
  type Frame,
  type PortMeta,
  type Shape,
} from "../../engine";
import { inputName } from "../shared/inputs";
import { plural, TextThrottle } from "../shared/text";

/** Where samples from a device's link go (what a protocol module calls). */
export interface DeviceSampleSink {
  /** One sample of the output's size (rows × cols values, row-major) from `values[offset…]`. */
  push(values: ArrayLike<number>, offset?: number): void;
  /** The link's state in a few words, for the block's status ("connecting…", "streaming"). */
  state(phase: "connecting" | "streaming" | "lost", text: string): void;
  /** A problem worth a warning (rate-limited by the engine). */
  warn(message: string): void;
}

/** An open link to a device. */
export interface DeviceConnection {
  close(): void;
}

/**
 * A device's protocol module: opens the link when the pipeline starts (through `ctx.io`) and
 * pushes samples into the sink. Returns undefined, after saying why through the sink, when the
 * transport it needs is not available here.
 */
export interface DeviceProtocol {
  open(ctx: BlockContext, sink: DeviceSampleSink): DeviceConnection | undefined;
}

export interface PacedDeviceOptions {
  /** The device as users know it, for messages: "Muovi". */
  device: string;
  /** What the block tries to reach, for messages: "the Muovi SyncStation at 192.168.76.1:54320 (TCP)". */
  target: string;
  /** The output's shape (one event per tick). */
  shape: Shape;
  /** What the channels are (names, unit, electrode grid), for panels and recorders. */
  meta?: PortMeta;
  /** Output port name (the default port). */
  port: string;
  /** The protocol module; undefined: this version does not speak the device's protocol yet. */
  protocol: DeviceProtocol | undefined;
  /** Samples kept waiting for ticks (older ones are dropped and counted). */
  maxQueue?: number;
}

/** The block's one input must be a timer with a known rate (checked at load); returns its rate. */
export function pacingTimer(ctx: BlockContext): number {
  const timer = ctx.inputs[0];
  if (!timer || !timer.isTimer) {
    throw new BlockConfigError(
      `${ctx.type} is paced by one timer input (ScheduledTimer or DecimatorTimer), as in the original MOSAIC` +
        (timer ? `; ${inputName(timer)} is not a timer` : ""),
    );
  }
  if (!(timer.rate > 0)) {
    throw new BlockConfigError(
      `the rate of timer ${inputName(timer)} is unknown; ${ctx.type} emits one event per tick`,
    );
  }
  return timer.rate;
}

/** The sentence a device block without its protocol says when the pipeline starts. */
export function unreachableMessage(device: string, target: string): string {
  return (
    `${device} not reachable: this version cannot talk to ${target} yet (the ${device} protocol ` +
    "comes in a later release), so this block sends zeros. To run the pipeline without the " +
    "device: mosaic run FILE --simulate-devices, or switch on “Simulate devices” in the app"
  );
}

/** The instance of a timer-paced device block (see the file comment). */
export function pacedDevice(ctx: BlockContext, o: PacedDeviceOptions): BlockInstance {
  const out = ctx.output(o.shape, o.port, o.meta);
  const size = shapeSize(o.shape);
  const maxQueue = Math.max(1, o.maxQueue ?? 15);
  const queue = new Float64Array(maxQueue * size);
  let qHead = 0;
  let qLen = 0;
  const held = new Float64Array(size);
  let streaming = false;
  let phaseText = "stopped";
  let samples = 0;
  let dropped = 0;
  let conn: DeviceConnection | undefined;
  const throttle = new TextThrottle(0.5);
  let lastText = "";

  const refresh = (): void => {
    let text = phaseText;
    if (samples > 0) text += ` · ${plural(samples, "sample")}`;
    if (dropped > 0) text += ` · ${dropped} dropped (queue of ${maxQueue})`;
    if (text !== lastText) {
      lastText = text;
      ctx.setText(text);
    }
  };

  const sink: DeviceSampleSink = {
    push(values, offset = 0) {
      if (qLen === maxQueue) {
        qHead = (qHead + 1) % maxQueue;
        qLen--;
        dropped++;
      }
      const at = ((qHead + qLen) % maxQueue) * size;
      for (let k = 0; k < size; k++) queue[at + k] = values[offset + k]!;
      qLen++;
      samples++;
    },
    state(phase, text) {
      streaming = phase === "streaming";
      if (!streaming) {
        qHead = 0;
        qLen = 0;
        held.fill(0);
      }
      phaseText = text;
      refresh();
    },
    warn(message) {
      ctx.warn(`${o.device}: ${message}`);
    },
  };

  const emit = (f: Frame): void => {
    const n = f.n;
    if (n === 0) return;
    const e = out.frame(n);
    e.t.set(f.t.subarray(0, n));
    const v = e.v;
    for (let i = 0; i < n; i++) {
      if (streaming && qLen > 0) {
        const at = qHead * size;
        for (let k = 0; k < size; k++) held[k] = queue[at + k]!;
        qHead = (qHead + 1) % maxQueue;
        qLen--;
      }
      v.set(held, i * size);
    }
    out.emit(e);
    if (throttle.due(f.t[n - 1]!)) refresh();
  };

  phaseText = o.protocol ? `${o.device}: not started` : `${o.device}: no protocol yet`;
  refresh();

  return {
    start() {
      if (!o.protocol) {
        phaseText = `not reachable: ${o.target} (sending zeros; --simulate-devices simulates it)`;
        refresh();
        ctx.warn(unreachableMessage(o.device, o.target));
        return;
      }
      phaseText = `connecting to ${o.target}…`;
      refresh();
      conn = o.protocol.open(ctx, sink);
    },
    process(f) {
      emit(f);
    },
    stop() {
      conn?.close();
      conn = undefined;
      streaming = false;
      held.fill(0);
      qHead = 0;
      qLen = 0;
      if (o.protocol) phaseText = "stopped";
      refresh();
    },
    reset() {
      samples = 0;
      dropped = 0;
      held.fill(0);
      qHead = 0;
      qLen = 0;
      throttle.reset();
      refresh();
    },
    dispose() {
      conn?.close();
      conn = undefined;
    },
  };
}
