import { describe, expect, test } from "vitest";
import { BlockHarness } from "../../engine/testing";
import { ELECTRODE_ARRAYS, electrodeGrid, type ElectrodeArrayCode } from "./electrode-arrays";
import { Quattrocento } from "./quattrocento";
import { MuoviSingleProbe } from "./muovi-single-probe";
import { EMPTY_SHAPE } from "../../engine";

const grid = (Array: ElectrodeArrayCode, Orientation: 0 | 180, FirstChannel = 0, outputs = 64) =>
  electrodeGrid({ Array, Orientation, FirstChannel }, outputs)!;

/** Row r of a grid, as 1-based channel numbers (NaN: empty), as openhdemg's tables print them. */
const row = (g: ReturnType<typeof grid>, r: number) =>
  g.cells.slice(r * g.cols, (r + 1) * g.cols).map((k) => (k < 0 ? NaN : k + 1));

describe("electrode arrays", () => {
  test.each(Object.keys(ELECTRODE_ARRAYS) as ElectrodeArrayCode[])(
    "%s: every channel on exactly one electrode, in both orientations",
    (code) => {
      const n = ELECTRODE_ARRAYS[code].channels;
      for (const o of [0, 180] as const) {
        const g = grid(code, o, 0, n);
        const used = g.cells.filter((k) => k >= 0).sort((a, b) => a - b);
        expect(used).toEqual(Array.from({ length: n }, (_, i) => i));
      }
    },
  );

  test("the rows of openhdemg's tables (sort_rawemg's docstrings)", () => {
    expect(row(grid("GR08MM1305", 0), 0)).toEqual([64, 39, 38, 13, 12]);
    expect(row(grid("GR08MM1305", 0), 12)).toEqual([52, 51, 26, 25, NaN]);
    expect(row(grid("GR08MM1305", 180), 0)).toEqual([NaN, 25, 26, 51, 52]);
    expect(row(grid("GR08MM1305", 180), 12)).toEqual([12, 13, 38, 39, 64]);
    expect(row(grid("HD08MM1305", 0), 0)).toEqual([12, 25, 38, 51, 64]);
    expect(row(grid("HD08MM1305", 0), 12)).toEqual([NaN, 13, 26, 39, 52]);
    expect(row(grid("GR10MM0808", 0), 0)).toEqual([57, 49, 41, 33, 25, 17, 9, 1]);
    expect(row(grid("GR10MM0808", 0), 7)).toEqual([64, 56, 48, 40, 32, 24, 16, 8]);
    expect(row(grid("GR10MM0808", 180), 0)).toEqual([8, 16, 24, 32, 40, 48, 56, 64]);
    expect(row(grid("HD10MM0804", 0, 0, 32), 0)).toEqual([32, 24, 16, 8]);
    expect(row(grid("HD10MM0804", 0, 0, 32), 7)).toEqual([25, 17, 9, 1]);
  });

  test("an array from a later channel; too few channels is a clear error", () => {
    const g = grid("HD10MM0804", 180, 32, 64);
    expect(g.name).toBe("HD10MM0804 (180°)");
    expect(Math.min(...g.cells)).toBe(32);
    expect(() =>
      electrodeGrid({ Array: "GR10MM0808", Orientation: 0, FirstChannel: 8 }, 64),
    ).toThrow("Grid: GR10MM0808 has 64 channels; from channel 8 the output has only 56");
    expect(electrodeGrid(undefined, 64)).toBeUndefined();
  });
});

describe("a block that reads an array declares it", () => {
  test("Quattrocento: labels, unit and the array's grid on its output; a grid that does not fit names the param", async () => {
    const h = await BlockHarness.create(
      Quattrocento,
      { Connectors: ["MULTIPLE IN1"], Grid: { Array: "GR08MM1305", Orientation: 0 } },
      { io: {} },
    );
    const meta = h.metas.get("emg")!;
    expect(meta.labels!.slice(0, 2)).toEqual(["MULTIPLE IN1/1", "MULTIPLE IN1/2"]);
    expect(meta.unit).toBe("mV");
    expect(meta.grid!.name).toBe("GR08MM1305 (0°)");
    expect(meta.grid!.cells.slice(0, 5)).toEqual([63, 38, 37, 12, 11]);
    await expect(
      BlockHarness.create(
        Quattrocento,
        { Connectors: ["IN1"], Grid: { Array: "GR10MM0808" } },
        { io: {} },
      ),
    ).rejects.toThrow(/Grid: GR10MM0808 has 64 channels; from channel 0 the output has only 16/);
  });
});

describe("Muovi blocks declare their probes' channels and arrays", () => {
  test("MuoviSingleProbe (native): labels per probe channel, the array from a channel; paced: Grid refused", async () => {
    const h = await BlockHarness.create(
      MuoviSingleProbe,
      { Probes: [2], Grid: { Array: "HD10MM0804", Orientation: 0 } },
      { io: {} },
    );
    const meta = h.metas.get("emg")!;
    expect(meta.labels!.slice(0, 2)).toEqual(["probe 3 ch 1", "probe 3 ch 2"]);
    expect(meta.unit).toBe("mV");
    expect(meta.grid!.rows * meta.grid!.cols).toBe(32);
    await expect(
      BlockHarness.create(
        MuoviSingleProbe,
        { Probes: [0], Grid: { Array: "HD10MM0804" } },
        { io: {}, inputs: [{ shape: EMPTY_SHAPE, rate: 100, isTimer: true }] },
      ),
    ).rejects.toThrow(/Grid places a vector's channels on an electrode array/);
  });
});
