/**
 * The block contract as a program (`mosaic test-block`, docs/writing-blocks.md): the checks every
 * built-in block passes in app/blocks/contract.test.ts, run on any block definition with a setup
 * (params and input shapes), each giving pass or fail with the reason. The checks: docs, the
 * example params validate and declare their outputs, one frame of N events = N frames of one,
 * reset repeats, dispose twice, and garbage params refused by the schema, the positional form or a
 * BlockConfigError — never an internal error.
 */
import { z } from "zod";
import {
  outputNames,
  type AnyBlockDefinition,
  type BlockContext,
  type BlockInstance,
  type Resources,
} from "./block";
import { createCatalog, type Catalog } from "./catalog";
import { VirtualClock } from "./clock";
import { BlockConfigError, errorMessage } from "./diagnostics";
import { EMPTY_SHAPE, Frame, matrixShape, shapeSize, type Shape } from "./frame";
import { LegacyParamsError } from "./pipeline/legacy";
import { loadPipeline, objectKeys } from "./pipeline/loader";
import { Runtime } from "./runtime/runtime";
import { runVirtual } from "./runtime/virtual";
import { defineBlock } from "./block";
import { BlockHarness } from "./testing";

/** One input of a setup: its shape `[rows, cols]` (or channels), rate, and whether a timer. */
export interface ContractInput {
  shape?: readonly [number, number];
  channels?: number;
  rate?: number;
  timer?: boolean;
}

/** How to try a block: its params and its inputs (the module's `contract` export). */
export interface ContractSetup {
  params?: unknown;
  inputs?: ContractInput[];
  /** Events fed in the splitting and reset checks (default 40). */
  events?: number;
  /** The block produces nothing observable from its inputs (a sink). */
  silent?: boolean;
}

export interface CheckResult {
  name: string;
  ok: boolean;
  /** Why it failed, or what was checked. */
  detail: string;
}

interface Input {
  shape: Shape;
  rate: number;
  isTimer: boolean;
}

interface Event {
  port: number;
  t: number;
  v: number[];
}

/** The setup's inputs, or the block's default ones: `inputs.min` (at least one) of 2 channels. */
export function contractInputs(def: AnyBlockDefinition, s: ContractSetup): Input[] {
  if (s.inputs) {
    return s.inputs.map((i) => ({
      shape: i.timer
        ? EMPTY_SHAPE
        : i.shape
          ? matrixShape(i.shape[0], i.shape[1])
          : matrixShape(1, i.channels ?? 2),
      rate: i.rate ?? 100,
      isTimer: i.timer === true,
    }));
  }
  const n = Math.max(def.inputs.min, def.inputs.max > 0 ? 1 : 0);
  return Array.from({ length: n }, (_, i) => {
    const timer = def.inputs.labels?.[i] === "timer";
    return { shape: timer ? EMPTY_SHAPE : matrixShape(1, 2), rate: 100, isTimer: timer };
  });
}

/**
 * Runs every check on `def`; `resources` are the files it may read (the module's folder);
 * `onResult` hears each result as soon as it is known (a later check may never end).
 */
export async function runBlockContract(
  def: AnyBlockDefinition,
  setup: ContractSetup,
  resources: Resources,
  base: Catalog,
  onResult?: (r: CheckResult) => void,
): Promise<CheckResult[]> {
  const inputs = contractInputs(def, setup);
  const ctx: Run = { def, setup, inputs, resources, base };
  const out: CheckResult[] = [];
  for (const [name, check] of CHECKS) {
    let r: CheckResult;
    try {
      r = { name, ...(await check(ctx)) };
    } catch (e) {
      r = { name, ok: false, detail: `${(e as Error).name ?? "Error"}: ${errorMessage(e)}` };
    }
    out.push(r);
    onResult?.(r);
  }
  return out;
}

interface Run {
  def: AnyBlockDefinition;
  setup: ContractSetup;
  inputs: Input[];
  resources: Resources;
  base: Catalog;
}

type Check = (r: Run) => Promise<{ ok: boolean; detail: string }>;

const pass = (detail: string) => ({ ok: true, detail });
const fail = (detail: string) => ({ ok: false, detail });

/** The checks' names, in the order they run. */
export const CHECK_NAMES = [
  "docs",
  "defaults validate",
  "frame splitting",
  "reset repeats",
  "dispose twice",
  "garbage params",
] as const;

const CHECKS: [(typeof CHECK_NAMES)[number], Check][] = [
  ["docs", checkDocs],
  ["defaults validate", checkDefaults],
  ["frame splitting", checkSplitting],
  ["reset repeats", checkReset],
  ["dispose twice", checkDispose],
  ["garbage params", checkGarbage],
];

async function checkDocs({ def }: Run): Promise<{ ok: boolean; detail: string }> {
  if (def.summary.trim() === "" || def.summary.includes("\n")) {
    return fail("summary must be one line of text");
  }
  if (def.help.trim() === "") return fail("help is empty: say what the block does");
  const schema = z.toJSONSchema(def.params, { io: "input", unrepresentable: "any" }) as {
    properties?: Record<string, { description?: string }>;
  };
  const keys = objectKeys(def.params) ?? [];
  const bare = keys.filter((k) => (schema.properties?.[k]?.description ?? "").trim() === "");
  if (bare.length > 0) return fail(`params without .describe(...): ${bare.join(", ")}`);
  const notParams = (def.live ?? []).filter((l) => !keys.includes(l));
  if (notParams.length > 0) return fail(`live names what is not a param: ${notParams.join(", ")}`);
  if (def.legacyParams && !def.legacyForm) return fail("legacyParams without legacyForm");
  return pass(`summary, help and ${keys.length} described params`);
}

async function harness(r: Run): Promise<BlockHarness> {
  const h = await BlockHarness.create(r.def, r.setup.params ?? {}, {
    inputs: r.inputs.map((i) => ({ shape: i.shape, rate: i.rate, isTimer: i.isTimer })),
    now: 0,
    resources: r.resources,
  });
  h.start();
  return h;
}

async function checkDefaults(r: Run): Promise<{ ok: boolean; detail: string }> {
  const parsed = r.def.params.safeParse(r.setup.params ?? {});
  if (!parsed.success) {
    const issues = parsed.error.issues.map(
      (i: { path: PropertyKey[]; message: string }) =>
        `${i.path.map(String).join(".") || "(params)"}: ${i.message}`,
    );
    return fail(
      `params ${JSON.stringify(r.setup.params ?? {})} do not validate: ${issues.join("; ")}`,
    );
  }
  const h = await harness(r);
  const declared = [...outputNames(r.def, h.params)];
  const made = h.ports.map((p) => p.name);
  h.instance.dispose?.();
  if (JSON.stringify(declared) !== JSON.stringify(made)) {
    return fail(`outputs declared [${declared.join(", ")}] but create() made [${made.join(", ")}]`);
  }
  if ((r.def.live ?? []).length > 0 && typeof h.instance.setParam !== "function") {
    return fail("live params but no setParam in the instance");
  }
  return pass(`params ${JSON.stringify(r.setup.params ?? {})}; outputs [${made.join(", ")}]`);
}

function makeEvents(r: Run): Event[] {
  const n = r.setup.events ?? 40;
  const ports = r.inputs.map((_, i) => i).filter((i) => !r.inputs[i]!.isTimer);
  const order = ports.length > 0 ? ports : r.inputs.map((_, i) => i);
  const out: Event[] = [];
  for (let i = 0; i < n; i++) {
    const port = order[i % order.length]!;
    const size = shapeSize(r.inputs[port]!.shape);
    const v = Array.from({ length: size }, (_, k) => Math.sin(0.37 * i + 1.3 * k) * (k + 1));
    out.push({ port, t: i / 1000, v });
  }
  return out;
}

function feed(h: BlockHarness, r: Run, events: Event[], grouped: boolean): void {
  let i = 0;
  while (i < events.length) {
    let j = i + 1;
    if (grouped) while (j < events.length && events[j]!.port === events[i]!.port) j++;
    const port = events[i]!.port;
    const part = events.slice(i, j);
    const f = Frame.from(
      r.inputs[port]!.shape,
      part.map((e) => e.t),
      part.map((e) => e.v),
    );
    h.push(f, port);
    i = j;
  }
}

type Snapshot = Record<string, { t: number[]; v: number[][] }>;

function snapshot(h: BlockHarness): Snapshot {
  const s: Snapshot = {};
  for (const [name, rec] of h.out) s[name] = { t: [...rec.t], v: rec.v.map((x) => [...x]) };
  return s;
}

/** Where two snapshots first differ, in words; undefined when equal (NaN equals NaN). */
export function firstDifference(a: Snapshot, b: Snapshot): string | undefined {
  for (const port of new Set([...Object.keys(a), ...Object.keys(b)])) {
    const x = a[port] ?? { t: [], v: [] };
    const y = b[port] ?? { t: [], v: [] };
    if (x.t.length !== y.t.length) {
      return `output '${port}': ${x.t.length} events vs ${y.t.length}`;
    }
    for (let e = 0; e < x.t.length; e++) {
      if (!Object.is(x.t[e], y.t[e]))
        return `output '${port}' event ${e}: time ${x.t[e]} vs ${y.t[e]}`;
      const vx = x.v[e]!;
      const vy = y.v[e]!;
      for (let k = 0; k < vx.length; k++) {
        if (!Object.is(vx[k], vy[k])) {
          return `output '${port}' event ${e} value ${k}: ${vx[k]} vs ${vy[k]}`;
        }
      }
    }
  }
  return undefined;
}

const eventsIn = (s: Snapshot): number => Object.values(s).reduce((n, x) => n + x.t.length, 0);

/** Sources paced by their own timer have nothing to batch. */
const sourceOnly = (r: Run): boolean => r.inputs.length === 0;

async function checkSplitting(r: Run): Promise<{ ok: boolean; detail: string }> {
  if (sourceOnly(r)) return pass("skipped: no inputs (a source paced by its own timer)");
  const events = makeEvents(r);
  const one = await harness(r);
  feed(one, r, events, false);
  const expected = snapshot(one);
  one.instance.dispose?.();
  if (!r.setup.silent && eventsIn(expected) === 0) {
    return fail(
      `${events.length} input events gave no output (export contract { silent: true } for a sink)`,
    );
  }
  const grouped = await harness(r);
  feed(grouped, r, events, true);
  const got = snapshot(grouped);
  grouped.instance.dispose?.();
  const diff = firstDifference(expected, got);
  if (diff) return fail(`one frame of many events ≠ one event per frame: ${diff}`);
  return pass(`${events.length} events, ${eventsIn(expected)} out, bit for bit`);
}

async function checkReset(r: Run): Promise<{ ok: boolean; detail: string }> {
  if (sourceOnly(r)) return pass("skipped: no inputs");
  const events = makeEvents(r);
  const h = await harness(r);
  feed(h, r, events, false);
  const first = snapshot(h);
  h.clear();
  h.instance.reset?.();
  feed(h, r, events, false);
  const again = snapshot(h);
  h.instance.dispose?.();
  const diff = firstDifference(first, again);
  if (diff) return fail(`after reset() the output differs: ${diff}`);
  return pass(`the same ${eventsIn(first)} output events after reset()`);
}

async function checkDispose(r: Run): Promise<{ ok: boolean; detail: string }> {
  const fresh = await BlockHarness.create(r.def, r.setup.params ?? {}, {
    inputs: r.inputs.map((i) => ({ shape: i.shape, rate: i.rate, isTimer: i.isTimer })),
    now: 0,
    resources: r.resources,
  });
  fresh.instance.dispose?.();
  fresh.instance.dispose?.();
  const started = await harness(r);
  if (!sourceOnly(r)) feed(started, r, makeEvents(r).slice(0, 5), false);
  started.instance.stop?.();
  started.instance.dispose?.();
  started.instance.dispose?.();
  return pass("dispose() twice before and after start threw nothing");
}

// ---------------------------------------------------------------------------------------------
// Garbage params, through the loader and the runtime as a pipeline file would bring them.

/** Errors that mean a bug in the block, not a refused value. */
function internal(e: unknown): boolean {
  return (
    e instanceof TypeError ||
    e instanceof RangeError ||
    e instanceof ReferenceError ||
    e instanceof SyntaxError ||
    (e instanceof Error && e.constructor.name === "RuntimeError")
  );
}

const GARBAGE: unknown[] = [
  0,
  -0,
  -1,
  1,
  2.5,
  1e15,
  -1e15,
  1e300,
  NaN,
  Infinity,
  -Infinity,
  "",
  "x",
  "1",
  true,
  null,
  [],
  [0],
  [-1, 1e15],
  ["a"],
  {},
  { a: 1 },
];

/** A seeded generator (mulberry32): the same garbage on every run. */
function random(seed: number): () => number {
  let a = seed >>> 0;
  return () => {
    a = (a + 0x6d2b79f5) >>> 0;
    let t = a;
    t = Math.imul(t ^ (t >>> 15), t | 1);
    t ^= t + Math.imul(t ^ (t >>> 7), t | 61);
    return ((t ^ (t >>> 14)) >>> 0) / 4294967296;
  };
}

/** Params to try: each param set to each garbage value, then random mixtures, then non-objects. */
export function garbageParams(def: AnyBlockDefinition, base: unknown, runs = 60): unknown[] {
  const keys = objectKeys(def.params) ?? [];
  const b = (typeof base === "object" && base !== null ? base : {}) as Record<string, unknown>;
  const out: unknown[] = [];
  for (const k of keys) for (const v of GARBAGE) out.push({ ...b, [k]: v });
  const rnd = random(20261124);
  const pick = (): unknown => GARBAGE[Math.floor(rnd() * GARBAGE.length)];
  for (let i = 0; i < runs && keys.length > 0; i++) {
    const p: Record<string, unknown> = { ...b };
    for (const k of keys) if (rnd() < 0.5) p[k] = pick();
    out.push(p);
  }
  out.push(null, 1, "x", [], ["1", "2"]);
  return out;
}

/** A source of any shape for the garbage pipelines (as contract.test.ts's). */
const ContractSource = defineBlock({
  type: "ContractSource",
  category: "Testing",
  summary: "Test source of a given shape.",
  help: "Emits one value of shape [Rows, Cols] per tick of its timer (mosaic test-block only).",
  params: z.strictObject({
    Rows: z.number().int().min(1).describe("rows"),
    Cols: z.number().int().min(1).describe("columns"),
  }),
  inputs: { min: 1, max: 1 },
  create(ctx, p) {
    const out = ctx.output(matrixShape(p.Rows, p.Cols));
    const size = p.Rows * p.Cols;
    return {
      process(f) {
        const o = out.frame(f.n);
        for (let e = 0; e < f.n; e++) {
          o.t[e] = f.t[e]!;
          for (let k = 0; k < size; k++) o.v[e * size + k] = Math.sin(97 * f.t[e]! + k) * (k + 1);
        }
        out.emit(o);
      },
    };
  },
});

function garbagePipeline(
  def: AnyBlockDefinition,
  inputs: Input[],
  params: unknown,
  timer: string,
): string {
  const lines = [`Clock: { Type: ${timer}, DesiredRate: 100 }`];
  const names = inputs.map((inp, i) => {
    const name = `Src${i}`;
    lines.push(
      inp.isTimer
        ? `${name}: { Type: ${timer}, DesiredRate: ${inp.rate} }`
        : `${name}: { Type: ContractSource, DesiredRate: ${inp.rate}, Inputs: [Clock], Params: { Rows: ${inp.shape.rows}, Cols: ${inp.shape.cols} } }`,
    );
    return name;
  });
  const rate = def.timer || def.requiresRate ? ", DesiredRate: 100" : "";
  const ins = names.length > 0 ? `, Inputs: [${names.join(", ")}]` : "";
  lines.push(`Block: { Type: ${def.type}${rate}${ins}, Params: ${JSON.stringify(params)} }`);
  return lines.join("\n") + "\n";
}

/** The definition with every internal error it raises recorded in `found`. */
function guarded(def: AnyBlockDefinition, found: string[]): AnyBlockDefinition {
  const note = (stage: string, e: unknown): void => {
    const s = `${stage}: ${(e as Error).name}: ${errorMessage(e)}`;
    if (internal(e) && !found.includes(s)) found.push(s);
  };
  const wrap = (inst: BlockInstance): BlockInstance => {
    const w: BlockInstance = { ...inst };
    for (const m of [
      "process",
      "flush",
      "start",
      "stop",
      "reset",
      "dispose",
      "setParam",
    ] as const) {
      const f = inst[m] as ((...a: unknown[]) => unknown) | undefined;
      if (!f) continue;
      (w as Record<string, unknown>)[m] = (...a: unknown[]) => {
        try {
          return f.apply(inst, a);
        } catch (e) {
          note(m, e);
          throw e;
        }
      };
    }
    return w;
  };
  const legacy = def.legacyParams;
  return {
    ...def,
    ...(legacy
      ? {
          legacyParams: (args: readonly string[]) => {
            try {
              return legacy(args);
            } catch (e) {
              if (!(e instanceof LegacyParamsError) && !(e instanceof BlockConfigError)) {
                note("legacyParams", e);
              }
              throw e;
            }
          },
        }
      : {}),
    async create(ctx: BlockContext, params: unknown) {
      try {
        return wrap(await def.create(ctx, params));
      } catch (e) {
        if (!(e instanceof BlockConfigError)) note("create", e);
        throw e;
      }
    },
  };
}

async function tryGarbage(r: Run, params: unknown, found: string[]): Promise<void> {
  const catalog = createCatalog([
    ...[...r.base].filter(([n, d]) => n === d.type && d.type !== r.def.type).map(([, d]) => d),
    guarded(r.def, found),
    ContractSource,
  ]);
  // The base catalog's timer (ScheduledTimer among the built-in blocks).
  const timer = [...r.base.values()].find((d) => d.timer === true)?.type ?? "ScheduledTimer";
  const text = garbagePipeline(r.def, r.inputs, params, timer);
  const loaded = loadPipeline(text, "garbage.yaml", catalog);
  if (!loaded.spec) return;
  const clock = new VirtualClock(0);
  const created = await Runtime.create({
    spec: loaded.spec,
    catalog,
    clock,
    virtual: true,
    resources: r.resources,
    ignorePlacement: true,
  });
  const rt = created.runtime;
  if (!rt) return;
  try {
    rt.start();
    runVirtual(rt, clock, 0.05, 2000);
  } finally {
    rt.dispose();
  }
}

async function checkGarbage(r: Run): Promise<{ ok: boolean; detail: string }> {
  const found: string[] = [];
  const tries = garbageParams(r.def, r.setup.params);
  for (const p of tries) {
    const before = found.length;
    await tryGarbage(r, p, found);
    for (let i = before; i < found.length; i++) found[i] = `${JSON.stringify(p)} → ${found[i]}`;
  }
  if (found.length > 0) {
    return fail(
      `${found.length} internal error${found.length === 1 ? "" : "s"} (refuse such values in the zod schema or with a BlockConfigError): ${found.slice(0, 3).join("; ")}`,
    );
  }
  return pass(`${tries.length} garbage params refused or handled`);
}
