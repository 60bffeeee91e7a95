// The committed docs/blocks.md and pipelines/schema/pipeline.schema.json must equal what
// tools/gen-docs.ts produces from the catalog now, and the schema must accept a valid pipeline and
// reject broken ones.
import { readFileSync } from "node:fs";
import { join } from "node:path";
import { describe, expect, test } from "vitest";
import { parse as parseYaml } from "yaml";
import { BLOCKS } from "../app/blocks/catalog";
import type { AnyBlockDefinition } from "../app/engine/block";
import {
  BLOCKS_MD,
  generateDocs,
  paramsJsonSchema,
  PIPELINE_SCHEMA,
  renderFiles,
  repoRoot,
} from "./gen-docs";

const ROOT = repoRoot();

describe("generated docs are up to date", () => {
  test.each([BLOCKS_MD, PIPELINE_SCHEMA])("%s", async (rel) => {
    const files = await renderFiles(BLOCKS, ROOT);
    let committed: string;
    try {
      committed = readFileSync(join(ROOT, rel), "utf8");
    } catch {
      committed = "";
    }
    expect(
      committed === files[rel],
      `${rel} is out of date with app/blocks/catalog.ts: run npm run docs (npm run build:ts first) and commit the result`,
    ).toBe(true);
  });
});

// ------------------------------------------------------------------------------------------------
// A tiny JSON Schema (draft-07) checker: only the keywords the generator and zod emit. An unknown
// keyword fails loudly, so a new kind of schema is noticed instead of silently accepted.

type Schema = { [key: string]: unknown } | boolean;
const ANNOTATIONS = new Set([
  "$schema",
  "$id",
  "title",
  "description",
  "default",
  "examples",
  "definitions",
  "format",
  "readOnly",
  "writeOnly",
  "$comment",
]);

function typeOf(v: unknown): string {
  if (v === null) return "null";
  if (Array.isArray(v)) return "array";
  if (typeof v === "number") return Number.isInteger(v) ? "integer" : "number";
  return typeof v;
}

function deepEqual(a: unknown, b: unknown): boolean {
  return JSON.stringify(a) === JSON.stringify(b);
}

/** Errors of `value` against `schema` (empty = valid); `root` resolves `#/definitions/…`. */
function validate(schema: Schema, value: unknown, root: Schema = schema, at = "$"): string[] {
  if (schema === true) return [];
  if (schema === false) return [`${at}: not allowed`];
  const errs: string[] = [];
  const sub = (s: unknown, v: unknown, where: string) => validate(s as Schema, v, root, where);
  for (const [k, kv] of Object.entries(schema)) {
    if (ANNOTATIONS.has(k)) continue;
    switch (k) {
      case "$ref": {
        const ref = kv as string;
        if (!ref.startsWith("#/definitions/")) throw new Error(`unsupported $ref ${ref}`);
        const target = (root as { definitions?: Record<string, Schema> }).definitions?.[
          ref.slice("#/definitions/".length)
        ];
        if (target === undefined) throw new Error(`dangling $ref ${ref}`);
        errs.push(...sub(target, value, at));
        break;
      }
      case "type": {
        const types = Array.isArray(kv) ? (kv as string[]) : [kv as string];
        const t = typeOf(value);
        if (!types.some((x) => x === t || (x === "number" && t === "integer"))) {
          errs.push(`${at}: expected ${types.join("|")}, got ${t}`);
        }
        break;
      }
      case "enum":
        if (!(kv as unknown[]).some((e) => deepEqual(e, value)))
          errs.push(`${at}: not one of ${JSON.stringify(kv)}`);
        break;
      case "const":
        if (!deepEqual(kv, value)) errs.push(`${at}: expected ${JSON.stringify(kv)}`);
        break;
      case "minimum":
        if (typeof value === "number" && value < (kv as number)) errs.push(`${at}: < ${kv}`);
        break;
      case "maximum":
        if (typeof value === "number" && value > (kv as number)) errs.push(`${at}: > ${kv}`);
        break;
      case "exclusiveMinimum":
        if (typeof value === "number" && value <= (kv as number)) errs.push(`${at}: <= ${kv}`);
        break;
      case "exclusiveMaximum":
        if (typeof value === "number" && value >= (kv as number)) errs.push(`${at}: >= ${kv}`);
        break;
      case "multipleOf":
        if (typeof value === "number" && !Number.isInteger(value / (kv as number)))
          errs.push(`${at}: not a multiple of ${kv}`);
        break;
      case "minLength":
        if (typeof value === "string" && [...value].length < (kv as number))
          errs.push(`${at}: too short`);
        break;
      case "maxLength":
        if (typeof value === "string" && [...value].length > (kv as number))
          errs.push(`${at}: too long`);
        break;
      case "pattern":
        if (typeof value === "string" && !new RegExp(kv as string, "u").test(value))
          errs.push(`${at}: does not match ${kv}`);
        break;
      case "items":
        if (Array.isArray(value)) {
          if (Array.isArray(kv))
            kv.forEach((s, i) => i < value.length && errs.push(...sub(s, value[i], `${at}[${i}]`)));
          else value.forEach((v, i) => errs.push(...sub(kv, v, `${at}[${i}]`)));
        }
        break;
      case "additionalItems":
        if (Array.isArray(value) && Array.isArray(schema.items)) {
          value
            .slice(schema.items.length)
            .forEach((v, i) => errs.push(...sub(kv, v, `${at}[+${i}]`)));
        }
        break;
      case "minItems":
        if (Array.isArray(value) && value.length < (kv as number))
          errs.push(`${at}: fewer than ${kv} items`);
        break;
      case "maxItems":
        if (Array.isArray(value) && value.length > (kv as number))
          errs.push(`${at}: more than ${kv} items`);
        break;
      case "required":
        if (typeOf(value) === "object") {
          for (const r of kv as string[])
            if (!(r in (value as object))) errs.push(`${at}: missing ${r}`);
        }
        break;
      case "minProperties":
        if (typeOf(value) === "object" && Object.keys(value as object).length < (kv as number))
          errs.push(`${at}: too few keys`);
        break;
      case "maxProperties":
        if (typeOf(value) === "object" && Object.keys(value as object).length > (kv as number))
          errs.push(`${at}: too many keys`);
        break;
      case "properties":
      case "patternProperties":
        break; // with additionalProperties below
      case "additionalProperties":
        break;
      case "propertyNames":
        if (typeOf(value) === "object") {
          for (const key of Object.keys(value as object))
            errs.push(...sub(kv, key, `${at} key ${key}`));
        }
        break;
      case "allOf":
        for (const s of kv as Schema[]) errs.push(...sub(s, value, at));
        break;
      case "anyOf":
        if (!(kv as Schema[]).some((s) => sub(s, value, at).length === 0)) {
          errs.push(
            `${at}: matches none of anyOf (${(kv as Schema[]).map((s) => sub(s, value, at).join("; ")).join(" / ")})`,
          );
        }
        break;
      case "oneOf": {
        const n = (kv as Schema[]).filter((s) => sub(s, value, at).length === 0).length;
        if (n !== 1) errs.push(`${at}: matches ${n} of oneOf`);
        break;
      }
      case "not":
        if (sub(kv, value, at).length === 0) errs.push(`${at}: matches not`);
        break;
      case "if":
        if (sub(kv, value, at).length === 0) {
          if (schema.then !== undefined) errs.push(...sub(schema.then, value, at));
        } else if (schema.else !== undefined) {
          errs.push(...sub(schema.else, value, at));
        }
        break;
      case "then":
      case "else":
        break;
      default:
        throw new Error(
          `the test's JSON Schema checker does not know '${k}' (at ${at}); extend it or use a real validator`,
        );
    }
  }
  // Object members: properties, patternProperties, additionalProperties.
  if (
    typeOf(value) === "object" &&
    (schema.properties || schema.patternProperties || schema.additionalProperties !== undefined)
  ) {
    const props = (schema.properties ?? {}) as Record<string, Schema>;
    const patterns = Object.entries((schema.patternProperties ?? {}) as Record<string, Schema>);
    for (const [key, v] of Object.entries(value as object)) {
      let matched = false;
      if (key in props) {
        matched = true;
        errs.push(...sub(props[key], v, `${at}.${key}`));
      }
      for (const [re, s] of patterns) {
        if (new RegExp(re, "u").test(key)) {
          matched = true;
          errs.push(...sub(s, v, `${at}.${key}`));
        }
      }
      if (!matched && schema.additionalProperties !== undefined) {
        errs.push(
          ...sub(schema.additionalProperties, v, `${at}.${key}`).map((e) =>
            schema.additionalProperties === false ? `${at}: unknown key '${key}'` : e,
          ),
        );
      }
    }
  }
  return errs;
}

// ------------------------------------------------------------------------------------------------

const { schema } = generateDocs(BLOCKS);
const check = (yamlText: string): string[] => validate(schema as Schema, parseYaml(yamlText));

describe("pipeline JSON Schema", () => {
  test("is a draft-07 schema whose Type enum lists every registered block and its aliases", () => {
    const s = schema as {
      $schema: string;
      definitions: { Block: { properties: { Type: { enum: string[] } } } };
    };
    expect(s.$schema).toBe("http://json-schema.org/draft-07/schema#");
    expect(s.definitions.Block.properties.Type.enum).toEqual(
      BLOCKS.flatMap((d) => [d.type, ...(d.aliases ?? [])]),
    );
  });

  test("every property of a block carries a description", () => {
    const props = (
      schema as { definitions: { Block: { properties: Record<string, { description?: string }> } } }
    ).definitions.Block.properties;
    for (const [k, p] of Object.entries(props)) expect(p.description, k).toBeTruthy();
  });

  test("accepts a valid pipeline with every optional key", () => {
    const errors = check(`
Timer: { Type: ScheduledTimer, DesiredRate: 200, Params: { Autostart: false }, Layout: { X: 10, Y: -2.5 } }
Slow: { Type: DecimatorTimer, DesiredRate: 25, Inputs: [Timer], Path: recordings/ }
Late_2: { Type: DecimatorTimer, DesiredRate: 5, Inputs: [-Timer], Worker: slow-io, Queue: { Policy: latest, Capacity: 8 } }
Port-ref: { Type: DecimatorTimer, DesiredRate: 5, Inputs: [Timer.out] }
Legacy: { Type: ScheduledTimer, DesiredRate: 100, Params: [] }
`);
    expect(errors).toEqual([]);
  });

  test("accepts the BlockTable's groups and comments in Pipeline: { Layout }", () => {
    const errors = check(`
Timer: { Type: ScheduledTimer, DesiredRate: 200 }
Pipeline:
  BatchingMs: 2
  Layout:
    Groups:
      - { Title: Acquisition, X: -24, Y: -48, Width: 440, Height: 260 }
    Comments:
      - { Text: "Band-pass, then rectify", X: 480.5, Y: 300, Width: 220, Height: 90 }
`);
    expect(errors).toEqual([]);
  });

  test.each([
    [
      "a group without a Width",
      "Pipeline: { Layout: { Groups: [{ Title: A, X: 0, Y: 0, Height: 9 }] } }",
      /missing Width/,
    ],
    [
      "a comment of zero height",
      "Pipeline: { Layout: { Comments: [{ Text: a, X: 0, Y: 0, Width: 9, Height: 0 }] } }",
      /Height: <= 0/,
    ],
    ["an unknown Layout key", "Pipeline: { Layout: { Notes: [] } }", /unknown key 'Notes'/],
    [
      "a block named Pipeline with an unknown Type",
      "Pipeline: { Type: ScheduledTimr, DesiredRate: 200 }",
      /matches none of anyOf/,
    ],
  ])("rejects %s (the Pipeline entry)", (_name, yamlText, expected) => {
    expect(check(yamlText).join("\n")).toMatch(expected);
  });

  test.each([
    ["an unknown Type", "A: { Type: ScheduledTimr, DesiredRate: 200 }", /not one of/],
    ["no Type", "A: { DesiredRate: 200 }", /missing Type/],
    [
      "an unknown block key",
      "A: { Type: ScheduledTimer, DesiredRate: 200, Rate: 3 }",
      /unknown key 'Rate'/,
    ],
    ["a bad block name", "1st: { Type: ScheduledTimer, DesiredRate: 200 }", /unknown key '1st'/],
    ["a timer without DesiredRate", "A: { Type: ScheduledTimer }", /missing DesiredRate/],
    ["DesiredRate 0", "A: { Type: ScheduledTimer, DesiredRate: 0 }", /DesiredRate: <= 0/],
    [
      "a bad input reference",
      "A: { Type: DecimatorTimer, DesiredRate: 5, Inputs: ['Timer..x'] }",
      /does not match/,
    ],
    [
      "too many inputs",
      "A: { Type: DecimatorTimer, DesiredRate: 5, Inputs: [T1, T2] }",
      /more than 1 items/,
    ],
    [
      "a wrong param type",
      "A: { Type: ScheduledTimer, DesiredRate: 200, Params: { Autostart: yes please } }",
      /Autostart: expected boolean/,
    ],
    [
      "an unknown param",
      "A: { Type: ScheduledTimer, DesiredRate: 200, Params: { Autostrat: true } }",
      /unknown key 'Autostrat'/,
    ],
    [
      "a bad queue policy",
      "A: { Type: ScheduledTimer, DesiredRate: 200, Queue: { Policy: fifo } }",
      /Policy: not one of/,
    ],
    [
      "a zero queue capacity",
      "A: { Type: ScheduledTimer, DesiredRate: 200, Queue: { Capacity: 0 } }",
      /Capacity: < 1/,
    ],
    [
      "a half layout",
      "A: { Type: ScheduledTimer, DesiredRate: 200, Layout: { X: 1 } }",
      /missing Y/,
    ],
  ])("rejects %s", (_name, yamlText, expected) => {
    const errors = check(yamlText);
    expect(errors.length).toBeGreaterThan(0);
    expect(errors.join("\n")).toMatch(expected);
  });

  test("a block whose params all have defaults is valid with no Params, as the loader says", () => {
    for (const def of BLOCKS as readonly AnyBlockDefinition[]) {
      if (!def.params.safeParse({}).success) continue;
      const spec: Record<string, unknown> = { Type: def.type, Params: {} };
      if (def.timer || def.requiresRate) spec.DesiredRate = 10;
      if (def.inputs.min > 0)
        spec.Inputs = Array.from({ length: def.inputs.min }, (_, i) => `In${i}`);
      expect(validate(schema as Schema, { B: spec }), def.type).toEqual([]);
    }
  });

  test("params schemas are derived with io: input (defaulted params are optional)", () => {
    for (const def of BLOCKS as readonly AnyBlockDefinition[]) {
      const s = paramsJsonSchema(def) as {
        properties?: Record<string, { default?: unknown }>;
        required?: string[];
      };
      for (const [k, p] of Object.entries(s.properties ?? {})) {
        if (p.default !== undefined) expect(s.required ?? [], `${def.type}.${k}`).not.toContain(k);
      }
    }
  });
});

describe("blocks.md", () => {
  const { markdown } = generateDocs(BLOCKS);

  test("starts with the do-not-edit header and documents every block", () => {
    expect(markdown.split("\n")[0]).toContain("do not edit; run `npm run docs`");
    for (const def of BLOCKS) {
      expect(markdown).toContain(`### ${def.type}\n`);
      expect(markdown).toContain(`(#${def.type.toLowerCase()})`);
    }
  });
});
