/**
 * The block contract, one for the built-in blocks and for a user's: `mosaic test-block FILE`
 * (docs/writing-blocks.md) runs these checks on any block definition with a setup (params and
 * input shapes), each giving pass or fail with the reason; app/blocks/contract.test.ts runs the
 * same program (`runBlockContract`) on every block of the catalog with its SETUPS, and builds its
 * own assertions (and its fast-check garbage) from the pieces exported here: the events, the
 * feeding, the snapshots, the guarded definition, the garbage pipelines. The checks: docs, the
 * example params validate and declare their outputs, one frame of N events = N frames of one,
 * reset repeats, dispose twice, and garbage params refused by the schema, the positional form or a
 * BlockConfigError — never an internal error (nor one at run time, from an action or a live param).
 */
import { stringify } from "yaml";
import { z } from "zod";
import {
  defineBlock,
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
import type { IoBridges } from "./io";
import { LegacyParamsError } from "./pipeline/legacy";
import { loadPipeline, objectKeys } from "./pipeline/loader";
import type { CatchUp, TickCallback } from "./runtime/scheduler";
import { Runtime } from "./runtime/runtime";
import { runVirtual } from "./runtime/virtual";
import { BlockHarness } from "./testing";

/** One input of a module's setup: its shape `[rows, cols]` (or channels), rate, and whether a timer. */
export interface ContractInput {
  shape?: readonly [number, number];
  channels?: number;
  rate?: number;
  timer?: boolean;
}

/** Fake I/O bridges for a block; what they recorded (e.g. datagrams sent) joins the snapshot. */
export interface ContractIo {
  io: IoBridges;
  recorded(): unknown;
  clear(): void;
}

/** What a setup says besides its inputs (the same for a module's and for contract.test.ts's). */
interface SetupOptions {
  params?: unknown;
  /** Input port of each event, repeated (default: the inputs that are not timers, in turn). */
  pattern?: readonly number[];
  /** Events fed in the splitting and reset checks (default 40). */
  events?: number;
  /** Values of event `i` on `port` (default: `smoothValues`); `size` values. */
  values?: (i: number, port: number, size: number) => number[];
  /** The block produces nothing observable from its inputs (a sink). */
  silent?: boolean;
  /**
   * Params the garbage check leaves alone, because a huge value is a legitimate way to make the
   * block take that long (with the reason); everything else is fuzzed.
   */
  fuzzKeep?: { keys: string[]; reason: string };
  /** Fake I/O bridges for the block (a fresh set for each harness). */
  io?: () => ContractIo;
}

/** How to try a block: its params and its inputs (the module's `contract` export). */
export interface ContractSetup extends SetupOptions {
  inputs?: ContractInput[];
}

/** One input as the harness takes it. */
export interface SetupInput {
  shape: Shape;
  rate?: number;
  isTimer?: boolean;
}

/** A setup with its inputs as shapes and its files: what the checks and helpers below take. */
export interface BlockSetup extends SetupOptions {
  inputs: readonly SetupInput[];
  resources?: Resources;
}

export interface CheckResult {
  name: string;
  ok: boolean;
  /** Why it failed, or what was checked. */
  detail: string;
}

export interface Event {
  port: number;
  t: number;
  v: number[];
}

/** The setup's inputs, or the block's default ones: `inputs.min` (at least one) of 2 channels. */
export function contractInputs(def: AnyBlockDefinition, s: ContractSetup): Required<SetupInput>[] {
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

/** A module's setup as the checks take it, with the files its block may read. */
export function blockSetup(
  def: AnyBlockDefinition,
  s: ContractSetup,
  resources: Resources,
): BlockSetup {
  return { ...s, inputs: contractInputs(def, s), resources };
}

export interface ContractOptions {
  /** Random mixtures of garbage params after the one-param sweep (default 60). */
  garbageRuns?: number;
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
  options: ContractOptions = {},
): Promise<CheckResult[]> {
  const ctx: Run = { def, s: blockSetup(def, setup, resources), base, options };
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
  s: BlockSetup;
  base: Catalog;
  options: ContractOptions;
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

// ---------------------------------------------------------------------------------------------
// Harnesses, events and snapshots

const fakeIo = new WeakMap<BlockHarness, ContractIo>();

/** A harness of the block with the setup's params, inputs, files and fake I/O; started unless told. */
export async function harness(
  def: AnyBlockDefinition,
  s: BlockSetup,
  start = true,
): Promise<BlockHarness> {
  const io = s.io?.();
  const h = await BlockHarness.create(def, s.params ?? {}, {
    inputs: [...s.inputs],
    now: 0,
    ...(s.resources ? { resources: s.resources } : {}),
    ...(io ? { io: io.io } : {}),
  });
  if (io) fakeIo.set(h, io);
  if (start) h.start();
  return h;
}

/** The default values of event `i`: `size` smooth, varied numbers. */
export const smoothValues = (i: number, _port: number, size: number): number[] =>
  Array.from({ length: size }, (_, k) => Math.sin(1.3 * i + 0.7 * k) * (1 + k));

/** The events fed to the block: `events` of them (40), on the ports of `pattern`, 1 ms apart. */
export function makeEvents(s: BlockSetup): Event[] {
  const n = s.events ?? 40;
  const data = s.inputs.map((_, i) => i).filter((i) => !s.inputs[i]!.isTimer);
  const pattern = s.pattern ?? (data.length > 0 ? data : s.inputs.map((_, i) => i));
  const values = s.values ?? smoothValues;
  const out: Event[] = [];
  for (let i = 0; i < n; i++) {
    const port = pattern[i % pattern.length]!;
    const size = shapeSize(s.inputs[port]!.shape);
    out.push({ port, t: i / 1000, v: values(i, port, size) });
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

/** Each event in a frame of its own. */
export function feedOneByOne(h: BlockHarness, s: BlockSetup, events: Event[]): void {
  for (const e of events) h.push(frameOf(s.inputs[e.port]!.shape, [e]), e.port);
}

/** The events in frames as large as can be: each run of events on the same port in one frame. */
export function feedGrouped(h: BlockHarness, s: BlockSetup, events: Event[]): void {
  let i = 0;
  while (i < events.length) {
    let j = i;
    while (j < events.length && events[j]!.port === events[i]!.port) j++;
    const port = events[i]!.port;
    h.push(frameOf(s.inputs[port]!.shape, events.slice(i, j)), port);
    i = j;
  }
}

/** Everything a block produced: `port:NAME` outputs, `log:NAME` files, `io` what its fake I/O kept. */
export type Snapshot = Record<string, { t: number[]; v: number[][] } | unknown[]>;

export function snapshot(h: BlockHarness): Snapshot {
  const s: Snapshot = {};
  for (const [name, r] of h.out) s[`port:${name}`] = { t: [...r.t], v: r.v.map((x) => [...x]) };
  for (const [name, lines] of h.logs.files) s[`log:${name}`] = [...lines];
  const io = fakeIo.get(h);
  if (io) s.io = io.recorded() as unknown[];
  return s;
}

/** Forgets what the harness recorded: outputs, log files and fake I/O. */
export function clearAll(h: BlockHarness): void {
  h.clear();
  for (const lines of h.logs.files.values()) lines.length = 0;
  fakeIo.get(h)?.clear();
}

/** Output events, log lines and I/O records in a snapshot. */
export const eventsIn = (s: Snapshot): number =>
  Object.values(s).reduce<number>((n, x) => n + (Array.isArray(x) ? x.length : x.t.length), 0);

const place = (key: string): string => {
  const [kind, ...rest] = key.split(":");
  const name = rest.join(":");
  return kind === "port" ? `output '${name}'` : kind === "log" ? `log '${name}'` : key;
};

/** Where two snapshots first differ, in words; undefined when equal (NaN equals NaN). */
export function firstDifference(a: Snapshot, b: Snapshot): string | undefined {
  for (const key of new Set([...Object.keys(a), ...Object.keys(b)])) {
    const x = a[key];
    const y = b[key];
    if (Array.isArray(x) || Array.isArray(y)) {
      const lx = Array.isArray(x) ? x : [];
      const ly = Array.isArray(y) ? y : [];
      for (let i = 0; i < Math.max(lx.length, ly.length); i++) {
        const ex = JSON.stringify(lx[i]);
        const ey = JSON.stringify(ly[i]);
        if (ex !== ey) return `${place(key)} record ${i}: ${ex} vs ${ey}`;
      }
      continue;
    }
    const px = x ?? { t: [], v: [] };
    const py = y ?? { t: [], v: [] };
    if (px.t.length !== py.t.length) {
      return `${place(key)}: ${px.t.length} events vs ${py.t.length}`;
    }
    for (let e = 0; e < px.t.length; e++) {
      if (!Object.is(px.t[e], py.t[e])) {
        return `${place(key)} event ${e}: time ${px.t[e]} vs ${py.t[e]}`;
      }
      const vx = px.v[e]!;
      const vy = py.v[e]!;
      for (let k = 0; k < Math.max(vx.length, vy.length); k++) {
        if (!Object.is(vx[k], vy[k])) {
          return `${place(key)} event ${e} value ${k}: ${vx[k]} vs ${vy[k]}`;
        }
      }
    }
  }
  return undefined;
}

async function checkDefaults({ def, s }: Run): Promise<{ ok: boolean; detail: string }> {
  const parsed = def.params.safeParse(s.params ?? {});
  if (!parsed.success) {
    const issues = parsed.error.issues.map(
      (i: { path: PropertyKey[]; message: string }) =>
        `${i.path.map(String).join(".") || "(params)"}: ${i.message}`,
    );
    return fail(`params ${JSON.stringify(s.params ?? {})} do not validate: ${issues.join("; ")}`);
  }
  const h = await harness(def, s);
  const declared = [...outputNames(def, h.params)];
  const made = h.ports.map((p) => p.name);
  h.instance.dispose?.();
  if (JSON.stringify(declared) !== JSON.stringify(made)) {
    return fail(`outputs declared [${declared.join(", ")}] but create() made [${made.join(", ")}]`);
  }
  if ((def.live ?? []).length > 0 && typeof h.instance.setParam !== "function") {
    return fail("live params but no setParam in the instance");
  }
  return pass(`params ${JSON.stringify(s.params ?? {})}; outputs [${made.join(", ")}]`);
}

/** Sources paced by their own timer have nothing to batch. */
const sourceOnly = (s: BlockSetup): boolean => s.inputs.length === 0;

async function checkSplitting({ def, s }: Run): Promise<{ ok: boolean; detail: string }> {
  if (sourceOnly(s)) return pass("skipped: no inputs (a source paced by its own timer)");
  const events = makeEvents(s);
  const one = await harness(def, s);
  feedOneByOne(one, s, events);
  const expected = snapshot(one);
  one.instance.dispose?.();
  if (!s.silent && eventsIn(expected) === 0) {
    return fail(
      `${events.length} input events gave no output (export contract { silent: true } for a sink)`,
    );
  }
  const grouped = await harness(def, s);
  feedGrouped(grouped, s, events);
  const got = snapshot(grouped);
  grouped.instance.dispose?.();
  const diff = firstDifference(expected, got);
  if (diff) return fail(`one frame of many events ≠ one event per frame: ${diff}`);
  return pass(`${events.length} events, ${eventsIn(expected)} out, bit for bit`);
}

async function checkReset({ def, s }: Run): Promise<{ ok: boolean; detail: string }> {
  if (sourceOnly(s)) return pass("skipped: no inputs");
  const events = makeEvents(s);
  const h = await harness(def, s);
  feedOneByOne(h, s, events);
  const first = snapshot(h);
  clearAll(h);
  h.instance.reset?.();
  feedOneByOne(h, s, events);
  const again = snapshot(h);
  h.instance.dispose?.();
  const diff = firstDifference(first, again);
  if (diff) return fail(`after reset() the output differs: ${diff}`);
  return pass(`the same ${eventsIn(first)} output events after reset()`);
}

async function checkDispose({ def, s }: Run): Promise<{ ok: boolean; detail: string }> {
  const fresh = await harness(def, s, false);
  fresh.instance.dispose?.();
  fresh.instance.dispose?.();
  const started = await harness(def, s);
  if (!sourceOnly(s)) feedOneByOne(started, s, makeEvents(s).slice(0, 5));
  started.instance.stop?.();
  started.instance.dispose?.();
  started.instance.dispose?.();
  return pass("dispose() twice before and after start threw nothing");
}

// ---------------------------------------------------------------------------------------------
// Garbage params, through the loader and the runtime as a pipeline file would bring them.

/** Errors that mean a bug in the block, not a refused value. */
export function internal(e: unknown): boolean {
  return (
    e instanceof TypeError ||
    e instanceof RangeError ||
    e instanceof ReferenceError ||
    e instanceof SyntaxError ||
    (e instanceof Error && e.constructor.name === "RuntimeError") // a wasm trap
  );
}

/** An internal error and where it came from (`create`, `process`, `action go`, `timer`…). */
export interface Failure {
  stage: string;
  error: string;
}

/** A failure with the params that caused it, in words. */
export const describeFailure = (params: unknown, f: Failure): string =>
  `${JSON.stringify(params)?.slice(0, 160)} → ${f.stage}: ${f.error}`;

/** A source of any shape for the garbage pipelines: on every tick, values depending on the time. */
export const ContractSource = defineBlock({
  type: "ContractSource",
  category: "Testing",
  summary: "Test source of a given shape.",
  help: "Emits one value of shape [Rows, Cols] per tick of its timer (the block contract only).",
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
          const t = f.t[e]!;
          o.t[e] = t;
          for (let k = 0; k < size; k++) o.v[e * size + k] = Math.sin(97 * t + k) * (k + 1);
        }
        out.emit(o);
      },
    };
  },
});

/**
 * The definition with every internal error it raises recorded in `list` (once each): any error
 * but a BlockConfigError from `create`, any but a LegacyParamsError or a BlockConfigError from the
 * positional form, and a TypeError, RangeError, ReferenceError, SyntaxError or wasm trap from the
 * instance's methods, its actions, its timers and one-shots.
 */
export function guarded(def: AnyBlockDefinition, list: Failure[]): AnyBlockDefinition {
  const record = (f: Failure): void => {
    if (!list.some((x) => x.stage === f.stage && x.error === f.error)) list.push(f);
  };
  const error = (e: unknown): string => `${(e as Error).name}: ${errorMessage(e)}`;
  const guard = <T>(stage: string, fn: () => T): T => {
    try {
      return fn();
    } catch (e) {
      if (internal(e)) record({ stage, error: error(e) });
      throw e;
    }
  };
  const wrapInstance = (inst: BlockInstance): BlockInstance => {
    const w: BlockInstance = {};
    const methods = ["process", "flush", "start", "stop", "reset", "dispose", "setParam"] as const;
    for (const m of methods) {
      const f = inst[m] as ((...a: unknown[]) => unknown) | undefined;
      if (f) {
        (w as Record<string, unknown>)[m] = (...a: unknown[]) => guard(m, () => f.apply(inst, a));
      }
    }
    if (inst.actions) {
      w.actions = Object.fromEntries(
        Object.entries(inst.actions).map(([name, a]) => [
          name,
          { ...a, run: (arg?: unknown) => guard(`action ${name}`, () => a.run(arg)) },
        ]),
      );
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
                record({
                  stage: `legacyParams(${JSON.stringify(args).slice(0, 80)})`,
                  error: error(e),
                });
              }
              throw e;
            }
          },
        }
      : {}),
    async create(ctx: BlockContext, params: unknown) {
      const g = Object.create(ctx) as BlockContext & Record<string, unknown>;
      g.every = (hz: number, tick: TickCallback, options?: { catchUp?: CatchUp }) =>
        ctx.every(hz, (t, n) => guard("timer", () => tick(t, n)), options);
      g.at = (t: number, fn: (t: number) => void, latest?: number) =>
        ctx.at(t, (x) => guard("one-shot", () => fn(x)), latest);
      try {
        return wrapInstance(await def.create(g, params));
      } catch (e) {
        if (!(e instanceof BlockConfigError)) record({ stage: "create", error: error(e) });
        throw e;
      }
    },
  };
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

/**
 * Params to try: each param (but the `kept` ones) set to each garbage value, then `runs` random
 * mixtures, then non-objects.
 */
export function garbageParams(
  def: AnyBlockDefinition,
  base: unknown,
  runs = 60,
  kept: readonly string[] = [],
): unknown[] {
  const keys = (objectKeys(def.params) ?? []).filter((k) => !kept.includes(k));
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
  if (kept.length === 0) out.push(null, 1, "x", [], ["1", "2"]);
  return out;
}

/** Files for a setup that names none: every read fails as a missing file would. */
export const noFiles: Resources = {
  resolve: (p) => p,
  readText: (p) => Promise.reject(new Error(`ENOENT: no such file '${p}'`)),
  writeText: () => Promise.resolve(),
};

/** The timer type of the garbage pipelines: ScheduledTimer, or the catalog's first timer. */
const timerOf = (base: Catalog): string =>
  base.has("ScheduledTimer")
    ? "ScheduledTimer"
    : ([...base.values()].find((d) => d.timer === true)?.type ?? "ScheduledTimer");

/** The pipeline: sources of the setup's input shapes, then the block with these params. */
export function garbagePipeline(
  def: AnyBlockDefinition,
  s: BlockSetup,
  params: unknown,
  timer = "ScheduledTimer",
): string {
  const doc: Record<string, unknown> = { Clock: { Type: timer, DesiredRate: 100 } };
  const inputs = s.inputs.map((inp, i) => {
    const name = `Src${i}`;
    doc[name] = inp.isTimer
      ? { Type: timer, DesiredRate: inp.rate ?? 100 }
      : {
          Type: ContractSource.type,
          DesiredRate: inp.rate ?? 100,
          Inputs: ["Clock"],
          Params: { Rows: inp.shape.rows, Cols: inp.shape.cols },
        };
    return name;
  });
  doc.Block = {
    Type: def.type,
    ...(def.timer || def.requiresRate ? { DesiredRate: 100 } : {}),
    ...(inputs.length > 0 ? { Inputs: inputs } : {}),
    Params: params,
  };
  return stringify(doc);
}

const ACTION_ARGS: unknown[] = [
  undefined,
  -1,
  0,
  1,
  1e9,
  NaN,
  "x",
  "",
  [],
  [1e9],
  [0, 1],
  {},
  null,
];

/**
 * Loads, instantiates and briefly runs the pipeline of the block with these params in `base`'s
 * blocks; invokes each of its actions and sets each live param (but the kept ones) to garbage,
 * and runs again. Returns the internal errors raised inside the block.
 */
export async function tryGarbage(
  def: AnyBlockDefinition,
  s: BlockSetup,
  params: unknown,
  base: Catalog,
): Promise<Failure[]> {
  const failures: Failure[] = [];
  const catalog = createCatalog([
    ...[...base].filter(([n, d]) => n === d.type && d.type !== def.type).map(([, d]) => d),
    guarded(def, failures),
    ContractSource,
  ]);
  const yaml = garbagePipeline(def, s, params, timerOf(base));
  let loaded;
  try {
    loaded = loadPipeline(yaml, "garbage.yaml", catalog);
  } catch (e) {
    return [{ stage: "loadPipeline threw", error: `${(e as Error).name}: ${errorMessage(e)}` }];
  }
  if (!loaded.spec) return failures;
  const clock = new VirtualClock(0);
  let created;
  try {
    created = await Runtime.create({
      spec: loaded.spec,
      catalog,
      clock,
      virtual: true,
      resources: s.resources ?? noFiles,
      ignorePlacement: true,
    });
  } catch (e) {
    return [{ stage: "Runtime.create threw", error: `${(e as Error).name}: ${errorMessage(e)}` }];
  }
  const rt = created.runtime;
  if (!rt) {
    for (const d of created.diagnostics) {
      if (d.message.trim() === "") failures.push({ stage: "diagnostic", error: "empty message" });
    }
    return failures;
  }
  try {
    rt.start();
    runVirtual(rt, clock, 0.05, 2000);
    const node = rt.node("Block")!;
    for (const name of Object.keys(node.instance.actions ?? {})) {
      for (const arg of ACTION_ARGS) {
        try {
          rt.invoke("Block", name, arg);
        } catch {
          // refusals are fine; internal errors were recorded by the guard
        }
      }
    }
    for (const p of (def.live ?? []).filter((k) => !(s.fuzzKeep?.keys ?? []).includes(k))) {
      for (const v of [0, -1, 1e9, [], [1e9], "x", true]) {
        try {
          rt.setParam("Block", p, v);
        } catch {
          // idem
        }
      }
    }
    runVirtual(rt, clock, 0.1, 2000);
  } finally {
    rt.dispose();
  }
  return failures;
}

async function checkGarbage({
  def,
  s,
  base,
  options,
}: Run): Promise<{ ok: boolean; detail: string }> {
  const found: string[] = [];
  const tries = garbageParams(def, s.params, options.garbageRuns, s.fuzzKeep?.keys);
  for (const p of tries) {
    for (const f of await tryGarbage(def, s, p, base)) {
      const text = describeFailure(p, f);
      if (!found.includes(text)) found.push(text);
    }
  }
  if (found.length > 0) {
    return fail(
      `${found.length} internal error${found.length === 1 ? "" : "s"} (refuse such values in the zod schema, with a BlockConfigError, or in legacyParams with a LegacyParamsError): ${found.slice(0, 3).join("; ")}`,
    );
  }
  return pass(`${tries.length} garbage params refused or handled`);
}
