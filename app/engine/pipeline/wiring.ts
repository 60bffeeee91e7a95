/**
 * Loader stage 5, wiring: every input names a block of the pipeline (and one of its output
 * ports), and every block has as many inputs as its type takes. Resolves each input's default
 * port.
 */
import { closest } from "../suggest";
import type { Collector } from "./collector";
import type { BlockSpec, InputRef } from "./spec";

const MAX_SUGGESTIONS = 100;
const MAX_LISTED = 50;

/** What checking every input shares. */
interface WiringContext {
  readonly c: Collector;
  readonly byName: ReadonlyMap<string, BlockSpec>;
  readonly allNames: readonly string[];
  /** `allNames` as a set. */
  readonly named: ReadonlySet<string>;
  /**
   * Suggestions made so far. Suggestions compare a name with every other: only for the first few
   * (a file of thousands of dangling inputs stays linear), and the names are listed only when
   * there are few.
   */
  suggestions: number;
}

/**
 * Stage 5. `allNames`: every top-level name of the file, so that an input naming a block that
 * has its own error is not reported a second time.
 */
export function checkWiring(
  c: Collector,
  blocks: readonly BlockSpec[],
  byName: ReadonlyMap<string, BlockSpec>,
  allNames: readonly string[],
): void {
  const ctx: WiringContext = { c, byName, allNames, named: new Set(allNames), suggestions: 0 };
  for (const b of blocks) {
    for (const inp of b.inputs) checkInput(ctx, b, inp);
    checkInputCount(c, b);
  }
}

/** One input of `b`: its block exists and has its port (an empty port becomes the default). */
function checkInput(ctx: WiringContext, b: BlockSpec, inp: InputRef): void {
  const src = ctx.byName.get(inp.block);
  if (!src) {
    if (ctx.named.has(inp.block)) return; // that block has its own error already
    reportMissingInput(ctx, b, inp);
    return;
  }
  if (inp.port === "") {
    inp.port = src.outputs[0] ?? "out";
  } else if (!src.outputs.includes(inp.port)) {
    reportMissingPort(ctx.c, b, inp, src);
  }
}

/** An input naming no block of the file. */
function reportMissingInput(ctx: WiringContext, b: BlockSpec, inp: InputRef): void {
  const { allNames } = ctx;
  const suggestion = ctx.suggestions++ < MAX_SUGGESTIONS ? closest(inp.block, allNames) : undefined;
  ctx.c.error(
    "missing-input",
    inp.pos,
    `block '${b.name}': input '${inp.block}' is not a block in this pipeline`,
    {
      block: b.name,
      ...(suggestion !== undefined
        ? { suggestion }
        : {
            expected:
              allNames.length <= MAX_LISTED
                ? `one of ${allNames.join(", ")}`
                : "the name of a block of this pipeline",
          }),
    },
  );
}

/** An input naming a port that its block `src` does not have. */
function reportMissingPort(c: Collector, b: BlockSpec, inp: InputRef, src: BlockSpec): void {
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

/** `b` has as many inputs as its type takes. */
function checkInputCount(c: Collector, b: BlockSpec): void {
  const n = b.inputs.length;
  const { min, max } = b.def.inputs;
  if (!(n < min || n > max)) return;
  const want =
    min === max
      ? `exactly ${min}`
      : max === Infinity
        ? `at least ${min}`
        : `between ${min} and ${max}`;
  // The noun agrees with the number it ends on: "at least 1 input", "between 1 and 2 inputs".
  const last = max === Infinity ? min : max;
  const labels = b.def.inputs.labels ? ` (${b.def.inputs.labels.join(", ")})` : "";
  c.error(
    "input-count",
    b.inputsPos,
    `block '${b.name}' (${b.type}) has ${n} input${n === 1 ? "" : "s"}`,
    {
      block: b.name,
      expected: `${want} input${last === 1 ? "" : "s"}${labels}`,
    },
  );
}
