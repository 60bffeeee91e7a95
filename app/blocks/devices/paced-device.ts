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
  type OutputPort,
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

/** The samples waiting for ticks: a ring of `capacity` samples of `size` values each. */
class SampleQueue {
  private readonly data: Float64Array;
  private head = 0;
  private length = 0;

  constructor(
    readonly capacity: number,
    private readonly size: number,
  ) {
    this.data = new Float64Array(capacity * size);
  }

  /** Appends a sample from `values[offset…]`; when full, drops the oldest first and says so. */
  push(values: ArrayLike<number>, offset: number): boolean {
    const { capacity, size, data } = this;
    let dropped = false;
    if (this.length === capacity) {
      this.head = (this.head + 1) % capacity;
      this.length--;
      dropped = true;
    }
    const at = ((this.head + this.length) % capacity) * size;
    for (let k = 0; k < size; k++) data[at + k] = values[offset + k]!;
    this.length++;
    return dropped;
  }

  /** Moves the oldest sample into `into`; nothing when the queue is empty. */
  shift(into: Float64Array): void {
    if (this.length === 0) return;
    const { size, data } = this;
    const at = this.head * size;
    for (let k = 0; k < size; k++) into[k] = data[at + k]!;
    this.head = (this.head + 1) % this.capacity;
    this.length--;
  }

  clear(): void {
    this.head = 0;
    this.length = 0;
  }
}

/** A timer-paced device block at run time: the link, the queue, the held sample, the status. */
class PacedDevice {
  private readonly out: OutputPort;
  private readonly size: number;
  private readonly queue: SampleQueue;
  /** The sample every tick emits: the last one taken from the queue, zeros when not streaming. */
  private readonly held: Float64Array;
  private streaming = false;
  private phaseText: string;
  private samples = 0;
  private dropped = 0;
  private conn: DeviceConnection | undefined;
  private readonly throttle = new TextThrottle(0.5);
  private lastText = "";
  /** What the protocol module pushes into. */
  private readonly sink: DeviceSampleSink;

  constructor(
    private readonly ctx: BlockContext,
    private readonly o: PacedDeviceOptions,
  ) {
    this.out = ctx.output(o.shape, o.port, o.meta);
    this.size = shapeSize(o.shape);
    this.queue = new SampleQueue(Math.max(1, o.maxQueue ?? 15), this.size);
    this.held = new Float64Array(this.size);
    this.sink = {
      push: (values, offset = 0) => this.push(values, offset),
      state: (phase, text) => this.setState(phase, text),
      warn: (message) => ctx.warn(`${o.device}: ${message}`),
    };
    this.phaseText = o.protocol ? `${o.device}: not started` : `${o.device}: no protocol yet`;
    this.refresh();
  }

  start(): void {
    const o = this.o;
    if (!o.protocol) {
      this.phaseText = `not reachable: ${o.target} (sending zeros; --simulate-devices simulates it)`;
      this.refresh();
      this.ctx.warn(unreachableMessage(o.device, o.target));
      return;
    }
    this.phaseText = `connecting to ${o.target}…`;
    this.refresh();
    this.conn = o.protocol.open(this.ctx, this.sink);
  }

  /** One event per tick: the oldest waiting sample, else the held one again. */
  process(f: Frame): void {
    const n = f.n;
    if (n === 0) return;
    const { out, held, size } = this;
    const e = out.frame(n);
    e.t.set(f.t.subarray(0, n));
    const v = e.v;
    for (let i = 0; i < n; i++) {
      if (this.streaming) this.queue.shift(held);
      v.set(held, i * size);
    }
    out.emit(e);
    if (this.throttle.due(f.t[n - 1]!)) this.refresh();
  }

  stop(): void {
    this.close();
    this.streaming = false;
    this.held.fill(0);
    this.queue.clear();
    if (this.o.protocol) this.phaseText = "stopped";
    this.refresh();
  }

  reset(): void {
    this.samples = 0;
    this.dropped = 0;
    this.held.fill(0);
    this.queue.clear();
    this.throttle.reset();
    this.refresh();
  }

  dispose(): void {
    this.close();
  }

  private close(): void {
    this.conn?.close();
    this.conn = undefined;
  }

  private push(values: ArrayLike<number>, offset: number): void {
    if (this.queue.push(values, offset)) this.dropped++;
    this.samples++;
  }

  private setState(phase: "connecting" | "streaming" | "lost", text: string): void {
    this.streaming = phase === "streaming";
    if (!this.streaming) {
      this.queue.clear();
      this.held.fill(0);
    }
    this.phaseText = text;
    this.refresh();
  }

  /** The status line (set only when its text changes). */
  private refresh(): void {
    let text = this.phaseText;
    if (this.samples > 0) text += ` · ${plural(this.samples, "sample")}`;
    if (this.dropped > 0) text += ` · ${this.dropped} dropped (queue of ${this.queue.capacity})`;
    if (text !== this.lastText) {
      this.lastText = text;
      this.ctx.setText(text);
    }
  }
}

/** The instance of a timer-paced device block (see the file comment). */
export function pacedDevice(ctx: BlockContext, o: PacedDeviceOptions): BlockInstance {
  const device = new PacedDevice(ctx, o);
  return {
    start() {
      device.start();
    },
    process(f) {
      device.process(f);
    },
    stop() {
      device.stop();
    },
    reset() {
      device.reset();
    },
    dispose() {
      device.dispose();
    },
  };
}
