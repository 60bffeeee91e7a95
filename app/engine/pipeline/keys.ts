/**
 * Loader stage 3, block keys: everything a block says besides its Params — Type (looked up in the
 * catalog, through MOSAIC's old names), DesiredRate, Inputs, Path, Worker, BatchingMs, Queue and
 * Layout — and the pipeline's settings (`Pipeline: { BatchingMs }`). Each bad key is one
 * positioned error; the stage never throws.
 */
import { isMap, isScalar, isSeq, type Node as YamlNode, type YAMLMap } from "yaml";
import type { AnyBlockDefinition } from "../block";
import type { Catalog } from "../catalog";
import { closest } from "../suggest";
import { Collector, describeNode, isNullish, scalarString } from "./collector";
import {
  EMPTY_PATH,
  emptyPathWarning,
  mosaicType,
  unknownTypeNote,
  type MosaicTypeRule,
  type MosaicView,
} from "./mosaic";
import { readPipelineLayout } from "./pipeline-layout";
import {
  BLOCK_KEYS,
  BLOCK_MODULE_RE,
  QUEUE_POLICIES,
  SETTINGS_KEY,
  SETTINGS_KEYS,
  WORKER_RE,
  type BlockModuleRef,
  type InputRef,
  type PipelineSettings,
  type QueuePolicy,
  type QueueSpec,
  type SourcePos,
} from "./spec";

/** What stage 3 read from one block. */
export interface BlockKeys {
  /** Undefined when Type is missing, bad or unknown (reported). */
  def: AnyBlockDefinition | undefined;
  /** The canonical type name ("" when unknown). */
  type: string;
  /** The type name as written (undefined when missing or not a string). */
  written: string | undefined;
  /** Where the Type value is. */
  typePos: SourcePos;
  /** The old name's rule, when `written` is one of MOSAIC_TYPES. */
  rule: MosaicTypeRule | undefined;
  /** True when the block loads under another name (a block alias or an old name). */
  renamed: boolean;
  desiredRate: number | undefined;
  inputs: InputRef[];
  inputsPos: SourcePos;
  path: string | undefined;
  worker: string;
  batchingMs: number | undefined;
  queue: QueueSpec;
  layout: { x: number; y: number } | undefined;
  /** The Params node (undefined: no Params key). */
  paramsNode: unknown;
  paramsPos: SourcePos;
}

/** One key of a block's map: its value node and where the key is. */
interface KeyEntry {
  node: unknown;
  keyPos: SourcePos;
}

/** Stage 3 for one block (`at`: where its name is). */
export function readBlockKeys(
  c: Collector,
  name: string,
  at: SourcePos,
  map: YAMLMap,
  catalog: Catalog,
  view: MosaicView,
): BlockKeys {
  const get = (k: string): KeyEntry | undefined => keyEntry(c, map, k);
  reportUnknownKeys(c, name, map, view);

  const t = readType(c, name, at, get("Type")?.node, get("Type") !== undefined, catalog);
  const { def, rule } = t;
  const desiredRate = readDesiredRate(c, name, at, get("DesiredRate")?.node, def, t.type, rule);

  const inputsEntry = get("Inputs");
  const inputsPos = inputsEntry ? c.pos(inputsEntry.node as YamlNode) : at;
  const inputs = inputsEntry ? readInputs(c, name, inputsEntry.node, inputsPos) : [];

  const { path, worker, batchingMs, queue, layout } = readRunKeys(c, name, get, view);

  const paramsEntry = get("Params");
  return {
    def,
    type: t.type,
    written: t.written,
    typePos: t.pos,
    rule,
    renamed: def !== undefined && t.written !== def.type,
    desiredRate,
    inputs,
    inputsPos,
    path,
    worker,
    batchingMs,
    queue,
    layout,
    paramsNode: paramsEntry?.node,
    paramsPos: paramsEntry ? c.pos(paramsEntry.node as YamlNode) : at,
  };
}

/** The key `k` of a block's map, undefined when the block has none. */
function keyEntry(c: Collector, map: YAMLMap, k: string): KeyEntry | undefined {
  const p = map.items.find((it) => scalarString(it.key) === k);
  return p ? { node: p.value, keyPos: c.pos(p.key as YamlNode) } : undefined;
}

/** One error per key that is not a block key (stage 2's ignored keys aside), in file order. */
function reportUnknownKeys(c: Collector, name: string, map: YAMLMap, view: MosaicView): void {
  const ignored = new Set(view.ignored.map((p) => p.key));
  for (const it of map.items) {
    if (ignored.has(it.key)) continue;
    const k = scalarString(it.key) ?? "";
    if (!(BLOCK_KEYS as readonly string[]).includes(k)) {
      const suggestion = closest(k, BLOCK_KEYS);
      c.error("unknown-key", c.pos(it.key as YamlNode), `block '${name}': unknown key '${k}'`, {
        block: name,
        expected: `one of ${BLOCK_KEYS.join(", ")}`,
        ...(suggestion !== undefined ? { suggestion } : {}),
      });
    }
  }
}

/** Path, Worker, BatchingMs, Queue and Layout, in that order (so are their errors). */
function readRunKeys(
  c: Collector,
  name: string,
  get: (k: string) => KeyEntry | undefined,
  view: MosaicView,
): Pick<BlockKeys, "path" | "worker" | "batchingMs" | "queue" | "layout"> {
  const pathEntry = get("Path");
  const path = pathEntry ? readBlockPath(c, name, pathEntry.node, view) : undefined;

  let worker = "main";
  const workerEntry = get("Worker");
  if (workerEntry) worker = readWorker(c, name, workerEntry.node) ?? worker;

  const batchingEntry = get("BatchingMs");
  const batchingMs = batchingEntry ? readBatchingMs(c, batchingEntry.node, name) : undefined;

  const queueEntry = get("Queue");
  const queue = queueEntry
    ? readQueue(c, name, queueEntry.node)
    : { policy: "drop-oldest" as QueuePolicy, capacity: undefined };

  const layoutEntry = get("Layout");
  const layout = layoutEntry ? readLayout(c, name, layoutEntry.node) : undefined;
  return { path, worker, batchingMs, queue, layout };
}

/** A present Path: MOSAIC's empty Path (stage 2 found it) is a warning and EMPTY_PATH. */
function readBlockPath(
  c: Collector,
  name: string,
  node: unknown,
  view: MosaicView,
): string | undefined {
  if (node === view.emptyPath && view.emptyPath) {
    emptyPathWarning(c, name, view.emptyPath);
    return EMPTY_PATH;
  }
  return readPath(c, name, node);
}

interface TypeResult {
  def: AnyBlockDefinition | undefined;
  type: string;
  written: string | undefined;
  rule: MosaicTypeRule | undefined;
  pos: SourcePos;
}

/** Type: the catalog's name or alias, or one of the original's old names (stage 2's table). */
export function readType(
  c: Collector,
  name: string,
  at: SourcePos,
  node: unknown,
  present: boolean,
  catalog: Catalog,
): TypeResult {
  if (!present) {
    c.error("missing-type", at, `block '${name}' has no Type`, {
      block: name,
      expected: "`Type: <block type>`, e.g. `Type: Filter`",
    });
    return { def: undefined, type: "", written: undefined, rule: undefined, pos: at };
  }
  const pos = c.pos(node as YamlNode);
  const t = scalarString(node);
  if (t === undefined || t === "") {
    c.error("bad-type", pos, `block '${name}': Type is ${describeNode(node)}`, {
      block: name,
      expected: "the name of a block type",
    });
    return { def: undefined, type: "", written: undefined, rule: undefined, pos };
  }
  const { lookup, rule } = mosaicType(t, catalog);
  const def = catalog.get(lookup);
  if (def) return { def, type: def.type, written: t, rule, pos };
  const note = unknownTypeNote(t, catalog);
  const typeNames = [...catalog].filter(([n, d]) => n === d.type).map(([n]) => n);
  const suggestion = note === undefined ? closest(t, typeNames) : undefined;
  c.error(
    "unknown-type",
    pos,
    `block '${name}': unknown block type '${t}'${note !== undefined ? `: ${note}` : ""}`,
    {
      block: name,
      ...(suggestion !== undefined
        ? { suggestion }
        : note === undefined
          ? { expected: "a type listed in docs/blocks.md" }
          : {}),
    },
  );
  return { def: undefined, type: t, written: t, rule, pos };
}

function readDesiredRate(
  c: Collector,
  name: string,
  at: SourcePos,
  node: unknown,
  def: AnyBlockDefinition | undefined,
  type: string,
  rule: MosaicTypeRule | undefined,
): number | undefined {
  if (node !== undefined) {
    const v = isScalar(node) ? node.value : undefined;
    if (typeof v === "number" && Number.isFinite(v) && v > 0) return v;
    c.error(
      "bad-rate",
      c.pos(node as YamlNode),
      `block '${name}': DesiredRate has ${describeNode(node)}`,
      {
        block: name,
        expected: "a positive number of Hz",
      },
    );
    return undefined;
  }
  // An old TimerDecimator's rate comes from its input's (computed after all blocks are read).
  if (def && (def.timer || def.requiresRate) && !rule?.rateDivisor) {
    c.error("missing-rate", at, `block '${name}' (${type}) needs a DesiredRate`, {
      block: name,
      expected: "`DesiredRate: <Hz>`",
    });
  }
  return undefined;
}

function readInputs(c: Collector, name: string, node: unknown, inputsPos: SourcePos): InputRef[] {
  const inputs: InputRef[] = [];
  if (isNullish(node)) return inputs;
  const items: unknown[] = isSeq(node) ? node.items : isScalar(node) ? [node] : [];
  if (!isSeq(node) && !isScalar(node)) {
    c.error("bad-inputs", inputsPos, `block '${name}': Inputs is ${describeNode(node)}`, {
      block: name,
      expected: "a list of block names, e.g. `Inputs: [Timer]`",
    });
  }
  for (const item of items) {
    const s = scalarString(item);
    const ipos = c.pos(item as YamlNode);
    if (s === undefined || s === "" || s === "-") {
      c.error("bad-input", ipos, `block '${name}': an input is ${describeNode(item)}`, {
        block: name,
        expected: "a block name, or -Name to declare it without subscribing",
      });
      continue;
    }
    const subscribed = !s.startsWith("-");
    const ref = subscribed ? s : s.slice(1);
    const dot = ref.indexOf(".");
    inputs.push({
      source: ref,
      block: dot < 0 ? ref : ref.slice(0, dot),
      port: dot < 0 ? "" : ref.slice(dot + 1),
      subscribed,
      pos: ipos,
    });
  }
  return inputs;
}

function readPath(c: Collector, name: string, node: unknown): string | undefined {
  const s = isScalar(node) && typeof node.value === "string" ? node.value : undefined;
  if (s !== undefined && s.trim() !== "") return s;
  c.error("bad-path", c.pos(node as YamlNode), `block '${name}': Path is ${describeNode(node)}`, {
    block: name,
    expected: "a folder (the log is <Path>/<block>.txt) or a file name",
  });
  return undefined;
}

function readWorker(c: Collector, name: string, node: unknown): string | undefined {
  const s = scalarString(node);
  if (s !== undefined && WORKER_RE.test(s)) return s;
  c.error(
    "bad-worker",
    c.pos(node as YamlNode),
    `block '${name}': Worker is ${describeNode(node)}`,
    {
      block: name,
      expected: "a worker name (a plain word); blocks with the same name share a thread",
    },
  );
  return undefined;
}

function readQueue(c: Collector, name: string, qn: unknown): QueueSpec {
  const queue: QueueSpec = { policy: "drop-oldest", capacity: undefined };
  if (!isMap(qn)) {
    c.error("bad-queue", c.pos(qn as YamlNode), `block '${name}': Queue is ${describeNode(qn)}`, {
      block: name,
      expected: "`{ Policy: drop-oldest | drop-newest | latest, Capacity: <events> }`",
    });
    return queue;
  }
  for (const it of qn.items) {
    const k = scalarString(it.key) ?? "";
    const vpos = c.pos((it.value as YamlNode | null) ?? (it.key as YamlNode));
    if (k === "Policy") {
      const v = scalarString(it.value) ?? "";
      if ((QUEUE_POLICIES as readonly string[]).includes(v)) queue.policy = v as QueuePolicy;
      else {
        const suggestion = closest(v, QUEUE_POLICIES);
        c.error("bad-queue", vpos, `block '${name}': Queue.Policy '${v}' is not a policy`, {
          block: name,
          param: "Queue.Policy",
          expected: `one of ${QUEUE_POLICIES.join(", ")}`,
          ...(suggestion !== undefined ? { suggestion } : {}),
        });
      }
    } else if (k === "Capacity") {
      const v = isScalar(it.value) ? it.value.value : undefined;
      if (typeof v === "number" && Number.isInteger(v) && v >= 1 && v <= 1 << 24)
        queue.capacity = v;
      else
        c.error(
          "bad-queue",
          vpos,
          `block '${name}': Queue.Capacity has ${describeNode(it.value)}`,
          {
            block: name,
            param: "Queue.Capacity",
            expected: "a whole number of events between 1 and 16777216",
          },
        );
    } else {
      const suggestion = closest(k, ["Policy", "Capacity"]);
      c.error("bad-queue", c.pos(it.key as YamlNode), `block '${name}': unknown Queue key '${k}'`, {
        block: name,
        expected: "Policy or Capacity",
        ...(suggestion !== undefined ? { suggestion } : {}),
      });
    }
  }
  return queue;
}

function readLayout(c: Collector, name: string, ln: unknown): { x: number; y: number } | undefined {
  const xs = isMap(ln) ? ln.get("X") : undefined;
  const ys = isMap(ln) ? ln.get("Y") : undefined;
  if (
    typeof xs === "number" &&
    typeof ys === "number" &&
    Number.isFinite(xs) &&
    Number.isFinite(ys)
  )
    return { x: xs, y: ys };
  c.error("bad-layout", c.pos(ln as YamlNode), `block '${name}': Layout is ${describeNode(ln)}`, {
    block: name,
    expected: "`{ X: <number>, Y: <number> }`",
  });
  return undefined;
}

/** `Pipeline: { … }` without a `Type` is the settings entry (a block may still be named Pipeline). */
export function isSettingsEntry(name: string | undefined, value: unknown): boolean {
  return (
    name === SETTINGS_KEY &&
    isMap(value) &&
    !value.items.some((it) => scalarString(it.key) === "Type")
  );
}

/** The settings entry `Pipeline: { BatchingMs, Layout, Blocks }`. */
export function readSettings(c: Collector, node: YAMLMap, settings: PipelineSettings): void {
  for (const it of node.items) {
    const k = scalarString(it.key) ?? "";
    if (k === "BatchingMs") {
      settings.batchingMs = readBatchingMs(c, it.value, undefined);
      continue;
    }
    if (k === "Blocks") {
      settings.blocks = readBlockModules(c, it.value);
      continue;
    }
    if (k === "Layout") {
      const layout = readPipelineLayout(c, it.value);
      if (layout) settings.layout = layout;
      continue;
    }
    const suggestion = closest(k, SETTINGS_KEYS);
    c.error("unknown-key", c.pos(it.key as YamlNode), `${SETTINGS_KEY}: unknown setting '${k}'`, {
      expected: `one of ${SETTINGS_KEYS.join(", ")} (a block named ${SETTINGS_KEY} needs a Type)`,
      ...(suggestion !== undefined ? { suggestion } : {}),
    });
  }
}

/** `Blocks`: a list of module files (`.ts`, `.mts`, `.js`, `.mjs`), relative to the pipeline. */
export function readBlockModules(c: Collector, node: unknown): BlockModuleRef[] {
  const expected =
    "a list of module files relative to this file, e.g. `Blocks: [blocks/smoother.ts]` (docs/writing-blocks.md)";
  if (!isSeq(node)) {
    c.error(
      "bad-blocks",
      c.pos(node as YamlNode),
      `${SETTINGS_KEY}: Blocks has ${describeNode(node)}`,
      {
        expected,
      },
    );
    return [];
  }
  const refs: BlockModuleRef[] = [];
  for (const item of node.items) {
    const path = scalarString(item);
    const at = c.pos(item as YamlNode);
    if (path === undefined || path.trim() === "") {
      c.error("bad-blocks", at, `${SETTINGS_KEY}: a Blocks entry has ${describeNode(item)}`, {
        expected,
      });
    } else if (!BLOCK_MODULE_RE.test(path)) {
      c.error("bad-blocks", at, `${SETTINGS_KEY}: Blocks entry '${path}' is not a module file`, {
        expected: "a file ending in .ts, .mts, .js or .mjs",
      });
    } else refs.push({ path, pos: at });
  }
  return refs;
}

/** `BatchingMs`: a number of milliseconds, 0 (a wake-up per tick) to 1000. */
export function readBatchingMs(
  c: Collector,
  node: unknown,
  block: string | undefined,
): number | undefined {
  const v = isScalar(node) ? node.value : undefined;
  if (typeof v === "number" && Number.isFinite(v) && v >= 0 && v <= 1000) return v;
  c.error(
    "bad-batching",
    c.pos(node as YamlNode),
    `${block !== undefined ? `block '${block}'` : SETTINGS_KEY}: BatchingMs has ${describeNode(node)}`,
    {
      ...(block !== undefined ? { block } : {}),
      expected: "milliseconds from 0 (wake up for every tick) to 1000, e.g. `BatchingMs: 2`",
    },
  );
  return undefined;
}
