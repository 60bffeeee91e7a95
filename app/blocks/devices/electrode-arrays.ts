/**
 * OT Bioelettronica's electrode arrays: where each channel of an HD-EMG array sits on the skin,
 * so that the heatmap draws the channels as the electrodes lie (docs/protocols.md, "Electrode
 * arrays"). Each array is a function (row, column) → channel (0-based, −1: no electrode), for the
 * array's connector pointing away from (0°) or toward (180°) the researcher, as openhdemg's
 * `sort_rawemg` tabulates them (GiacomoValliPhD/openhdemg, `openhdemg/library/electrodes.py`).
 */
import { z } from "zod";
import type { ElectrodeGrid } from "../../engine";

type CellFn = (r: number, c: number) => number;

interface ArrayLayout {
  rows: number;
  cols: number;
  channels: number;
  /** Channel of each cell, by orientation. */
  at: Record<0 | 180, CellFn>;
}

/** 13 × 5, 64 channels, the corner cell empty: GR08MM1305, GR04MM1305 (channels snake). */
const GR_1305: ArrayLayout = {
  rows: 13,
  cols: 5,
  channels: 64,
  at: {
    0: (r, c) => [63 - r, 38 + r, 37 - r, 12 + r, r === 12 ? -1 : 11 - r][c]!,
    180: (r, c) => [r === 0 ? -1 : r - 1, 24 - r, 25 + r, 50 - r, 51 + r][c]!,
  },
};

/** 13 × 5, 64 channels, columns in the same direction: HD08MM1305, HD04MM1305. */
const HD_1305: ArrayLayout = {
  rows: 13,
  cols: 5,
  channels: 64,
  at: {
    0: (r, c) => (c === 0 ? (r === 12 ? -1 : 11 - r) : 13 * c + 11 - r),
    180: (r, c) => (c === 4 ? (r === 0 ? -1 : r - 1) : 51 - 13 * c + r),
  },
};

/** 8 × 8, 64 channels: GR10MM0808, HD10MM0808. */
const A_0808: ArrayLayout = {
  rows: 8,
  cols: 8,
  channels: 64,
  at: {
    0: (r, c) => 56 - 8 * c + r,
    180: (r, c) => 8 * c + 7 - r,
  },
};

/** 8 × 4, 32 channels: HD10MM0804, HD05MM0804. */
const HD_0804: ArrayLayout = {
  rows: 8,
  cols: 4,
  channels: 32,
  at: {
    0: (r, c) => 31 - 8 * c - r,
    180: (r, c) => 8 * c + r,
  },
};

export const ELECTRODE_ARRAYS = {
  GR08MM1305: GR_1305,
  GR04MM1305: GR_1305,
  HD08MM1305: HD_1305,
  HD04MM1305: HD_1305,
  GR10MM0808: A_0808,
  HD10MM0808: A_0808,
  HD10MM0804: HD_0804,
  HD05MM0804: HD_0804,
} as const;

export type ElectrodeArrayCode = keyof typeof ELECTRODE_ARRAYS;

const CODES = Object.keys(ELECTRODE_ARRAYS) as [ElectrodeArrayCode, ...ElectrodeArrayCode[]];

/** The `Grid` param of the blocks that read HD-EMG arrays. */
export const gridParam = () =>
  z
    .strictObject({
      Array: z.enum(CODES).describe("OT Bioelettronica's code of the electrode array"),
      Orientation: z
        .union([z.literal(0), z.literal(180)])
        .default(180)
        .describe("0: connector pointing away from the researcher; 180: toward (openhdemg's)"),
      FirstChannel: z
        .number()
        .int()
        .min(0)
        .default(0)
        .describe("The output channel (0-based) of the array's channel 1"),
    })
    .optional()
    .describe(
      "The electrode array on the channels, so the heatmap draws them as they lie on the skin",
    );

export type GridParam = NonNullable<z.output<ReturnType<typeof gridParam>>>;

/** Channels an array needs. */
export const arrayChannels = (code: ElectrodeArrayCode): number => ELECTRODE_ARRAYS[code].channels;

/**
 * The ElectrodeGrid of an array whose channel 1 is output channel `FirstChannel`; undefined
 * without a Grid. Throws when the output has too few channels for it.
 */
export function electrodeGrid(
  p: GridParam | undefined,
  outputs: number,
): ElectrodeGrid | undefined {
  if (!p) return undefined;
  const a = ELECTRODE_ARRAYS[p.Array];
  if (p.FirstChannel + a.channels > outputs) {
    throw new Error(
      `Grid: ${p.Array} has ${a.channels} channels; from channel ${p.FirstChannel} the output has only ${Math.max(0, outputs - p.FirstChannel)}`,
    );
  }
  const at = a.at[p.Orientation];
  const cells: number[] = [];
  for (let r = 0; r < a.rows; r++) {
    for (let c = 0; c < a.cols; c++) {
      const k = at(r, c);
      cells.push(k < 0 ? -1 : k + p.FirstChannel);
    }
  }
  return { rows: a.rows, cols: a.cols, cells, name: `${p.Array} (${p.Orientation}°)` };
}
