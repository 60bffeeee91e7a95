import { beforeAll, describe, expect, test } from "vitest";
import { EMPTY_SHAPE, Frame, vectorShape } from "../../engine";
import { BlockHarness, type Recorded } from "../../engine/testing";
import { loadBlock, ticks, vectors } from "../../../tests/support/blocks";
import { initDspForTests } from "../../../tests/support/wasm";
import { DEFAULT_GESTURES, defaultGestures, EmgSimulator } from "./emg-simulator";

beforeAll(() => initDspForTests());

const RATE = 2000;
const timer = { shape: EMPTY_SHAPE, rate: RATE, isTimer: true };

/** One frame of `n` ticks at RATE from `from` (tick k at from + k/RATE). */
function tickFrame(n: number, from = 0, start = 0): Frame {
  const f = new Frame(EMPTY_SHAPE, n);
  for (let k = 0; k < n; k++) f.t[k] = from + (start + k) / RATE;
  f.n = n;
  return f;
}

async function sim(params: object = {}): Promise<BlockHarness> {
  const h = await BlockHarness.create(EmgSimulator, params, { inputs: [timer], now: 0 });
  h.start();
  return h;
}

const rms = (out: Recorded, ch: number, from: number, to: number): number => {
  let s = 0;
  for (let i = from; i < to; i++) s += out.v[i]![ch]! ** 2;
  return Math.sqrt(s / (to - from));
};

describe("EmgSimulator", () => {
  test("the default gesture set: smooth von Mises patterns around the forearm", () => {
    const g = defaultGestures(8);
    expect(Object.keys(g)).toEqual([...DEFAULT_GESTURES]);
    expect(g.rest).toEqual(new Array(8).fill(0.02));
    // flexion is centred at 0 rad (channel 0): 0.05 + 0.85·exp(3(cos θ − 1))
    expect(g.flexion![0]).toBeCloseTo(0.9, 15);
    expect(g.flexion![2]).toBeCloseTo(0.05 + 0.85 * Math.exp(-3), 15);
    expect(g.flexion![1]).toBeCloseTo(g.flexion![7]!, 15); // symmetric around its centre
    // extension is centred at π (channel 4 of 8)
    expect(g.extension![4]).toBeCloseTo(0.9, 15);
    for (const v of Object.values(defaultGestures(5))) {
      for (const a of v) expect(a >= 0 && a <= 1).toBe(true);
    }
    // any channel count works
    expect(defaultGestures(1).fist).toHaveLength(1);
    expect(defaultGestures(64).pinch).toHaveLength(64);
  });

  test("outputs emg [1, Channels] in mV and a one-hot gesture [1, gestures], stamped with the ticks", async () => {
    const h = await sim({ Gesture: "flexion" });
    expect(h.ports.map((p) => [p.name, p.shape])).toEqual([
      ["emg", vectorShape(8)],
      ["gesture", vectorShape(8)],
    ]);
    expect(h.text).toBe("flexion");
    h.push(tickFrame(RATE));
    const emg = h.output("emg");
    expect(emg.t).toHaveLength(RATE);
    expect(emg.t[10]).toBe(10 / RATE);
    expect(h.output("gesture").v[0]).toEqual([0, 0, 0, 0, 1, 0, 0, 0]);
    // After the 60 ms attack: channel 0 (activation 0.9) near 0.9 × 0.5 mV RMS, channel 4 near rest
    const active = rms(emg, 0, RATE / 2, RATE);
    expect(active).toBeGreaterThan(0.35);
    expect(active).toBeLessThan(0.6);
    expect(rms(emg, 4, RATE / 2, RATE)).toBeLessThan(0.08);
    // neighbouring channels are more alike than opposite ones
    expect(rms(emg, 1, RATE / 2, RATE)).toBeGreaterThan(rms(emg, 3, RATE / 2, RATE));
  });

  test("deterministic per seed", async () => {
    const run = async (seed: number) => {
      const h = await sim({ Seed: seed, Gesture: "fist" });
      h.push(tickFrame(200));
      return h.output("emg").v;
    };
    const a = await run(42);
    expect(await run(42)).toEqual(a);
    expect(await run(43)).not.toEqual(a);
  });

  test("Sequence: gestures change at the tick times, cycled; batching does not matter", async () => {
    const sequence = [
      { Gesture: "rest", Seconds: 0.25 },
      { Gesture: "fist", Seconds: 0.5 },
    ];
    const whole = await sim({ Sequence: sequence, Channels: 4 });
    whole.push(tickFrame(RATE + 1));
    const pieces = await sim({ Sequence: sequence, Channels: 4 });
    for (let k = 0; k <= RATE; k += 7) pieces.push(tickFrame(Math.min(7, RATE + 1 - k), 0, k));
    expect(pieces.output("emg").v).toEqual(whole.output("emg").v);
    expect(pieces.output("gesture").v).toEqual(whole.output("gesture").v);
    const g = whole.output("gesture").v.map((v) => v.indexOf(1));
    const at = (s: number) => g[Math.round(s * RATE)];
    expect([at(0), at(0.2495), at(0.25), at(0.7495), at(0.75), at(1.0)]).toEqual([
      0, 0, 1, 1, 0, 1,
    ]);
    expect(whole.text).toBe("fist (sequence step 2 of 2)");
  });

  test("actions setGesture and next, the live Gesture param, and reset", async () => {
    const h = await sim({
      Sequence: [
        { Gesture: "pinch", Seconds: 1 },
        { Gesture: "open", Seconds: 1 },
      ],
    });
    expect(h.text).toBe("pinch (sequence step 1 of 2)");
    h.clock = 0.1;
    expect(h.instance.actions!.next!.run()).toBe("gesture: open");
    h.push(ticks(0.1));
    expect(h.output("gesture").v.at(-1)![2]).toBe(1);
    expect(h.instance.actions!.setGesture!.run("fist")).toBe("gesture: fist");
    expect(h.text).toBe("fist");
    h.push(ticks(5)); // the sequence no longer plays
    expect(h.output("gesture").v.at(-1)![1]).toBe(1);
    expect(() => h.instance.actions!.setGesture!.run("fits")).toThrow(
      "unknown gesture 'fits' (gestures: rest, fist, open, pinch, flexion, extension, pronation, supination); did you mean 'fist'?",
    );
    h.instance.actions!.next!.run();
    expect(h.text).toBe("open");
    h.instance.setParam!("Gesture", "supination");
    expect(h.text).toBe("supination");
    // reset: the sequence plays again from the start, and the signal repeats
    h.instance.reset!();
    h.clear();
    h.push(tickFrame(100));
    const first = h.output("emg").v;
    expect(h.output("gesture").v[0]![3]).toBe(1);
    h.instance.reset!();
    h.clear();
    h.push(tickFrame(100));
    expect(h.output("emg").v).toEqual(first);
  });

  test("custom Gestures", async () => {
    const h = await sim({
      Channels: 2,
      Gestures: { left: [1, 0], right: [0, 1], both: [1, 1] },
      Gesture: "right",
    });
    expect(h.ports[1]!.shape).toEqual(vectorShape(3));
    h.push(tickFrame(RATE));
    const emg = h.output("emg");
    expect(rms(emg, 1, RATE / 2, RATE)).toBeGreaterThan(0.35);
    expect(rms(emg, 0, RATE / 2, RATE)).toBeLessThan(0.05);
    expect(h.output("gesture").v[0]).toEqual([0, 1, 0]);
  });

  describe("a simulated participant following cue inputs", () => {
    /** A simulator with a timer and cue inputs of `width` values each. */
    async function follower(params: object, width: number, cues = 1): Promise<BlockHarness> {
      const inputs = [
        timer,
        ...Array.from({ length: cues }, () => ({ shape: vectorShape(width), rate: 25 })),
      ];
      const h = await BlockHarness.create(EmgSimulator, params, { inputs, now: 0 });
      h.start();
      return h;
    }
    const cue = (t: number, ...w: number[]): Frame => vectors([t], [w]);

    test("one-hot cues: the gesture output follows them; the EMG takes the cued pattern", async () => {
      const h = await follower({ Channels: 8, CueGestures: ["fist", "flexion"] }, 2);
      expect(h.text).toBe("rest");
      h.push(tickFrame(RATE / 2)); // 0.5 s of rest
      h.push(cue(0.5, 0, 1), 1); // flexion from the first tick at or after 0.5 s
      h.push(tickFrame(RATE, 0, RATE / 2));
      h.push(cue(1.5, NaN, NaN), 1); // a stop: back to rest
      h.push(tickFrame(RATE / 2, 0, RATE + RATE / 2));
      const g = h.output("gesture").v;
      const flexion = DEFAULT_GESTURES.indexOf("flexion");
      expect(g[RATE / 2 - 1]![0]).toBe(1);
      expect(g[RATE / 2]![flexion]).toBe(1);
      expect(g[RATE / 2]!.reduce((a, b) => a + b, 0)).toBe(1);
      expect(g[RATE + RATE / 2]![0]).toBe(1);
      expect(h.text).toBe("rest (following cues)");
      // Flexion is centred on channel 0, away from channel 4 (≈ 0.9 vs 0.05 activation).
      const emg = h.output("emg");
      expect(rms(emg, 0, RATE, RATE + RATE / 2)).toBeGreaterThan(0.3);
      expect(rms(emg, 4, RATE, RATE + RATE / 2)).toBeLessThan(0.08);
      expect(rms(emg, 0, 0, RATE / 2)).toBeLessThan(0.05);
      // The same levels as holding flexion by the Gesture param (the same seed and generator).
      const held = await sim({ Gesture: "flexion" });
      held.push(tickFrame(RATE));
      const ratio = rms(emg, 0, RATE, RATE + RATE / 2) / rms(held.output("emg"), 0, RATE / 2, RATE);
      expect(ratio).toBeGreaterThan(0.85);
      expect(ratio).toBeLessThan(1.15);
    });

    test("graded weights mix the patterns (rest + Σ w·(gesture − rest)), rest takes the remainder", async () => {
      const gestures = { rest: [0.1, 0.1], a: [1, 0.1], b: [0.1, 0.6] };
      const h = await follower({ Channels: 2, Gestures: gestures, CueGestures: ["a", "b"] }, 2);
      h.push(cue(0, 0.5, 0.25), 1);
      h.push(tickFrame(1));
      expect(h.output("gesture").v[0]).toEqual([0.25, 0.5, 0.25]);
      // Weights are clipped to 0..1 (the activations to 0..1); NaN and negatives count as 0.
      h.push(cue(0.001, 3, -1), 1);
      h.push(cue(0.0015, NaN, 0.5), 1);
      h.push(tickFrame(2, 0, 2));
      expect(h.output("gesture").v.slice(1)).toEqual([
        [0, 1, 0],
        [0.5, 0, 0.5],
      ]);
      expect(h.text).toBe("rest (following cues)");
    });

    test("ReactionMs delays the following; a cue input of all the gestures by default", async () => {
      const h = await follower({ Channels: 4, ReactionMs: 250 }, DEFAULT_GESTURES.length);
      const fist = DEFAULT_GESTURES.map((n) => (n === "fist" ? 1 : 0));
      h.push(cue(0.1, ...fist), 1);
      h.push(tickFrame(RATE));
      const g = h.output("gesture").v.map((v) => v.indexOf(1));
      expect(g.indexOf(1)).toBe(Math.round(0.35 * RATE));
      expect(h.text).toBe("fist (following cues)");
    });

    test("the latest cue of any input wins, by time; batching does not matter", async () => {
      const events: [number, number, number[]][] = [
        [1, 0.1, [1, 0]],
        [2, 0.2, [0, 1]],
        [1, 0.3, [0.5, 0.5]],
        [2, 0.31, [0, 0]],
        [1, 0.6, [0, 1]],
      ];
      const params = { Channels: 3, CueGestures: ["fist", "open"] };
      // All cues first, then one frame of ticks.
      const whole = await follower(params, 2, 2);
      for (const [port, t, w] of [...events].reverse()) whole.push(cue(t, ...w), port);
      whole.push(tickFrame(RATE));
      // Interleaved with frames of 7 ticks, each cue just before the ticks at its time.
      const pieces = await follower(params, 2, 2);
      let next = 0;
      for (let k = 0; k < RATE; k += 7) {
        while (next < events.length && events[next]![1] <= (k + 6) / RATE) {
          const [port, t, w] = events[next++]!;
          pieces.push(cue(t, ...w), port);
        }
        pieces.push(tickFrame(Math.min(7, RATE - k), 0, k));
      }
      expect(pieces.output("emg").v).toEqual(whole.output("emg").v);
      expect(pieces.output("gesture").v).toEqual(whole.output("gesture").v);
      const g = whole.output("gesture").v;
      const at = (s: number) => g[Math.round(s * RATE)];
      expect([at(0.05), at(0.15), at(0.25), at(0.305), at(0.5), at(0.7)]).toEqual([
        [1, 0, 0, 0, 0, 0, 0, 0],
        [0, 1, 0, 0, 0, 0, 0, 0],
        [0, 0, 1, 0, 0, 0, 0, 0],
        [0, 0.5, 0.5, 0, 0, 0, 0, 0],
        [1, 0, 0, 0, 0, 0, 0, 0],
        [0, 0, 1, 0, 0, 0, 0, 0],
      ]);
    });

    test("setting a gesture by hand stops following until reset", async () => {
      const h = await follower({ Channels: 2, CueGestures: ["fist"] }, 1);
      h.push(cue(0, 1), 1);
      h.push(tickFrame(2));
      expect(h.output("gesture").v[1]![1]).toBe(1);
      expect(h.instance.actions!.setGesture!.run("open")).toBe("gesture: open");
      h.push(cue(0.01, 1), 1); // ignored
      h.push(tickFrame(2, 0.02));
      expect(h.output("gesture").v.at(-1)![2]).toBe(1);
      h.instance.reset!();
      h.clear();
      h.push(cue(0, 1), 1);
      h.push(tickFrame(2));
      expect(h.output("gesture").v.at(-1)![1]).toBe(1);
    });

    test("errors: a Sequence with cue inputs, a cue input of the wrong width, unknown CueGestures", async () => {
      await expect(
        follower({ CueGestures: ["fist"], Sequence: [{ Gesture: "fist", Seconds: 1 }] }, 1),
      ).rejects.toThrow("a Sequence and cue inputs both choose the gesture: give one or the other");
      await expect(follower({}, 2)).rejects.toThrow(
        "cue input 'in1' carries 2 values per event, but there are 8 cue gestures (every " +
          "gesture: rest, fist, open, pinch, flexion, extension, pronation, supination); set " +
          "CueGestures to the 2 gestures its values stand for",
      );
      const errors = loadBlock(
        "T: { Type: ScheduledTimer, DesiredRate: 1000 }\n" +
          "E: { Type: EmgSimulator, Inputs: [T], Params: { CueGestures: [fist, opn] } }\n",
        "E",
      ).errors;
      expect(errors.map((e) => e.param)).toEqual(["CueGestures[1]"]);
      expect(errors[0]!.message).toContain("unknown gesture 'opn'");
      expect(errors[0]!.message).toContain("did you mean 'open'?");
    });
  });

  test("errors: not a timer input, gesture vectors of the wrong length, unknown gesture names", async () => {
    await expect(
      BlockHarness.create(EmgSimulator, {}, { inputs: [{ shape: vectorShape(1), rate: 100 }] }),
    ).rejects.toThrow("input 'in0' is not a timer; EmgSimulator is paced by a timer input");
    const base = "T: { Type: ScheduledTimer, DesiredRate: 1000 }\n";
    const err = (params: string) =>
      loadBlock(`${base}E: { Type: EmgSimulator, Inputs: [T], Params: ${params} }`, "E").errors.map(
        (e) => [e.param, e.message],
      );
    expect(err("{ Channels: 2, Gestures: { a: [1, 0, 0] }, Gesture: a }")).toEqual([
      [
        "Gestures.a",
        "block 'E' (EmgSimulator): param 'Gestures.a' gesture 'a' has 3 activations; expected 2 (one per channel)",
      ],
    ]);
    expect(err("{ Gesture: fisst }")[0]![1]).toContain("unknown gesture 'fisst'");
    expect(err("{ Gesture: fisst }")[0]![1]).toContain("did you mean 'fist'?");
    expect(
      err("{ Sequence: [{ Gesture: rest, Seconds: 1 }, { Gesture: pnch, Seconds: 1 }] }")[0]![0],
    ).toBe("Sequence[1].Gesture");
    expect(err("{ BandLowHz: 500, BandHighHz: 450 }")[0]![1]).toContain(
      "BandLowHz 500 must be below BandHighHz 450",
    );
  });
});
