/**
 * The control-panel form's model, free of React and the DOM: a block's params JSON Schema (the
 * input side of its zod schema, as `BlockInfo.paramsSchema` carries it) → field descriptors, the
 * text ↔ value conversions of the editors, and a validator that reports problems in the schema's
 * own terms (required, ≥ min, integer, one of …). Only what the validator accepts is ever sent to
 * the engine; the engine's zod schema still has the last word (refinements that JSON Schema
 * cannot express, such as "Min must not be greater than Max", come back in its reply).
 *
 * The subset understood is what `z.toJSONSchema(…, { io: "input" })` produces for the block
 * catalog: type (number, integer, boolean, string, array, object, null), minimum / maximum /
 * exclusive bounds, enum / const, minLength / maxLength / pattern, items / prefixItems, minItems /
 * maxItems, properties / required / additionalProperties / propertyNames, anyOf / oneOf / allOf,
 * default, description, $ref into $defs. Anything else is edited as JSON and checked as far as the
 * subset goes.
 */

export interface JsonSchema {
  type?: string | string[];
  title?: string;
  description?: string;
  default?: unknown;
  const?: unknown;
  enum?: unknown[];
  minimum?: number;
  maximum?: number;
  exclusiveMinimum?: number | boolean;
  exclusiveMaximum?: number | boolean;
  multipleOf?: number;
  minLength?: number;
  maxLength?: number;
  pattern?: string;
  items?: JsonSchema | JsonSchema[] | boolean;
  prefixItems?: JsonSchema[];
  minItems?: number;
  maxItems?: number;
  properties?: Record<string, JsonSchema>;
  required?: string[];
  additionalProperties?: boolean | JsonSchema;
  propertyNames?: JsonSchema;
  anyOf?: JsonSchema[];
  oneOf?: JsonSchema[];
  allOf?: JsonSchema[];
  $ref?: string;
  $defs?: Record<string, JsonSchema>;
  definitions?: Record<string, JsonSchema>;
  /** Proposed marker (see the report): this number accepts .inf / -.inf. */
  "x-infinity"?: boolean;
  [k: string]: unknown;
}

// ---------------------------------------------------------------------------------------------
// Field descriptors

interface Common {
  /** Property name (top-level param, object key) or "" for list items and record values. */
  name: string;
  description?: string;
  /** Present in `required` of the parent object (list items and record values always are). */
  required: boolean;
  hasDefault: boolean;
  default?: unknown;
  /** The (resolved) schema the value is validated against. */
  schema: JsonSchema;
  /** `null` is accepted (a nullable schema). */
  nullable: boolean;
}

export interface NumberField extends Common {
  kind: "number";
  integer: boolean;
  min?: number;
  max?: number;
  exclusiveMin?: number;
  exclusiveMax?: number;
  /** The step of an <input type=number>-like control: 1 for integers, else "any". */
  step: number | "any";
  /** `.inf` and `-.inf` are accepted (YAML's infinities). */
  allowInfinity: boolean;
}
export interface BooleanField extends Common {
  kind: "boolean";
}
export interface EnumOption {
  value: unknown;
  label: string;
}
export interface EnumField extends Common {
  kind: "enum";
  options: EnumOption[];
}
export interface StringField extends Common {
  kind: "string";
  minLength?: number;
  maxLength?: number;
  pattern?: string;
}
/** A list of numbers, typed as one line: `1, 2, 3`. */
export interface NumberListField extends Common {
  kind: "numberList";
  item: NumberField;
  minItems?: number;
  maxItems?: number;
}
/** One number or a list of numbers (e.g. a gain for all channels or one per channel). */
export interface NumberOrListField extends Common {
  kind: "numberOrList";
  number: NumberField;
  list: NumberListField;
}
/** A list of rows of numbers, one row per line. */
export interface MatrixField extends Common {
  kind: "matrix";
  row: NumberListField;
  minRows?: number;
  maxRows?: number;
}
/** A union of scalars (e.g. a header name or a column index, or `false`): one text box. */
export interface ScalarUnionField extends Common {
  kind: "scalarUnion";
  branches: Field[];
}
export interface ObjectField extends Common {
  kind: "object";
  fields: Field[];
}
/** A list of anything but numbers: one editor per item. */
export interface ListField extends Common {
  kind: "list";
  item: Field;
  minItems?: number;
  maxItems?: number;
}
/** A mapping from free names to values of one schema (e.g. gestures by name). */
export interface RecordField extends Common {
  kind: "record";
  value: Field;
  keySchema?: JsonSchema;
}
/** Anything else: edited as JSON. */
export interface JsonField extends Common {
  kind: "json";
}

export type Field =
  | NumberField
  | BooleanField
  | EnumField
  | StringField
  | NumberListField
  | NumberOrListField
  | MatrixField
  | ScalarUnionField
  | ObjectField
  | ListField
  | RecordField
  | JsonField;

/** Fields edited in one text input or text area (commit on Enter / blur for one-liners). */
export const TEXT_KINDS: ReadonlySet<Field["kind"]> = new Set([
  "number",
  "string",
  "numberList",
  "numberOrList",
  "matrix",
  "scalarUnion",
  "json",
]);

/** The largest integer bounds zod writes for `.int()`: not worth showing. */
const SAFE = Number.MAX_SAFE_INTEGER;

function asSchema(s: unknown): JsonSchema {
  return s !== null && typeof s === "object" && !Array.isArray(s) ? (s as JsonSchema) : {};
}

/** Follows a local `$ref` (`#/$defs/x`, `#/definitions/x`, `#`). */
export function resolveRef(s: JsonSchema, root: JsonSchema): JsonSchema {
  let cur = s;
  for (let hops = 0; cur.$ref !== undefined && hops < 32; hops++) {
    const ref = cur.$ref;
    if (!ref.startsWith("#")) return {};
    let target: unknown = root;
    for (const part of ref.slice(1).split("/").filter(Boolean)) {
      const key = decodeURIComponent(part.replace(/~1/g, "/").replace(/~0/g, "~"));
      target = (target as Record<string, unknown> | undefined)?.[key];
    }
    const { $ref: _ref, ...rest } = cur;
    cur = { ...asSchema(target), ...rest };
  }
  return cur;
}

function types(s: JsonSchema): string[] {
  if (Array.isArray(s.type)) return s.type;
  return s.type !== undefined ? [s.type] : [];
}

/** Merges `allOf` parts into one schema (enough for describing; validation checks each part). */
function flatten(s: JsonSchema, root: JsonSchema): JsonSchema {
  const r = resolveRef(s, root);
  if (!r.allOf?.length) return r;
  const { allOf, ...rest } = r;
  let out: JsonSchema = { ...rest };
  for (const part of allOf) out = { ...flatten(part, root), ...out };
  return out;
}

/** Branches of a union, nested unions flattened; the `null` branch is reported separately. */
function branchesOf(
  s: JsonSchema,
  root: JsonSchema,
): { branches: JsonSchema[]; nullable: boolean } {
  const out: JsonSchema[] = [];
  let nullable = false;
  const visit = (b: JsonSchema): void => {
    const f = flatten(b, root);
    const u = f.anyOf ?? f.oneOf;
    if (u) {
      for (const x of u) visit(x);
      return;
    }
    if (types(f).length === 1 && types(f)[0] === "null") nullable = true;
    else out.push(f);
  };
  visit(s);
  return { branches: out, nullable };
}

const isConstLike = (s: JsonSchema): boolean => "const" in s || Array.isArray(s.enum);

function constValues(s: JsonSchema): unknown[] {
  if ("const" in s) return [s.const];
  if (Array.isArray(s.enum)) return s.enum;
  if (types(s).length === 1 && types(s)[0] === "boolean") return [true, false];
  return [];
}

export function optionLabel(v: unknown): string {
  if (v === " ") return "' ' (space)";
  if (v === "\t") return "tab";
  if (v === "") return '"" (empty)';
  if (typeof v === "string") return v;
  return JSON.stringify(v);
}

function numberLimits(
  s: JsonSchema,
): Pick<NumberField, "min" | "max" | "exclusiveMin" | "exclusiveMax"> {
  const out: Pick<NumberField, "min" | "max" | "exclusiveMin" | "exclusiveMax"> = {};
  if (typeof s.minimum === "number" && s.minimum > -SAFE) {
    if (s.exclusiveMinimum === true) out.exclusiveMin = s.minimum;
    else out.min = s.minimum;
  }
  if (typeof s.maximum === "number" && s.maximum < SAFE) {
    if (s.exclusiveMaximum === true) out.exclusiveMax = s.maximum;
    else out.max = s.maximum;
  }
  if (typeof s.exclusiveMinimum === "number") out.exclusiveMin = s.exclusiveMinimum;
  if (typeof s.exclusiveMaximum === "number") out.exclusiveMax = s.exclusiveMaximum;
  return out;
}

/**
 * Whether a `{type: number}` accepts infinities. JSON Schema cannot say so; the blocks' extended
 * numbers are `{type: number}` described with ".inf", and a default of Infinity is written `null`
 * by JSON. An explicit `x-infinity` marker (proposed) wins.
 */
function acceptsInfinity(s: JsonSchema): boolean {
  if (typeof s["x-infinity"] === "boolean") return s["x-infinity"];
  if (types(s)[0] !== "number") return false;
  if (s.default === null) return true;
  return /(^|[^\w])-?\.inf\b/i.test(s.description ?? "");
}

function common(name: string, s: JsonSchema, required: boolean, nullable: boolean): Common {
  const c: Common = { name, required, hasDefault: "default" in s, schema: s, nullable };
  if (s.description !== undefined) c.description = s.description;
  if ("default" in s) c.default = s.default;
  return c;
}

/**
 * The field descriptor of a schema. `root` resolves `$ref`s; `name` and `required` come from the
 * parent object.
 */
export function describe(
  schema: unknown,
  name = "",
  required = true,
  root: JsonSchema = asSchema(schema),
): Field {
  const outer = flatten(asSchema(schema), root);
  const { branches, nullable } = branchesOf(outer, root);
  if (branches.length === 0) return { kind: "json", ...common(name, outer, required, nullable) };
  if (branches.length > 1) {
    return describeUnion(branches, common(name, outer, required, nullable), root);
  }
  const s = nullable ? annotate(branches[0]!, outer) : branches[0]!;
  return describeSingle(s, common(name, s, required, nullable), root);
}

/** The one branch of a nullable union, given the outer schema's description and default. */
function annotate(inner: JsonSchema, outer: JsonSchema): JsonSchema {
  const s: JsonSchema = { ...inner };
  if (outer.description !== undefined) s.description = outer.description;
  if ("default" in outer) s.default = outer.default;
  return s;
}

/** A union of several (non-null) branches: a select, a number-or-list, a scalar union, or JSON. */
function describeUnion(branches: JsonSchema[], c: Common, root: JsonSchema): Field {
  // Constants and booleans only → a select.
  if (branches.every((b) => isConstLike(b) || types(b)[0] === "boolean")) {
    const options: EnumOption[] = [];
    for (const b of branches)
      for (const v of constValues(b)) options.push({ value: v, label: optionLabel(v) });
    return { kind: "enum", options, ...c };
  }
  const described = branches.map((b) => describe(b, "", true, root));
  const num = described.find((d): d is NumberField => d.kind === "number");
  const list = described.find((d): d is NumberListField => d.kind === "numberList");
  if (described.length === 2 && num && list) {
    return { kind: "numberOrList", number: num, list, ...c };
  }
  const scalar = (d: Field): boolean =>
    d.kind === "number" || d.kind === "string" || d.kind === "enum" || d.kind === "boolean";
  if (described.every(scalar)) return { kind: "scalarUnion", branches: described, ...c };
  // A scalar choice or a list of numbers (e.g. Safe: rest | hold | [values]).
  if (described.every((d) => scalar(d) || d.kind === "numberList")) {
    return { kind: "scalarUnion", branches: described, ...c };
  }
  return { kind: "json", ...c };
}

/** A schema that is not a union: by its constants, else by its one type. */
function describeSingle(s: JsonSchema, c: Common, root: JsonSchema): Field {
  if (isConstLike(s)) {
    return {
      kind: "enum",
      options: constValues(s).map((v) => ({ value: v, label: optionLabel(v) })),
      ...c,
    };
  }
  const t = types(s).filter((x) => x !== "null");
  const kind = t.length === 1 ? t[0] : undefined;
  switch (kind) {
    case "number":
    case "integer":
      return describeNumber(s, c, kind === "integer");
    case "boolean":
      return { kind: "boolean", ...c };
    case "string":
      return describeString(s, c);
    case "array":
      return describeArray(s, c, root);
    case "object":
      return describeObject(s, c, root);
    default:
      return { kind: "json", ...c };
  }
}

/** A number or integer field, with its limits; a default of Infinity comes as null. */
function describeNumber(s: JsonSchema, c: Common, integer: boolean): NumberField {
  const allowInfinity = !integer && acceptsInfinity(s);
  // JSON writes a default of Infinity as null.
  if (allowInfinity && c.default === null) c.default = Infinity;
  return {
    kind: "number",
    integer,
    step: integer ? 1 : "any",
    allowInfinity,
    ...numberLimits(s),
    ...c,
  };
}

/** A text field, with its length bounds and pattern. */
function describeString(s: JsonSchema, c: Common): StringField {
  const f: StringField = { kind: "string", ...c };
  if (s.minLength !== undefined) f.minLength = s.minLength;
  if (s.maxLength !== undefined) f.maxLength = s.maxLength;
  if (s.pattern !== undefined) f.pattern = s.pattern;
  return f;
}

/** A list of numbers, a matrix (rows of numbers), a list of anything else, or JSON for tuples. */
function describeArray(s: JsonSchema, c: Common, root: JsonSchema): Field {
  if (Array.isArray(s.items) || s.prefixItems) return { kind: "json", ...c };
  const item = describe(typeof s.items === "object" ? s.items : {}, "", true, root);
  const bounds: { minItems?: number; maxItems?: number } = {};
  if (s.minItems !== undefined) bounds.minItems = s.minItems;
  if (s.maxItems !== undefined) bounds.maxItems = s.maxItems;
  if (item.kind === "number") return { kind: "numberList", item, ...bounds, ...c };
  if (item.kind === "numberList") {
    const m: MatrixField = { kind: "matrix", row: item, ...c };
    if (bounds.minItems !== undefined) m.minRows = bounds.minItems;
    if (bounds.maxItems !== undefined) m.maxRows = bounds.maxItems;
    return m;
  }
  return { kind: "list", item, ...bounds, ...c };
}

/** An object with its properties as fields, a record (free names → one schema), or JSON. */
function describeObject(s: JsonSchema, c: Common, root: JsonSchema): Field {
  const props = s.properties ?? {};
  const req = new Set(s.required ?? []);
  const fields = Object.entries(props).map(([k, p]) => describe(p, k, req.has(k), root));
  const extra = s.additionalProperties;
  if (fields.length === 0 && extra !== undefined && typeof extra === "object") {
    const r: RecordField = { kind: "record", value: describe(extra, "", true, root), ...c };
    if (s.propertyNames) r.keySchema = resolveRef(s.propertyNames, root);
    return r;
  }
  if (fields.length === 0 && extra !== false) return { kind: "json", ...c };
  return { kind: "object", fields, ...c };
}

/** The fields of a block's params form, one per top-level param, in schema order. */
export function describeParams(paramsSchema: unknown): ObjectField {
  const f = describe(paramsSchema, "", true);
  if (f.kind === "object") return f;
  if (f.kind === "record" || f.kind === "json") return { ...f, kind: "object", fields: [] };
  return {
    kind: "object",
    name: "",
    required: true,
    hasDefault: false,
    schema: f.schema,
    nullable: false,
    fields: [],
  };
}

// ---------------------------------------------------------------------------------------------
// Text ↔ value

export type Parsed = { ok: true; value: unknown } | { ok: false; error: string };

/** What an editor reports while its text does not parse: never sent, shown where it was typed. */
export class InvalidText {
  constructor(
    readonly text: string,
    readonly error: string,
  ) {}
}

const INF = /^[+]?(\.?inf|infinity|∞)$/i;
const NEG_INF = /^-(\.?inf|infinity|∞)$/i;
const NUMBER = /^[+-]?(\d+\.?\d*|\.\d+)(e[+-]?\d+)?$/i;

/** Parses one number as typed ("1.5", "-2e-3", ".inf" where allowed). Empty text is undefined. */
export function parseNumber(
  text: string,
  f: Pick<NumberField, "integer" | "allowInfinity">,
): Parsed {
  const s = text.trim();
  if (s === "") return { ok: true, value: undefined };
  if (INF.test(s) || NEG_INF.test(s)) {
    if (!f.allowInfinity) return { ok: false, error: "must be a finite number" };
    return { ok: true, value: NEG_INF.test(s) ? -Infinity : Infinity };
  }
  if (!NUMBER.test(s)) {
    if (/^[+-]?\d+,\d+$/.test(s))
      return { ok: false, error: "not a number (use a point for decimals)" };
    return { ok: false, error: f.integer ? "must be a whole number" : "not a number" };
  }
  const v = Number(s);
  if (!Number.isFinite(v)) return { ok: false, error: "number too large" };
  return { ok: true, value: v };
}

/**
 * `1, 2, 3` (also `1;2;3`, spaces, or `[1, 2, 3]`). Empty text is undefined; `[]` is a list.
 * Lists of non-negative integers (channel indices) also take ranges: `0-3, 8` is 0, 1, 2, 3, 8.
 */
export function parseNumberList(
  text: string,
  item: Pick<NumberField, "integer" | "allowInfinity"> & { min?: number },
): Parsed {
  let s = text.trim();
  if (s === "") return { ok: true, value: undefined };
  if (s.startsWith("[") && s.endsWith("]")) s = s.slice(1, -1).trim();
  if (s === "") return { ok: true, value: [] };
  const parts = s.split(/\s*[,;]\s*|\s+/);
  const out: number[] = [];
  for (let i = 0; i < parts.length; i++) {
    const p = parts[i]!;
    if (p === "") return { ok: false, error: `item ${i + 1} is missing (two separators in a row)` };
    const range =
      item.integer && item.min !== undefined && item.min >= 0 ? /^(\d+)-(\d+)$/.exec(p) : null;
    if (range) {
      const a = Number(range[1]);
      const b = Number(range[2]);
      if (b < a) return { ok: false, error: `item ${i + 1} '${p}': a range goes from low to high` };
      if (b - a > 100_000) return { ok: false, error: `item ${i + 1} '${p}': range too long` };
      for (let k = a; k <= b; k++) out.push(k);
      continue;
    }
    const r = parseNumber(p, item);
    if (!r.ok) return { ok: false, error: `item ${i + 1} '${p}': ${r.error}` };
    out.push(r.value as number);
  }
  return { ok: true, value: out };
}

/** One row per line (or JSON `[[…], […]]`); each row as `parseNumberList`. */
export function parseMatrix(
  text: string,
  item: Pick<NumberField, "integer" | "allowInfinity"> & { min?: number },
): Parsed {
  const s = text.trim();
  if (s === "") return { ok: true, value: undefined };
  if (s.startsWith("[[") || s === "[]") {
    try {
      const v: unknown = JSON.parse(s);
      if (Array.isArray(v)) return { ok: true, value: v };
    } catch {
      return { ok: false, error: "not a list of rows (write one row per line: 1, 2, 3)" };
    }
  }
  const rows: number[][] = [];
  const lines = s
    .split(/\r?\n/)
    .map((l) => l.trim())
    .filter((l) => l !== "");
  for (let i = 0; i < lines.length; i++) {
    const r = parseNumberList(lines[i]!, item);
    if (!r.ok) return { ok: false, error: `row ${i + 1}: ${r.error}` };
    rows.push(r.value as number[]);
  }
  return { ok: true, value: rows };
}

function parseScalarBranch(text: string, f: Field): Parsed {
  const s = text.trim();
  switch (f.kind) {
    case "number":
      return s === "" ? { ok: false, error: "empty" } : parseNumber(s, f);
    case "numberList":
      return parseNumberList(s, f.item);
    case "boolean":
      return s === "true" || s === "false"
        ? { ok: true, value: s === "true" }
        : { ok: false, error: "not true/false" };
    case "enum": {
      const o = f.options.find((x) => optionLabel(x.value) === s || String(x.value) === s);
      return o ? { ok: true, value: o.value } : { ok: false, error: "not an option" };
    }
    case "string":
      return { ok: true, value: text };
    default:
      return { ok: false, error: "unsupported" };
  }
}

/** Parses the text of a text-edited field (see TEXT_KINDS). Empty text is undefined. */
export function parseText(f: Field, text: string): Parsed {
  switch (f.kind) {
    case "number":
      return parseNumber(text, f);
    case "string":
      return { ok: true, value: text === "" && !f.required ? undefined : text };
    case "numberList":
      return parseNumberList(text, f.item);
    case "numberOrList": {
      const s = text.trim();
      if (s === "") return { ok: true, value: undefined };
      if (/^\[|[,;\s]/.test(s)) return parseNumberList(s, f.list.item);
      return parseNumber(s, f.number);
    }
    case "matrix":
      return parseMatrix(text, f.row.item);
    case "scalarUnion": {
      if (text.trim() === "") return { ok: true, value: undefined };
      // Constants and numbers first, then lists, then free text.
      const order = [...f.branches].sort((a, b) => rank(a) - rank(b));
      let firstError = "";
      for (const b of order) {
        const r = parseScalarBranch(text, b);
        if (r.ok) return r;
        if (!firstError && b.kind !== "enum" && b.kind !== "boolean") firstError = r.error;
      }
      return {
        ok: false,
        error: `expected ${describeType(f)}${firstError ? ` (${firstError})` : ""}`,
      };
    }
    case "json": {
      if (text.trim() === "") return { ok: true, value: undefined };
      try {
        return { ok: true, value: JSON.parse(text) as unknown };
      } catch (e) {
        return { ok: false, error: `not valid JSON: ${(e as Error).message}` };
      }
    }
    default:
      return { ok: false, error: `${f.kind} is not edited as text` };
  }
}

function rank(f: Field): number {
  return f.kind === "enum" || f.kind === "boolean"
    ? 0
    : f.kind === "number"
      ? 1
      : f.kind === "numberList"
        ? 2
        : 3;
}

/** Shortest round-trip text of a number; infinities as YAML writes them. */
export function formatNumber(v: number): string {
  if (v === Infinity) return ".inf";
  if (v === -Infinity) return "-.inf";
  return String(v);
}

const formatList = (v: unknown): string =>
  Array.isArray(v)
    ? v.map((x) => (typeof x === "number" ? formatNumber(x) : String(x))).join(", ")
    : "";

/** The text an editor shows for a value (the inverse of parseText). */
export function formatText(f: Field, v: unknown): string {
  if (v === undefined || v === null) return "";
  if (v instanceof InvalidText) return v.text;
  switch (f.kind) {
    case "number":
      return typeof v === "number" ? formatNumber(v) : String(v);
    case "string":
      return typeof v === "string" ? v : JSON.stringify(v);
    case "numberList":
      return Array.isArray(v) && v.length === 0 ? "[]" : formatList(v);
    case "numberOrList":
      return typeof v === "number"
        ? formatNumber(v)
        : Array.isArray(v) && v.length === 0
          ? "[]"
          : formatList(v);
    case "matrix":
      return Array.isArray(v) ? v.map(formatList).join("\n") : "";
    case "scalarUnion":
      if (typeof v === "number") return formatNumber(v);
      if (Array.isArray(v)) return v.length === 0 ? "[]" : formatList(v);
      return typeof v === "string" ? v : JSON.stringify(v);
    default:
      return JSON.stringify(v, (_k, x: unknown) =>
        x === Infinity ? ".inf" : x === -Infinity ? "-.inf" : x,
      );
  }
}

/** A compact one-line rendering of any value (read-only params, defaults). */
export function summarize(v: unknown, max = 120): string {
  let s: string;
  if (v === undefined) s = "—";
  else if (typeof v === "number") s = formatNumber(v);
  else if (typeof v === "string") s = v === "" ? '""' : v;
  else
    s = JSON.stringify(v, (_k, x: unknown) =>
      x === Infinity ? ".inf" : x === -Infinity ? "-.inf" : x,
    )
      .replace(/"([A-Za-z_][\w-]*)":/g, "$1: ")
      .replace(/,(?=\S)/g, ", ");
  return s.length > max ? `${s.slice(0, max - 1)}…` : s;
}

/** What the field takes, in words ("integer ≥ 1, ≤ 4096", "list of numbers", …). */
export function describeType(f: Field): string {
  switch (f.kind) {
    case "number": {
      const parts: string[] = [];
      if (f.min !== undefined) parts.push(`≥ ${formatNumber(f.min)}`);
      if (f.exclusiveMin !== undefined) parts.push(`> ${formatNumber(f.exclusiveMin)}`);
      if (f.max !== undefined) parts.push(`≤ ${formatNumber(f.max)}`);
      if (f.exclusiveMax !== undefined) parts.push(`< ${formatNumber(f.exclusiveMax)}`);
      const base = f.integer ? "integer" : f.allowInfinity ? "number or ±.inf" : "number";
      return parts.length ? `${base} ${parts.join(", ")}` : base;
    }
    case "boolean":
      return "true or false";
    case "enum":
      return f.options.length === 1
        ? f.options[0]!.label
        : `one of ${f.options.map((o) => o.label).join(", ")}`;
    case "string":
      return f.minLength ? "text (non-empty)" : "text";
    case "numberList":
      return `list of ${describeType(f.item)
        .replace(/^integer/, "integers")
        .replace(/^number/, "numbers")}${itemsBounds(f.minItems, f.maxItems)}`;
    case "numberOrList":
      return `${describeType(f.number)}, or one per channel`;
    case "matrix":
      return `rows of ${describeType(f.row.item).replace(/^number/, "numbers")}, one row per line`;
    case "scalarUnion":
      return f.branches.map(describeType).join(" or ");
    case "object":
      return "mapping";
    case "list":
      return `list of ${f.item.kind === "object" ? "mappings" : describeType(f.item)}${itemsBounds(f.minItems, f.maxItems)}`;
    case "record":
      return "mapping of names";
    case "json":
      return "JSON";
  }
}

function itemsBounds(min?: number, max?: number): string {
  if (min !== undefined && max !== undefined) return ` (${min}–${max} items)`;
  if (min !== undefined) return min === 1 ? " (≥ 1)" : ` (≥ ${min} items)`;
  if (max !== undefined) return ` (≤ ${max} items)`;
  return "";
}

// ---------------------------------------------------------------------------------------------
// Validation

export type Path = (string | number)[];

export interface Issue {
  path: Path;
  message: string;
}

export const pathKey = (p: Path): string => p.map(String).join("/");

/** "[2]" for list items, ".Name" for keys, relative to a field. */
export function formatPath(p: Path): string {
  return p
    .map((x) => (typeof x === "number" ? `[${x}]` : `.${x}`))
    .join("")
    .replace(/^\./, "");
}

function typeMatches(t: string, v: unknown): boolean {
  switch (t) {
    case "number":
      return typeof v === "number" && !Number.isNaN(v);
    case "integer":
      return typeof v === "number" && Number.isInteger(v);
    case "string":
      return typeof v === "string";
    case "boolean":
      return typeof v === "boolean";
    case "array":
      return Array.isArray(v);
    case "object":
      return (
        v !== null && typeof v === "object" && !Array.isArray(v) && !(v instanceof InvalidText)
      );
    case "null":
      return v === null;
    default:
      return true;
  }
}

const TYPE_WORDS: Record<string, string> = {
  number: "a number",
  integer: "a whole number",
  string: "text",
  boolean: "true or false",
  array: "a list",
  object: "a mapping",
  null: "empty",
};

function deepEqual(a: unknown, b: unknown): boolean {
  if (Object.is(a, b)) return true;
  if (typeof a !== "object" || typeof b !== "object" || a === null || b === null) return false;
  if (Array.isArray(a) !== Array.isArray(b)) return false;
  if (Array.isArray(a)) {
    const bb = b as unknown[];
    return a.length === bb.length && a.every((x, i) => deepEqual(x, bb[i]));
  }
  const ka = Object.keys(a).filter((k) => (a as Record<string, unknown>)[k] !== undefined);
  const kb = Object.keys(b).filter((k) => (b as Record<string, unknown>)[k] !== undefined);
  return (
    ka.length === kb.length &&
    ka.every((k) => deepEqual((a as Record<string, unknown>)[k], (b as Record<string, unknown>)[k]))
  );
}
export { deepEqual };

/** Whether a value holds text that did not parse anywhere inside it. */
export function hasInvalid(v: unknown): boolean {
  if (v instanceof InvalidText) return true;
  if (Array.isArray(v)) return v.some(hasInvalid);
  if (v !== null && typeof v === "object") return Object.values(v).some(hasInvalid);
  return false;
}

/**
 * Checks a value against a schema (the subset above). `undefined` is "not given": the parent
 * object reports it when required. Text that did not parse (InvalidText) is reported with its
 * parse error. Issues are in the schema's terms and carry the path to the offending value.
 */
export function validate(
  schema: unknown,
  value: unknown,
  root: JsonSchema = asSchema(schema),
  path: Path = [],
): Issue[] {
  const s = resolveRef(asSchema(schema), root);
  const { issues, add } = collector(path);
  if (value instanceof InvalidText) {
    add(value.error);
    return issues;
  }
  if (value === undefined) return issues;
  for (const part of s.allOf ?? []) issues.push(...validate(part, value, root, path));
  const union = s.anyOf ?? s.oneOf;
  if (union) {
    issues.push(...unionIssues(union, value, root, path));
    return issues;
  }
  const t = types(s);
  if (t.length && !t.some((x) => typeMatches(x, value))) {
    add(`must be ${t.map((x) => TYPE_WORDS[x] ?? x).join(" or ")}`);
    return issues;
  }
  issues.push(...constIssues(s, value, path));
  if (typeof value === "number") issues.push(...numberIssues(s, t, value, path));
  if (typeof value === "string") issues.push(...stringIssues(s, value, path));
  if (Array.isArray(value)) issues.push(...arrayIssues(s, value, root, path));
  if (
    typeMatches("object", value) &&
    (t.includes("object") || s.properties || s.additionalProperties !== undefined)
  ) {
    issues.push(...objectIssues(s, value as Record<string, unknown>, root, path));
  }
  return issues;
}

/** A new list of issues and a function adding one at `path` (or at the path it is given). */
function collector(path: Path): { issues: Issue[]; add: (message: string, p?: Path) => void } {
  const issues: Issue[] = [];
  const add = (message: string, p: Path = path): void => {
    issues.push({ path: p, message });
  };
  return { issues, add };
}

/**
 * A value against `anyOf` / `oneOf`: none if a branch accepts it, else the problems of the one
 * branch of the value's own type, else what is expected.
 */
function unionIssues(union: JsonSchema[], value: unknown, root: JsonSchema, path: Path): Issue[] {
  const results = union.map((b) => validate(b, value, root, path));
  if (results.some((r) => r.length === 0)) return [];
  const own = union
    .map((_b, i) => i)
    .filter((i) => {
      const b = resolveRef(union[i]!, root);
      return !isConstLike(b) && types(b).some((x) => typeMatches(x, value));
    });
  if (own.length === 1) return results[own[0]!]!;
  return [{ path, message: `must be ${unionWords(union, root)}` }];
}

/** `const` and `enum`. */
function constIssues(s: JsonSchema, value: unknown, path: Path): Issue[] {
  const { issues, add } = collector(path);
  if ("const" in s && !deepEqual(s.const, value)) add(`must be ${optionLabel(s.const)}`);
  if (Array.isArray(s.enum) && !s.enum.some((e) => deepEqual(e, value)))
    add(`must be one of ${s.enum.map(optionLabel).join(", ")}`);
  return issues;
}

/** A number: finite unless infinities are accepted, bounds, zod's int bounds, multipleOf. */
function numberIssues(s: JsonSchema, t: string[], value: number, path: Path): Issue[] {
  const { issues, add } = collector(path);
  if (!Number.isFinite(value) && t.includes("number") && !acceptsInfinity(s))
    add("must be a finite number");
  const l = numberLimits(s);
  if (l.min !== undefined && !(value >= l.min)) add(`must be ≥ ${formatNumber(l.min)}`);
  if (l.max !== undefined && !(value <= l.max)) add(`must be ≤ ${formatNumber(l.max)}`);
  if (l.exclusiveMin !== undefined && !(value > l.exclusiveMin))
    add(`must be > ${formatNumber(l.exclusiveMin)}`);
  if (l.exclusiveMax !== undefined && !(value < l.exclusiveMax))
    add(`must be < ${formatNumber(l.exclusiveMax)}`);
  // zod's .int() bounds (±2^53−1) are shown only when crossed.
  if (typeof s.minimum === "number" && s.minimum <= -SAFE && value < s.minimum)
    add(`must be ≥ ${s.minimum}`);
  if (typeof s.maximum === "number" && s.maximum >= SAFE && value > s.maximum)
    add(`must be ≤ ${s.maximum}`);
  if (typeof s.multipleOf === "number" && s.multipleOf > 0) {
    const q = value / s.multipleOf;
    if (Math.abs(q - Math.round(q)) > 1e-9) add(`must be a multiple of ${s.multipleOf}`);
  }
  return issues;
}

/** A string: length in code points, and pattern (one that does not compile is ignored). */
function stringIssues(s: JsonSchema, value: string, path: Path): Issue[] {
  const { issues, add } = collector(path);
  const n = [...value].length;
  if (s.minLength !== undefined && n < s.minLength)
    add(s.minLength === 1 ? "must not be empty" : `must have at least ${s.minLength} characters`);
  if (s.maxLength !== undefined && n > s.maxLength)
    add(`must have at most ${s.maxLength} characters`);
  if (s.pattern !== undefined) {
    let re: RegExp | undefined;
    try {
      re = new RegExp(s.pattern, "u");
    } catch {
      re = undefined;
    }
    if (re && !re.test(value)) add(`must match ${s.pattern}`);
  }
  return issues;
}

/** A list: its length, then each item against its prefixItems / items schema (or missing). */
function arrayIssues(s: JsonSchema, value: unknown[], root: JsonSchema, path: Path): Issue[] {
  const { issues, add } = collector(path);
  if (s.minItems !== undefined && value.length < s.minItems)
    add(s.minItems === 1 ? "needs at least 1 item" : `needs at least ${s.minItems} items`);
  if (s.maxItems !== undefined && value.length > s.maxItems)
    add(`must have at most ${s.maxItems} items`);
  const prefix = s.prefixItems ?? (Array.isArray(s.items) ? s.items : undefined);
  value.forEach((item, i) => {
    const is =
      prefix && i < prefix.length
        ? prefix[i]
        : typeof s.items === "object" && !Array.isArray(s.items)
          ? s.items
          : undefined;
    if (item === undefined) add("item is missing", [...path, i]);
    else if (is) issues.push(...validate(is, item, root, [...path, i]));
  });
  return issues;
}

/** A mapping: required keys, then each given key's name and value (or that it is unknown). */
function objectIssues(
  s: JsonSchema,
  obj: Record<string, unknown>,
  root: JsonSchema,
  path: Path,
): Issue[] {
  const { issues, add } = collector(path);
  const props = s.properties ?? {};
  for (const k of s.required ?? []) if (obj[k] === undefined) add("required", [...path, k]);
  for (const [k, v] of Object.entries(obj)) {
    if (v === undefined) continue;
    if (s.propertyNames) {
      const kIssues = validate(s.propertyNames, k, root, [...path, k]);
      for (const i of kIssues) add(`name '${k}' ${i.message}`, i.path);
    }
    if (k in props) issues.push(...validate(props[k], v, root, [...path, k]));
    else if (s.additionalProperties === false) {
      const allowed = Object.keys(props);
      add(`unknown key '${k}'${allowed.length ? ` (allowed: ${allowed.join(", ")})` : ""}`, [
        ...path,
        k,
      ]);
    } else if (typeof s.additionalProperties === "object")
      issues.push(...validate(s.additionalProperties, v, root, [...path, k]));
  }
  return issues;
}

function unionWords(union: JsonSchema[], root: JsonSchema): string {
  const words = union.map((b) => {
    const f = describe(b, "", true, root);
    if (f.kind === "enum") return f.options.map((o) => o.label).join(" or ");
    return describeType(f)
      .replace(/^integer/, "a whole number")
      .replace(/^number/, "a number");
  });
  return [...new Set(words)].join(", or ");
}

/** Issues at or below `prefix`, with paths made relative to it. */
export function issuesUnder(issues: readonly Issue[], prefix: Path): Issue[] {
  const out: Issue[] = [];
  for (const i of issues) {
    if (i.path.length < prefix.length) continue;
    if (prefix.every((p, k) => i.path[k] === p))
      out.push({ path: i.path.slice(prefix.length), message: i.message });
  }
  return out;
}

/** One line per issue, "[2]: must be ≤ 1" for nested ones. */
export function issueText(i: Issue): string {
  return i.path.length ? `${formatPath(i.path)}: ${i.message}` : i.message;
}

/** A new value for an item added to a list or record (its default, or an empty one). */
export function emptyValue(f: Field): unknown {
  if (f.hasDefault) return structuredCloneSafe(f.default);
  switch (f.kind) {
    case "boolean":
      return false;
    case "enum":
      return f.options[0]?.value;
    case "object": {
      const o: Record<string, unknown> = {};
      for (const sub of f.fields) if (sub.required) o[sub.name] = emptyValue(sub);
      return o;
    }
    case "list":
    case "numberList":
    case "matrix":
      return [];
    case "record":
      return {};
    case "string":
      return "";
    default:
      return undefined;
  }
}

function structuredCloneSafe<T>(v: T): T {
  return v === undefined ? v : (JSON.parse(JSON.stringify(v)) as T);
}
