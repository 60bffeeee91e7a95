/**
 * EmgSimulator: one simulator, its state in one place. It generates one EMG sample per tick of
 * its timer with the targets of the gesture it holds: the Gesture param or one set by hand, the
 * current Sequence step, or the mixture of gestures the latest cue asks for.
 */
import {
  BlockConfigError,
  errorMessage,
  vectorShape,
  type BlockContext,
  type Frame,
  type OutputPort,
} from "../../engine";
import { EmgSynth } from "../../engine/dsp";
import { requireDsp } from "../shared/dsp";
import { inputName, timerInput } from "../shared/inputs";
import { checkCueInputs, CUE_QUEUE_ROWS, CueMixer, CueQueue } from "./emg-simulator-cues";
import { GestureSet } from "./emg-simulator-gestures";
import { GestureSequence, type SequenceStep } from "./emg-simulator-sequence";

/** The EmgSimulator's params (after validation). */
export interface EmgSimulatorParams {
  Channels: number;
  Seed: number;
  Gesture: string;
  Gestures?: Record<string, number[]> | undefined;
  Sequence?: SequenceStep[] | undefined;
  CueGestures?: string[] | undefined;
  ReactionMs: number;
  AmplitudeMv: number;
  NoiseFloorMv: number;
  HumMv: number;
  HumHz: number;
  BandLowHz: number;
  BandHighHz: number;
  AttackMs: number;
  ReleaseMs: number;
  Modulation: number;
}

/** The rate of the timer input, the simulator's sample rate (it must be known). */
function sampleRate(ctx: BlockContext): number {
  const timer = timerInput(ctx, 0);
  if (!(timer.rate > 0)) {
    throw new BlockConfigError(
      `the rate of timer ${inputName(timer)} is unknown; EmgSimulator uses it as its sample rate`,
    );
  }
  return timer.rate;
}

/** The EMG generator of the params, at the sample rate. */
function createSynth(p: EmgSimulatorParams, sampleRate: number): EmgSynth {
  try {
    return new EmgSynth({
      channels: p.Channels,
      sampleRate,
      seed: p.Seed,
      amplitudeMv: p.AmplitudeMv,
      noiseFloorMv: p.NoiseFloorMv,
      humMv: p.HumMv,
      humHz: p.HumHz,
      bandLowHz: p.BandLowHz,
      bandHighHz: p.BandHighHz,
      attackMs: p.AttackMs,
      releaseMs: p.ReleaseMs,
      modulation: p.Modulation,
    });
  } catch (e) {
    throw new BlockConfigError(`cannot create the EMG generator: ${errorMessage(e)}`);
  }
}

/** Declares the outputs: `emg` (a vector of the channels, in mV), then `gesture` (one-hot). */
function declareOutputs(
  ctx: BlockContext,
  channels: number,
  names: string[],
): [emg: OutputPort, gesture: OutputPort] {
  const emg = ctx.output(vectorShape(channels), "emg", {
    labels: Array.from({ length: channels }, (_, k) => `EMG ${k + 1}`),
    unit: "mV",
  });
  return [emg, ctx.output(vectorShape(names.length), "gesture", { labels: names })];
}

/**
 * A simulator's state and what changes it. `select` and `followCue` set the generator's targets
 * and the status text; `process` generates each frame in runs of ticks between those changes.
 */
export class SimulatorRun {
  readonly gestures: GestureSet;
  private readonly channels: number;
  private readonly synth: EmgSynth;
  private readonly emg: OutputPort;
  private readonly oneHot: OutputPort;
  private readonly seq: GestureSequence | undefined;
  /** True with cue inputs: the simulated participant follows them (unless `manual`). */
  private readonly following: boolean;
  private readonly cues: CueQueue;
  private readonly mixer: CueMixer;
  /** Values per cue event: one per cue gesture. */
  private readonly cueWidth: number;
  /** ReactionMs, in s. */
  private readonly reaction: number;
  /** The gesture held from the start without a Sequence (the Gesture param). */
  private initialGesture: number;
  /** A gesture was set by hand: the Sequence and the cues are not followed until reset. */
  private manual = false;
  /** The gesture held; -1 while following a cue's mixture. */
  private current = -1;
  /** The gesture of the largest weight, while following cues (shown in the status text). */
  private dominant = -1;
  /** Room for the samples of a run of ticks that starts inside a frame (grows, is reused). */
  private scratch = new Float64Array(0);

  /** Checks the inputs, declares the outputs and holds the first gesture. */
  constructor(
    private readonly ctx: BlockContext,
    p: EmgSimulatorParams,
  ) {
    requireDsp(ctx.type);
    const rate = sampleRate(ctx);
    this.channels = p.Channels;
    const gestures = new GestureSet(p);
    this.gestures = gestures;
    [this.emg, this.oneHot] = declareOutputs(ctx, this.channels, gestures.names);
    const cueMap = Int32Array.from(p.CueGestures ?? gestures.names, (n) => gestures.indexOf(n));
    this.following = checkCueInputs(ctx, gestures, cueMap, p.CueGestures) > 0;
    if (this.following && p.Sequence !== undefined) {
      throw new BlockConfigError(
        "a Sequence and cue inputs both choose the gesture: give one or the other",
        "Sequence",
      );
    }
    this.reaction = p.ReactionMs / 1000;
    this.cueWidth = cueMap.length;
    this.cues = new CueQueue(this.cueWidth, this.following ? CUE_QUEUE_ROWS : 0);
    this.mixer = new CueMixer(gestures, cueMap, this.channels);
    this.seq =
      p.Sequence !== undefined ? new GestureSequence(p.Sequence, gestures, ctx) : undefined;
    this.initialGesture = gestures.indexOf(p.Gesture);
    // Last, once every param has been checked: a refused block leaves no generator behind.
    this.synth = createSynth(p, rate);
    this.restart();
  }

  /** A frame of the timer (port 0): one sample a tick; of a cue input: its events are queued. */
  process(f: Frame, port: number): void {
    if (f.n === 0) return;
    if (port > 0) this.queueCues(f);
    else this.generateFrame(f);
  }

  /** Back to the start: the generator's state, and the first gesture held. */
  reset(): void {
    this.synth.reset();
    this.restart();
  }

  dispose(): void {
    this.synth.dispose();
  }

  /** The Gesture param changed while running: it is held, as if set by hand. */
  setInitialGesture(name: string): void {
    const g = this.gestures.indexOf(name);
    this.initialGesture = g;
    this.holdByHand(g);
  }

  /** The `setGesture` action: holds the gesture named `arg`; returns what it did. */
  setGesture(arg: unknown): string {
    if (typeof arg !== "string") {
      throw new Error(`setGesture needs a gesture name: one of ${this.gestures.names.join(", ")}`);
    }
    return this.holdByHand(this.gestures.indexOf(arg));
  }

  /**
   * The `next` action: the next Sequence step while a Sequence plays, else the gesture after the
   * one held (or after the strongest of a cue's mixture), held by hand; returns what it did.
   */
  next(): string {
    const names = this.gestures.names;
    if (this.seq !== undefined && !this.manual) {
      const g = this.seq.skip();
      this.current = -1;
      this.select(g);
      return `gesture: ${names[this.current]}`;
    }
    return this.holdByHand(((this.current >= 0 ? this.current : this.dominant) + 1) % names.length);
  }

  /** Queues the events of a cue frame, due ReactionMs after their times (none while manual). */
  private queueCues(f: Frame): void {
    if (this.manual) return;
    const n = f.n;
    const stride = f.stride;
    for (let e = 0; e < n; e++) this.cues.push(f.t[e]! + this.reaction, f.v, e * stride);
  }

  /**
   * One sample per tick of a timer frame, on both outputs, stamped with the ticks. The gesture
   * (or cue) due at each tick is taken up there; the EMG is generated in runs between changes.
   */
  private generateFrame(f: Frame): void {
    const n = f.n;
    const o = this.emg.frame(n);
    const h = this.oneHot.frame(n);
    const ov = o.v;
    const hv = h.v;
    const ft = f.t;
    const g = this.gestures.names.length;
    const weights = this.mixer.weights;
    let runStart = 0;
    for (let e = 0; e < n; e++) {
      const t = ft[e]!;
      o.t[e] = t;
      h.t[e] = t;
      const off = e * g;
      if (this.following && !this.manual) {
        const row = this.cues.takeDue(t);
        if (row >= 0) {
          this.generate(ov, runStart, e);
          runStart = e;
          this.followCue(row);
        }
        for (let k = 0; k < g; k++) hv[off + k] = weights[k]!;
        continue;
      }
      const want = this.gestureAt(t);
      if (want !== this.current) {
        this.generate(ov, runStart, e);
        runStart = e;
        this.select(want);
      }
      for (let k = 0; k < g; k++) hv[off + k] = 0;
      hv[off + this.current] = 1;
    }
    this.generate(ov, runStart, n);
    this.emg.emit(o);
    this.oneHot.emit(h);
  }

  /** The gesture at tick time t: the Sequence's (advancing it) unless one is held. */
  private gestureAt(t: number): number {
    const seq = this.seq;
    return seq === undefined || this.manual ? this.current : seq.gestureAt(t);
  }

  /** Generates events [from, to) of `out` with the current targets. */
  private generate(out: Float64Array, from: number, to: number): void {
    const count = to - from;
    if (count <= 0) return;
    if (from === 0) {
      this.synth.generate(out, count);
      return;
    }
    const m = count * this.channels;
    if (this.scratch.length < m)
      this.scratch = new Float64Array(Math.max(m, this.scratch.length * 2));
    const scratch = this.scratch;
    this.synth.generate(scratch, count);
    const off = from * this.channels;
    for (let k = 0; k < m; k++) out[off + k] = scratch[k]!;
  }

  /** Holds gesture g: its pattern as the targets, its name as the status text (if not held). */
  private select(g: number): void {
    if (g === this.current) return;
    this.current = g;
    this.synth.setTargets(this.gestures.patterns[g]!);
    const name = this.gestures.names[g]!;
    this.ctx.setText(this.seq !== undefined && !this.manual ? this.seq.text(name) : name);
  }

  /** Follows the cue in row `row` of the queue: its mixture as the targets and weights. */
  private followCue(row: number): void {
    const mixer = this.mixer;
    mixer.mix(this.cues.values, row * this.cueWidth);
    this.synth.setTargets(mixer.activations);
    this.current = -1;
    const best = mixer.strongest();
    if (best !== this.dominant) {
      this.dominant = best;
      this.ctx.setText(`${this.gestures.names[best]} (following cues)`);
    }
  }

  /** Holds gesture g by hand: the Sequence and the cues stop until reset. */
  private holdByHand(g: number): string {
    this.manual = true;
    this.current = -1;
    this.cues.clear();
    this.select(g);
    return `gesture: ${this.gestures.names[g]}`;
  }

  /** Back to the first gesture: the Sequence's first step or the Gesture param; no cues. */
  private restart(): void {
    this.manual = false;
    this.seq?.restart();
    this.current = -1;
    this.cues.clear();
    const g = this.seq !== undefined ? this.seq.gesture : this.initialGesture;
    this.mixer.hold(g);
    this.dominant = g;
    this.select(g);
  }
}
