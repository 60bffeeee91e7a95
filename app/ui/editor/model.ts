/**
 * What the editor shows of a pipeline's text: the blocks as written (type, inputs, params,
 * DesiredRate, Path, Layout), and whether the text parses at all. Its problems are not judged
 * here: the engine checks every text as `mosaic validate` does (use-validation.ts).
 */
import { LineCounter, parseDocument, isMap, isScalar, type Pair } from "yaml";
import type { BlockTypeInfo, CatalogInfo } from "../../engine/protocol";

export interface EditInput {
  /** As written, without the leading '-': "Block" or "Block.port". */
  source: string;
  block: string;
  port: string;
  subscribed: boolean;
}

export interface EditBlock {
  name: string;
  type: string;
  inputs: EditInput[];
  params: Record<string, unknown>;
  desiredRate?: number;
  path?: string;
  layout?: { x: number; y: number };
  /** 1-based line of the block's key (0: unknown). */
  line: number;
}

export interface EditIssue {
  severity: "error" | "warning";
  message: string;
  block?: string;
  /** What the issue is about: "Type", "Inputs", "DesiredRate", "Params.<name>". */
  field?: string;
  /** 1-based; 0 when unknown. */
  line: number;
  col: number;
}

export interface ReadResult {
  blocks: EditBlock[];
  /** YAML syntax errors: the text does not parse (the canvas keeps the last good blocks). */
  errors: EditIssue[];
}

function keyOf(pair: Pair): unknown {
  return isScalar(pair.key) ? pair.key.value : pair.key;
}

function parseInput(s: string): EditInput {
  const subscribed = !s.startsWith("-");
  const source = subscribed ? s : s.slice(1);
  const dot = source.indexOf(".");
  return {
    source,
    block: dot < 0 ? source : source.slice(0, dot),
    port: dot < 0 ? "" : source.slice(dot + 1),
    subscribed,
  };
}

const isRecord = (v: unknown): v is Record<string, unknown> =>
  v !== null && typeof v === "object" && !Array.isArray(v);

/** `Pipeline: { … }` without a Type is the pipeline's settings, not a block (keys.ts). */
const isSettings = (name: string, value: unknown): boolean =>
  name === "Pipeline" && isMap(value) && !value.items.some((p) => keyOf(p) === "Type");

/** The blocks of a pipeline's text, in file order. */
export function readBlocks(text: string): ReadResult {
  const lc = new LineCounter();
  const doc = parseDocument(text, { lineCounter: lc, prettyErrors: false });
  const errors: EditIssue[] = doc.errors.map((e) => {
    const p = lc.linePos(e.pos[0]);
    return {
      severity: "error",
      message: e.message.split("\n")[0]!,
      line: p.line,
      col: p.col,
    };
  });
  if (errors.length > 0) return { blocks: [], errors };
  const root = doc.contents;
  if (root === null || (isScalar(root) && root.value === null)) return { blocks: [], errors };
  if (!isMap(root)) {
    return {
      blocks: [],
      errors: [
        {
          severity: "error",
          message: "the pipeline is not a mapping of blocks (Name: { Type: …, Inputs: [...] })",
          line: 1,
          col: 1,
        },
      ],
    };
  }
  const blocks: EditBlock[] = [];
  for (const pair of root.items) {
    const name = keyOf(pair);
    if (typeof name !== "string" || isSettings(name, pair.value)) continue;
    const start = (pair.key as { range?: [number, number, number] } | null)?.range?.[0];
    const line = start !== undefined ? lc.linePos(start).line : 0;
    const v = (pair.value as { toJSON?(): unknown } | null)?.toJSON?.() ?? null;
    const o = isRecord(v) ? v : {};
    const rawInputs = o.Inputs;
    const list = Array.isArray(rawInputs)
      ? rawInputs
      : rawInputs === undefined || rawInputs === null
        ? []
        : [rawInputs];
    const layout = isRecord(o.Layout) ? o.Layout : undefined;
    blocks.push({
      name,
      type: typeof o.Type === "string" ? o.Type : "",
      inputs: list.map((x) => parseInput(String(x))),
      params: isRecord(o.Params) ? o.Params : {},
      ...(typeof o.DesiredRate === "number" ? { desiredRate: o.DesiredRate } : {}),
      ...(typeof o.Path === "string" ? { path: o.Path } : {}),
      ...(layout && typeof layout.X === "number" && typeof layout.Y === "number"
        ? { layout: { x: layout.X, y: layout.Y } }
        : {}),
      line,
    });
  }
  return { blocks, errors };
}

/** The catalog by type name, aliases included. */
export function typeIndex(catalog: CatalogInfo | undefined): Map<string, BlockTypeInfo> {
  const m = new Map<string, BlockTypeInfo>();
  for (const t of catalog?.types ?? []) {
    m.set(t.type, t);
    for (const a of t.aliases) m.set(a, t);
  }
  return m;
}
