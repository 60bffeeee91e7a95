/**
 * One block through the loader's stages (loader.ts walks the top level and calls `loadBlock` for
 * each entry that names a block): MOSAIC normalisation (mosaic.ts), the block's keys (keys.ts),
 * its Params' aliases expanded within the limits on values, MOSAIC's positional Params converted
 * (positional.ts and the old name's rule), params (params.ts), the one warning that says what an
 * old name or positional Params became, and the BlockSpec. Nothing here looks at other blocks:
 * the loader stays linear in their number.
 */
import {
  isAlias,
  isMap,
  isSeq,
  Pair,
  YAMLMap,
  YAMLSeq,
  type Alias,
  type Document,
  type Node as YamlNode,
} from "yaml";
import type { AnyBlockDefinition } from "../block";
import type { Catalog } from "../catalog";
import { errorMessage } from "../diagnostics";
import type { Collector } from "./collector";
import { readBlockKeys, type BlockKeys } from "./keys";
import { LegacyParamsError } from "./legacy";
import { mappingMessage, mosaicView, type PendingRate } from "./mosaic";
import {
  convertedWarning,
  paramKeyPositions,
  paramsText,
  readParams,
  type ParamsResult,
} from "./params";
import { decimalCommaWarning, positionalArgs } from "./positional";
import type { BlockSpec, LoadLimits, SourcePos } from "./spec";

/** What every block is read against. */
export interface LoadContext {
  catalog: Catalog;
  limits: LoadLimits;
  doc: Document;
  /** The parse stage's aliases and what they stand for. */
  aliases: ReadonlyMap<Alias, YamlNode>;
}

/** What the blocks read so far leave for the whole pipeline. */
export interface LoadState {
  blocks: BlockSpec[];
  byName: Map<string, BlockSpec>;
  /** The original's keys this loader ignores, warned about once at the end. */
  ignoredKeys: { block: string; pair: Pair }[];
  /** Blocks whose DesiredRate is their input's divided by a factor (mosaic.ts). */
  pendingRates: PendingRate[];
  /** The values in the Params of the blocks read so far (aliases expanded). */
  values: number;
}

/** A top-level entry that names a block: its name, where the name is, its mapping. */
export interface BlockEntry {
  name: string;
  at: SourcePos;
  value: YAMLMap;
}

/** "stop": a limit on the whole pipeline was reached (reported); read no further block. */
export type BlockOutcome = "next" | "stop";

/** MOSAIC's positional Params as the new block takes them, and an old name's rate divisor. */
interface LegacyArgs {
  /** False when the old name's rule refused the Params (reported). */
  ok: boolean;
  args: readonly string[] | undefined;
  divisor: number | undefined;
}

/** Stages 2 to 4 for one block; the BlockSpec is added to `state` when it has no error. */
export function loadBlock(
  c: Collector,
  entry: BlockEntry,
  ctx: LoadContext,
  state: LoadState,
): BlockOutcome {
  const { name, value } = entry;
  const errorsBefore = c.errors;

  // Stage 2: what the original's keys and names mean here.
  const view = mosaicView(value);
  for (const p of view.ignored) state.ignoredKeys.push({ block: name, pair: p });

  // Stage 3: the block's keys.
  const keys = readBlockKeys(c, name, entry.at, value, ctx.catalog, view);
  const def = keys.def;
  if (!def) return "next";

  const expanded = expandBlockParams(c, name, keys, ctx.limits, ctx.aliases, state);
  if (expanded !== "ok") return expanded;

  // Stage 4: params, positional ones as the original's blocks read them.
  const legacy = legacyArgs(c, name, keys, def);
  const params = legacy.ok
    ? readParams(c, {
        block: name,
        def,
        doc: ctx.doc,
        node: keys.paramsNode,
        pos: keys.paramsPos,
        args: legacy.args,
      })
    : undefined;
  const converted = convertedText(params);
  const mapping = conversionWarning(c, name, keys, def, params, converted);

  if (c.errors > errorsBefore || !params?.ok) return "next";
  const spec = blockSpec(c, entry, keys, def, params);
  state.blocks.push(spec);
  state.byName.set(name, spec);
  if (legacy.divisor !== undefined && mapping) {
    state.pendingRates.push({
      spec,
      divisor: legacy.divisor,
      at: keys.paramsPos,
      warning: mapping,
      withParams: converted !== undefined,
    });
  }
  return "next";
}

/**
 * The block's Params with their aliases expanded (copies) into `keys.paramsNode`, within the
 * limits on the values of one block and of the whole pipeline. "next": this block's Params are
 * too large (reported); "stop": the pipeline's are (reported).
 */
function expandBlockParams(
  c: Collector,
  name: string,
  keys: BlockKeys,
  limits: LoadLimits,
  aliases: ReadonlyMap<Alias, YamlNode>,
  state: LoadState,
): "ok" | BlockOutcome {
  const expanded = expandParams(keys.paramsNode, aliases, limits.maxParamsValues);
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
    return "next";
  }
  state.values += expanded.values;
  if (state.values > limits.maxValues) {
    c.error(
      "too-many-values",
      keys.paramsPos,
      `the Params of the pipeline's blocks hold more than ${limits.maxValues} values in all (aliases expanded); this block's reach past it`,
      { block: name },
    );
    return "stop";
  }
  keys.paramsNode = expanded.node;
  return "ok";
}

/**
 * Positional Params (a list) as strings, warned about when they hold decimal commas, and what an
 * old type name's rule makes of them: the new block's args (named Params, a mapping, are already
 * in its form) and the rate divisor. A rule that refuses them is a positioned error.
 */
function legacyArgs(
  c: Collector,
  name: string,
  keys: BlockKeys,
  def: AnyBlockDefinition,
): LegacyArgs {
  const written = isSeq(keys.paramsNode) ? positionalArgs(keys.paramsNode) : undefined;
  if (isSeq(keys.paramsNode)) decimalCommaWarning(c, name, keys.paramsNode);
  const rule = keys.rule;
  const result: LegacyArgs = { ok: true, args: written, divisor: undefined };
  if (!rule) return result;
  try {
    if (rule.rateDivisor) result.divisor = rule.rateDivisor(written);
    if (rule.args && !isMap(keys.paramsNode)) result.args = rule.args(written);
  } catch (e) {
    result.ok = false;
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
  return result;
}

/** "Params {…}" for the named params positional ones became; undefined when there are none. */
function convertedText(params: ParamsResult | undefined): string | undefined {
  return params?.converted !== undefined && !isEmptyObject(params.converted)
    ? `Params ${paramsText(params.converted)}`
    : undefined;
}

/**
 * One warning per block: what an old name became (returned: an old TimerDecimator's rate is
 * added to it later), or else what positional Params became.
 */
function conversionWarning(
  c: Collector,
  name: string,
  keys: BlockKeys,
  def: AnyBlockDefinition,
  params: ParamsResult | undefined,
  converted: string | undefined,
): { message: string } | undefined {
  if (keys.renamed && keys.written !== undefined) {
    return c.warn(
      "type-alias",
      keys.typePos,
      mappingMessage(name, keys.written, def, keys.rule, converted),
      { block: name },
    );
  }
  if (params?.converted !== undefined) {
    convertedWarning(c, name, def.type, keys.paramsPos, params.converted);
  }
  return undefined;
}

function blockSpec(
  c: Collector,
  entry: BlockEntry,
  keys: BlockKeys,
  def: AnyBlockDefinition,
  params: ParamsResult,
): BlockSpec {
  return {
    name: entry.name,
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
    pos: entry.at,
    paramsPos: keys.paramsPos,
    inputsPos: keys.inputsPos,
    paramPos: paramKeyPositions(c, keys.paramsNode),
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
  return { node: copyAliases(node, aliases), values };
}

/** `n` with its aliases replaced by copies of what they stand for (expandParams). */
function copyAliases(n: unknown, aliases: ReadonlyMap<Alias, YamlNode>): unknown {
  // Recursion is bounded: the parse stage refused aliases that nest deeper than maxDepth.
  if (isAlias(n)) {
    const target = aliases.get(n);
    return target ? copyAliases(target, aliases) : n;
  }
  if (isMap(n)) {
    const m = new YAMLMap();
    Object.assign(m, { range: n.range, flow: n.flow, tag: n.tag });
    m.items = n.items.map(
      (p) => new Pair(copyAliases(p.key, aliases), copyAliases(p.value, aliases)),
    );
    return m;
  }
  if (isSeq(n)) {
    const s = new YAMLSeq();
    Object.assign(s, { range: n.range, flow: n.flow, tag: n.tag });
    s.items = n.items.map((it) => copyAliases(it, aliases));
    return s;
  }
  return n;
}
