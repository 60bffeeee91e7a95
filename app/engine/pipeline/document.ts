/**
 * The editing model of a pipeline file (issue 8, "round trip"): the canvas, the inspector and
 * `mosaic format` change a pipeline through this class, and only what an edit touches changes in
 * the file. Comments, key order, quoting, flow or block style, blank lines, line endings (LF or
 * CRLF) and every block an edit does not touch stay byte for byte.
 *
 * How: the source text is the state. Every edit is parsed with the `yaml` Document API (which
 * gives each node's source range), turned into text replacements of those ranges (or new
 * entries in the style of the mapping they go into), applied, and the result parsed again; an
 * edit whose result would not parse, or that is refused, throws and leaves the text as it was.
 * Pure: no Node, no DOM (runs in the browser and in Node).
 *
 * Choices (documented for the editor):
 * - New blocks are one flow line `Name: { Type: T, DesiredRate: r, Inputs: [..], Params: {..},
 *   Layout: { X: 0, Y: 0 } }` after the last block; new keys of a block go after the key that
 *   precedes them in the usual order (Type, DesiredRate, Inputs, Params, Path, Worker, Queue),
 *   `Layout` last; new values are written in flow style on one line.
 * - MOSAIC's positional `Params: [...]` are never rewritten implicitly: `setParam`/`removeParam`
 *   refuse them with an error that says to call `convertLegacyParams` (which replaces the list
 *   by the named mapping the loader would build from it).
 * - Removing a block keeps the comment lines above it (they may introduce a section); the lines
 *   of the block itself (and comments inside it) go. References to it are dropped from other
 *   blocks' `Inputs` (and a Joiner `Trigger` naming it), reported by the call's return value and
 *   `lastDropped`.
 * - Renaming follows every reference: `Inputs` items (`Name`, `-Name`, `Name.port`), a Joiner's
 *   `Trigger` and MOSAIC's `timerBlockName:Name`.
 * - `normalize()` (what `mosaic format` adds to a plain round trip): the file ends with a line
 *   break. Nothing else is normalised; CRLF files stay CRLF (new lines use the file's ending).
 */
import { isMap, isPair, isScalar, isSeq, stringify } from "yaml";
import type { Document, Node as YamlNode, Pair, Scalar, YAMLMap, YAMLSeq } from "yaml";
import type { Catalog } from "../catalog";
import { errorMessage, type Diagnostic } from "../diagnostics";
import { closest } from "../suggest";
import { BLOCK_NAME_RE, loadPipeline, type LoadResult } from "./loader";
import { mosaicType } from "./mosaic";
import { parsePipelineYaml } from "./parse";
import { positionalArgs } from "./positional";
import { SETTINGS_KEY } from "./spec";

export interface AddBlockOptions {
  inputs?: string[];
  params?: Record<string, unknown>;
  desiredRate?: number;
  layout?: { x: number; y: number };
}

/** An input (or Joiner trigger) dropped because the block it named was removed. */
export interface DroppedInput {
  /** The block that lost the reference. */
  block: string;
  /** The reference as written (`Emg`, `-Emg`, `Emg.port`). */
  input: string;
  /** Where it was: an `Inputs` item or the `Trigger` param. */
  kind: "input" | "trigger";
}

/** What the file says about one block (JS values; `params` is a list for positional Params). */
export interface BlockInfo {
  name: string;
  type: string | undefined;
  inputs: string[];
  params: Record<string, unknown> | unknown[] | undefined;
  positionalParams: boolean;
  desiredRate: number | undefined;
  path: string | undefined;
  worker: string | undefined;
  layout: { x: number; y: number } | undefined;
}

interface Edit {
  start: number;
  end: number;
  text: string;
}

/** A place in the file that names a block. */
interface Reference {
  /** The block holding the reference. */
  holder: string;
  /** legacy-trigger: a `timerBlockName:Name` item; legacy-trigger-value: Name in `[timerBlockName: Name]`. */
  kind: "input" | "trigger" | "legacy-trigger" | "legacy-trigger-value";
  node: Scalar;
  /** The whole scalar value (`-Emg.out`, `timerBlockName:Timer`). */
  value: string;
  /** The block it names. */
  target: string;
}

/** Usual order of a block's keys: a new key goes after the last one before it in this list. */
const KEY_ORDER = ["Type", "DesiredRate", "Inputs", "Params", "Path", "Worker", "Queue", "Layout"];
/** Params whose value is the name of one of the block's inputs. */
const BLOCK_REF_PARAMS = new Set(["Trigger"]);
const LEGACY_TRIGGER = "timerBlockName";
const INPUT_RE = /^-?[A-Za-z_][A-Za-z0-9_-]*(\.[A-Za-z0-9_-]+)?$/;

/** The block an input reference names (`-Emg.out` → `Emg`). */
export function referencedBlock(ref: string): string {
  const r = ref.startsWith("-") ? ref.slice(1) : ref;
  const dot = r.indexOf(".");
  return dot < 0 ? r : r.slice(0, dot);
}

/** `ref` with its block part replaced (`-Emg.out`, Emg → Sim: `-Sim.out`). */
function renameRef(ref: string, to: string): string {
  const dash = ref.startsWith("-") ? "-" : "";
  const r = dash ? ref.slice(1) : ref;
  const dot = r.indexOf(".");
  return dash + to + (dot < 0 ? "" : r.slice(dot));
}

function keyOf(pair: Pair): unknown {
  return isScalar(pair.key) ? pair.key.value : pair.key;
}

function str(node: unknown): string | undefined {
  if (!isScalar(node)) return undefined;
  const v = node.value;
  return typeof v === "string"
    ? v
    : typeof v === "number" || typeof v === "boolean"
      ? String(v)
      : undefined;
}

/** One scalar as YAML text that reads back as the same value inside a flow collection. */
export function scalarYaml(v: unknown): string {
  if (v === null || v === undefined) return "null";
  if (typeof v === "number") {
    if (Number.isNaN(v)) return ".nan";
    if (v === Infinity) return ".inf";
    if (v === -Infinity) return "-.inf";
    return String(v);
  }
  if (typeof v === "boolean") return String(v);
  if (typeof v === "bigint") return String(v);
  if (typeof v === "string") {
    // Double-quoted YAML reads JSON escapes the same way; keeps the value on one line.
    if (/[\u0000-\u001f\u007f-\u009f\u2028\u2029\ufeff]/.test(v)) return JSON.stringify(v);
    const s = stringify([v], {
      collectionStyle: "flow",
      lineWidth: 0,
      flowCollectionPadding: false,
    }).trim();
    return s.slice(1, -1);
  }
  throw new Error(`cannot write ${typeof v} into a pipeline file`);
}

/** A value as one line of flow YAML, in the examples' style: `{ A: 1, B: [1, 2] }`. */
export function flowYaml(value: unknown): string {
  if (ArrayBuffer.isView(value) && !(value instanceof DataView)) {
    return flowYaml(Array.from(value as unknown as ArrayLike<number>));
  }
  if (Array.isArray(value)) return `[${value.map((x) => flowYaml(x ?? null)).join(", ")}]`;
  if (value !== null && typeof value === "object") {
    const proto = Object.getPrototypeOf(value) as unknown;
    if (proto !== Object.prototype && proto !== null) {
      throw new Error(`cannot write a ${value.constructor?.name ?? "object"} into a pipeline file`);
    }
    const entries = Object.entries(value).filter(([, v]) => v !== undefined);
    if (entries.length === 0) return "{}";
    return `{ ${entries.map(([k, v]) => `${scalarYaml(k)}: ${flowYaml(v)}`).join(", ")} }`;
  }
  if (typeof value === "function" || typeof value === "symbol") {
    throw new Error(`cannot write a ${typeof value} into a pipeline file`);
  }
  return scalarYaml(value);
}

function checkBlockName(name: string, what = "block name"): void {
  if (typeof name !== "string" || !BLOCK_NAME_RE.test(name)) {
    throw new Error(
      `'${String(name)}' is not a valid ${what}: use letters, digits, '_' or '-', starting with a letter or '_'`,
    );
  }
}

function checkFinite(v: number, what: string): void {
  if (typeof v !== "number" || !Number.isFinite(v)) {
    throw new Error(`${what} must be a finite number, not ${String(v)}`);
  }
}

/**
 * Parses the text as the loader does (parse.ts: MOSAIC's multi-line flow layouts are read through
 * an offset-keeping pre-pass, so node ranges index `text` as it is).
 */
function parseText(text: string): Document {
  // parsePipelineYaml also reports an alias whose anchor is gone (`yaml` notices only when read).
  const { doc } = parsePipelineYaml(text);
  if (doc.errors.length > 0) {
    const e = doc.errors[0]!;
    const before = text.slice(0, e.pos[0]);
    const line = before.split("\n").length;
    const col = e.pos[0] - (before.lastIndexOf("\n") + 1) + 1;
    throw new Error(`YAML error at ${line}:${col}: ${e.message.split("\n")[0] ?? e.message}`);
  }
  const root = doc.contents;
  if (root !== null && !isMap(root) && !(isScalar(root) && root.value === null)) {
    throw new Error("the pipeline is not a mapping of block names to blocks");
  }
  return doc;
}

export class PipelineDocument {
  private text: string;
  private doc: Document;
  private readonly eol: string;
  /** What the last `removeBlock` dropped from other blocks. */
  lastDropped: DroppedInput[] = [];

  private constructor(
    text: string,
    doc: Document,
    readonly file: string,
  ) {
    this.text = text;
    this.doc = doc;
    this.eol = text.includes("\r\n") ? "\r\n" : "\n";
  }

  /** Parses a pipeline's text; throws when it is not YAML or not a mapping (the empty file is fine). */
  static parse(text: string, file: string): PipelineDocument {
    return new PipelineDocument(text, parseText(text), file);
  }

  /** The file: the parsed text with every edit applied, everything else byte for byte. */
  toString(): string {
    return this.text;
  }

  /** Runs the loader on the current text. */
  load(catalog: Catalog): LoadResult {
    return loadPipeline(this.text, this.file, catalog);
  }

  /** The loader's diagnostics for the current text (errors and warnings, with positions). */
  validate(catalog: Catalog): Diagnostic[] {
    return this.load(catalog).diagnostics;
  }

  blockNames(): string[] {
    const root = this.root();
    if (!root) return [];
    return root.items.map((p) => str(p.key)).filter((s): s is string => s !== undefined);
  }

  hasBlock(name: string): boolean {
    return this.findPair(name) !== undefined;
  }

  /** A name not used by any block: `base`, else `base2`, `base3`, … (made a valid name first). */
  freshName(base: string): string {
    let b = String(base).replace(/[^A-Za-z0-9_-]/g, "_");
    if (!/^[A-Za-z_]/.test(b)) b = `_${b}`;
    const names = new Set(this.blockNames());
    if (!names.has(b)) return b;
    const stem = b.replace(/\d+$/, "") || b;
    for (let i = 2; ; i++) if (!names.has(`${stem}${i}`)) return `${stem}${i}`;
  }

  /** What the file says about a block. */
  block(name: string): BlockInfo {
    const map = this.blockMap(name);
    const get = (k: string): unknown => map.items.find((q) => keyOf(q) === k)?.value;
    const paramsNode = get("Params");
    const layout = get("Layout");
    const lx = isMap(layout) ? layout.get("X") : undefined;
    const ly = isMap(layout) ? layout.get("Y") : undefined;
    const rate = get("DesiredRate");
    const params: unknown =
      isMap(paramsNode) || isSeq(paramsNode) ? paramsNode.toJS(this.doc) : undefined;
    return {
      name,
      type: str(get("Type")),
      inputs: this.inputsOf(name),
      params: params as BlockInfo["params"],
      positionalParams: isSeq(paramsNode),
      desiredRate: isScalar(rate) && typeof rate.value === "number" ? rate.value : undefined,
      path: str(get("Path")),
      worker: str(get("Worker")),
      layout: typeof lx === "number" && typeof ly === "number" ? { x: lx, y: ly } : undefined,
    };
  }

  /** A block's `Inputs` as written. */
  inputsOf(name: string): string[] {
    const map = this.blockMap(name);
    const v = map.items.find((q) => keyOf(q) === "Inputs")?.value;
    if (isSeq(v)) return v.items.map((x) => str(x) ?? "");
    const s = str(v);
    return s === undefined || s === "" ? [] : [s];
  }

  // ---- edits -------------------------------------------------------------------------------

  /** Adds a block (one flow line) after the last block. */
  addBlock(name: string, type: string, opts: AddBlockOptions = {}): void {
    checkBlockName(name);
    if (this.hasBlock(name)) throw new Error(`a block '${name}' exists already`);
    if (typeof type !== "string" || type.trim() === "") throw new Error("a block needs a Type");
    const parts = [`Type: ${scalarYaml(type)}`];
    if (opts.desiredRate !== undefined) {
      checkRate(opts.desiredRate);
      parts.push(`DesiredRate: ${scalarYaml(opts.desiredRate)}`);
    }
    if (opts.inputs && opts.inputs.length > 0) {
      for (const i of opts.inputs) this.checkInputRef(i, name);
      parts.push(`Inputs: ${flowYaml(opts.inputs)}`);
    }
    if (opts.params && Object.keys(opts.params).length > 0) {
      parts.push(`Params: ${flowYaml(opts.params)}`);
    }
    if (opts.layout) parts.push(`Layout: ${layoutYaml(opts.layout)}`);
    this.appendBlock(name, `{ ${parts.join(", ")} }`);
  }

  /**
   * Removes a block, and every reference to it from other blocks (their `Inputs`, a Joiner's
   * `Trigger`); returns what was dropped (also kept in `lastDropped`).
   */
  removeBlock(name: string): DroppedInput[] {
    const pair = this.pairOf(name);
    const dropped: DroppedInput[] = [];
    this.transaction(() => {
      this.apply([this.removeEntryEdit(this.root()!, pair)]);
      for (const b of this.blockNames()) {
        if (!isMap(this.findPair(b)?.value)) continue;
        const ins = this.inputsOf(b);
        const keep = ins.filter((s) => referencedBlock(s) !== name);
        if (keep.length !== ins.length) {
          for (const s of ins) {
            if (referencedBlock(s) === name) dropped.push({ block: b, input: s, kind: "input" });
          }
          this.setInputs(b, keep);
        }
        for (const r of this.references().filter((x) => x.holder === b && x.target === name)) {
          if (r.kind === "trigger") {
            this.removeParam(b, "Trigger");
            dropped.push({ block: b, input: r.value, kind: "trigger" });
          } else if (r.kind === "legacy-trigger" || r.kind === "legacy-trigger-value") {
            const seq = this.paramsNode(b);
            if (isSeq(seq)) {
              const items = seq.items.filter((it) => !containsNode(it, r.node));
              this.apply([
                this.replaceValueEdit(
                  seq,
                  this.seqText(
                    seq,
                    items.map((it) => this.src(it)),
                  ),
                ),
              ]);
              dropped.push({ block: b, input: r.value, kind: "trigger" });
            }
          }
        }
      }
    });
    this.lastDropped = dropped;
    return dropped;
  }

  /** Renames a block; every reference follows (`Name`, `-Name`, `Name.port`, Trigger). */
  renameBlock(from: string, to: string): void {
    const pair = this.pairOf(from);
    if (from === to) return;
    checkBlockName(to);
    if (this.hasBlock(to)) throw new Error(`a block '${to}' exists already`);
    const edits: Edit[] = [this.scalarEdit(pair.key as Scalar, to)];
    for (const r of this.references()) {
      if (r.target !== from) continue;
      if (r.kind !== "legacy-trigger") {
        edits.push(this.scalarEdit(r.node, renameRef(r.value, to)));
      } else {
        const i = r.value.indexOf(":");
        edits.push(this.scalarEdit(r.node, `${r.value.slice(0, i + 1)}${to}`));
      }
    }
    this.apply(edits);
  }

  /**
   * Adds a copy of a block (same type, inputs, params and other keys, one flow line) after the
   * last block; its Layout, if any, is moved by (40, 40).
   */
  duplicateBlock(name: string, newName: string): void {
    const map = this.blockMap(name);
    checkBlockName(newName);
    if (this.hasBlock(newName)) throw new Error(`a block '${newName}' exists already`);
    const js = map.toJS(this.doc) as Record<string, unknown>;
    const layout = js.Layout as { X?: unknown; Y?: unknown } | undefined;
    if (layout && typeof layout.X === "number" && typeof layout.Y === "number") {
      js.Layout = { X: Math.round(layout.X + 40), Y: Math.round(layout.Y + 40) };
    }
    this.appendBlock(newName, flowYaml(js));
  }

  /**
   * Sets `Params.<param>` of a block. When the param exists (block or flow style) only its value
   * changes; otherwise a new entry is added in the style of the Params mapping (or `Params:
   * { param: value }` when the block has none). Refuses positional Params (see the header).
   */
  setParam(block: string, param: string, value: unknown): void {
    if (value === undefined) {
      this.removeParam(block, param);
      return;
    }
    if (typeof param !== "string" || param === "") throw new Error("a param needs a name");
    const map = this.blockMap(block);
    const params = this.paramsNode(block);
    const text = flowYaml(value);
    if (params === undefined || isNullish(params)) {
      this.apply([this.setEntryEdit(map, "Params", `{ ${scalarYaml(param)}: ${text} }`)]);
      return;
    }
    this.refuseNonMapParams(block, params);
    this.apply([this.setEntryEdit(params as YAMLMap, param, text)]);
  }

  /** Removes `Params.<param>` (the whole `Params` entry with its last param); no-op when absent. */
  removeParam(block: string, param: string): void {
    const map = this.blockMap(block);
    const params = this.paramsNode(block);
    if (params === undefined || isNullish(params)) return;
    this.refuseNonMapParams(block, params);
    const pm = params as YAMLMap;
    const pair = pm.items.find((q) => keyOf(q) === param);
    if (!pair) return;
    if (pm.items.length === 1) {
      this.apply([
        this.removeEntryEdit(
          map,
          map.items.find((q) => keyOf(q) === "Params")!,
        ),
      ]);
    } else {
      this.apply([this.removeEntryEdit(pm, pair)]);
    }
  }

  /**
   * Replaces MOSAIC's positional `Params: [...]` of a block with the named mapping the loader
   * converts it to (the catalog's `legacyParams`). A block whose Type is one of the original's
   * old names (mosaic.ts: `Func_Multiplier`, `TimerDecimator`, …) gets the Type it loads as too,
   * and a TimerDecimator the DesiredRate the loader computes. Throws when the block's type is
   * unknown, has no positional form, or the list does not convert; then nothing changes.
   */
  convertLegacyParams(block: string, catalog: Catalog): void {
    const params = this.paramsNode(block);
    if (!isSeq(params)) throw new Error(`the Params of '${block}' are not positional`);
    const type = this.block(block).type ?? "";
    const { lookup, rule } = mosaicType(type, catalog);
    const def = catalog.get(lookup);
    if (!def) throw new Error(`block '${block}': unknown block type '${type}'`);
    if (!def.legacyParams) throw new Error(`block '${block}': ${def.type} has no positional form`);
    let args = positionalArgs(params);
    let raw: unknown;
    let rate: number | undefined;
    try {
      if (rule?.rateDivisor) {
        rule.rateDivisor(args);
        rate = this.load(catalog).spec?.byName.get(block)?.desiredRate;
        if (rate === undefined)
          throw new Error(
            "its DesiredRate comes from its input's, which is not known (the file has errors)",
          );
      }
      if (rule?.args) args = rule.args(args);
      raw = def.legacyParams(args.length === 1 && args[0] === "" ? [] : args);
    } catch (e) {
      throw new Error(`block '${block}': cannot convert its positional Params: ${errorMessage(e)}`);
    }
    this.transaction(() => {
      this.apply([this.replaceValueEdit(params, flowYaml(raw))]);
      if (rule) this.setKey(block, "Type", scalarYaml(def.type));
      if (rate !== undefined) this.setDesiredRate(block, rate);
    });
  }

  /** Sets a block's `Inputs` (kept items keep their spelling; an empty list removes the key). */
  setInputs(block: string, inputs: string[]): void {
    const map = this.blockMap(block);
    const current = this.inputsOf(block);
    if (current.length === inputs.length && current.every((s, i) => s === inputs[i])) return;
    for (const i of inputs) if (!current.includes(i)) this.checkInputRef(i, block);
    const pair = map.items.find((q) => keyOf(q) === "Inputs");
    if (inputs.length === 0) {
      if (pair) this.apply([this.removeEntryEdit(map, pair)]);
      return;
    }
    const v = pair?.value;
    const old = isSeq(v) ? v.items : isScalar(v) && !isNullish(v) ? [v] : [];
    const texts = inputs.map((s) => {
      const same = old.find((o) => str(o) === s);
      return same ? this.src(same) : scalarYaml(s);
    });
    if (isSeq(v)) {
      this.apply([this.replaceValueEdit(v, this.seqText(v, texts))]);
    } else if (isScalar(v) && !isNullish(v) && texts.length === 1) {
      this.apply([this.replaceValueEdit(v, texts[0]!)]);
    } else {
      this.apply([this.setEntryEdit(map, "Inputs", `[${texts.join(", ")}]`)]);
    }
  }

  /** Adds `from` (a block, `-Block` or `Block.port`) to the Inputs of `to`, at `index` (default last). */
  connect(from: string, to: string, index?: number): void {
    const ins = this.inputsOf(to);
    this.checkInputRef(from, to);
    if (ins.includes(from)) throw new Error(`'${to}' has the input '${from}' already`);
    const at =
      index === undefined ? ins.length : Math.max(0, Math.min(ins.length, Math.trunc(index)));
    ins.splice(at, 0, from);
    this.setInputs(to, ins);
  }

  /** Removes `from` from the Inputs of `to`: that exact reference, else the first naming that block. */
  disconnect(from: string, to: string): void {
    const ins = this.inputsOf(to);
    let i = ins.indexOf(from);
    if (i < 0) i = ins.findIndex((s) => referencedBlock(s) === referencedBlock(from));
    if (i < 0) throw new Error(`'${to}' has no input '${from}'`);
    ins.splice(i, 1);
    this.setInputs(to, ins);
  }

  /** Sets (or, with undefined, removes) a block's DesiredRate (Hz, positive). */
  setDesiredRate(block: string, rate: number | undefined): void {
    if (rate !== undefined) checkRate(rate);
    this.setKey(block, "DesiredRate", rate === undefined ? undefined : scalarYaml(rate));
  }

  /** Sets (or, with undefined or "", removes) a block's log Path. */
  setPath(block: string, path: string | undefined): void {
    this.setKey(block, "Path", path === undefined || path === "" ? undefined : scalarYaml(path));
  }

  /** Sets (or removes) a block's Worker (its thread). */
  setWorker(block: string, worker: string | undefined): void {
    if (worker !== undefined && worker !== "") checkBlockName(worker, "worker name");
    this.setKey(
      block,
      "Worker",
      worker === undefined || worker === "" ? undefined : scalarYaml(worker),
    );
  }

  /** Sets a block's `Layout` (rounded to whole pixels): only the numbers change when it has one. */
  setLayout(block: string, pos: { x: number; y: number }): void {
    checkFinite(pos.x, "Layout X");
    checkFinite(pos.y, "Layout Y");
    const map = this.blockMap(block);
    const layout = map.items.find((q) => keyOf(q) === "Layout")?.value;
    const xs = isMap(layout) ? layout.items.find((q) => keyOf(q) === "X")?.value : undefined;
    const ys = isMap(layout) ? layout.items.find((q) => keyOf(q) === "Y")?.value : undefined;
    if (isScalar(xs) && isScalar(ys) && xs.range && ys.range && !xs.anchor && !ys.anchor) {
      this.apply([
        { start: xs.range[0], end: xs.range[1], text: String(Math.round(pos.x)) },
        { start: ys.range[0], end: ys.range[1], text: String(Math.round(pos.y)) },
      ]);
    } else {
      this.apply([this.setEntryEdit(map, "Layout", layoutYaml(pos))]);
    }
  }

  /** Sets several Layouts in one edit (blocks not in the file are ignored). */
  setLayouts(positions: ReadonlyMap<string, { x: number; y: number }>): void {
    this.transaction(() => {
      for (const [name, p] of positions)
        if (isMap(this.findPair(name)?.value)) this.setLayout(name, p);
    });
  }

  /** A key of the settings entry `Pipeline:` as plain data (undefined: not set). */
  setting(key: string): unknown {
    const map = this.settingsMap();
    const pair = map?.items.find((q) => keyOf(q) === key);
    return pair ? ((pair.value as { toJSON?(): unknown } | null)?.toJSON?.() ?? null) : undefined;
  }

  /**
   * Sets (undefined: removes) `key` of the settings entry `Pipeline:`, which is added at the end
   * of the file when missing and removed with its last key. In a block-style entry the value is
   * written in block style (mappings nested, list items one flow mapping a line), in a flow one
   * on one line; other keys, comments outside the value and the blocks stay as they were.
   */
  setSetting(key: string, value: unknown): void {
    const root = this.root();
    const pair = this.findPair(SETTINGS_KEY);
    if (pair && !this.settingsMap()) {
      throw new Error(`'${SETTINGS_KEY}' is a block here; its settings cannot be written`);
    }
    const map = this.settingsMap();
    if (value === undefined) {
      const old = map?.items.find((q) => keyOf(q) === key);
      if (!map || !old) return;
      if (map.items.length === 1) this.apply([this.removeEntryEdit(root!, pair!)]);
      else this.apply([this.removeEntryEdit(map, old)]);
      return;
    }
    if (!map) {
      this.appendEntry(
        root?.flow === true
          ? `${SETTINGS_KEY}: ${flowYaml({ [key]: value })}`
          : `${SETTINGS_KEY}:${blockYaml({ [key]: value }, "  ", this.eol)}`,
      );
      return;
    }
    if (map.flow) {
      this.apply([this.setEntryEdit(map, key, flowYaml(value))]);
      return;
    }
    const first = map.items[0]?.key as YamlNode | undefined;
    const at = first?.range?.[0];
    const indent = at !== undefined ? " ".repeat(at - lineStart(this.text, at)) : "  ";
    const entry = blockYaml({ [key]: value }, indent, this.eol).slice(
      this.eol.length + indent.length,
    );
    const old = map.items.find((q) => keyOf(q) === key);
    if (old) {
      // The old entry's lines (and comments indented under it) give way to the new ones.
      const gone = this.removeEntryEdit(map, old);
      this.apply([{ ...gone, text: `${indent}${entry}${this.eol}` }]);
    } else {
      this.apply([this.newEntryEdit(map, entry, map.items[map.items.length - 1])]);
    }
  }

  /** Adds a line break at the end when the file has none (what `mosaic format` normalises). */
  normalize(): void {
    if (this.text !== "" && !this.text.endsWith("\n")) {
      this.apply([{ start: this.text.length, end: this.text.length, text: this.eol }]);
    }
  }

  // ---- internals ---------------------------------------------------------------------------

  private root(): YAMLMap | null {
    const r = this.doc.contents;
    return isMap(r) ? r : null;
  }

  /** The settings entry's mapping (`Pipeline:` without a Type), if any. */
  private settingsMap(): YAMLMap | undefined {
    const v = this.findPair(SETTINGS_KEY)?.value;
    return isMap(v) && !v.items.some((q) => keyOf(q) === "Type") ? v : undefined;
  }

  private findPair(name: string): Pair | undefined {
    return this.root()?.items.find((p) => str(p.key) === name);
  }

  private pairOf(name: string): Pair {
    const p = this.findPair(name);
    if (!p) {
      const s = closest(String(name), this.blockNames());
      throw new Error(
        `no block '${String(name)}'${s !== undefined ? ` (did you mean '${s}'?)` : ""}`,
      );
    }
    return p;
  }

  private blockMap(name: string): YAMLMap {
    const v = this.pairOf(name).value;
    if (!isMap(v)) throw new Error(`block '${name}' is not a mapping (fix it in the text first)`);
    return v;
  }

  private paramsNode(block: string): YamlNode | null | undefined {
    const p = this.blockMap(block).items.find((q) => keyOf(q) === "Params");
    return p ? ((p.value as YamlNode | null) ?? null) : undefined;
  }

  private refuseNonMapParams(block: string, params: YamlNode | null): void {
    if (isSeq(params)) {
      throw new Error(
        `the Params of '${block}' are in MOSAIC's positional form: convert them to named params first (convertLegacyParams)`,
      );
    }
    if (!isMap(params)) {
      throw new Error(`the Params of '${block}' are not a mapping (fix them in the text first)`);
    }
  }

  private checkInputRef(ref: string, block: string): void {
    if (typeof ref !== "string" || !INPUT_RE.test(ref)) {
      throw new Error(`'${String(ref)}' is not an input: write Name, -Name or Name.port`);
    }
    const target = referencedBlock(ref);
    if (!this.hasBlock(target) && target !== block) {
      const s = closest(target, this.blockNames());
      throw new Error(
        `no block '${target}' to connect${s !== undefined ? ` (did you mean '${s}'?)` : ""}`,
      );
    }
  }

  private setKey(block: string, key: string, text: string | undefined): void {
    const map = this.blockMap(block);
    if (text === undefined) {
      const pair = map.items.find((q) => keyOf(q) === key);
      if (pair) this.apply([this.removeEntryEdit(map, pair)]);
      return;
    }
    this.apply([this.setEntryEdit(map, key, text)]);
  }

  private appendBlock(name: string, value: string): void {
    this.appendEntry(`${scalarYaml(name)}: ${value}`);
  }

  /** Adds a top-level entry (its text) after the last one. */
  private appendEntry(entry: string): void {
    const root = this.root();
    if (root) {
      this.apply([this.newEntryEdit(root, entry, root.items[root.items.length - 1])]);
      return;
    }
    // Empty (or comments only): a new line at the end.
    const t = this.text;
    const sep = t === "" || t.endsWith("\n") ? "" : this.eol;
    this.apply([{ start: t.length, end: t.length, text: `${sep}${entry}${this.eol}` }]);
  }

  /** Every place that names a block. */
  private references(): Reference[] {
    const out: Reference[] = [];
    const root = this.root();
    if (!root) return out;
    for (const pair of root.items) {
      const holder = str(pair.key);
      if (holder === undefined || !isMap(pair.value)) continue;
      for (const it of pair.value.items) keyReferences(holder, it, out);
    }
    return out;
  }

  /** The source text of a node. */
  private src(node: unknown): string {
    const r = (node as YamlNode | null)?.range;
    return r
      ? this.text.slice(r[0], r[1]).replace(/\s+$/, "")
      : flowYaml((node as Scalar)?.value ?? null);
  }

  /** A sequence in the style of `seq`: flow `[a, b]` / `[ a, b ]`, or block `- a` lines. */
  private seqText(seq: YAMLSeq, items: string[]): string {
    if (seq.flow || items.length === 0) {
      const r = seq.range!;
      const pad = seq.flow && this.text[r[0] + 1] === " " && items.length > 0 ? " " : "";
      return `[${pad}${items.join(", ")}${pad}]`;
    }
    const first = seq.range![0];
    const indent = " ".repeat(first - lineStart(this.text, first));
    return items.map((s, i) => `${i === 0 ? "" : indent}- ${s}`).join(this.eol);
  }

  /** Replacement text of a scalar, in its quoting style when it had one. */
  private scalarEdit(node: Scalar, value: string): Edit {
    const r = node.range!;
    let text = scalarYaml(value);
    if (node.type === "QUOTE_SINGLE") text = `'${value.replace(/'/g, "''")}'`;
    else if (node.type === "QUOTE_DOUBLE") text = JSON.stringify(value);
    return { start: r[0], end: r[1], text };
  }

  /** Replaces a value (its anchor kept; a block collection's final line break kept). */
  private replaceValueEdit(node: YamlNode, text: string): Edit {
    const [start, end] = node.range!;
    if (end > start && this.text[end - 1] === "\n") {
      const brk = this.text[end - 2] === "\r" ? "\r\n" : "\n";
      return { start, end, text: `${text}${brk}` };
    }
    return { start, end, text };
  }

  /** Sets `key` of a mapping to `value` (YAML text): replaces the old value or adds an entry. */
  private setEntryEdit(map: YAMLMap, key: string, value: string): Edit {
    const pair = map.items.find((q) => keyOf(q) === key);
    if (!pair) {
      const entry = `${scalarYaml(key)}: ${value}`;
      const idx = KEY_ORDER.indexOf(key);
      let after: Pair | undefined = map.items[map.items.length - 1];
      if (idx >= 0 && key !== "Layout") {
        const before = map.items.filter((q) => {
          const i = KEY_ORDER.indexOf(String(keyOf(q)));
          return i >= 0 && i < idx;
        });
        if (before.length > 0) after = before[before.length - 1];
      }
      return this.newEntryEdit(map, entry, after);
    }
    const v = pair.value as YamlNode | null;
    if (v && v.range && !(isScalar(v) && v.value === null && v.range[0] === v.range[1])) {
      return this.replaceValueEdit(v, value);
    }
    const k = pair.key as YamlNode;
    const at = v?.range ? v.range[0] : k.range![1] + (this.text[k.range![1]] === ":" ? 1 : 0);
    return { start: at, end: at, text: ` ${value}` };
  }

  /** A new `key: value` entry (text `entry`) after `after` (default last), in the mapping's style. */
  private newEntryEdit(map: YAMLMap, entry: string, after: Pair | undefined): Edit {
    const t = this.text;
    if (map.flow) {
      const end = after ? ((after.value ?? after.key) as YamlNode | null)?.range?.[1] : undefined;
      if (end !== undefined) return { start: end, end, text: `, ${entry}` };
      const open = t.indexOf("{", map.range![0]);
      return { start: open + 1, end: open + 1, text: ` ${entry} ` };
    }
    const firstKey = map.items[0]?.key as YamlNode | undefined;
    const keyStart = firstKey?.range?.[0] ?? map.range![0];
    const indent = " ".repeat(keyStart - lineStart(t, keyStart));
    const ref = after ?? map.items[map.items.length - 1];
    const node = (ref?.value ?? ref?.key) as YamlNode | null | undefined;
    const at = node?.range?.[1] ?? map.range![1];
    if (at > 0 && t[at - 1] === "\n")
      return { start: at, end: at, text: `${indent}${entry}${this.eol}` };
    const nl = t.indexOf("\n", at);
    if (nl < 0) return { start: t.length, end: t.length, text: `${this.eol}${indent}${entry}` };
    return { start: nl + 1, end: nl + 1, text: `${indent}${entry}${this.eol}` };
  }

  /** Removes an entry: its lines in a block mapping, the entry and one comma in a flow mapping. */
  private removeEntryEdit(map: YAMLMap, pair: Pair): Edit {
    const t = this.text;
    const key = pair.key as YamlNode;
    const kStart = key.range![0];
    const v = pair.value as YamlNode | null;
    const vEnd = v?.range?.[1] ?? key.range![1];
    const ls = lineStart(t, kStart);
    const atLineStart = /^[ \t]*$/.test(t.slice(ls, kStart));
    if (!map.flow) {
      const start = atLineStart ? ls : kStart;
      let end = vEnd > 0 && t[vEnd - 1] === "\n" ? vEnd : lineEndAfter(t, vEnd);
      // Comment lines indented under the entry belong to it.
      const col = kStart - ls;
      for (;;) {
        const m = /^([ \t]*)#[^\n]*(\n|$)/.exec(t.slice(end, lineEndAfter(t, end)));
        if (!m || m[1]!.length <= col || end >= t.length) break;
        end = lineEndAfter(t, end);
      }
      return { start, end, text: "" };
    }
    const i = map.items.indexOf(pair);
    if (map.items.length === 1) {
      const r = map.range!;
      return { start: r[0], end: r[1], text: "{}" };
    }
    if (i < map.items.length - 1) {
      const comma = t.indexOf(",", vEnd);
      let end = comma + 1;
      while (t[end] === " " || t[end] === "\t") end++;
      if (atLineStart && (t[end] === "\n" || t.startsWith("\r\n", end))) {
        return { start: ls, end: lineEndAfter(t, end), text: "" };
      }
      return { start: kStart, end, text: "" };
    }
    const prev = map.items[i - 1]!;
    const pEnd = ((prev.value ?? prev.key) as YamlNode).range![1];
    return { start: pEnd, end: vEnd, text: "" };
  }

  /** Applies edits (non-overlapping, any order) and re-parses; throws and changes nothing when the result would not parse. */
  private apply(edits: Edit[]): void {
    const sorted = [...edits].sort((a, b) => b.start - a.start);
    let out = this.text;
    for (const e of sorted) out = out.slice(0, e.start) + e.text + out.slice(e.end);
    if (out === this.text) return;
    let doc: Document;
    try {
      doc = parseText(out);
    } catch (e) {
      throw new Error(`the edit would break the file (${errorMessage(e)}); nothing changed`);
    }
    this.text = out;
    this.doc = doc;
  }

  /** Runs several edits as one: when one throws, the text is as before. */
  private transaction(fn: () => void): void {
    const text = this.text;
    const doc = this.doc;
    try {
      fn();
    } catch (e) {
      this.text = text;
      this.doc = doc;
      throw e;
    }
  }
}

/** The references in one key (`Inputs` or `Params`) of block `holder`, added to `out`. */
function keyReferences(holder: string, it: Pair, out: Reference[]): void {
  const k = keyOf(it);
  if (k === "Inputs") inputReferences(holder, it.value, out);
  else if (k === "Params" && isMap(it.value)) triggerReferences(holder, it.value, out);
  else if (k === "Params" && isSeq(it.value)) legacyTriggerReferences(holder, it.value, out);
}

/** The items of an `Inputs` value (a list, or one item) that name a block. */
function inputReferences(holder: string, value: unknown, out: Reference[]): void {
  const items = isSeq(value) ? value.items : [value];
  for (const n of items) {
    const s = isScalar(n) && typeof n.value === "string" ? n.value : undefined;
    if (s === undefined || s === "") continue;
    out.push({
      holder,
      kind: "input",
      node: n as Scalar,
      value: s,
      target: referencedBlock(s),
    });
  }
}

/** Named params that name a block (a Joiner's `Trigger`). */
function triggerReferences(holder: string, params: YAMLMap, out: Reference[]): void {
  for (const q of params.items) {
    const v = q.value;
    if (BLOCK_REF_PARAMS.has(String(keyOf(q))) && isScalar(v) && typeof v.value === "string") {
      out.push({
        holder,
        kind: "trigger",
        node: v,
        value: v.value,
        target: referencedBlock(v.value),
      });
    }
  }
}

/** Positional params that name a block: MOSAIC's `timerBlockName`, in either form. */
function legacyTriggerReferences(holder: string, params: YAMLSeq, out: Reference[]): void {
  for (const n of params.items) {
    if (isScalar(n) && typeof n.value === "string") {
      const m = /^\s*timerBlockName\s*:\s*(.*?)\s*$/.exec(n.value);
      if (m && m[1]) {
        out.push({ holder, kind: "legacy-trigger", node: n, value: n.value, target: m[1] });
      }
    } else if (isMap(n) && n.items.length === 1) {
      const q = n.items[0]!;
      const v = q.value;
      if (keyOf(q) === LEGACY_TRIGGER && isScalar(v) && typeof v.value === "string") {
        out.push({
          holder,
          kind: "legacy-trigger-value",
          node: v,
          value: v.value,
          target: v.value.trim(),
        });
      }
    }
  }
}

function checkRate(rate: number): void {
  if (typeof rate !== "number" || !Number.isFinite(rate) || rate <= 0) {
    throw new Error(`DesiredRate must be a positive number of Hz, not ${String(rate)}`);
  }
}

/**
 * A mapping in block style, each key on its own line at `indent` (text starting with a line
 * break): nested mappings go deeper, a list of values is one `- <flow>` line per item, anything
 * else (scalars, empty collections) stays on the key's line in flow style.
 */
function blockYaml(value: Record<string, unknown>, indent: string, eol: string): string {
  let out = "";
  for (const [k, v] of Object.entries(value)) {
    if (v === undefined) continue;
    out += `${eol}${indent}${scalarYaml(k)}:`;
    if (isPlainRecord(v) && Object.keys(v).length > 0) out += blockYaml(v, `${indent}  `, eol);
    else if (Array.isArray(v) && v.length > 0)
      out += v.map((item) => `${eol}${indent}  - ${flowYaml(item ?? null)}`).join("");
    else out += ` ${flowYaml(v)}`;
  }
  return out;
}

function isPlainRecord(v: unknown): v is Record<string, unknown> {
  if (v === null || typeof v !== "object" || Array.isArray(v)) return false;
  const proto = Object.getPrototypeOf(v) as unknown;
  return proto === Object.prototype || proto === null;
}

function layoutYaml(p: { x: number; y: number }): string {
  checkFinite(p.x, "Layout X");
  checkFinite(p.y, "Layout Y");
  return `{ X: ${Math.round(p.x)}, Y: ${Math.round(p.y)} }`;
}

function isNullish(node: unknown): boolean {
  return node === null || (isScalar(node) && node.value === null);
}

function containsNode(root: unknown, node: unknown): boolean {
  if (root === node) return true;
  if (isMap(root) || isSeq(root)) {
    return (root.items as unknown[]).some((it) =>
      isPair(it)
        ? containsNode(it.key, node) || containsNode(it.value, node)
        : containsNode(it, node),
    );
  }
  return false;
}

/** Start of the line holding `offset`. */
function lineStart(src: string, offset: number): number {
  return src.lastIndexOf("\n", offset - 1) + 1;
}

/** Just after the line break that ends the line holding `offset` (or the end of the text). */
function lineEndAfter(src: string, offset: number): number {
  const nl = src.indexOf("\n", offset);
  return nl < 0 ? src.length : nl + 1;
}

/** Undo/redo over text snapshots (the UI keeps one per open file). */
export class DocumentHistory {
  private readonly undos: string[] = [];
  private redos: string[] = [];

  constructor(
    private now: string,
    readonly limit = 200,
  ) {}

  get current(): string {
    return this.now;
  }
  get canUndo(): boolean {
    return this.undos.length > 0;
  }
  get canRedo(): boolean {
    return this.redos.length > 0;
  }

  /** Records a new state (ignored when equal to the current one); clears what could be redone. */
  push(text: string): void {
    if (text === this.now) return;
    this.undos.push(this.now);
    if (this.undos.length > this.limit) this.undos.splice(0, this.undos.length - this.limit);
    this.redos = [];
    this.now = text;
  }

  /** Steps back; returns the text now current, or undefined when there is nothing to undo. */
  undo(): string | undefined {
    const prev = this.undos.pop();
    if (prev === undefined) return undefined;
    this.redos.push(this.now);
    this.now = prev;
    return prev;
  }

  redo(): string | undefined {
    const next = this.redos.pop();
    if (next === undefined) return undefined;
    this.undos.push(this.now);
    this.now = next;
    return next;
  }

  /** Forgets the history (e.g. another file was opened). */
  reset(text: string): void {
    this.undos.length = 0;
    this.redos = [];
    this.now = text;
  }
}
