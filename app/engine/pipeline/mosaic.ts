/**
 * Loader stage 2, MOSAIC normalisation: what files written for the original MOSAIC say, in the
 * words of this one. Every compatibility rule about the original's names and keys lives here
 * (docs/mosaic-compatibility.md lists them):
 * - `MOSAIC_TYPES`: the original's old or misspelt type names, each mapped to one of our blocks
 *   (with what its positional Params and DesiredRate become); a name whose block is not in the
 *   catalog yet says so;
 * - `ORIGINAL_TYPES` and `UNDEFINED_TYPES`: what an unknown type's error adds (a block of the
 *   original not available yet; a name no public source defines, so not a typo);
 * - `IGNORED_KEYS`: keys of older files that are ignored with one warning per file;
 * - `Path: ''`: the original logged to the drive's root; here to the log folder.
 * Simple renames that belong to a block (MYO → Myo, MeanAverageValue → MeanAbsoluteValue) are
 * that block's `aliases`; either way a block loaded under another name gets ONE warning that says
 * what it became (`mappingMessage`).
 */
import { isScalar, type Node as YamlNode, type Pair, type YAMLMap } from "yaml";
import type { AnyBlockDefinition } from "../block";
import type { Catalog } from "../catalog";
import { legacyInteger, LegacyParamsError } from "./legacy";
import { Collector, scalarString } from "./collector";
import type { BlockSpec, SourcePos } from "./spec";

/** One of the original's type names that loads as one of our blocks. */
export interface MosaicTypeRule {
  /** Our block type it loads as. */
  type: string;
  /** What the name was, for the warning: "the original MOSAIC's old name of ScheduledTimer". */
  was: string;
  /**
   * Rewrites the positional Params (undefined: the block has no `Params`) into `type`'s
   * positional form; throws LegacyParamsError when they cannot be.
   */
  args?: (args: readonly string[] | undefined) => string[];
  /**
   * The block's DesiredRate is its (timer) input's rate divided by this number, read from the
   * positional Params (TimerDecimator's decimation factor).
   */
  rateDivisor?: (args: readonly string[] | undefined) => number;
}

const ORIGINAL = "the original MOSAIC's";

/** The original's type names that load as one of our blocks (checked after the catalog). */
export const MOSAIC_TYPES: Readonly<Record<string, MosaicTypeRule>> = {
  // Older files used the abstract base class as a periodic timer.
  Timer: { type: "ScheduledTimer", was: `${ORIGINAL} old name of ScheduledTimer` },
  // `Params: [ 8 ]`: every 8th tick of its input timer.
  TimerDecimator: {
    type: "DecimatorTimer",
    was: `${ORIGINAL} old name of DecimatorTimer (Params: [factor], every factor-th tick)`,
    args: () => [],
    rateDivisor: (args) => {
      const a = args?.[0];
      if (a === undefined || a.trim() === "")
        throw new LegacyParamsError("expected the decimation factor, e.g. Params: [ 8 ]");
      const f = legacyInteger(a, "decimation factor");
      if (f < 1) throw new LegacyParamsError(`decimation factor '${a}' is not 1 or more`);
      return f;
    },
  },
  // `Params: [ 5 ]`: multiply by 5.
  Func_Multiplier: {
    type: "Function",
    was: `${ORIGINAL} old name of Function multiply (Params: [factor])`,
    args: (args) => {
      const k = args?.[0];
      if (k === undefined || k.trim() === "")
        throw new LegacyParamsError("expected the factor, e.g. Params: [ 5 ]", "Value");
      return [`multiply:${k}`];
    },
  },
  Func_Rectifier: {
    type: "Function",
    was: `${ORIGINAL} old name of Function abs`,
    args: () => ["abs:0"],
  },
  // The original looked class names up case-sensitively: this spelling never loaded there.
  vectorialFunction: {
    type: "VectorialFunction",
    was: "a misspelling of VectorialFunction (the original MOSAIC's type names are case-sensitive)",
  },
  // HannesGUI takes [host, port, nRawEMGBytes, nARVBytes] and three inputs; the old files give
  // [host, port] and one input. Its block decides what to make of that.
  HannesArm: { type: "HannesGUI", was: `${ORIGINAL} old name of HannesGUI` },
};

/** Every `Type` the original MOSAIC accepts: its block classes (reference §3). */
export const ORIGINAL_TYPES: ReadonlySet<string> = new Set([
  "ScheduledTimer",
  "DecimatorTimer",
  "SinGenerator",
  "Myo",
  "Muovi",
  "MuoviSingleProbe",
  "Delsys",
  "DLR_ADCBT",
  "NilsPod",
  "HannesReceiver",
  "Stimulus",
  "BlenderArm",
  "HannesHand",
  "HannesGUI",
  "UDP_StreamlinedSender",
  "Trigger",
  "StimTrigger",
  "Buffer",
  "Switch",
  "Selector",
  "Projector",
  "SlidingWindow",
  "MeanAverageValue",
  "WaveformLength",
  "ZeroCrossings",
  "SlopeSignChanges",
  "FilePlayer",
  "Function",
  "Filter",
  "AdaptiveFilter",
  "Resampler",
  "Joiner",
  "VectorialFunction",
  "ROS",
  "PythonNetFiltUC",
  "IncrementalPredictor",
  "BatchPredictor",
  "TAC",
  "PythonNetLearning",
  "SimplePyTorch",
  "iNMF",
  "ControlAlgorithm",
]);

/**
 * Types the original's older example files use that no public source defines (neither the
 * original's library nor anything else published): there is nothing to load them as.
 */
export const UNDEFINED_TYPES: ReadonlySet<string> = new Set(["FBGS", "hyperplaneFitting"]);

/** Keys of the original's older files that we ignore, and why. */
export const IGNORED_KEYS: Readonly<Record<string, string>> = {
  OutputType:
    "an output-shape hint of the original's older files; our blocks take their output shape from their inputs and params",
};

/** How a block's `Type` is looked up: the name itself, or the block an old name maps to. */
export interface TypeLookup {
  /** The name to look up in the catalog. */
  lookup: string;
  /** The rule of an old name (undefined when the name is looked up as it is). */
  rule: MosaicTypeRule | undefined;
}

/** The catalog's own names (and block aliases) win; then the original's old names. */
export function mosaicType(written: string, catalog: Catalog): TypeLookup {
  if (catalog.has(written)) return { lookup: written, rule: undefined };
  const rule = Object.hasOwn(MOSAIC_TYPES, written) ? MOSAIC_TYPES[written] : undefined;
  return rule ? { lookup: rule.type, rule } : { lookup: written, rule: undefined };
}

/** What the error for a type name the catalog does not have adds, if anything. */
export function unknownTypeNote(written: string, catalog: Catalog): string | undefined {
  const rule = Object.hasOwn(MOSAIC_TYPES, written) ? MOSAIC_TYPES[written] : undefined;
  if (rule && !catalog.has(rule.type))
    return `'${written}' is ${rule.was}, a block that is not available yet`;
  if (UNDEFINED_TYPES.has(written))
    return `no public source of the original MOSAIC defines '${written}' (it is not a typo of a block type here), so there is nothing to load it as`;
  if (ORIGINAL_TYPES.has(written))
    return `'${written}' is a block of the original MOSAIC that is not available yet`;
  return undefined;
}

/** What stage 2 found in one block. */
export interface MosaicView {
  /** Keys of the original's older files present in the block (ignored). */
  ignored: Pair[];
  /** `Path: ''`: the scalar, when the block has it. */
  emptyPath: YamlNode | undefined;
}

/** Stage 2 for one block: the keys to ignore and the original's empty Path. */
export function mosaicView(map: YAMLMap): MosaicView {
  const ignored: Pair[] = [];
  let emptyPath: YamlNode | undefined;
  for (const it of map.items) {
    const k = scalarString(it.key) ?? "";
    if (Object.hasOwn(IGNORED_KEYS, k)) ignored.push(it);
    if (k === "Path" && isScalar(it.value) && it.value.value === "") emptyPath = it.value;
  }
  return { ignored, emptyPath };
}

/** Where `Path: ''` logs: the log folder itself (the pipeline's, or `mosaic run --log-dir`). */
export const EMPTY_PATH = ".";

/** The warning for `Path: ''` (the original logged to `\<block>.txt` at the drive's root). */
export function emptyPathWarning(c: Collector, block: string, node: YamlNode): void {
  c.warn(
    "mosaic-path",
    c.pos(node),
    `block '${block}': Path '' logged to the root of the drive in the original MOSAIC; here it logs to ${block}.txt in the log folder (the pipeline's folder, or mosaic run --log-dir)`,
    { block, param: "Path" },
  );
}

/** ONE warning per file for the ignored keys, at the first one, naming every block that has one. */
export function ignoredKeysWarning(c: Collector, found: { block: string; pair: Pair }[]): void {
  if (found.length === 0) return;
  const keys = [...new Set(found.map((f) => scalarString(f.pair.key) ?? ""))];
  const blocks = [...new Set(found.map((f) => f.block))];
  const why = keys.map((k) => `${k} is ${IGNORED_KEYS[k]}`).join("; ");
  c.warn(
    "ignored-key",
    c.pos(found[0]!.pair.key as YamlNode),
    `${keys.join(", ")} (on ${blocks.length} block${blocks.length === 1 ? "" : "s"}: ${blocks.join(", ")}) ignored: ${why}`,
  );
}

/** The one warning for a block loaded under another name: what it became. */
export function mappingMessage(
  block: string,
  written: string,
  def: AnyBlockDefinition,
  rule: MosaicTypeRule | undefined,
  converted: string | undefined,
): string {
  const was = rule ? rule.was : `the old name of ${def.type}`;
  return `block '${block}': '${written}' is ${was}; loading it as ${def.type}${converted !== undefined ? ` with ${converted}` : ""}`;
}

/** A block whose DesiredRate comes from its input's (an old TimerDecimator). */
export interface PendingRate {
  spec: BlockSpec;
  divisor: number;
  /** Where the block's Params are (errors). */
  at: SourcePos;
  /** Its mapping warning, completed with the rate. */
  warning: { message: string };
  /** True when the warning already says "with Params …". */
  withParams: boolean;
}

/**
 * After every block is read: the DesiredRate of each block whose rate is its input's divided by
 * a factor (chains of them too), and the rate added to its mapping warning. A block whose input
 * rate is unknown is an error.
 */
export function resolvePendingRates(
  c: Collector,
  pending: PendingRate[],
  byName: ReadonlyMap<string, BlockSpec>,
): void {
  const waiting = new Map(pending.map((p) => [p.spec, p]));
  const visiting = new Set<BlockSpec>();
  const rateOf = (spec: BlockSpec): number | undefined => {
    const p = waiting.get(spec);
    if (!p) return spec.desiredRate;
    if (visiting.has(spec)) return undefined;
    visiting.add(spec);
    const input = spec.inputs[0];
    const src = input ? byName.get(input.block) : undefined;
    const inRate = src ? rateOf(src) : undefined;
    visiting.delete(spec);
    waiting.delete(spec);
    if (!input) return undefined; // the wiring stage reports the missing input
    if (inRate === undefined) {
      c.error(
        "missing-rate",
        p.at,
        `block '${spec.name}' (${spec.type}): its DesiredRate is its input's divided by ${p.divisor}, but input '${input.block}' has no known rate`,
        {
          block: spec.name,
          expected: "a timer input with a DesiredRate",
        },
      );
      return undefined;
    }
    spec.desiredRate = inRate / p.divisor;
    p.warning.message += `${p.withParams ? " and" : " with"} DesiredRate ${formatRate(spec.desiredRate)} Hz (${input.block}'s ${formatRate(inRate)} Hz / ${p.divisor})`;
    return spec.desiredRate;
  };
  for (const p of pending) rateOf(p.spec);
}

const formatRate = (hz: number) => String(Number(hz.toPrecision(12)));
