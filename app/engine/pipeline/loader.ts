/**
 * Pipeline loader: YAML text → validated PipelineSpec, or diagnostics that name file, line,
 * column, block and parameter (DESIGN.md §2). Stages: YAML Document API → block keys → params
 * (zod, or MOSAIC's positional form converted first) → wiring check. Never throws on bad input.
 */
import {
  isMap,
  isPair,
  isScalar,
  isSeq,
  LineCounter,
  parseDocument,
  type Document,
  type Node as YamlNode,
  type YAMLMap,
} from "yaml";
import type { z } from "zod";
import { outputNames, type AnyBlockDefinition } from "../block";
import type { Catalog } from "../catalog";
import { errorMessage, type Diagnostic } from "../diagnostics";
import { closest } from "../suggest";
import { LegacyParamsError } from "./legacy";

export type QueuePolicy = "drop-oldest" | "drop-newest" | "latest";
export const QUEUE_POLICIES: readonly QueuePolicy[] = ["drop-oldest", "drop-newest", "latest"];

export interface SourcePos {
  line: number;
  col: number;
}

export interface InputRef {
  /** As written, without the leading '-'. */
  source: string;
  block: string;
  /** Output port of the source block ("" = its default port until resolved). */
  port: string;
  subscribed: boolean;
  pos: SourcePos;
}

export interface QueueSpec {
  policy: QueuePolicy;
  /** Capacity in events; undefined = default (one second of data, at least 64 events). */
  capacity: number | undefined;
}

export interface BlockSpec {
  name: string;
  type: string;
  def: AnyBlockDefinition;
  /** Validated params (zod output: defaults applied). */
  params: unknown;
  desiredRate: number | undefined;
  inputs: InputRef[];
  /** Log this block's output (folder, or a file when it has an extension). */
  path: string | undefined;
  worker: string;
  /** `BatchingMs`: this block's timers' batching interval, ms (overrides the pipeline's). */
  batchingMs: number | undefined;
  queue: QueueSpec;
  layout: { x: number; y: number } | undefined;
  /** Output port names (first is the default). */
  outputs: readonly string[];
  legacy: boolean;
  pos: SourcePos;
  paramsPos: SourcePos;
  inputsPos: SourcePos;
  /** Position of each param key, for errors found after validation. */
  paramPos: Record<string, SourcePos>;
}

/** Settings of the whole pipeline: the reserved top-level entry `Pipeline: { … }`. */
export interface PipelineSettings {
  /** `BatchingMs`: how long a timer's ticks may wait to go out together, ms (DESIGN.md §3). */
  batchingMs: number | undefined;
}

export interface PipelineSpec {
  file: string;
  blocks: BlockSpec[];
  byName: Map<string, BlockSpec>;
  settings: PipelineSettings;
}

export interface LoadResult {
  spec: PipelineSpec | undefined;
  diagnostics: Diagnostic[];
  ok: boolean;
  /** The parsed document (for editors that keep comments through an edit). */
  doc: Document | undefined;
}

const BLOCK_KEYS = [
  "Type",
  "DesiredRate",
  "Inputs",
  "Params",
  "Path",
  "Layout",
  "Worker",
  "Queue",
  "BatchingMs",
] as const;
/** The reserved top-level name for pipeline settings (a mapping without `Type`). */
export const SETTINGS_KEY = "Pipeline";
const SETTINGS_KEYS = ["BatchingMs"] as const;
export const BLOCK_NAME_RE = /^[A-Za-z_][A-Za-z0-9_-]*$/;
const WORKER_RE = /^[A-Za-z_][A-Za-z0-9_-]*$/;

class Collector {
  readonly list: Diagnostic[] = [];
  constructor(
    readonly file: string,
    readonly lc: LineCounter,
  ) {}

  pos(node: YamlNode | null | undefined): SourcePos {
    const r = node?.range;
    if (!r) return { line: 0, col: 0 };
    const p = this.lc.linePos(r[0]);
    return { line: p.line, col: p.col };
  }

  add(
    severity: Diagnostic["severity"],
    code: string,
    at: SourcePos,
    message: string,
    extra: Partial<Diagnostic> = {},
  ): void {
    this.list.push({
      severity,
      code,
      message,
      file: this.file,
      line: at.line,
      col: at.col,
      ...extra,
    });
  }

  error(code: string, at: SourcePos, message: string, extra: Partial<Diagnostic> = {}): void {
    this.add("error", code, at, message, extra);
  }

  get errors(): number {
    return this.list.filter((d) => d.severity === "error").length;
  }
}

function scalarString(node: unknown): string | undefined {
  if (isScalar(node)) {
    const v = node.value;
    if (typeof v === "string") return v;
    if (typeof v === "number" || typeof v === "boolean") return String(v);
    if (v === null) return "";
  }
  return undefined;
}

function describeValue(v: unknown): string {
  if (v === null || v === undefined) return "nothing";
  if (Array.isArray(v)) return "a list";
  if (typeof v === "object") return "a mapping";
  if (typeof v === "string")
    return `the string ${JSON.stringify(v.length > 40 ? v.slice(0, 40) + "…" : v)}`;
  return `${typeof v} ${String(v)}`;
}

function describeNode(node: unknown): string {
  if (isMap(node)) return "a mapping";
  if (isSeq(node)) return "a list";
  if (isScalar(node)) return describeValue(node.value);
  return "nothing";
}

/** The object schema behind a params schema (unwrapping pipes and defaults), if any. */
export function objectKeys(schema: z.ZodType): string[] | undefined {
  // eslint-disable-next-line @typescript-eslint/no-explicit-any
  let s: any = schema;
  for (let i = 0; i < 8 && s; i++) {
    if (s.shape && typeof s.shape === "object") return Object.keys(s.shape as object);
    const d = s._zod?.def;
    if (!d) return undefined;
    s = d.in ?? d.innerType ?? d.schema;
  }
  return undefined;
}

/** JSON, but with infinities written as YAML's `.inf` (JSON.stringify would print null). */
function paramsText(v: unknown): string {
  return JSON.stringify(v, (_k, x: unknown) =>
    x === Infinity ? ".inf" : x === -Infinity ? "-.inf" : x,
  ).replace(/"(-?\.inf)"/g, "$1");
}

function pathText(path: readonly PropertyKey[]): string {
  let s = "";
  for (const p of path) {
    if (typeof p === "number") s += `[${p}]`;
    else s += s === "" ? String(p) : `.${String(p)}`;
  }
  return s;
}

function nodeAtPath(root: unknown, path: readonly PropertyKey[]): YamlNode | undefined {
  let node: unknown = root;
  let last: YamlNode | undefined =
    isMap(root) || isSeq(root) || isScalar(root) ? (root as YamlNode) : undefined;
  for (const seg of path) {
    if (isMap(node)) {
      const pair = node.items.find((p) => isPair(p) && scalarString(p.key) === String(seg));
      if (!pair) return last;
      node = pair.value ?? pair.key;
    } else if (isSeq(node) && typeof seg === "number") {
      node = node.items[seg];
    } else {
      return last;
    }
    if (isMap(node) || isSeq(node) || isScalar(node)) last = node as YamlNode;
  }
  return last;
}

function paramKeyPositions(c: Collector, paramsNode: unknown): Record<string, SourcePos> {
  const out: Record<string, SourcePos> = {};
  if (isMap(paramsNode)) {
    for (const p of paramsNode.items) {
      const k = scalarString(p.key);
      if (k !== undefined) out[k] = c.pos(p.key as YamlNode);
    }
  }
  return out;
}

function legacyArgs(seq: unknown): string[] {
  const args: string[] = [];
  if (!isSeq(seq)) return args;
  for (const item of seq.items) {
    const s = scalarString(item);
    if (s !== undefined) {
      args.push(s);
    } else if (isMap(item) && item.items.length === 1) {
      // `[ rest: 0;0;1 ]` inside a flow list is a one-pair mapping; MOSAIC read it as "rest:0;0;1".
      const p = item.items[0]!;
      args.push(`${scalarString(p.key) ?? ""}:${scalarString(p.value) ?? ""}`);
    } else if (isSeq(item)) {
      args.push(item.items.map((x) => scalarString(x) ?? "").join(";"));
    } else {
      args.push("");
    }
  }
  return args;
}

/** Formats one zod issue as a sentence, with what was expected and a suggestion for typos. */
function explainIssue(
  issue: z.core.$ZodIssue,
  knownKeys: string[] | undefined,
): { message: string; expected?: string; suggestion?: string } {
  const input = (issue as { input?: unknown }).input;
  switch (issue.code) {
    case "invalid_type":
      if (input === undefined) return { message: "is required", expected: issue.expected };
      return { message: `has ${describeValue(input)}`, expected: issue.expected };
    case "invalid_value": {
      const values = issue.values.map((v) => String(v));
      const suggestion = typeof input === "string" ? closest(input, values) : undefined;
      return {
        message: `has ${describeValue(input)}`,
        expected: `one of ${values.join(", ")}`,
        ...(suggestion !== undefined ? { suggestion } : {}),
      };
    }
    case "unrecognized_keys": {
      const key = issue.keys[0] ?? "";
      const suggestion = knownKeys ? closest(key, knownKeys) : undefined;
      return {
        message: `unknown parameter '${key}'`,
        ...(knownKeys ? { expected: `one of ${knownKeys.join(", ") || "(no parameters)"}` } : {}),
        ...(suggestion !== undefined ? { suggestion } : {}),
      };
    }
    case "too_small": {
      const what =
        issue.origin === "array" ? "items" : issue.origin === "string" ? "characters" : "";
      const op = issue.inclusive === false ? "more than" : "at least";
      return {
        message: `is too small${input !== undefined ? ` (${describeValue(input)})` : ""}`,
        expected: `${op} ${String(issue.minimum)}${what ? " " + what : ""}`,
      };
    }
    case "too_big": {
      const what =
        issue.origin === "array" ? "items" : issue.origin === "string" ? "characters" : "";
      const op = issue.inclusive === false ? "less than" : "at most";
      return {
        message: `is too big${input !== undefined ? ` (${describeValue(input)})` : ""}`,
        expected: `${op} ${String(issue.maximum)}${what ? " " + what : ""}`,
      };
    }
    case "not_multiple_of":
      return {
        message: `has ${describeValue(input)}`,
        expected: `a multiple of ${String(issue.divisor)}`,
      };
    case "invalid_union":
      return {
        message: `has ${describeValue(input)}`,
        expected: "one of the allowed forms (see the block's docs)",
      };
    default:
      return { message: issue.message };
  }
}

export function loadPipeline(source: string, file: string, catalog: Catalog): LoadResult {
  const lc = new LineCounter();
  const c = new Collector(file, lc);
  let doc: Document;
  try {
    doc = parseDocument(source, { lineCounter: lc, uniqueKeys: true, prettyErrors: false });
  } catch (e) {
    c.error("yaml-syntax", { line: 0, col: 0 }, `cannot parse YAML: ${errorMessage(e)}`);
    return { spec: undefined, diagnostics: c.list, ok: false, doc: undefined };
  }
  if (doc.errors.length > 0) {
    // The first syntax error is the real one; later ones are usually its echoes.
    const e = doc.errors[0]!;
    let p: SourcePos = lc.linePos(e.pos[0]);
    const first = e.message.split("\n")[0] ?? e.message;
    let msg = `YAML syntax error: ${first}`;
    if (e.code === "DUPLICATE_KEY") {
      msg =
        "duplicate key: a block (or a key inside one) is defined twice; the second definition is here";
    } else if (e.code === "BLOCK_AS_IMPLICIT_KEY" || e.code === "MULTILINE_IMPLICIT_KEY") {
      // The parser notices this on the line above the culprit: point at the over-indented line.
      const lines = source.split(/\r?\n/);
      const indent = (l: string) => l.length - l.trimStart().length;
      const base = indent(lines[p.line - 1] ?? "");
      for (let i = p.line; i < lines.length; i++) {
        const l = lines[i]!;
        if (l.trim() === "" || l.trimStart().startsWith("#")) continue;
        if (indent(l) > base) p = { line: i + 1, col: indent(l) + 1 };
        break;
      }
      msg =
        "bad indentation: this line is indented further than the keys above it (the keys of one block must start in the same column)";
    } else if (e.code === "BAD_INDENT") {
      msg = `bad indentation: ${first}`;
    }
    c.error(
      e.code === "DUPLICATE_KEY" ? "duplicate-key" : "yaml-syntax",
      { line: p.line, col: p.col },
      msg,
    );
    return { spec: undefined, diagnostics: c.list, ok: false, doc };
  }
  const root = doc.contents;
  if (root === null || (isScalar(root) && (root.value === null || root.value === ""))) {
    c.error("empty", { line: 1, col: 1 }, "the pipeline is empty", {
      expected:
        "a mapping from block names to blocks, e.g. `Timer: { Type: ScheduledTimer, DesiredRate: 200 }`",
    });
    return { spec: undefined, diagnostics: c.list, ok: false, doc };
  }
  if (!isMap(root)) {
    c.error("not-a-mapping", c.pos(root), `the top level is ${describeNode(root)}`, {
      expected: "a mapping from block names to blocks",
    });
    return { spec: undefined, diagnostics: c.list, ok: false, doc };
  }

  const blocks: BlockSpec[] = [];
  const byName = new Map<string, BlockSpec>();
  const typeNames = [...catalog].filter(([n, d]) => n === d.type).map(([n]) => n);
  const settings: PipelineSettings = { batchingMs: undefined };

  for (const pair of (root as YAMLMap).items) {
    const keyNode = pair.key as YamlNode | null;
    const at = c.pos(keyNode);
    const name = scalarString(keyNode);
    if (isSettingsEntry(name, pair.value)) {
      readSettings(c, pair.value as YAMLMap, settings);
      continue;
    }
    if (name === undefined || name === "") {
      c.error("bad-name", at, "a block name must be a plain word", {
        expected: "a name like `LowPass`",
      });
      continue;
    }
    if (!BLOCK_NAME_RE.test(name)) {
      c.error("bad-name", at, `block name '${name}' is not valid`, {
        block: name,
        expected:
          "letters, digits, '_' or '-', starting with a letter or '_' ('.' is reserved for ports)",
      });
      continue;
    }
    const value = pair.value;
    if (!isMap(value)) {
      c.error(
        "bad-block",
        c.pos((value as YamlNode | null) ?? keyNode),
        `block '${name}' is ${describeNode(value)}`,
        {
          block: name,
          expected:
            "a mapping with at least `Type`, e.g. `{ Type: Filter, Inputs: [Emg], Params: {...} }`",
        },
      );
      continue;
    }
    const errorsBefore = c.errors;
    const get = (k: string): { node: unknown; keyPos: SourcePos } | undefined => {
      const p = value.items.find((it) => scalarString(it.key) === k);
      return p ? { node: p.value, keyPos: c.pos(p.key as YamlNode) } : undefined;
    };
    for (const it of value.items) {
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

    // Type
    const typeEntry = get("Type");
    let def: AnyBlockDefinition | undefined;
    let type = "";
    if (!typeEntry) {
      c.error("missing-type", at, `block '${name}' has no Type`, {
        block: name,
        expected: "`Type: <block type>`, e.g. `Type: Filter`",
      });
    } else {
      const t = scalarString(typeEntry.node);
      if (t === undefined || t === "") {
        c.error(
          "bad-type",
          c.pos(typeEntry.node as YamlNode),
          `block '${name}': Type is ${describeNode(typeEntry.node)}`,
          {
            block: name,
            expected: "the name of a block type",
          },
        );
      } else {
        type = t;
        def = catalog.get(t);
        if (def && def.type !== t) {
          c.add(
            "warning",
            "type-alias",
            c.pos(typeEntry.node as YamlNode),
            `block '${name}': '${t}' is the old name of ${def.type}; loading it as ${def.type}`,
            {
              block: name,
            },
          );
          type = def.type;
        }
        if (!def) {
          const suggestion = closest(t, typeNames);
          c.error(
            "unknown-type",
            c.pos(typeEntry.node as YamlNode),
            `block '${name}': unknown block type '${t}'`,
            {
              block: name,
              ...(suggestion !== undefined
                ? { suggestion }
                : { expected: "a type listed in docs/blocks.md" }),
            },
          );
        }
      }
    }

    // DesiredRate
    let desiredRate: number | undefined;
    const rateEntry = get("DesiredRate");
    if (rateEntry) {
      const v = isScalar(rateEntry.node) ? rateEntry.node.value : undefined;
      if (typeof v !== "number" || !Number.isFinite(v) || v <= 0) {
        c.error(
          "bad-rate",
          c.pos(rateEntry.node as YamlNode),
          `block '${name}': DesiredRate has ${describeNode(rateEntry.node)}`,
          {
            block: name,
            expected: "a positive number of Hz",
          },
        );
      } else {
        desiredRate = v;
      }
    } else if (def && (def.timer || def.requiresRate)) {
      c.error("missing-rate", at, `block '${name}' (${type}) needs a DesiredRate`, {
        block: name,
        expected: "`DesiredRate: <Hz>`",
      });
    }

    // Inputs
    const inputs: InputRef[] = [];
    const inputsEntry = get("Inputs");
    const inputsPos = inputsEntry ? c.pos(inputsEntry.node as YamlNode) : at;
    if (
      inputsEntry &&
      inputsEntry.node !== null &&
      !(isScalar(inputsEntry.node) && inputsEntry.node.value === null)
    ) {
      const items: unknown[] = isSeq(inputsEntry.node)
        ? inputsEntry.node.items
        : isScalar(inputsEntry.node)
          ? [inputsEntry.node]
          : [];
      if (!isSeq(inputsEntry.node) && !isScalar(inputsEntry.node)) {
        c.error(
          "bad-inputs",
          inputsPos,
          `block '${name}': Inputs is ${describeNode(inputsEntry.node)}`,
          {
            block: name,
            expected: "a list of block names, e.g. `Inputs: [Timer]`",
          },
        );
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
    }

    // Path
    let path: string | undefined;
    const pathEntry = get("Path");
    if (pathEntry) {
      const s =
        isScalar(pathEntry.node) && typeof pathEntry.node.value === "string"
          ? pathEntry.node.value
          : undefined;
      if (s === undefined || s.trim() === "") {
        c.error(
          "bad-path",
          c.pos(pathEntry.node as YamlNode),
          `block '${name}': Path is ${describeNode(pathEntry.node)}`,
          {
            block: name,
            expected: "a folder (the log is <Path>/<block>.txt) or a file name",
          },
        );
      } else {
        path = s;
      }
    }

    // Worker
    let worker = "main";
    const workerEntry = get("Worker");
    if (workerEntry) {
      const s = scalarString(workerEntry.node);
      if (s === undefined || !WORKER_RE.test(s)) {
        c.error(
          "bad-worker",
          c.pos(workerEntry.node as YamlNode),
          `block '${name}': Worker is ${describeNode(workerEntry.node)}`,
          {
            block: name,
            expected: "a worker name (a plain word); blocks with the same name share a thread",
          },
        );
      } else {
        worker = s;
      }
    }

    const batchingEntry = get("BatchingMs");
    const batchingMs = batchingEntry ? readBatchingMs(c, batchingEntry.node, name) : undefined;

    // Queue
    const queue: QueueSpec = { policy: "drop-oldest", capacity: undefined };
    const queueEntry = get("Queue");
    if (queueEntry) {
      const qn = queueEntry.node;
      if (!isMap(qn)) {
        c.error(
          "bad-queue",
          c.pos(qn as YamlNode),
          `block '${name}': Queue is ${describeNode(qn)}`,
          {
            block: name,
            expected: "`{ Policy: drop-oldest | drop-newest | latest, Capacity: <events> }`",
          },
        );
      } else {
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
            c.error(
              "bad-queue",
              c.pos(it.key as YamlNode),
              `block '${name}': unknown Queue key '${k}'`,
              {
                block: name,
                expected: "Policy or Capacity",
                ...(suggestion !== undefined ? { suggestion } : {}),
              },
            );
          }
        }
      }
    }

    // Layout
    let layout: { x: number; y: number } | undefined;
    const layoutEntry = get("Layout");
    if (layoutEntry) {
      const ln = layoutEntry.node;
      const xs = isMap(ln) ? ln.get("X") : undefined;
      const ys = isMap(ln) ? ln.get("Y") : undefined;
      if (
        typeof xs === "number" &&
        typeof ys === "number" &&
        Number.isFinite(xs) &&
        Number.isFinite(ys)
      ) {
        layout = { x: xs, y: ys };
      } else {
        c.error(
          "bad-layout",
          c.pos(ln as YamlNode),
          `block '${name}': Layout is ${describeNode(ln)}`,
          {
            block: name,
            expected: "`{ X: <number>, Y: <number> }`",
          },
        );
      }
    }

    // Params
    let params: unknown = undefined;
    let legacy = false;
    const paramsEntry = get("Params");
    const paramsNode = paramsEntry?.node;
    const paramsPos = paramsEntry ? c.pos(paramsNode as YamlNode) : at;
    let outputs: readonly string[] = ["out"];
    if (def) {
      const knownKeys = objectKeys(def.params);
      let raw: unknown = {};
      let rawOk = true;
      if (
        paramsNode === undefined ||
        paramsNode === null ||
        (isScalar(paramsNode) && paramsNode.value === null)
      ) {
        raw = {};
      } else if (isSeq(paramsNode)) {
        const args = legacyArgs(paramsNode);
        if (!def.legacyParams) {
          rawOk = false;
          c.error(
            "legacy-unsupported",
            paramsPos,
            `block '${name}' (${type}): Params is a positional list, but ${type} has no positional form`,
            {
              block: name,
              expected: `named params: a mapping with ${knownKeys && knownKeys.length ? knownKeys.join(", ") : "no keys"}`,
            },
          );
        } else {
          const positional = args.length === 1 && args[0] === "" ? [] : args;
          try {
            raw = def.legacyParams(positional);
            legacy = true;
          } catch (e) {
            rawOk = false;
            c.error(
              "legacy-params",
              paramsPos,
              `block '${name}' (${type}): cannot convert positional Params [${args.join(", ")}]: ${errorMessage(e)}`,
              {
                block: name,
                ...(e instanceof LegacyParamsError && e.param ? { param: e.param } : {}),
                ...(def.legacyForm ? { expected: def.legacyForm } : {}),
              },
            );
          }
        }
      } else if (isMap(paramsNode)) {
        try {
          raw = paramsNode.toJS(doc);
        } catch (e) {
          rawOk = false;
          c.error(
            "bad-params",
            paramsPos,
            `block '${name}': cannot read Params: ${errorMessage(e)}`,
            { block: name },
          );
        }
      } else {
        rawOk = false;
        c.error(
          "bad-params",
          paramsPos,
          `block '${name}' (${type}): Params is ${describeNode(paramsNode)}`,
          {
            block: name,
            expected: `a mapping${knownKeys && knownKeys.length ? ` with ${knownKeys.join(", ")}` : ""}${def.legacyParams ? ", or MOSAIC's positional list" : ""}`,
          },
        );
      }
      if (rawOk) {
        const r = def.params.safeParse(raw, { reportInput: true });
        if (r.success) {
          params = r.data;
          if (legacy) {
            c.add(
              "warning",
              "legacy-converted",
              paramsPos,
              `block '${name}' (${type}): converted MOSAIC positional Params to ${paramsText(raw)}`,
              {
                block: name,
              },
            );
          }
          try {
            outputs = outputNames(def, params);
          } catch (e) {
            c.error("bad-params", paramsPos, `block '${name}' (${type}): ${errorMessage(e)}`, {
              block: name,
            });
          }
        } else {
          for (const issue of r.error.issues) {
            const p = pathText(issue.path);
            const node = legacy ? undefined : nodeAtPath(paramsNode, issue.path);
            const where = node ? c.pos(node) : paramsPos;
            const ex = explainIssue(issue, knownKeys);
            const subject = p === "" ? "Params" : `param '${p}'`;
            const unknownKeyMsg = issue.code === "unrecognized_keys";
            let kpos = where;
            if (unknownKeyMsg && isMap(paramsNode) && !legacy) {
              const k = issue.keys[0];
              const kp = paramsNode.items.find((it) => scalarString(it.key) === k);
              if (kp) kpos = c.pos(kp.key as YamlNode);
            }
            const message = unknownKeyMsg
              ? `block '${name}' (${type}): ${ex.message}`
              : `block '${name}' (${type}): ${subject} ${ex.message}`;
            c.error(
              "bad-param",
              kpos,
              message + (legacy ? " (after converting the positional Params)" : ""),
              {
                block: name,
                ...(p !== "" ? { param: p } : {}),
                ...(ex.expected !== undefined ? { expected: ex.expected } : {}),
                ...(ex.suggestion !== undefined ? { suggestion: ex.suggestion } : {}),
              },
            );
          }
        }
      }
    }

    if (c.errors > errorsBefore || !def) continue;
    const spec: BlockSpec = {
      name,
      type,
      def,
      params,
      desiredRate,
      inputs,
      path,
      worker,
      batchingMs,
      queue,
      layout,
      outputs,
      legacy,
      pos: at,
      paramsPos,
      inputsPos,
      paramPos: paramKeyPositions(c, paramsNode),
    };
    blocks.push(spec);
    byName.set(name, spec);
  }

  // Wiring: every input names an existing block (and port); arity matches the block type.
  const allNames = [...(root as YAMLMap).items]
    .map((p) => scalarString(p.key))
    .filter((s): s is string => !!s);
  for (const b of blocks) {
    for (const inp of b.inputs) {
      const src = byName.get(inp.block);
      if (!src) {
        if (allNames.includes(inp.block)) continue; // that block has its own error already
        const suggestion = closest(inp.block, allNames);
        c.error(
          "missing-input",
          inp.pos,
          `block '${b.name}': input '${inp.block}' is not a block in this pipeline`,
          {
            block: b.name,
            ...(suggestion !== undefined
              ? { suggestion }
              : { expected: `one of ${allNames.join(", ")}` }),
          },
        );
        continue;
      }
      if (inp.port === "") {
        inp.port = src.outputs[0] ?? "out";
      } else if (!src.outputs.includes(inp.port)) {
        const suggestion = closest(inp.port, src.outputs);
        c.error(
          "missing-port",
          inp.pos,
          `block '${b.name}': '${inp.block}' has no output '${inp.port}'`,
          {
            block: b.name,
            expected: `one of ${src.outputs.map((o) => `${inp.block}.${o}`).join(", ")}`,
            ...(suggestion !== undefined ? { suggestion: `${inp.block}.${suggestion}` } : {}),
          },
        );
      }
    }
    const n = b.inputs.length;
    const { min, max } = b.def.inputs;
    if (n < min || n > max) {
      const want =
        min === max
          ? `exactly ${min}`
          : max === Infinity
            ? `at least ${min}`
            : `between ${min} and ${max}`;
      const labels = b.def.inputs.labels ? ` (${b.def.inputs.labels.join(", ")})` : "";
      c.error(
        "input-count",
        b.inputsPos,
        `block '${b.name}' (${b.type}) has ${n} input${n === 1 ? "" : "s"}`,
        {
          block: b.name,
          expected: `${want} input${max === 1 ? "" : "s"}${labels}`,
        },
      );
    }
  }

  if (blocks.length === 0 && c.errors === 0) {
    c.error("empty", { line: 1, col: 1 }, "the pipeline has no blocks");
  }
  const ok = c.errors === 0;
  return {
    spec: ok ? { file, blocks, byName, settings } : undefined,
    diagnostics: c.list,
    ok,
    doc,
  };
}

/** `Pipeline: { … }` without a `Type` is the settings entry (a block may still be named Pipeline). */
function isSettingsEntry(name: string | undefined, value: unknown): boolean {
  return (
    name === SETTINGS_KEY &&
    isMap(value) &&
    !value.items.some((it) => scalarString(it.key) === "Type")
  );
}

function readSettings(c: Collector, node: YAMLMap, settings: PipelineSettings): void {
  for (const it of node.items) {
    const k = scalarString(it.key) ?? "";
    if (k === "BatchingMs") {
      settings.batchingMs = readBatchingMs(c, it.value, undefined);
      continue;
    }
    const suggestion = closest(k, SETTINGS_KEYS);
    c.error("unknown-key", c.pos(it.key as YamlNode), `${SETTINGS_KEY}: unknown setting '${k}'`, {
      expected: `one of ${SETTINGS_KEYS.join(", ")} (a block named ${SETTINGS_KEY} needs a Type)`,
      ...(suggestion !== undefined ? { suggestion } : {}),
    });
  }
}

/** `BatchingMs`: a number of milliseconds, 0 (a wake-up per tick) to 1000. */
function readBatchingMs(
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
