/**
 * Contract tests over every block of the catalog (CONVENTIONS.md, after fundsp/biquad-rs): the
 * params validate and produce a JSON Schema with every param described; one frame of N events
 * gives the same output, bit for bit, as N frames of one event; after `reset` the output repeats.
 * A block missing from the table below fails the test, so every new block gets a setup here.
 */
import { beforeAll, describe, expect, test } from "vitest";
import { z } from "zod";
import { BLOCKS } from "./catalog";
import {
  EMPTY_SHAPE,
  Frame,
  matrixShape,
  objectKeys,
  outputNames,
  shapeSize,
  vectorShape,
  type AnyBlockDefinition,
  type Resources,
  type Shape,
} from "../engine";
import { BlockHarness } from "../engine/testing";
import { memoryResources } from "../../tests/support/fs-resources";
import { initDspForTests } from "../../tests/support/wasm";

beforeAll(() => initDspForTests());

interface InputSetup {
  shape: Shape;
  rate?: number;
  isTimer?: boolean;
}

interface Setup {
  params: unknown;
  inputs: InputSetup[];
  /** Input port of each event, repeated (default: all on port 0). */
  pattern?: number[];
  /** Number of events (default 40). */
  events?: number;
  resources?: Resources;
  /** The block produces nothing observable (a sink). */
  silent?: boolean;
}

const timer = (rate: number): InputSetup => ({ shape: EMPTY_SHAPE, rate, isTimer: true });
const vec = (c: number, rate = 100): InputSetup => ({ shape: vectorShape(c), rate });

const RECORDING = "time_s,a,b\n0,1,-1\n0.01,2,-2\n0.02,3.5,0.25\n0.03,-4,1e-3\n0.04,5,NaN\n";

/** A valid setup for every block type of the catalog. */
const SETUPS: Record<string, Setup> = {
  ScheduledTimer: { params: {}, inputs: [] },
  DecimatorTimer: { params: {}, inputs: [timer(200)] },
  SinGenerator: { params: { Components: 3, Frequency: 7 }, inputs: [timer(100)] },
  EmgSimulator: {
    params: {
      Channels: 6,
      Sequence: [
        { Gesture: "fist", Seconds: 0.004 },
        { Gesture: "rest", Seconds: 0.003 },
        { Gesture: "pinch", Seconds: 0.005 },
      ],
    },
    inputs: [timer(1000)],
    events: 60,
  },
  FilePlayer: {
    params: { File: "r.csv", Loop: true },
    inputs: [timer(100)],
    resources: memoryResources({ "r.csv": RECORDING }),
  },
  Function: {
    params: { Operation: "multiply" },
    inputs: [{ shape: matrixShape(2, 3) }, vec(3)],
    pattern: [0, 0, 1, 0, 1, 1, 0, 0, 0],
  },
  Filter: {
    params: { Numerator: [0.2, 0.3, 0.1], Denominator: [1, -0.6, 0.2] },
    inputs: [vec(4)],
  },
  LinearMap: { params: { Outputs: 3, Bias: [1, 2, 3] }, inputs: [vec(5)] },
  Resampler: {
    params: { Mode: "mean" },
    inputs: [vec(3), timer(25)],
    pattern: [0, 0, 1, 1, 0, 0, 0, 1, 0, 1, 1, 1],
  },
  Joiner: {
    params: { Trigger: "in2" },
    inputs: [vec(2), timer(50), vec(3)],
    pattern: [1, 0, 2, 2, 1, 0, 0, 2, 1, 1, 2],
  },
  Splitter: { params: { Parts: { a: [3, 0], b: [1, 1, 2] } }, inputs: [vec(4)] },
  Projector: { params: { Indices: [2, 0, 2] }, inputs: [{ shape: matrixShape(3, 3) }] },
  Logger: {
    params: { Folder: "logs" },
    inputs: [vec(2), timer(10), { shape: matrixShape(2, 2) }],
    pattern: [0, 1, 1, 2, 0, 2],
  },
  Sink: { params: {}, inputs: [vec(2), timer(10)], pattern: [0, 1, 1], silent: true },
  Busy: { params: { Milliseconds: 0, Every: 3 }, inputs: [vec(2)] },
};

interface Event {
  port: number;
  t: number;
  v: number[];
}

function makeEvents(s: Setup): Event[] {
  const n = s.events ?? 40;
  const pattern = s.pattern ?? [0];
  const out: Event[] = [];
  for (let i = 0; i < n; i++) {
    const port = pattern[i % pattern.length]!;
    const size = shapeSize(s.inputs[port]!.shape);
    const v = Array.from({ length: size }, (_, k) => Math.sin(1.3 * i + 0.7 * k) * (1 + k));
    out.push({ port, t: i / 1000, v });
  }
  return out;
}

function frameOf(shape: Shape, events: Event[]): Frame {
  return Frame.from(
    shape,
    events.map((e) => e.t),
    events.map((e) => e.v),
  );
}

/** Everything a block produced: output ports and log files. */
function snapshot(h: BlockHarness): Record<string, { t: number[]; v: number[][] } | string[]> {
  const s: Record<string, { t: number[]; v: number[][] } | string[]> = {};
  for (const [name, r] of h.out) s[`port:${name}`] = { t: [...r.t], v: r.v.map((x) => [...x]) };
  for (const [name, lines] of h.logs.files) s[`log:${name}`] = [...lines];
  return s;
}

function clearAll(h: BlockHarness): void {
  h.clear();
  for (const lines of h.logs.files.values()) lines.length = 0;
}

async function harness(def: AnyBlockDefinition, s: Setup): Promise<BlockHarness> {
  const h = await BlockHarness.create(def, s.params, {
    inputs: s.inputs,
    now: 0,
    ...(s.resources ? { resources: s.resources } : {}),
  });
  h.start();
  return h;
}

function feedOneByOne(h: BlockHarness, s: Setup, events: Event[]): void {
  for (const e of events) h.push(frameOf(s.inputs[e.port]!.shape, [e]), e.port);
}

function feedGrouped(h: BlockHarness, s: Setup, events: Event[]): void {
  let i = 0;
  while (i < events.length) {
    let j = i;
    while (j < events.length && events[j]!.port === events[i]!.port) j++;
    const port = events[i]!.port;
    h.push(frameOf(s.inputs[port]!.shape, events.slice(i, j)), port);
    i = j;
  }
}

describe("block contract", () => {
  test("every catalog block has a setup here", () => {
    const missing = BLOCKS.map((b) => b.type).filter((t) => !(t in SETUPS));
    expect(missing).toEqual([]);
    const unknown = Object.keys(SETUPS).filter((t) => !BLOCKS.some((b) => b.type === t));
    expect(unknown).toEqual([]);
  });

  describe.each(BLOCKS.map((def) => [def.type, def] as const))("%s", (type, def) => {
    const setup = SETUPS[type];

    test("docs: summary, help, panel and a description for every param; JSON Schema", () => {
      expect(def.summary.trim()).not.toBe("");
      expect(def.summary).not.toContain("\n");
      expect(def.help.trim().length).toBeGreaterThan(80);
      expect(def.panel?.trim() ?? "").not.toBe("");
      const schema = z.toJSONSchema(def.params, { io: "input" }) as {
        properties?: Record<string, { description?: string }>;
      };
      const keys = objectKeys(def.params) ?? [];
      expect(Object.keys(schema.properties ?? {})).toEqual(keys);
      for (const k of keys) {
        expect(
          schema.properties![k]!.description ?? "",
          `${type}.${k} has no description`,
        ).not.toBe("");
      }
      for (const l of def.live ?? []) expect(keys).toContain(l);
      if (def.legacyParams) expect(def.legacyForm ?? "").not.toBe("");
    });

    test("the setup's params validate and its outputs are declared", async () => {
      expect(setup).toBeDefined();
      const parsed = def.params.safeParse(setup!.params);
      expect(parsed.success, JSON.stringify(parsed.error?.issues)).toBe(true);
      const h = await harness(def, setup!);
      expect(h.ports.map((p) => p.name)).toEqual([...outputNames(def, h.params)]);
      if ((def.live ?? []).length > 0) expect(h.instance.setParam).toBeTypeOf("function");
    });

    test("one frame of N events = N frames of one event; after reset the output repeats", async () => {
      const s = setup!;
      if (s.inputs.length === 0) return; // sources paced by their own timer: nothing to batch
      const events = makeEvents(s);
      const one = await harness(def, s);
      feedOneByOne(one, s, events);
      const expected = snapshot(one);
      // The comparison means something only if the block produced something.
      const produced = Object.values(expected).reduce(
        (n, x) => n + (Array.isArray(x) ? x.length : x.t.length),
        0,
      );
      if (!s.silent) expect(produced).toBeGreaterThan(0);

      const grouped = await harness(def, s);
      feedGrouped(grouped, s, events);
      expect(snapshot(grouped)).toEqual(expected);

      clearAll(one);
      one.instance.reset?.();
      feedOneByOne(one, s, events);
      expect(snapshot(one)).toEqual(expected);
      one.instance.dispose?.();
      grouped.instance.dispose?.();
    });
  });
});
