/**
 * Generates the block reference (docs/blocks.md) and the pipeline JSON Schema
 * (pipelines/schema/pipeline.schema.json) from the explicit block catalog. The zod params schema of
 * each block is the single source of truth (CONVENTIONS.md): both files come from it.
 *
 *   npm run build:ts && npm run docs      (= node scripts/build-ts.mjs && node dist/tools/gen-docs.mjs)
 *
 * `generateDocs(blocks)` is pure (a test compares its output with the committed files);
 * `renderFiles` formats that output with prettier; `main` writes the files.
 */
import { existsSync, readFileSync } from "node:fs";
import { mkdir, writeFile } from "node:fs/promises";
import { dirname, join, resolve } from "node:path";
import { fileURLToPath, pathToFileURL } from "node:url";
import * as prettier from "prettier";
import { z } from "zod";
import { BLOCKS } from "../app/blocks/catalog";
import { outputNames, type AnyBlockDefinition, type BlockCategory } from "../app/engine/block";
import { catalogTypes, createCatalog } from "../app/engine/catalog";
import { formatDiagnostic } from "../app/engine/diagnostics";
import { pipelineCatalog } from "../app/engine/user-blocks";
import { loadBlockModule } from "../app/host/user-blocks";
import { MAX_LAYOUT_BOXES, MAX_LAYOUT_TEXT } from "../app/engine/pipeline/pipeline-layout";

/** Output paths, repo-relative. */
export const BLOCKS_MD = "docs/blocks.md";
export const PIPELINE_SCHEMA = "pipelines/schema/pipeline.schema.json";

/** Category order in the docs (a new category in block.ts is a type error here until listed). */
const CATEGORY_ORDER: Record<BlockCategory, number> = {
  Timing: 0,
  Sources: 1,
  "Signal processing": 2,
  Features: 3,
  Kinematics: 4,
  "Flow control": 5,
  Learning: 6,
  Control: 7,
  Communication: 8,
  Devices: 9,
  Recording: 10,
  Testing: 11,
};

/** Mirrors the pipeline loader (app/engine/pipeline/loader.ts). */
const BLOCK_NAME_PATTERN = "^[A-Za-z_][A-Za-z0-9_-]*$";
const WORKER_PATTERN = "^[A-Za-z_][A-Za-z0-9_-]*$";
const INPUT_PATTERN = "^-?[A-Za-z_][A-Za-z0-9_-]*(\\.[A-Za-z0-9_-]+)?$";
const QUEUE_POLICIES = ["drop-oldest", "drop-newest", "latest"];
const MAX_QUEUE_CAPACITY = 1 << 24;
const SETTINGS_KEY = "Pipeline";

type JsonSchema = { [key: string]: unknown };

/** The JSON Schema (draft-07) of a block's params as written in a file (`io: "input"`). */
export function paramsJsonSchema(def: AnyBlockDefinition): JsonSchema {
  const s = z.toJSONSchema(def.params, {
    io: "input",
    target: "draft-07",
    unrepresentable: "any",
  }) as JsonSchema;
  delete s.$schema;
  return s;
}

// ------------------------------------------------------------------------------------------------
// JSON Schema

/**
 * Moves a params schema under `#/definitions/<prefix>` of the pipeline schema: its own
 * definitions (zod emits them for recursive or reused parts) get prefixed names, and every local
 * `$ref` is rewritten to point at the new place.
 */
function hoist(schema: JsonSchema, prefix: string, definitions: Record<string, unknown>): void {
  const own = (schema.definitions ?? {}) as Record<string, unknown>;
  delete schema.definitions;
  const rewrite = (node: unknown): unknown => {
    if (Array.isArray(node)) return node.map(rewrite);
    if (node === null || typeof node !== "object") return node;
    const out: JsonSchema = {};
    for (const [k, v] of Object.entries(node)) {
      if (k === "$ref" && typeof v === "string") {
        out[k] =
          v === "#"
            ? `#/definitions/${prefix}`
            : v.replace(/^#\/definitions\//, `#/definitions/${prefix}.`);
      } else {
        out[k] = rewrite(v);
      }
    }
    return out;
  };
  definitions[prefix] = rewrite(schema);
  for (const [name, sub] of Object.entries(own)) definitions[`${prefix}.${name}`] = rewrite(sub);
}

/** MOSAIC's positional `Params`: a list of strings (numbers are read as their text). */
const LEGACY_PARAMS: JsonSchema = {
  type: "array",
  description:
    "MOSAIC's positional form: a list of strings such as `[power:2]` or `[b0;b1;b2, 1;a1;a2]` (vectors as `a;b;c`); converted to named params with a warning",
  items: {
    anyOf: [
      { type: ["string", "number", "boolean"] },
      { type: "array", items: { type: ["string", "number"] } },
      { type: "object", minProperties: 1, maxProperties: 1 },
    ],
  },
};

function pipelineSchema(blocks: readonly AnyBlockDefinition[]): JsonSchema {
  const definitions: Record<string, unknown> = {};
  const branches: JsonSchema[] = [];
  for (const def of blocks) {
    const ref = `${def.type}.Params`;
    hoist(paramsJsonSchema(def), ref, definitions);
    const params: JsonSchema = def.legacyParams
      ? {
          description: `Params of ${def.type} (see docs/blocks.md), or MOSAIC's positional list${def.legacyForm ? `: ${def.legacyForm}` : ""}`,
          anyOf: [{ $ref: `#/definitions/${ref}` }, LEGACY_PARAMS],
        }
      : {
          description: `Params of ${def.type} (see docs/blocks.md)`,
          allOf: [{ $ref: `#/definitions/${ref}` }],
        };
    const inputs: JsonSchema = {};
    if (def.inputs.min > 0) inputs.minItems = def.inputs.min;
    if (Number.isFinite(def.inputs.max)) inputs.maxItems = def.inputs.max;
    const required: string[] = [];
    if (def.timer || def.requiresRate) required.push("DesiredRate");
    if (def.inputs.min > 0) required.push("Inputs");
    branches.push({
      if: {
        properties: {
          Type: def.aliases?.length ? { enum: [def.type, ...def.aliases] } : { const: def.type },
        },
        required: ["Type"],
      },
      then: {
        properties: { Params: params, ...(Object.keys(inputs).length ? { Inputs: inputs } : {}) },
        ...(required.length ? { required } : {}),
      },
    });
  }

  const block: JsonSchema = {
    type: "object",
    description: "A block: its type, inputs and params.",
    properties: {
      Type: {
        description: "The block type (see docs/blocks.md).",
        type: "string",
        enum: blocks.flatMap((d) => [d.type, ...(d.aliases ?? [])]),
      },
      DesiredRate: {
        description:
          "Desired output rate in Hz. Required for timers; otherwise inherited from the inputs. Drives the timing status (lagging below 95 %).",
        type: "number",
        exclusiveMinimum: 0,
      },
      Inputs: {
        description:
          "Input blocks, in order: `Name` (its default port), `Name.port`, or `-Name` to declare an input that is subscribed only at run time.",
        type: "array",
        items: { type: "string", pattern: INPUT_PATTERN },
      },
      Params: {
        description:
          "The block's params: a mapping validated by the block's schema, or MOSAIC's positional list for blocks that have a positional form.",
        type: ["object", "array"],
      },
      Path: {
        description:
          "Log this block's output: a folder (the log is <Path>/<block>.txt) or a file name. One line per event: `timestamp,v1,…,vn`.",
        type: "string",
        minLength: 1,
      },
      Layout: {
        description: "Position of the block on the canvas.",
        type: "object",
        properties: {
          X: { description: "Horizontal position.", type: "number" },
          Y: { description: "Vertical position.", type: "number" },
        },
        required: ["X", "Y"],
      },
      Worker: {
        description:
          "Run this block on its own worker of that name (heavy or slow work), so that branches that do not depend on it stay on time. Default: main.",
        type: "string",
        pattern: WORKER_PATTERN,
      },
      Queue: {
        description:
          "The bounded queue on each of this block's input edges, and what happens when it is full.",
        type: "object",
        properties: {
          Policy: {
            description:
              "When the queue is full: drop-oldest (default) drops the oldest event, drop-newest the arriving one, latest keeps only the newest. Drops are counted.",
            type: "string",
            enum: QUEUE_POLICIES,
          },
          Capacity: {
            description:
              "Capacity of each input edge in events (default: one second of the source's data, at least 64).",
            type: "integer",
            minimum: 1,
            maximum: MAX_QUEUE_CAPACITY,
          },
        },
        additionalProperties: false,
      },
      BatchingMs: BATCHING_MS,
    },
    required: ["Type"],
    additionalProperties: false,
    allOf: branches,
  };

  return {
    $schema: "http://json-schema.org/draft-07/schema#",
    title: "MOSAIC pipeline",
    description:
      "A MOSAIC pipeline: a mapping from block name to block. Generated from the block catalog by tools/gen-docs.ts (npm run docs); do not edit.",
    type: "object",
    properties: {
      [SETTINGS_KEY]: {
        description:
          "Settings of the whole pipeline (reserved name; a block named Pipeline needs a Type).",
        anyOf: [
          {
            type: "object",
            properties: { BatchingMs: BATCHING_MS, Layout: PIPELINE_LAYOUT, Blocks: USER_BLOCKS },
            additionalProperties: false,
          },
          { $ref: "#/definitions/Block" },
        ],
      },
    },
    // Every name but the settings entry's (which `properties` covers, a block named so included):
    // a key matching both would be checked against both.
    patternProperties: {
      [`^(?!${SETTINGS_KEY}$)${BLOCK_NAME_PATTERN.slice(1)}`]: { $ref: "#/definitions/Block" },
    },
    additionalProperties: false,
    definitions: { Block: block, ...definitions },
  };
}

/** `Pipeline: { Blocks }`: the pipeline's own block modules (docs/writing-blocks.md). */
const USER_BLOCKS: JsonSchema = {
  description:
    "Modules defining extra block types for this pipeline (docs/writing-blocks.md): ES modules (.ts, .mts, .js, .mjs) whose default or named exports are defineBlock(...) definitions, each path relative to this file.",
  type: "array",
  items: { type: "string", pattern: "\\.(ts|mts|js|mjs)$" },
};

/** A box of `Pipeline: { Layout }` with its text key (app/engine/pipeline/pipeline-layout.ts). */
function layoutBox(textKey: string, text: string): JsonSchema {
  const size = { type: "number", exclusiveMinimum: 0 };
  return {
    type: "object",
    properties: {
      [textKey]: { description: text, type: "string", maxLength: MAX_LAYOUT_TEXT },
      X: { description: "Left edge on the canvas, px.", type: "number" },
      Y: { description: "Top edge on the canvas, px.", type: "number" },
      Width: { description: "Width, px.", ...size },
      Height: { description: "Height, px.", ...size },
    },
    required: ["X", "Y", "Width", "Height"],
    additionalProperties: false,
  };
}

const PIPELINE_LAYOUT: JsonSchema = {
  description:
    "Boxes drawn on the canvas besides the blocks: groups (a titled box; the blocks inside it move with it) and comments (free text).",
  type: "object",
  properties: {
    Groups: {
      type: "array",
      maxItems: MAX_LAYOUT_BOXES,
      items: layoutBox("Title", "The group's title."),
    },
    Comments: {
      type: "array",
      maxItems: MAX_LAYOUT_BOXES,
      items: layoutBox("Text", "The comment's text."),
    },
  },
  additionalProperties: false,
};

const BATCHING_MS: JsonSchema = {
  description:
    "How long a timer's ticks may wait to go out together, in ms (DESIGN.md §3): the worker wakes at most once per interval and fires every tick due, as a device delivers packets. 0 wakes for every tick. In `Pipeline:` the default for every block (5 ms when unset); on a block, that block's own.",
  type: "number",
  minimum: 0,
  maximum: 1000,
};

// ------------------------------------------------------------------------------------------------
// Markdown

/** GitHub's heading anchor. */
function slug(heading: string): string {
  return heading
    .toLowerCase()
    .replace(/[^\p{L}\p{N} _-]/gu, "")
    .replace(/ /g, "-");
}

/** Text safe inside a Markdown table cell. */
function cell(text: string): string {
  return text.replace(/\r?\n/g, " ").replace(/\|/g, "\\|");
}

function code(text: string): string {
  return text.includes("`") ? `\`\` ${text} \`\`` : `\`${text}\``;
}

function json(v: unknown): string {
  const s = JSON.stringify(v);
  return s === undefined ? String(v) : s;
}

/** A short type description of a JSON Schema node. */
function typeText(s: JsonSchema | undefined): string {
  if (!s || Object.keys(s).filter((k) => k !== "description" && k !== "default").length === 0) {
    return "any";
  }
  if (s.const !== undefined) return json(s.const);
  if (Array.isArray(s.enum)) return s.enum.map(json).join(" | ");
  for (const k of ["anyOf", "oneOf"] as const) {
    if (Array.isArray(s[k])) return (s[k] as JsonSchema[]).map(typeText).join(" | ");
  }
  if (Array.isArray(s.allOf) && s.allOf.length === 1) return typeText(s.allOf[0] as JsonSchema);
  if (typeof s.$ref === "string") return s.$ref.replace(/^.*\//, "");
  const types = Array.isArray(s.type) ? (s.type as string[]) : [s.type as string];
  return types
    .map((t) => {
      switch (t) {
        case "array": {
          const items = s.items as JsonSchema | undefined;
          let it = typeText(items);
          if (it.includes(" ")) it = `(${it})`;
          const min = s.minItems as number | undefined;
          const max = s.maxItems as number | undefined;
          const n =
            min !== undefined && min === max
              ? ` (${min})`
              : min !== undefined && max !== undefined
                ? ` (${min}–${max})`
                : min !== undefined && min > 0
                  ? ` (≥ ${min})`
                  : max !== undefined
                    ? ` (≤ ${max})`
                    : "";
          return `${it}[]${n}`;
        }
        case "number":
        case "integer": {
          const parts: string[] = [];
          const big = (v: unknown) =>
            typeof v === "number" && Math.abs(v) >= Number.MAX_SAFE_INTEGER;
          if (typeof s.exclusiveMinimum === "number") parts.push(`> ${s.exclusiveMinimum}`);
          else if (typeof s.minimum === "number" && !big(s.minimum)) parts.push(`≥ ${s.minimum}`);
          if (typeof s.exclusiveMaximum === "number") parts.push(`< ${s.exclusiveMaximum}`);
          else if (typeof s.maximum === "number" && !big(s.maximum)) parts.push(`≤ ${s.maximum}`);
          return parts.length ? `${t} ${parts.join(", ")}` : t;
        }
        case "string": {
          const min = s.minLength as number | undefined;
          return min && min > 0 ? "string (non-empty)" : "string";
        }
        case "object":
          return "mapping";
        case undefined:
          return "any";
        default:
          return t;
      }
    })
    .join(" | ");
}

function inputsText(def: AnyBlockDefinition): string {
  const { min, max, labels } = def.inputs;
  const count =
    max === 0
      ? "none (a source)"
      : min === max
        ? `exactly ${min}`
        : Number.isFinite(max)
          ? `${min}–${max}`
          : `${min} or more`;
  return labels && labels.length ? `${count}: ${labels.map(code).join(", ")}` : count;
}

function outputsText(def: AnyBlockDefinition): string {
  const o = def.outputs;
  if (typeof o === "function") {
    let withDefaults = "";
    try {
      const p = def.params.safeParse({});
      if (p.success) withDefaults = outputNames(def, p.data).map(code).join(", ");
    } catch {
      // a port function that needs params the defaults do not give: say nothing more
    }
    return `ports depend on the params${withDefaults ? ` (with the defaults: ${withDefaults})` : ""}; the first is the default port`;
  }
  const names = outputNames(def, undefined);
  if (names.length === 0) return "none (a sink)";
  if (names.length === 1) return code(names[0]!);
  return `${names.map(code).join(", ")}; the first is the default port`;
}

function paramsSection(def: AnyBlockDefinition): string[] {
  const s = paramsJsonSchema(def);
  const props = s.properties as Record<string, JsonSchema> | undefined;
  if (!props) return [`**Params:** ${code(typeText(s))}`, ""];
  const names = Object.keys(props);
  if (names.length === 0) return ["**Params:** none.", ""];
  const required = new Set((s.required as string[] | undefined) ?? []);
  const live = new Set(def.live ?? []);
  const lines = [
    "**Params:**",
    "",
    "| Name | Type | Default | Live | Description |",
    "| --- | --- | --- | --- | --- |",
  ];
  for (const name of names) {
    const p = props[name]!;
    const dflt =
      p.default !== undefined ? code(json(p.default)) : required.has(name) ? "required" : "—";
    lines.push(
      `| ${[
        code(name),
        cell(code(typeText(p))),
        cell(dflt),
        live.has(name) ? "yes" : "",
        cell(typeof p.description === "string" ? p.description : ""),
      ].join(" | ")} |`,
    );
  }
  if (s.additionalProperties === false) lines.push("", "Other keys are rejected.");
  lines.push("");
  return lines;
}

function blockSection(def: AnyBlockDefinition): string[] {
  const lines = [`### ${def.type}`, "", `**${def.summary.trim()}**`, "", def.help.trim(), ""];
  const facts = [`- **Type:** ${code(def.type)}`, `- **Category:** ${def.category}`];
  if (def.aliases?.length) {
    facts.push(
      `- **Also loads as:** ${def.aliases.map(code).join(", ")} (older names, with a warning)`,
    );
  }
  facts.push(`- **Inputs:** ${inputsText(def)}`);
  facts.push(`- **Outputs:** ${outputsText(def)}`);
  if (def.timer)
    facts.push("- **DesiredRate:** required (a timer: its ticks pace the blocks downstream)");
  else if (def.requiresRate) facts.push("- **DesiredRate:** required");
  if (def.views && def.views.length) facts.push(`- **Views:** ${def.views.join(", ")}`);
  if (def.panel) facts.push(`- **Panel:** ${def.panel}`);
  lines.push(...facts, "", ...paramsSection(def));
  if (def.legacyForm) lines.push(`**MOSAIC positional form:** ${def.legacyForm}`, "");
  else if (def.legacyParams) lines.push("**MOSAIC positional form:** accepted.", "");
  return lines;
}

function byCategory(blocks: readonly AnyBlockDefinition[]): [string, AnyBlockDefinition[]][] {
  const groups = new Map<string, AnyBlockDefinition[]>();
  for (const d of blocks) groups.set(d.category, [...(groups.get(d.category) ?? []), d]);
  const rank = (c: string) => (CATEGORY_ORDER as Record<string, number>)[c] ?? 1000;
  return [...groups.entries()]
    .sort(([a], [b]) => rank(a) - rank(b) || a.localeCompare(b))
    .map(([c, ds]) => [c, ds.slice().sort((a, b) => a.type.localeCompare(b.type))]);
}

function markdown(blocks: readonly AnyBlockDefinition[]): string {
  const groups = byCategory(blocks);
  const lines = [
    "<!-- Generated by tools/gen-docs.ts from app/blocks/catalog.ts: do not edit; run `npm run docs`. -->",
    "",
    "# Blocks",
    "",
    `Every block type MOSAIC knows (${blocks.length} in ${groups.length} ${groups.length === 1 ? "category" : "categories"}), generated from the block catalog (\`app/blocks/catalog.ts\`): each block's params schema is the single source of truth for this page, the pipeline JSON Schema (\`pipelines/schema/pipeline.schema.json\`) and the control-panel form.`,
    "",
    "In a pipeline file a block is written `Name: { Type: <type>, DesiredRate: <Hz>, Inputs: [...], Params: {...}, Path: <log> }`; see DESIGN.md §2. Params marked _live_ can be changed while the pipeline runs.",
    "",
    "## Contents",
    "",
  ];
  for (const [category, defs] of groups) {
    lines.push(
      `- [${category}](#${slug(category)}): ${defs.map((d) => `[${d.type}](#${slug(d.type)})`).join(", ")}`,
    );
  }
  lines.push("");
  for (const [category, defs] of groups) {
    lines.push(`## ${category}`, "");
    for (const d of defs) lines.push(...blockSection(d));
  }
  return lines.join("\n");
}

// ------------------------------------------------------------------------------------------------

/** Pure: the block reference (Markdown, unformatted) and the pipeline JSON Schema. */
export function generateDocs(blocks: readonly AnyBlockDefinition[]): {
  markdown: string;
  schema: object;
} {
  return { markdown: markdown(blocks), schema: pipelineSchema(blocks) };
}

/** The repository root: the nearest folder up from here whose package.json is MOSAIC's. */
export function repoRoot(from = dirname(fileURLToPath(import.meta.url))): string {
  for (let dir = resolve(from); ; dir = dirname(dir)) {
    const pkg = join(dir, "package.json");
    if (
      existsSync(pkg) &&
      (JSON.parse(readFileSync(pkg, "utf8")) as { name?: string }).name === "mosaic"
    ) {
      return dir;
    }
    if (dirname(dir) === dir) throw new Error(`gen-docs: no MOSAIC package.json above ${from}`);
  }
}

/** The two files exactly as committed: generated, then formatted with the repo's prettier config. */
export async function renderFiles(
  blocks: readonly AnyBlockDefinition[],
  root = repoRoot(),
): Promise<Record<string, string>> {
  const { markdown: md, schema } = generateDocs(blocks);
  const format = async (rel: string, text: string, parser: "markdown" | "json") => {
    const config = (await prettier.resolveConfig(join(root, rel))) ?? {};
    return prettier.format(text, { ...config, parser });
  };
  return {
    [BLOCKS_MD]: await format(BLOCKS_MD, md, "markdown"),
    [PIPELINE_SCHEMA]: await format(PIPELINE_SCHEMA, JSON.stringify(schema, null, 2), "json"),
  };
}

/**
 * `--pipeline FILE`: the reference and the JSON Schema of one pipeline's blocks — the built-in
 * ones and those of its `Pipeline: { Blocks }` modules (docs/writing-blocks.md) — written beside
 * it as blocks.md and pipeline.schema.json.
 */
async function pipelineDocs(file: string): Promise<void> {
  const source = readFileSync(file, "utf8");
  const own = await pipelineCatalog(source, resolve(file), createCatalog(BLOCKS), loadBlockModule);
  for (const d of own.diagnostics) console.error(formatDiagnostic(d));
  if (own.diagnostics.some((d) => d.severity === "error")) {
    process.exitCode = 2;
    return;
  }
  const blocks = catalogTypes(own.catalog);
  const { markdown: md, schema } = generateDocs(blocks);
  const dir = dirname(resolve(file));
  const out: [string, string][] = [
    [join(dir, "blocks.md"), await prettier.format(md, { parser: "markdown" })],
    [
      join(dir, "pipeline.schema.json"),
      await prettier.format(JSON.stringify(schema, null, 2), { parser: "json" }),
    ],
  ];
  for (const [path, text] of out) {
    await writeFile(path, text);
    console.log(
      `gen-docs: wrote ${path} (${blocks.length} block types, ${blocks.length - BLOCKS.length} of the pipeline's own)`,
    );
  }
}

export async function main(): Promise<void> {
  const at = process.argv.indexOf("--pipeline");
  if (at >= 0) return pipelineDocs(process.argv[at + 1] ?? "");
  const root = repoRoot();
  const files = await renderFiles(BLOCKS, root);
  for (const [rel, text] of Object.entries(files)) {
    const file = join(root, rel);
    await mkdir(dirname(file), { recursive: true });
    await writeFile(file, text);
    console.log(`gen-docs: wrote ${rel} (${BLOCKS.length} block types)`);
  }
}

if (process.argv[1] && import.meta.url === pathToFileURL(resolve(process.argv[1])).href) {
  main().catch((e: unknown) => {
    console.error(`gen-docs: ${e instanceof Error ? (e.stack ?? e.message) : String(e)}`);
    process.exitCode = 1;
  });
}
