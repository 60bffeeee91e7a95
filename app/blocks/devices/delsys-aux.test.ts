import { describe, expect, test } from "vitest";
import { MAX_WAIT, TrignoAuxJoin } from "./delsys-aux";

/** EMG sample i of slot s: 1000 s + i; AUX sample j, value c of slot s: −(100 s + 10 c + j). */
const emgSample = (i: number) => Float64Array.from({ length: 16 }, (_, s) => 1000 * s + i);
const auxSample = (j: number) =>
  Float64Array.from({ length: 144 }, (_, x) => -(100 * Math.floor(x / 9) + 10 * (x % 9) + j));

/** Feeds `frames` frames (26 EMG, 2 AUX each) in the given order; returns the joined rows. */
function run(join: TrignoAuxJoin, frames: number, auxFirst: boolean, auxDelay = 0): number[][] {
  const rows: number[][] = [];
  const take = () => {
    const { values, n } = join.drain();
    for (let r = 0; r < n; r++) {
      rows.push([...values.subarray(r * join.width, (r + 1) * join.width)]);
    }
  };
  const emgFrame = (f: number) => {
    for (let i = 0; i < 26; i++) join.pushEmg(emgSample(26 * f + i));
    take();
  };
  const auxFrame = (f: number) => {
    if (f < 0) return;
    for (let j = 0; j < 2; j++) join.pushAux(auxSample(2 * f + j));
    take();
  };
  for (let f = 0; f < frames + auxDelay; f++) {
    if (auxFirst) auxFrame(f - auxDelay);
    if (f < frames) emgFrame(f);
    if (!auxFirst) auxFrame(f - auxDelay);
  }
  return rows;
}

/** The row EMG sample i must become for slots [2, 0] with 3 AUX values each. */
const expected = (i: number) => {
  const j = Math.floor(i / 13);
  return [2, 0].flatMap((s) => [1000 * s + i, ...[0, 1, 2].map((c) => -(100 * s + 10 * c + j))]);
};

describe("TrignoAuxJoin", () => {
  test.each([
    ["AUX after EMG", false, 0],
    ["AUX before EMG", true, 0],
    ["AUX three frames late", false, 3],
  ])("%s: every EMG sample once, with the AUX sample of its half frame", (_, auxFirst, delay) => {
    const join = new TrignoAuxJoin(Int32Array.of(2, 0), 3, 26, 2);
    expect(join.width).toBe(8);
    const rows = run(join, 40, auxFirst as boolean, delay as number);
    expect(rows.length).toBe(40 * 26);
    rows.forEach((r, i) => expect(r, `row ${i}`).toEqual(expected(i)));
    expect(join.counts).toEqual({ held: 0, dropped: 0 });
  });

  test("an AUX stream that stops: EMG goes on after MAX_WAIT frames with the last values held, counted", () => {
    const join = new TrignoAuxJoin(Int32Array.of(0), 9, 26, 2);
    for (let j = 0; j < 2; j++) join.pushAux(auxSample(j));
    let n = 0;
    for (let i = 0; i < 26 * (MAX_WAIT + 3); i++) {
      join.pushEmg(emgSample(i));
      n += join.drain().n;
    }
    // Frame 0 joined; frames 1… waited until MAX_WAIT frames of AUX were missing, then held.
    expect(n).toBeGreaterThan(26 * 3);
    expect(join.counts.held).toBe(n - 26);
    const last = join.drain();
    expect(last.n).toBe(0);
  });

  test("AUX far ahead of the EMG is dropped and counted; restart starts both streams at 0", () => {
    const join = new TrignoAuxJoin(Int32Array.of(1), 3, 26, 2);
    for (let j = 0; j < 2 * (MAX_WAIT + 5); j++) join.pushAux(auxSample(j));
    expect(join.drain().n).toBe(0);
    expect(join.counts.dropped).toBe(2 * 5);
    join.restart(27, 2);
    join.pushAux(auxSample(0));
    join.pushEmg(emgSample(0));
    const { values, n } = join.drain();
    expect(n).toBe(1);
    expect([...values.subarray(0, 4)]).toEqual([1000, -100, -110, -120]);
  });
});
