import { describe, expect, test } from "vitest";
import { EMPTY_SHAPE, vectorShape } from "../../engine";
import { BlockHarness } from "../../engine/testing";
import { convertLegacy, ticks } from "../../../tests/support/blocks";
import { SinGenerator } from "./sin-generator";

const timer = { shape: EMPTY_SHAPE, rate: 100, isTimer: true };
const T0 = 1_700_000_000;

describe("SinGenerator", () => {
  test("component i is A·sin(2πf(t − start) + φ + 10·i) at every tick time", async () => {
    const h = await BlockHarness.create(
      SinGenerator,
      { Components: 3, Amplitude: 2, Frequency: 1.5, Phase: 0.3 },
      { inputs: [timer], now: T0 },
    );
    h.start();
    const times = [T0, T0 + 0.01, T0 + 0.25, T0 + 1.7];
    h.push(ticks(...times));
    const out = h.output();
    expect(out.t).toEqual(times);
    for (const [e, t] of times.entries()) {
      const dt = t - T0;
      for (let i = 0; i < 3; i++) {
        expect(out.v[e]![i]).toBeCloseTo(2 * Math.sin(2 * Math.PI * 1.5 * dt + 0.3 + 10 * i), 9);
      }
    }
    // At the start: A·sin(φ + 10 i)
    expect(out.v[0]).toEqual([2 * Math.sin(0.3), 2 * Math.sin(10.3), 2 * Math.sin(20.3)]);
  });

  test("defaults: one component, amplitude 1, 0.2 Hz, output [1, 1]", async () => {
    const h = await BlockHarness.create(SinGenerator, {}, { inputs: [timer], now: 0 });
    h.start();
    h.push(ticks(1.25));
    expect(h.ports[0]!.shape).toEqual(vectorShape(1));
    // 0.2 Hz at 1.25 s is a quarter period: sin(π/2) = 1
    expect(h.output().v[0]![0]).toBeCloseTo(1, 15);
  });

  test("live Amplitude and Phase apply from the next tick; Frequency continues the phase", async () => {
    const h = await BlockHarness.create(
      SinGenerator,
      { Frequency: 1 },
      { inputs: [timer], now: 0 },
    );
    h.start();
    h.push(ticks(0.1));
    h.clock = 0.2;
    h.instance.setParam!("Frequency", 3);
    h.push(ticks(0.3));
    // 1 Hz for 0.2 s, then 3 Hz for 0.1 s: phase 2π(0.2 + 0.3)
    expect(h.output().v[1]![0]).toBeCloseTo(Math.sin(2 * Math.PI * 0.5), 12);
    h.instance.setParam!("Amplitude", 4);
    h.instance.setParam!("Phase", 1);
    h.push(ticks(0.4));
    expect(h.output().v[2]![0]).toBeCloseTo(4 * Math.sin(2 * Math.PI * 0.8 + 1), 12);
    // reset: time again from the start, at the current params
    h.instance.reset!();
    h.push(ticks(0.4));
    expect(h.output().v[3]![0]).toBeCloseTo(4 * Math.sin(2 * Math.PI * 3 * 0.4 + 1), 12);
  });

  test("its input must be a timer", async () => {
    await expect(
      BlockHarness.create(SinGenerator, {}, { inputs: [{ shape: vectorShape(2), rate: 100 }] }),
    ).rejects.toThrow("input 'in0' is not a timer; SinGenerator is paced by a timer input");
  });

  test("legacy [d, G, nu, phi]", () => {
    const base = "Timer: { Type: ScheduledTimer, DesiredRate: 100 }\n";
    expect(
      convertLegacy(
        `${base}Sin: { Type: SinGenerator, Inputs: [Timer], Params: [4, 2.5, 3, 0.5] }`,
        "Sin",
      ),
    ).toEqual({ Components: 4, Amplitude: 2.5, Frequency: 3, Phase: 0.5, PhaseStep: 10 });
    expect(
      convertLegacy(`${base}Sin: { Type: SinGenerator, Inputs: [Timer], Params: ['2'] }`, "Sin"),
    ).toEqual({ Components: 2, Amplitude: 1, Frequency: 0.2, Phase: 0, PhaseStep: 10 });
  });
});
