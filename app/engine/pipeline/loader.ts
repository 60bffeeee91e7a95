/**
 * Pipeline loader: YAML text → validated PipelineSpec, or diagnostics that name file, line,
 * column, block and parameter (DESIGN.md §2). Never throws on bad input. Its stages, one module
 * each:
 * 1. parse (parse.ts, with the layout pre-pass of yaml-compat.ts): text → `yaml` Document;
 * 2. MOSAIC normalisation (mosaic.ts): the original's old type names, ignored keys, `Path: ''`;
 * 3. block keys (keys.ts): Type, DesiredRate, Inputs, Path, Worker, BatchingMs, Queue, Layout,
 *    and the `Pipeline:` settings;
 * 4. params (params.ts): zod, MOSAIC's positional form converted first (positional.ts);
 * 5. wiring (wiring.ts): inputs, ports and arity.
 * This file walks the top level and hands each block through the stages (load-block.ts). Every stage is linear
 * in the size of the file, and what a file may hold is bounded (LOAD_LIMITS in spec.ts: size,
 * blocks, values in Params, nesting): a refusal is one positioned error that names the limit.
 */
import { isMap, isScalar, type Document, type Node as YamlNode, type YAMLMap } from "yaml";
import type { Catalog } from "../catalog";
import { errorMessage } from "../diagnostics";
import { Collector, describeNode, scalarString } from "./collector";
import { isSettingsEntry, readSettings } from "./keys";
import { loadBlock, type BlockOutcome, type LoadContext, type LoadState } from "./load-block";
import { ignoredKeysWarning, resolvePendingRates } from "./mosaic";
import { lineCounterOf, parseStage } from "./parse";
import {
  BLOCK_NAME_RE,
  LOAD_LIMITS,
  type LoadLimits,
  type LoadResult,
  type PipelineSettings,
  type SourcePos,
} from "./spec";
import { checkWiring } from "./wiring";
import { checkPaths } from "./paths";

export * from "./spec";
export { objectKeys } from "./params";
export { expandParams } from "./load-block";

/**
 * Loads a pipeline file's text (`limits`: LOAD_LIMITS unless a caller raises or lowers them).
 * Never throws on bad input: every problem is a positioned diagnostic.
 */
export function loadPipeline(
  source: string,
  file: string,
  catalog: Catalog,
  limits: LoadLimits = LOAD_LIMITS,
): LoadResult {
  if (source.length > limits.maxChars) {
    const c = new Collector(file, lineCounterOf(""));
    c.error(
      "too-large",
      { line: 1, col: 1 },
      `the file has ${source.length} characters; a pipeline file may have at most ${limits.maxChars}`,
      { expected: "a smaller file: large tables belong in data files (FilePlayer, model files)" },
    );
    return { spec: undefined, diagnostics: c.list, ok: false, doc: undefined };
  }
  const c = new Collector(file, lineCounterOf(source));
  try {
    return loadParsed(c, source, file, catalog, limits);
  } catch (e) {
    // A net under the limits: a structure deeper than the stack was not caught by them.
    if (!(e instanceof RangeError)) throw e;
    c.error(
      "nesting-too-deep",
      { line: 1, col: 1 },
      `the pipeline nests or chains too deeply to load (${errorMessage(e)})`,
    );
    return { spec: undefined, diagnostics: c.list, ok: false, doc: undefined };
  }
}

/** The stages after the size check; `c` holds the diagnostics. */
function loadParsed(
  c: Collector,
  source: string,
  file: string,
  catalog: Catalog,
  limits: LoadLimits,
): LoadResult {
  const parsed = parseStage(c, source, limits);
  const doc = parsed.doc;
  if (!doc || !parsed.ok) return failed(c, doc);
  const root = topLevelMap(c, doc);
  if (!root) return failed(c, doc);

  const settings: PipelineSettings = { batchingMs: undefined };
  const state: LoadState = {
    blocks: [],
    byName: new Map(),
    ignoredKeys: [],
    pendingRates: [],
    values: 0,
  };
  readEntries(c, root, { catalog, limits, doc, aliases: parsed.aliases }, settings, state);
  ignoredKeysWarning(c, state.ignoredKeys);
  resolvePendingRates(c, state.pendingRates, state.byName);

  // Stage 5: wiring.
  checkWiring(c, state.blocks, state.byName, entryNames(root));
  checkPaths(c, state.blocks, doc);

  if (state.blocks.length === 0 && c.errors === 0) {
    c.error("empty", { line: 1, col: 1 }, "the pipeline has no blocks");
  }
  const ok = c.errors === 0;
  return {
    spec: ok ? { file, blocks: state.blocks, byName: state.byName, settings } : undefined,
    diagnostics: c.list,
    ok,
    doc,
  };
}

function failed(c: Collector, doc: Document | undefined): LoadResult {
  return { spec: undefined, diagnostics: c.list, ok: false, doc };
}

/** The document's top-level mapping; undefined (reported) when it is empty or not a mapping. */
function topLevelMap(c: Collector, doc: Document): YAMLMap | undefined {
  const root = doc.contents;
  if (root === null || (isScalar(root) && (root.value === null || root.value === ""))) {
    c.error("empty", { line: 1, col: 1 }, "the pipeline is empty", {
      expected:
        "a mapping from block names to blocks, e.g. `Timer: { Type: ScheduledTimer, DesiredRate: 200 }`",
    });
    return undefined;
  }
  if (!isMap(root)) {
    c.error("not-a-mapping", c.pos(root), `the top level is ${describeNode(root)}`, {
      expected: "a mapping from block names to blocks",
    });
    return undefined;
  }
  return root as YAMLMap;
}

/**
 * The top-level entries in order: the `Pipeline:` settings, and blocks (each through
 * load-block.ts) up to the limit on their number.
 */
function readEntries(
  c: Collector,
  root: YAMLMap,
  ctx: LoadContext,
  settings: PipelineSettings,
  state: LoadState,
): void {
  let entries = 0;
  for (const pair of root.items) {
    const keyNode = pair.key as YamlNode | null;
    const at = c.pos(keyNode);
    const name = scalarString(keyNode);
    if (isSettingsEntry(name, pair.value)) {
      readSettings(c, pair.value as YAMLMap, settings);
      continue;
    }
    if (++entries > ctx.limits.maxBlocks) {
      tooManyBlocks(c, at, ctx.limits.maxBlocks, entries);
      break;
    }
    const value = blockEntryValue(c, name, at, keyNode, pair.value);
    if (name === undefined || !value) continue;
    const outcome: BlockOutcome = loadBlock(c, { name, at, value }, ctx, state);
    if (outcome === "stop") break;
  }
}

function tooManyBlocks(c: Collector, at: SourcePos, maxBlocks: number, entries: number): void {
  c.error(
    "too-many-blocks",
    at,
    `the pipeline has more than ${maxBlocks} blocks; this is block ${entries}`,
    { expected: `at most ${maxBlocks} blocks in one pipeline` },
  );
}

/** A block entry's mapping; undefined (reported) when its name or its value is not valid. */
function blockEntryValue(
  c: Collector,
  name: string | undefined,
  at: SourcePos,
  keyNode: YamlNode | null,
  value: unknown,
): YAMLMap | undefined {
  if (name === undefined || name === "") {
    c.error("bad-name", at, "a block name must be a plain word", {
      expected: "a name like `LowPass`",
    });
    return undefined;
  }
  if (!BLOCK_NAME_RE.test(name)) {
    c.error("bad-name", at, `block name '${name}' is not valid`, {
      block: name,
      expected:
        "letters, digits, '_' or '-', starting with a letter or '_' ('.' is reserved for ports)",
    });
    return undefined;
  }
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
    return undefined;
  }
  return value;
}

/** Every top-level name, settings and refused blocks included (wiring's suggestions). */
function entryNames(root: YAMLMap): string[] {
  return root.items.map((p) => scalarString(p.key)).filter((s): s is string => !!s);
}
