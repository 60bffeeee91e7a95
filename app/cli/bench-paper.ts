/**
 * MOSAIC's published figures (paper section V: Tables 5 and 6, Fig. 6), for the comparison
 * columns of the bench's tables and targets.
 */

export interface PaperBlock {
  block: string;
  rate: number;
  meanDt: number;
  freq: number;
  stdDt: number;
  /** Table 6: G, I, L, S in % (null = "-"). */
  status: [number | null, number | null, number | null, number | null];
}

/** Keyed by our block names (the paper's row name is `block`). */
export const PAPER: Record<"myo" | "delsys", Record<string, PaperBlock>> = {
  myo: {
    Timer: {
      block: "Scheduled Timer",
      rate: 200,
      meanDt: 0.0050001,
      freq: 199.9955,
      stdDt: 0.0002417,
      status: [100, null, null, null],
    },
    Myo: {
      block: "Myo",
      rate: 200,
      meanDt: 0.0050001,
      freq: 199.9978,
      stdDt: 0.0002641,
      status: [100, null, null, null],
    },
    Amplification: {
      block: "Amplification",
      rate: 200,
      meanDt: 0.005,
      freq: 199.9993,
      stdDt: 0.0002837,
      status: [100, null, null, null],
    },
    Rectification: {
      block: "Rectification",
      rate: 200,
      meanDt: 0.005,
      freq: 199.9993,
      stdDt: 0.0003017,
      status: [100, null, null, null],
    },
    LowPass: {
      block: "Low Pass Filter",
      rate: 200,
      meanDt: 0.0049999,
      freq: 200.0042,
      stdDt: 0.0003385,
      status: [100, null, null, null],
    },
    Resampler: {
      block: "Resampler",
      rate: 25,
      meanDt: 0.0400009,
      freq: 24.9994,
      stdDt: 0.0002944,
      status: [100, null, null, null],
    },
    Predictor: {
      block: "Incremental Predictor",
      rate: 25,
      meanDt: 0.0400005,
      freq: 24.9997,
      stdDt: 0.0004624,
      status: [100, null, null, null],
    },
    Control: {
      block: "Control Algorithm",
      rate: 25,
      meanDt: 0.0400005,
      freq: 24.9997,
      stdDt: 0.0004755,
      status: [100, null, null, null],
    },
    Sender: {
      block: "UDP Sender",
      rate: 25,
      meanDt: 0.0399848,
      freq: 25.0095,
      stdDt: 0.0009457,
      status: [100, null, null, null],
    },
  },
  delsys: {
    Delsys: {
      block: "Delsys Trigno Avanti",
      rate: 1926,
      meanDt: 0.0005192,
      freq: 1926.0572,
      stdDt: 0.0003156,
      status: [99.175, 0.022, 0.802, null],
    },
    Amplification: {
      block: "Amplification",
      rate: 1926,
      meanDt: 0.0005192,
      freq: 1926.0736,
      stdDt: 0.0003523,
      status: [98.8, 0.037, 1.163, null],
    },
    Rectification: {
      block: "Rectification",
      rate: 1926,
      meanDt: 0.0005192,
      freq: 1926.0744,
      stdDt: 0.0003641,
      status: [98.666, 0.041, 1.293, null],
    },
    LowPass: {
      block: "Low Pass Filter",
      rate: 1926,
      meanDt: 0.0005192,
      freq: 1926.1146,
      stdDt: 0.000383,
      status: [98.319, 0.046, 1.635, null],
    },
    Resampler: {
      block: "Resampler",
      rate: 25,
      meanDt: 0.0399797,
      freq: 25.0127,
      stdDt: 0.0020564,
      status: [100, null, null, null],
    },
    Predictor: {
      block: "Incremental Predictor",
      rate: 25,
      meanDt: 0.0399795,
      freq: 25.0128,
      stdDt: 0.0022413,
      status: [100, null, null, null],
    },
    Control: {
      block: "Control Algorithm",
      rate: 25,
      meanDt: 0.0399796,
      freq: 25.0128,
      stdDt: 0.0022767,
      status: [100, null, null, null],
    },
    Sender: {
      block: "UDP Sender",
      rate: 25,
      meanDt: 0.0399674,
      freq: 25.0204,
      stdDt: 0.0025883,
      status: [100, null, null, null],
    },
  },
};

/** The paper's CPU figures are % of an 8-core machine (Fig. 6); in cores: × 8 / 100. */
export const PAPER_CPU = {
  myo: { pct8: 12.01, sd8: 1.73, cores: (12.01 * 8) / 100 },
  delsys: { pct8: 29.29, sd8: 2.19, cores: (29.29 * 8) / 100 },
};
