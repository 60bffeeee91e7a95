import { describe, expect, test } from "vitest";
import { vectorShape } from "../../engine";
import { BlockHarness, runVirtualPipeline } from "../../engine/testing";
import { convertLegacy, loadBlock, vectors } from "../../../tests/support/blocks";
import { catalog } from "../catalog";
import { Trigger } from "./trigger";

const LABELS = { rest: [0, 0, 0], power: [1, 1, 1], flex: [0, 1, 0] };
const STOP = [NaN, NaN, NaN];

async function trigger(params: object = {}, inputs?: { shape: ReturnType<typeof vectorShape> }[]) {
  const h = await BlockHarness.create(
    Trigger,
    { Labels: LABELS, ...params },
    { now: 10, ...(inputs ? { inputs } : {}) },
  );
  h.start();
  return h;
}

const run = (h: BlockHarness, action: string, arg?: unknown) =>
  h.instance.actions![action]!.run(arg);

describe("Trigger", () => {
  test("actions: start, switch, stop, next/previous, select; the label output follows", async () => {
    const h = await trigger({ Initial: "power" });
    expect(h.text).toBe("'power' (2/3) selected, not capturing");
    h.clock = 11;
    expect(run(h, "start")).toBe("capturing 'power' [1, 1, 1]");
    expect(h.text).toBe("capturing 'power' (2/3)");
    h.clock = 12;
    run(h, "start", "power"); // the same label again: nothing sent
    run(h, "start", 2); // switch by index
    h.clock = 13;
    expect(run(h, "stop")).toBe("stopped 'flex'");
    expect(run(h, "stop")).toBe("not capturing");
    expect(h.output("target")).toMatchObject({
      t: [11, 12, 13],
      v: [[1, 1, 1], [0, 1, 0], STOP],
    });
    expect(h.output("label").v).toEqual([[1], [2], [NaN]]);
    // next/previous cycle; while capturing they switch the capture.
    expect(run(h, "next")).toBe("selected 'rest'");
    expect(run(h, "previous")).toBe("selected 'flex'");
    run(h, "start");
    h.clock = 14;
    expect(run(h, "next")).toBe("capturing 'rest'");
    expect(run(h, "select", "flex")).toBe("capturing 'flex'");
    expect(h.output("label").v.slice(3)).toEqual([[2], [0], [2]]);
    expect(() => run(h, "start", "flx")).toThrow(
      "unknown label 'flx' (labels: rest, power, flex); did you mean 'flex'?",
    );
    expect(() => run(h, "start", 3)).toThrow("expected a label name or index");
  });

  test("pulse: start now, stop after N seconds on the one-shot (MOSAIC's number keys)", async () => {
    const h = await trigger({ Pulse: 2 });
    h.clock = 20;
    expect(run(h, "pulse", 1.5)).toBe("capturing 'rest' for 1.5 s");
    expect(h.text).toBe("capturing 'rest' (1/3), pulse of 1.5 s");
    expect(h.oneShot?.t).toBe(21.5);
    h.fireOneShot();
    h.clock = 30;
    run(h, "pulse"); // default: Pulse seconds
    expect(h.oneShot?.t).toBe(32);
    // A stop and a new start in the meantime cancel the pulse's stop.
    run(h, "stop");
    run(h, "start", "flex");
    h.fireOneShot();
    expect(h.output("target")).toMatchObject({
      t: [20, 21.5, 30, 30, 30],
      v: [[0, 0, 0], STOP, [0, 0, 0], STOP, [0, 1, 0]],
    });
    expect(() => run(h, "pulse", -1)).toThrow("expected a duration in seconds from 0 to 86400");
  });

  test("schedule: a list of { Label, At, Seconds } played from the pipeline start", async () => {
    const h = await trigger({
      Schedule: [
        { Label: "flex", At: 5, Seconds: 2 },
        { Label: "power", At: 1, Seconds: 2 },
        { Label: "rest", At: 3, Seconds: 1 }, // starts when power ends: a switch, no stop
      ],
    });
    expect(h.text).toBe("'rest' (1/3) selected, not capturing; schedule 0/3");
    const times: number[] = [];
    while (h.oneShot) {
      times.push(h.oneShot.t);
      h.fireOneShot();
    }
    expect(times).toEqual([11, 13, 14, 15, 17]);
    expect(h.output("target")).toMatchObject({
      t: [11, 13, 14, 15, 17],
      v: [[1, 1, 1], [0, 0, 0], STOP, [0, 1, 0], STOP],
    });
    expect(h.text).toBe("'flex' (3/3) selected, not capturing; schedule 3/3");
  });

  test("schedule: a repeating protocol; reset replays it from the reset", async () => {
    const h = await trigger({
      Schedule: { Sequence: ["power", "flex"], Seconds: 1, Pause: 0.5, Repetitions: 2, Start: 2 },
    });
    const fire = () => {
      const ts: number[] = [];
      while (h.oneShot) {
        ts.push(h.oneShot.t);
        h.fireOneShot();
      }
      return ts;
    };
    expect(fire()).toEqual([12, 13, 13.5, 14.5, 15, 16, 16.5, 17.5]);
    expect(h.output("label").v.flat()).toEqual([1, NaN, 2, NaN, 1, NaN, 2, NaN]);
    h.clear();
    h.clock = 100;
    run(h, "start");
    h.instance.reset!(); // stops the capture in progress and replays the schedule
    expect(h.output("target").v).toEqual([[0, 1, 0], STOP]); // flex: the last selected
    expect(fire()[0]).toBe(102);
  });

  test("condition input: capture the selected label while the value is above (or below) a threshold", async () => {
    const h = await trigger({ Initial: "power", Condition: { Channel: 1, Above: 0.5 } }, [
      { shape: vectorShape(2) },
    ]);
    h.push(
      vectors(
        [1, 2, 3, 4, 5, 6],
        [
          [9, 0],
          [9, 1],
          [0, 0.9],
          [0, NaN], // NaN does not hold
          [0, 0.7],
          [0, 0.2],
        ],
      ),
    );
    expect(h.output("target")).toMatchObject({
      t: [2, 4, 5, 6],
      v: [[1, 1, 1], STOP, [1, 1, 1], STOP],
    });
    // Between two thresholds, changed while running.
    h.instance.setParam!("Condition", { Channel: 0, Above: -1, Below: 1 });
    h.clear();
    h.push(
      vectors(
        [7, 8, 9],
        [
          [0.5, 0],
          [2, 0],
          [0, 0],
        ],
      ),
    );
    expect(h.output("target").t).toEqual([7, 8, 9]);
    expect(() => h.instance.setParam!("Condition", { Channel: 2, Above: 0 })).toThrow(
      "Condition.Channel 2 is out of range for input 'in0' with 2 values (valid: 0–1)",
    );
  });

  test("with an input and no Condition: Channel 0 above 0.5", async () => {
    const h = await trigger({}, [{ shape: vectorShape(1) }]);
    h.push(vectors([1, 2, 3], [[0.5], [0.51], [0]]));
    expect(h.output("target").t).toEqual([2, 3]);
  });

  test("configuration errors name the param", async () => {
    await expect(trigger({ Condition: { Channel: 0, Above: 1 } })).rejects.toThrow(
      "Condition needs an input",
    );
    await expect(
      trigger({ Condition: { Channel: 3, Above: 1 } }, [{ shape: vectorShape(2) }]),
    ).rejects.toThrow("Condition.Channel 3 is out of range");
    await expect(trigger({ Initial: "powr" })).rejects.toThrow(
      "Initial: unknown label 'powr' (labels: rest, power, flex); did you mean 'power'?",
    );
    await expect(trigger({ Labels: { a: [1], b: [1, 2] } })).rejects.toThrow(
      "label 'b' has 2 values, but 'a' has 1",
    );
    await expect(trigger({ Labels: {} })).rejects.toThrow("needs at least one label");
    await expect(trigger({ Schedule: { Sequence: ["flx"], Seconds: 1 } })).rejects.toThrow(
      "Schedule.Sequence.0: unknown label 'flx'",
    );
    await expect(
      trigger({ Condition: { Channel: 0 } }, [{ shape: vectorShape(1) }]),
    ).rejects.toThrow("give Above, Below or both");
  });

  test("in a pipeline: a scheduled Trigger drives a Buffer; rows carry the scheduled targets", async () => {
    const yaml =
      "T: { Type: ScheduledTimer, DesiredRate: 100 }\n" +
      "Emg: { Type: SinGenerator, Inputs: [T], Params: { Components: 2 } }\n" +
      "Labels:\n" +
      "  Type: Trigger\n" +
      "  Params:\n" +
      "    Labels: { rest: [0, 0], fist: [1, 0], open: [0, 1] }\n" +
      "    Schedule: [{ Label: fist, At: 0.105, Seconds: 0.2 }, { Label: open, At: 0.505, Seconds: 0.1 }]\n" +
      "Buf: { Type: Buffer, Inputs: [Labels, -Emg], Params: { Stream: true } }\n";
    const r = await runVirtualPipeline(yaml, { catalog, duration: 1, start: 1000 });
    const rows = r.outputs.get("Buf")!;
    const fist = rows.t.filter((_, i) => rows.v[i]![0] === 1);
    const open = rows.t.filter((_, i) => rows.v[i]![1] === 1);
    expect(fist.length + open.length).toBe(rows.t.length);
    // Exactly the data of the windows [1000.105, 1000.305) and [1000.505, 1000.605), at 100 Hz.
    // (A window starting exactly on a tick would lose or gain that tick's sample depending on
    // whether the timer or the Trigger's one-shot fires first: the runtime's tie order.)
    expect(fist).toHaveLength(20);
    expect(open).toHaveLength(10);
    expect(Math.min(...fist)).toBeCloseTo(1000.11, 9);
    expect(Math.max(...fist)).toBeCloseTo(1000.3, 9);
    expect(Math.min(...open)).toBeCloseTo(1000.51, 9);
    expect(Math.max(...open)).toBeCloseTo(1000.6, 9);
    expect(r.outputs.get("Labels")!.t).toEqual([1000.105, 1000.305, 1000.505, 1000.605]);
    const text = r.telemetry.blocks.find((b) => b.name === "Labels")!.text;
    expect(text).toBe("'open' (3/3) selected, not capturing; schedule 2/2");
  });

  test("legacy: MOSAIC's [rest: 0;0;0, power: 1;1;1, …] (a one-pair mapping inside a flow list)", () => {
    // As in MOSAIC's cfg5_incremental_myocontrol.yaml.
    const yaml =
      "capture_data: {\n" +
      "  Type: Trigger,\n" +
      "  Params: [\n" +
      "    rest:    0;0;0;0;0;0;0;0;0;0;0;0,\n" +
      "    power:   1;1;1;1;1;1;0;0;0;0;0;0,\n" +
      "    flex:    0;0;0;0;0;0;1;0;0;0;0;0,\n" +
      "    extend:  0;0;0;0;0;0;0;1;0;0;0;0,\n" +
      "    pron:    0;0;0;0;0;0;0;0;1;0;0;0,\n" +
      "    sup:     0;0;0;0;0;0;0;0;0;1;0;0\n" +
      "  ]\n" +
      "}\n";
    const p = convertLegacy(yaml, "capture_data") as { Labels: Record<string, number[]> };
    expect(Object.keys(p.Labels)).toEqual(["rest", "power", "flex", "extend", "pron", "sup"]);
    expect(p.Labels.power).toEqual([1, 1, 1, 1, 1, 1, 0, 0, 0, 0, 0, 0]);
    expect(p).toMatchObject({ Pulse: 3 });
    // Without spaces MOSAIC's form is a plain string; a missing colon or vector is an error.
    expect(convertLegacy("A: { Type: Trigger, Params: [a:1;0, b:0;1] }\n", "A")).toMatchObject({
      Labels: { a: [1, 0], b: [0, 1] },
    });
    const bad = loadBlock("A: { Type: Trigger, Params: [a:1;0, b] }\n", "A");
    expect(bad.errors[0]!.message).toContain("argument 2 'b' is not 'name:a;b;c'");
    const twice = loadBlock("A: { Type: Trigger, Params: [a:1, a:2] }\n", "A");
    expect(twice.errors[0]!.message).toContain("label 'a' is given twice");
  });
});
