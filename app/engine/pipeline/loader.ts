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
 * This file walks the top level and hands each block through the stages.
 */
import { isMap, isScalar, isSeq, type Node as YamlNode, type Pair, type YAMLMap } from "yaml";
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
import { BLOCK_NAME_RE, type BlockSpec, type LoadResult, type PipelineSettings } from "./spec";
import { checkWiring } from "./wiring";

export * from "./spec";
export { objectKeys } from "./params";

export function loadPipeline(source: string, file: string, catalog: Catalog): LoadResult {
  const c = new Collector(file, lineCounterOf(source));
  const parsed = parseStage(c, source);
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

    // Stage 2: what the original's keys and names mean here.
    const view = mosaicView(value);
    for (const p of view.ignored) ignoredKeys.push({ block: name, pair: p });

    // Stage 3: the block's keys.
    const keys = readBlockKeys(c, name, at, value, catalog, view);
    const def = keys.def;
    if (!def) continue;

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
