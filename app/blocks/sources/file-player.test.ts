import { readFileSync } from "node:fs";
import { join } from "node:path";
import { describe, expect, test } from "vitest";
import { catalog } from "../catalog";
import { EMPTY_SHAPE, vectorShape } from "../../engine";
import { BlockHarness, runVirtualPipeline, type HarnessOptions } from "../../engine/testing";
import { convertLegacy, ticks } from "../../../tests/support/blocks";
import { fsResources, memoryResources, REPO_ROOT } from "../../../tests/support/fs-resources";
import { FilePlayer } from "./file-player";
import { firstRowAtOrAfter, seekSeconds } from "./file-player-seek";
import { statusText } from "./file-player-status";
import { sortedMedian } from "./file-player-timing";

const RECORDING = "pipelines/data/emg_bursts_1000hz.csv";
const timer = { shape: EMPTY_SHAPE, rate: 1000, isTimer: true };
const T0 = 1_700_000_000;

/** The recording read independently of the block: [time_s, emg_mV] per row. */
function readRecording(): [number, number][] {
  const lines = readFileSync(join(REPO_ROOT, RECORDING), "utf8").trim().split("\n");
  expect(lines[0]).toBe("time_s,emg_mV");
  return lines.slice(1).map((l) => {
    const [t, v] = l.split(",");
    return [parseFloat(t!), parseFloat(v!)];
  });
}

const player = (params: object, files: Record<string, string>, opts: HarnessOptions = {}) =>
  BlockHarness.create(FilePlayer, params, { resources: memoryResources(files), ...opts });

/** Fires the pending one-shot at time `t` (later than due, like a loop that woke late). */
function wakeAt(h: BlockHarness, t: number): void {
  const o = h.oneShot!;
  h.oneShot = null;
  h.clock = t;
  o.fn(t);
}

describe("FilePlayer", () => {
  test("with a timer: one row of the real recording per tick, stamped with the tick time", async () => {
    const rows = readRecording();
    expect(rows).toHaveLength(28519);
    const h = await BlockHarness.create(
      FilePlayer,
      { File: RECORDING },
      {
        inputs: [timer],
        resources: fsResources(),
      },
    );
    expect(h.ports[0]!.shape).toEqual(vectorShape(1));
    h.start();
    const t = [5, 5.001, 5.002, 5.003, 5.004];
    h.push(ticks(...t.slice(0, 2)));
    h.push(ticks(...t.slice(2)));
    expect(h.output().t).toEqual(t);
    expect(h.output().v).toEqual(rows.slice(0, 5).map((r) => [r[1]]));
    expect(h.output().v[0]).toEqual([-0.002289]);
    expect(h.desiredRate).toBe(1000);
  });

  test("original timing: timestamps are startTime + time_s and every row plays once", async () => {
    const rows = readRecording();
    const run = await runVirtualPipeline(
      `Play: { Type: FilePlayer, Params: { File: ${RECORDING} } }`,
      {
        catalog,
        duration: 60,
        start: T0,
        resources: fsResources(),
      },
    );
    const out = run.outputs.get("Play")!;
    expect(out.t).toHaveLength(rows.length);
    expect(out.t).toEqual(rows.map((r) => T0 + r[0]));
    expect(out.v).toEqual(rows.map((r) => [r[1]]));
    const b = run.telemetry.blocks.find((x) => x.name === "Play")!;
    expect(run.telemetry.finished).toBe(true);
    expect(b.finished).toBe(true);
    expect(b.text).toBe(`finished: ${rows.length} rows played`);
    expect(b.desiredRate).toBeCloseTo(1000, 6);
  });

  test("original timing: a late wake emits every due row in one frame, stamped with its own time", async () => {
    const csv = "t,a,b\n0,1,10\n0.5,2,20\n1,3,30\n1.5,4,40\n";
    const h = await player({ File: "r.csv" }, { "r.csv": csv }, { now: T0 });
    expect(h.desiredRate).toBe(2);
    h.start();
    expect(h.oneShot!.t).toBe(T0);
    wakeAt(h, T0 + 1.2);
    expect(h.output()).toEqual({
      t: [T0, T0 + 0.5, T0 + 1],
      v: [
        [1, 10],
        [2, 20],
        [3, 30],
      ],
      frames: [3],
    });
    expect(h.oneShot!.t).toBe(T0 + 1.5);
    expect(h.finished).toBe(false);
    h.fireOneShot();
    expect(h.output().t).toEqual([T0, T0 + 0.5, T0 + 1, T0 + 1.5]);
    expect(h.finished).toBe(true);
    expect(h.oneShot).toBeNull();
    expect(h.text).toBe("finished: 4 rows played");
  });

  test("original timing with Loop and Speed: the next loop starts one median interval after the last row", async () => {
    const csv = "time;x\n10;1\n10.5;2\n11;3\n";
    const h = await player({ File: "r.csv", Loop: true, Speed: 2 }, { "r.csv": csv }, { now: 100 });
    expect(h.desiredRate).toBe(4);
    h.start();
    for (let i = 0; i < 7; i++) h.fireOneShot();
    expect(h.output().t).toEqual([100, 100.25, 100.5, 100.75, 101, 101.25, 101.5]);
    expect(h.output().v.flat()).toEqual([1, 2, 3, 1, 2, 3, 1]);
    expect(h.finished).toBe(false);
    expect(h.text).toMatch(/^row 1 \/ 3 \(loop 3\)$/);
  });

  test("original timing: pause shifts the remaining rows by the pause; restart plays from the start", async () => {
    const csv = "t,x\n0,1\n1,2\n2,3\n";
    const h = await player({ File: "r.csv" }, { "r.csv": csv }, { now: 0 });
    h.start();
    h.fireOneShot(); // row 0 at 0
    h.clock = 0.5;
    expect(h.instance.actions!.pause!.run()).toBe("paused at row 1");
    expect(h.text).toBe("paused at row 1 / 3");
    h.fireOneShot(); // the pending wake at 1 finds it paused: nothing
    expect(h.output().t).toEqual([0]);
    h.clock = 10.5;
    h.instance.actions!.resume!.run();
    h.fireOneShot();
    expect(h.output().t).toEqual([0, 11]); // row 1 was due 0.5 s after the pause began
    h.clock = 20;
    h.instance.actions!.restart!.run();
    h.fireOneShot();
    expect(h.output().t).toEqual([0, 11, 20]);
    expect(h.output().v.flat()).toEqual([1, 2, 1]);
  });

  test("seek: plays on from the row at that time, at once; bad or out-of-range times are refused", async () => {
    const csv = "t,x\n0,1\n1,2\n2,3\n3,4\n4,5\n";
    const h = await player({ File: "r.csv" }, { "r.csv": csv }, { now: 0 });
    h.start();
    h.fireOneShot(); // row 0 at 0
    h.clock = 0.5;
    const seek = h.instance.actions!.seek!;
    expect(seek.run(2.5)).toBe("at 3 s (row 4)");
    h.fireOneShot();
    h.fireOneShot();
    expect(h.output().t).toEqual([0, 0.5, 1.5]);
    expect(h.output().v.flat()).toEqual([1, 4, 5]);
    expect(h.finished).toBe(true);
    // After the end, a seek plays again from there.
    h.clock = 10;
    expect(seek.run("1")).toBe("at 1 s (row 2)");
    h.fireOneShot();
    expect(h.output().v.flat()).toEqual([1, 4, 5, 2]);
    expect(seek.run(9)).toBe("the recording lasts 4 s: nothing at 9 s");
    expect(seek.run(-1)).toMatch(/^seek: give the seconds/);
    expect(seek.run("soon")).toMatch(/^seek: give the seconds/);
  });

  test("position: [seconds, duration, row, rows] for every row played, and at once after a seek", async () => {
    const csv = "t,x\n10,1\n11,2\n12,3\n14,4\n";
    const h = await player({ File: "r.csv" }, { "r.csv": csv }, { now: 0 });
    h.start();
    h.fireOneShot();
    h.fireOneShot();
    expect(h.output("position").t).toEqual([0, 1]);
    expect(h.output("position").v).toEqual([
      [0, 4, 1, 4],
      [1, 4, 2, 4],
    ]);
    h.clock = 1.5;
    h.instance.actions!.seek!.run(3.5);
    expect(h.output("position").t.at(-1)).toBe(1.5);
    expect(h.output("position").v.at(-1)).toEqual([4, 4, 4, 4]);
    h.instance.actions!.restart!.run();
    expect(h.output("position").v.at(-1)).toEqual([0, 4, 1, 4]);
  });

  test("Speed and Loop change while it plays: the position stays, the rows after it follow", async () => {
    const csv = "t,x\n0,1\n1,2\n2,3\n3,4\n";
    const h = await player({ File: "r.csv" }, { "r.csv": csv }, { now: 0 });
    h.start();
    h.fireOneShot(); // row 0 at 0
    h.clock = 0.5;
    // At half a second into the recording, twice as fast: row 1 (at 1 s) is due 0.25 s later.
    h.instance.setParam!("Speed", 2);
    expect(h.desiredRate).toBe(2);
    h.fireOneShot();
    h.fireOneShot();
    expect(h.output().t).toEqual([0, 0.75, 1.25]);
    // Loop on before the end: after row 3 (at 1.75) comes row 0 one median interval later.
    h.instance.setParam!("Loop", true);
    h.fireOneShot();
    h.fireOneShot();
    expect(h.output().t).toEqual([0, 0.75, 1.25, 1.75, 2.25]);
    expect(h.output().v.flat()).toEqual([1, 2, 3, 4, 1]);
    expect(h.finished).toBe(false);
    // Loop off: it ends at the last row.
    h.instance.setParam!("Loop", false);
    for (let i = 0; i < 3; i++) h.fireOneShot();
    expect(h.output().v.flat()).toEqual([1, 2, 3, 4, 1, 2, 3, 4]);
    expect(h.finished).toBe(true);
    // Too fast for the engine: refused with the reason, the speed unchanged.
    expect(() => h.instance.setParam!("Speed", 1e9)).toThrow(/above the fastest the engine paces/);
  });

  test("original timing: after stop and start the remaining rows move by the stopped time", async () => {
    const csv = "t,x\n0,1\n1,2\n2,3\n";
    const h = await player({ File: "r.csv" }, { "r.csv": csv }, { now: 0 });
    h.start();
    h.fireOneShot(); // row 0 at 0
    h.clock = 0.25;
    h.instance.stop!();
    h.oneShot = null; // the runtime drops pending wake-ups on stop
    h.clock = 5.25;
    h.start();
    h.fireOneShot();
    h.fireOneShot();
    expect(h.output().t).toEqual([0, 6, 7]);
  });

  test("with a timer: Loop wraps around; without Loop it finishes and stops emitting", async () => {
    const csv = "1,2\n3,4\n5,6\n";
    const looped = await player(
      { File: "r.csv", Loop: true },
      { "r.csv": csv },
      { inputs: [timer] },
    );
    looped.start();
    looped.push(ticks(1, 2, 3, 4, 5, 6, 7));
    expect(looped.output().v).toEqual([
      [1, 2],
      [3, 4],
      [5, 6],
      [1, 2],
      [3, 4],
      [5, 6],
      [1, 2],
    ]);
    expect(looped.finished).toBe(false);

    const once = await player({ File: "r.csv" }, { "r.csv": csv }, { inputs: [timer] });
    once.start();
    once.push(ticks(1, 2));
    once.push(ticks(3, 4, 5));
    once.push(ticks(6));
    expect(once.output().t).toEqual([1, 2, 3]);
    expect(once.output().frames).toEqual([2, 1]);
    expect(once.finished).toBe(true);
    expect(once.text).toBe("finished: 3 rows played");
    // pause / resume / restart with a timer
    once.instance.actions!.restart!.run();
    once.push(ticks(7));
    once.instance.actions!.pause!.run();
    once.push(ticks(8));
    once.instance.actions!.resume!.run();
    once.push(ticks(9));
    expect(once.output().t).toEqual([1, 2, 3, 7, 9]);
    expect(once.output().v.slice(3)).toEqual([
      [1, 2],
      [3, 4],
    ]);
    // reset rewinds
    once.instance.reset!();
    once.push(ticks(10));
    expect(once.output().v.at(-1)).toEqual([1, 2]);
  });

  test("Columns, TimeColumn, Header and Delimiter", async () => {
    const tsv = "# exported by hand\nstamp\tx\ty\tlabel\n\n0\t1\t2\tup\n0.25\t3\t4\tdown\n";
    const h = await player(
      { File: "r.tsv", Columns: ["y", 1], TimeColumn: "stamp" },
      { "r.tsv": tsv },
      { now: 0 },
    );
    expect(h.desiredRate).toBe(4);
    h.start();
    h.fireOneShot();
    h.fireOneShot();
    expect(h.output()).toEqual({
      t: [0, 0.25],
      v: [
        [2, 1],
        [4, 3],
      ],
      frames: [1, 1],
    });

    // MOSAIC's own log format: no header, the time in column 0
    const log = "1700000000.000000,1,NaN\n1700000000.500000,2,-inf\n";
    const l = await player({ File: "Emg.txt", TimeColumn: 0 }, { "Emg.txt": log }, { now: 5 });
    l.start();
    l.fireOneShot();
    l.fireOneShot();
    expect(l.output().t).toEqual([5, 5.5]);
    expect(l.output().v).toEqual([
      [1, NaN],
      [2, -Infinity],
    ]);

    // spaces, explicit Header: false, no time column with a timer
    const h2 = await player(
      { File: "r.txt", Header: false, Delimiter: " ", TimeColumn: false },
      { "r.txt": "  1   2\n3 4  \n" },
      { inputs: [timer] },
    );
    h2.start();
    h2.push(ticks(0, 1));
    expect(h2.output().v).toEqual([
      [1, 2],
      [3, 4],
    ]);
  });

  test("errors name the line, the field and what was expected", async () => {
    const files = {
      "bad.csv": "time_s,a,b\n0,1,2\n0.1,1,abc\n",
      "short.csv": "time_s,a\n0,1\n0.1\n",
      "notime.csv": "a,b\n1,2\n3,4\n",
      "back.csv": "t,a\n0,1\n1,2\n0.5,3\n",
    };
    const fail = (params: object, opts: HarnessOptions = {}) =>
      expect(player(params, files, opts)).rejects;
    await fail({ File: "bad.csv" }).toThrow(
      `line 3 of 'bad.csv': field 3 (column "b") is "abc", which is not a number`,
    );
    await fail({ File: "short.csv" }).toThrow(
      "line 3 of 'short.csv' has 1 field; expected 2 like line 1",
    );
    await fail({ File: "notime.csv" }).toThrow(
      "'notime.csv' has no time column, so it cannot be played at its original timing; either give " +
        "the FilePlayer a timer input (one row per tick) or name the time column with TimeColumn",
    );
    await fail({ File: "back.csv" }).toThrow(
      "line 4 of 'back.csv': time 0.5 is before the previous row's 1",
    );
    await fail({ File: "notime.csv", Columns: ["bb"] }, { inputs: [timer] }).toThrow(
      `'notime.csv' has no column 'bb' (its columns: "a", "b"); did you mean "b"?`,
    );
    await fail({ File: "notime.csv", Columns: [5] }, { inputs: [timer] }).toThrow(
      "column index 5 is out of range: 'notime.csv' has 2 columns (valid: 0–1)",
    );
    await fail({ File: "missing.csv" }, { inputs: [timer] }).toThrow(
      "cannot read 'missing.csv': ENOENT",
    );
    await fail({ File: "notime.csv" }, { inputs: [{ shape: vectorShape(1) }] }).toThrow(
      "input 'in0' is not a timer",
    );
  });

  test("a load error is positioned on the File param", async () => {
    const err = await runVirtualPipeline(
      "P:\n  Type: FilePlayer\n  Params:\n    File: nope.csv\n",
      {
        catalog,
        duration: 0,
        resources: fsResources(),
      },
    ).catch((e: Error) => e.message);
    expect(err).toMatch(
      /^test\.yaml:4:5: error: block 'P' \(FilePlayer\): cannot read '.*nope\.csv': ENOENT/,
    );
  });

  test("legacy [path]", () => {
    expect(convertLegacy(`P: { Type: FilePlayer, Params: [${RECORDING}] }`, "P")).toEqual({
      File: RECORDING,
      Header: "auto",
      Delimiter: "auto",
      Loop: false,
      Speed: 1,
    });
  });
});

describe("FilePlayer pieces", () => {
  test("status text: position, total, pause, loop; finished; stopped", () => {
    const s = { row: 7, loops: 0, done: false, paused: false, failed: undefined };
    expect(statusText(s, 20)).toBe("row 7 / 20");
    expect(statusText(s, undefined)).toBe("row 7");
    expect(statusText({ ...s, paused: true, loops: 2 }, 20)).toBe("paused at row 7 / 20 (loop 3)");
    expect(statusText({ ...s, done: true }, 20)).toBe("finished: 20 rows played");
    expect(statusText({ ...s, done: true }, undefined)).toBe("finished: 7 rows played");
    expect(statusText({ ...s, done: true, failed: "line 9: bad" }, 20)).toBe(
      "stopped at row 7: line 9: bad",
    );
  });

  test("seek argument: seconds as a number or a numeric string, finite and not negative", () => {
    expect(seekSeconds(2.5)).toBe(2.5);
    expect(seekSeconds("12")).toBe(12);
    expect(seekSeconds(0)).toBe(0);
    for (const bad of [-1, "soon", Infinity, NaN, undefined, null, [1]]) {
      expect(seekSeconds(bad)).toBeUndefined();
    }
  });

  test("the first row at or after a time (rows in time order, repeated times)", () => {
    const t = [0, 1, 1, 1, 2.5, 4];
    const at = (want: number) => firstRowAtOrAfter((r) => t[r]!, t.length, want);
    expect(at(-1)).toBe(0);
    expect(at(0)).toBe(0);
    expect(at(0.5)).toBe(1);
    expect(at(1)).toBe(1);
    expect(at(2.5)).toBe(4);
    expect(at(3)).toBe(5);
    expect(at(4.01)).toBe(6);
    expect(firstRowAtOrAfter(() => 0, 0, 1)).toBe(0);
  });

  test("median of sorted intervals: the middle one, or the mean of the middle two", () => {
    expect(sortedMedian(Float64Array.of(0.5))).toBe(0.5);
    expect(sortedMedian(Float64Array.of(0.1, 0.2, 0.9))).toBe(0.2);
    expect(sortedMedian(Float64Array.of(0, 0.25, 0.75, 1))).toBe(0.5);
  });
});
