/**
 * Loader stage 4, params: a block's `Params` validated by its zod schema, MOSAIC's positional form
 * converted first (the block's `legacyParams`). Each zod issue becomes one error positioned at the
 * param it is about, with what was expected and the closest valid name for typos.
 */
import { isMap, isPair, isScalar, isSeq, type Document, type Node as YamlNode } from "yaml";
import type { z } from "zod";
import { outputNames, type AnyBlockDefinition } from "../block";
import { errorMessage } from "../diagnostics";
import { closest } from "../suggest";
import { Collector, describeNode, describeValue, isNullish, scalarString } from "./collector";
import { LegacyParamsError } from "./legacy";
import type { SourcePos } from "./spec";

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
export function paramsText(v: unknown): string {
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

/** Where each key of a Params mapping is, for errors found after validation. */
export function paramKeyPositions(c: Collector, paramsNode: unknown): Record<string, SourcePos> {
  const out: Record<string, SourcePos> = {};
  if (isMap(paramsNode)) {
    for (const p of paramsNode.items) {
      const k = scalarString(p.key);
      if (k !== undefined) out[k] = c.pos(p.key as YamlNode);
    }
  }
  return out;
}

/** Formats one zod issue as a sentence, with what was expected and a suggestion for typos. */
export function explainIssue(
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

/** One block's Params as stage 4 sees them. */
export interface ParamsInput {
  block: string;
  def: AnyBlockDefinition;
  doc: Document;
  /** The Params node (undefined: no Params key). */
  node: unknown;
  /** Where Params is (the block's name when it has none). */
  pos: SourcePos;
  /**
   * MOSAIC's positional form to convert: the list's items as strings (positional.ts), or what an
   * old type name makes of them; undefined for named params.
   */
  args: readonly string[] | undefined;
}

export interface ParamsResult {
  ok: boolean;
  /** Validated params (zod output: defaults applied). */
  params: unknown;
  /** The named params the positional form was converted to (undefined: not positional). */
  converted: unknown;
  outputs: readonly string[];
}

/** Stage 4 for one block: convert, validate, resolve the output ports. */
export function readParams(c: Collector, p: ParamsInput): ParamsResult {
  const knownKeys = objectKeys(p.def.params);
  const read = rawParams(c, p, knownKeys);
  if (!read) return failed(undefined);
  const r = p.def.params.safeParse(read.raw, { reportInput: true });
  if (!r.success) {
    for (const issue of r.error.issues) reportIssue(c, p, issue, knownKeys, read.legacy);
    return failed(undefined);
  }
  return withOutputs(c, p, r.data, read.legacy ? read.raw : undefined);
}

/** The result of a block whose Params failed (its outputs: the default port). */
function failed(converted: unknown): ParamsResult {
  return { ok: false, params: undefined, converted, outputs: ["out"] };
}

/** What is validated: the Params as JS, and whether they were converted from the positional form. */
interface RawParams {
  raw: unknown;
  legacy: boolean;
}

/** The Params to validate, or undefined once an error is reported (they are not a mapping). */
function rawParams(
  c: Collector,
  p: ParamsInput,
  knownKeys: string[] | undefined,
): RawParams | undefined {
  const { block, def, node, pos } = p;
  if (p.args !== undefined) return convertPositional(c, p, p.args, knownKeys);
  if (isNullish(node)) return { raw: {}, legacy: false };
  if (isMap(node)) {
    try {
      return { raw: node.toJS(p.doc), legacy: false };
    } catch (e) {
      c.error("bad-params", pos, `block '${block}': cannot read Params: ${errorMessage(e)}`, {
        block,
      });
      return undefined;
    }
  }
  c.error("bad-params", pos, `block '${block}' (${def.type}): Params is ${describeNode(node)}`, {
    block,
    expected: `a mapping${knownKeys && knownKeys.length ? ` with ${knownKeys.join(", ")}` : ""}${def.legacyParams ? ", or MOSAIC's positional list" : ""}`,
  });
  return undefined;
}

/** MOSAIC's positional form converted by the block's `legacyParams` (undefined: an error reported). */
function convertPositional(
  c: Collector,
  p: ParamsInput,
  args: readonly string[],
  knownKeys: string[] | undefined,
): RawParams | undefined {
  const { block, def, pos } = p;
  const type = def.type;
  if (!def.legacyParams) {
    c.error(
      "legacy-unsupported",
      pos,
      `block '${block}' (${type}): Params is a positional list, but ${type} has no positional form`,
      {
        block,
        expected: `named params: a mapping with ${knownKeys && knownKeys.length ? knownKeys.join(", ") : "no keys"}`,
      },
    );
    return undefined;
  }
  const positional = args.length === 1 && args[0] === "" ? [] : args;
  try {
    return { raw: def.legacyParams(positional), legacy: true };
  } catch (e) {
    c.error(
      "legacy-params",
      pos,
      `block '${block}' (${type}): cannot convert positional Params [${args.join(", ")}]: ${errorMessage(e)}`,
      {
        block,
        ...(e instanceof LegacyParamsError && e.param ? { param: e.param } : {}),
        ...(def.legacyForm ? { expected: def.legacyForm } : {}),
      },
    );
    return undefined;
  }
}

/** Reports one zod issue at the param it is about (at Params after a conversion). */
function reportIssue(
  c: Collector,
  p: ParamsInput,
  issue: z.core.$ZodIssue,
  knownKeys: string[] | undefined,
  legacy: boolean,
): void {
  const { block, node, pos } = p;
  const type = p.def.type;
  const path = pathText(issue.path);
  const at = legacy ? undefined : nodeAtPath(node, issue.path);
  const where = at ? c.pos(at) : pos;
  const ex = explainIssue(issue, knownKeys);
  const subject = path === "" ? "Params" : `param '${path}'`;
  const unknownKey = issue.code === "unrecognized_keys";
  let kpos = where;
  if (unknownKey && isMap(node) && !legacy) {
    const k = issue.keys[0];
    const kp = node.items.find((it) => scalarString(it.key) === k);
    if (kp) kpos = c.pos(kp.key as YamlNode);
  }
  const message = unknownKey
    ? `block '${block}' (${type}): ${ex.message}`
    : `block '${block}' (${type}): ${subject} ${ex.message}`;
  c.error(
    "bad-param",
    kpos,
    message + (legacy ? " (after converting the positional Params)" : ""),
    {
      block,
      ...(path !== "" ? { param: path } : {}),
      ...(ex.expected !== undefined ? { expected: ex.expected } : {}),
      ...(ex.suggestion !== undefined ? { suggestion: ex.suggestion } : {}),
    },
  );
}

/** The validated params with their output ports (an error when the ports cannot be resolved). */
function withOutputs(
  c: Collector,
  p: ParamsInput,
  params: unknown,
  converted: unknown,
): ParamsResult {
  const { block, def, pos } = p;
  try {
    return { ok: true, params, converted, outputs: outputNames(def, params) };
  } catch (e) {
    c.error("bad-params", pos, `block '${block}' (${def.type}): ${errorMessage(e)}`, { block });
    return failed(converted);
  }
}

/** The warning for a block whose positional Params were converted (one per block). */
export function convertedWarning(
  c: Collector,
  block: string,
  type: string,
  at: SourcePos,
  converted: unknown,
): void {
  c.warn(
    "legacy-converted",
    at,
    `block '${block}' (${type}): converted MOSAIC positional Params to ${paramsText(converted)}`,
    { block },
  );
}
