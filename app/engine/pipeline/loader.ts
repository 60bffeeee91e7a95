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
 * This file walks the top level and hands each block through the stages. Every stage is linear
 * in the size of the file, and what a file may hold is bounded (LOAD_LIMITS in spec.ts: size,
 * blocks, values in Params, nesting): a refusal is one positioned error that names the limit.
 */
import {
  isAlias,
  isMap,
  isScalar,
  isSeq,
  Pair,
  YAMLMap,
  YAMLSeq,
  type Alias,
  type Node as YamlNode,
} from "yaml";
import type { Catalog } from "../catalog";
import { errorMessage } from "../diagnostics";
import { Collector, describeNode, scalarString } from "./collector";
import { isSettingsEntry, readBlockKeys, readSettings } from "./keys";
import {
  ignoredKeysWarning,
  mappingMessage,
  mosaicView,
  resolvePendingRates,
  type PendingRate,
} from "./mosaic";
import { convertedWarning, paramKeyPositions, paramsText, readParams } from "./params";
import { lineCounterOf, parseStage } from "./parse";
import { LegacyParamsError } from "./legacy";
import { decimalCommaWarning, positionalArgs } from "./positional";
import {
  BLOCK_NAME_RE,
  LOAD_LIMITS,
  type BlockSpec,
  type LoadLimits,
  type LoadResult,
  type PipelineSettings,
} from "./spec";
import { checkWiring } from "./wiring";
import { checkPaths } from "./paths";

export * from "./spec";
export { objectKeys } from "./params";

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

function loadParsed(
  c: Collector,
  source: string,
  file: string,
  catalog: Catalog,
  limits: LoadLimits,
): LoadResult {
  const parsed = parseStage(c, source, limits);
  const doc = parsed.doc;
  if (!doc || !parsed.ok) return { spec: undefined, diagnostics: c.list, ok: false, doc };
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
  const settings: PipelineSettings = { batchingMs: undefined };
  const ignoredKeys: { block: string; pair: Pair }[] = [];
  const pendingRates: PendingRate[] = [];
  let entries = 0;
  let values = 0;

  for (const pair of (root as YAMLMap).items) {
    const keyNode = pair.key as YamlNode | null;
    const at = c.pos(keyNode);
    const name = scalarString(keyNode);
    if (isSettingsEntry(name, pair.value)) {
      readSettings(c, pair.value as YAMLMap, settings);
      continue;
    }
    if (++entries > limits.maxBlocks) {
      c.error(
        "too-many-blocks",
        at,
        `the pipeline has more than ${limits.maxBlocks} blocks; this is block ${entries}`,
        { expected: `at most ${limits.maxBlocks} blocks in one pipeline` },
      );
      break;
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

    // Stage 2: what the original's keys and names mean here.
    const view = mosaicView(value);
    for (const p of view.ignored) ignoredKeys.push({ block: name, pair: p });

    // Stage 3: the block's keys.
    const keys = readBlockKeys(c, name, at, value, catalog, view);
    const def = keys.def;
    if (!def) continue;

    // Params with their aliases expanded (copies), within the limits on values.
    const expanded = expandParams(keys.paramsNode, parsed.aliases, limits.maxParamsValues);
    if (!expanded) {
      c.error(
        "too-many-values",
        keys.paramsPos,
        `block '${name}': Params hold more than ${limits.maxParamsValues} values (list items, keys and values, aliases expanded)`,
        {
          block: name,
          expected: "large tables in a data file (FilePlayer, a model file) instead of in Params",
        },
      );
      continue;
    }
    values += expanded.values;
    if (values > limits.maxValues) {
      c.error(
        "too-many-values",
        keys.paramsPos,
        `the Params of the pipeline's blocks hold more than ${limits.maxValues} values in all (aliases expanded); this block's reach past it`,
        { block: name },
      );
      break;
    }
    keys.paramsNode = expanded.node;

    // Stage 4: params, positional ones as the original's blocks read them.
    const written = isSeq(keys.paramsNode) ? positionalArgs(keys.paramsNode) : undefined;
    if (isSeq(keys.paramsNode)) decimalCommaWarning(c, name, keys.paramsNode);
    const rule = keys.rule;
    let args = written;
    let ruleOk = true;
    let divisor: number | undefined;
    if (rule) {
      try {
        if (rule.rateDivisor) divisor = rule.rateDivisor(written);
        // Named params (a mapping) are already in the new block's form.
        if (rule.args && !isMap(keys.paramsNode)) args = rule.args(written);
      } catch (e) {
        ruleOk = false;
        c.error(
          "legacy-params",
          keys.paramsPos,
          `block '${name}' (${keys.written} → ${def.type}): cannot convert positional Params [${(written ?? []).join(", ")}]: ${errorMessage(e)}`,
          {
            block: name,
            ...(e instanceof LegacyParamsError && e.param ? { param: e.param } : {}),
          },
        );
      }
    }
    const params = ruleOk
      ? readParams(c, {
          block: name,
          def,
          doc,
          node: keys.paramsNode,
          pos: keys.paramsPos,
          args,
        })
      : undefined;

    // One warning per block: what an old name became, or what positional Params became.
    const converted =
      params?.converted !== undefined && !isEmptyObject(params.converted)
        ? `Params ${paramsText(params.converted)}`
        : undefined;
    let mapping: { message: string } | undefined;
    if (keys.renamed && keys.written !== undefined) {
      mapping = c.warn(
        "type-alias",
        keys.typePos,
        mappingMessage(name, keys.written, def, rule, converted),
        { block: name },
      );
    } else if (params?.converted !== undefined) {
      convertedWarning(c, name, def.type, keys.paramsPos, params.converted);
    }

    if (c.errors > errorsBefore || !params?.ok) continue;
    const spec: BlockSpec = {
      name,
      type: def.type,
      def,
      params: params.params,
      desiredRate: keys.desiredRate,
      inputs: keys.inputs,
      path: keys.path,
      worker: keys.worker,
      batchingMs: keys.batchingMs,
      queue: keys.queue,
      layout: keys.layout,
      outputs: params.outputs,
      legacy: params.converted !== undefined,
      pos: at,
      paramsPos: keys.paramsPos,
      inputsPos: keys.inputsPos,
      paramPos: paramKeyPositions(c, keys.paramsNode),
    };
    blocks.push(spec);
    byName.set(name, spec);
    if (divisor !== undefined && mapping) {
      pendingRates.push({
        spec,
        divisor,
        at: keys.paramsPos,
        warning: mapping,
        withParams: converted !== undefined,
      });
    }
  }
  ignoredKeysWarning(c, ignoredKeys);
  resolvePendingRates(c, pendingRates, byName);

  // Stage 5: wiring.
  const allNames = (root as YAMLMap).items
    .map((p) => scalarString(p.key))
    .filter((s): s is string => !!s);
  checkWiring(c, blocks, byName, allNames);
  checkPaths(c, blocks, doc);

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

function isEmptyObject(v: unknown): boolean {
  return typeof v === "object" && v !== null && !Array.isArray(v) && Object.keys(v).length === 0;
}

/**
 * A block's Params node with its aliases expanded into copies (the document itself is not
 * changed: editors keep the file as written), and the values it holds; undefined when it holds
 * more than `max`. Without aliases the node is returned as it is. Copies keep the ranges of what
 * they copy, so errors point at the text an alias stands for.
 */
export function expandParams(
  node: unknown,
  aliases: ReadonlyMap<Alias, YamlNode>,
  max: number,
): { node: unknown; values: number } | undefined {
  let values = 0;
  let hasAlias = false;
  const stack: unknown[] = [node];
  while (stack.length > 0) {
    const n = stack.pop();
    if (n === null || n === undefined) continue;
    if (isAlias(n)) {
      hasAlias = true;
      const target = aliases.get(n);
      if (target) {
        stack.push(target);
        continue;
      }
    }
    if (++values > max) return undefined;
    if (isMap(n)) for (const p of n.items) stack.push(p.key, p.value);
    else if (isSeq(n)) for (const it of n.items) stack.push(it);
  }
  if (!hasAlias) return { node, values };
  // Recursion is bounded: the parse stage refused aliases that nest deeper than maxDepth.
  const copy = (n: unknown): unknown => {
    if (isAlias(n)) {
      const target = aliases.get(n);
      return target ? copy(target) : n;
    }
    if (isMap(n)) {
      const m = new YAMLMap();
      Object.assign(m, { range: n.range, flow: n.flow, tag: n.tag });
      m.items = n.items.map((p) => new Pair(copy(p.key), copy(p.value)));
      return m;
    }
    if (isSeq(n)) {
      const s = new YAMLSeq();
      Object.assign(s, { range: n.range, flow: n.flow, tag: n.tag });
      s.items = n.items.map(copy);
      return s;
    }
    return n;
  };
  return { node: copy(node), values };
}
