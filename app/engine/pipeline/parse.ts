/**
 * Loader stage 1, parse: YAML text → `yaml` Document (comments and node ranges kept) and a line
 * counter over the text as written; a syntax error becomes one positioned diagnostic.
 *
 * A file `yaml` rejects is parsed once more after the pre-pass of yaml-compat.ts (the layout of
 * multi-line flow collections the original MOSAIC accepted). The pre-pass keeps every offset, so
 * node ranges index the file as written and the editor (document.ts) edits it as it is. Files
 * that parse as they are never see the pre-pass.
 *
 * Linear in the size of the file, whatever it holds: lists and mappings nested deeper than
 * `maxDepth` are refused from the parser's tokens, before the (recursive) composer sees them;
 * duplicate keys are found with one set per mapping (the `yaml` option compares every key with
 * every other); an alias standing for more values than a block's Params may hold (a "billion
 * laughs") or nested too deep once expanded is refused at the alias, from sizes computed once per
 * anchor, without expanding anything. The limits are spec.ts's LOAD_LIMITS.
 */
import {
  type Alias,
  Composer,
  Document,
  isAlias,
  isMap,
  isScalar,
  isSeq,
  LineCounter,
  Parser,
  YAMLParseError,
  type CST,
  type ErrorCode,
  type Node as YamlNode,
} from "yaml";
import { Collector } from "./collector";
import { LOAD_LIMITS, type LoadLimits, type SourcePos } from "./spec";
import { relaxFlowLayout, type LayoutFix } from "./yaml-compat";

export interface ParsedYaml {
  doc: Document;
  /** Fixes the pre-pass needed (none when the file parsed as it is). */
  fixes: LayoutFix[];
  /**
   * The node each alias stands for (the latest anchor of its name before it), so that stages
   * expand aliases without `Alias.resolve`, which walks the whole document every time.
   */
  aliases: Map<Alias, YamlNode>;
}

/** Keys are checked for duplicates here (checkNodes), in linear time. */
const OPTIONS = { uniqueKeys: false, prettyErrors: false } as const;

/** Error codes of this stage besides `yaml`'s own (they travel in `doc.errors`). */
const TOO_DEEP = "NESTING_TOO_DEEP";
const ALIAS_TOO_LARGE = "ALIAS_TOO_LARGE";
const ALIAS_CYCLE = "ALIAS_CYCLE";
const UNRESOLVED_ALIAS = "UNRESOLVED_ALIAS";

/** Parses pipeline YAML the way the loader and the editor do (see the file comment). */
export function parsePipelineYaml(
  source: string,
  limits: Pick<LoadLimits, "maxDepth" | "maxParamsValues"> = LOAD_LIMITS,
): ParsedYaml {
  const first = parseLimited(source, limits);
  if (first.doc.errors.length === 0) return { ...first, fixes: [] };
  const relaxed = relaxFlowLayout(source);
  if (relaxed.fixes.length === 0) return { ...first, fixes: [] };
  return { ...parseLimited(relaxed.text, limits), fixes: relaxed.fixes };
}

/** `parseDocument` with the checks of the file comment. */
function parseLimited(
  source: string,
  limits: Pick<LoadLimits, "maxDepth" | "maxParamsValues">,
): { doc: Document; aliases: Map<Alias, YamlNode> } {
  const tokens = Array.from(new Parser().parse(source));
  const deep = tooDeep(tokens, limits.maxDepth);
  if (deep !== undefined) {
    const doc = new Document(null, OPTIONS);
    doc.contents = null;
    doc.errors.push(
      new YAMLParseError(
        [deep, deep + 1],
        TOO_DEEP as ErrorCode,
        `nesting too deep: lists and mappings more than ${limits.maxDepth} levels inside one another (a pipeline needs about 6)`,
      ),
    );
    return { doc, aliases: new Map() };
  }
  // As `parseDocument` does.
  const composer = new Composer(OPTIONS);
  let doc: Document | undefined;
  for (const d of composer.compose(tokens, true, source.length)) {
    if (!doc) doc = d as Document;
    else {
      doc.errors.push(
        new YAMLParseError(
          d.range.slice(0, 2) as [number, number],
          "MULTIPLE_DOCS",
          "Source contains multiple documents; please use YAML.parseAllDocuments()",
        ),
      );
      break;
    }
  }
  const parsed = doc!;
  const { errors, aliases } = checkNodes(parsed, limits);
  if (errors.length > 0) {
    parsed.errors.push(...errors);
    parsed.errors.sort((a, b) => a.pos[0] - b.pos[0]);
  }
  return { doc: parsed, aliases };
}

/**
 * The offset of the first list or mapping nested deeper than `max` in the parser's tokens, or
 * undefined. Iterative: the tokens of a hostile file may nest a million levels.
 */
function tooDeep(tokens: readonly CST.Token[], max: number): number | undefined {
  const stack: { t: CST.Token | null | undefined; depth: number }[] = [];
  for (const t of tokens) stack.push({ t, depth: 0 });
  while (stack.length > 0) {
    const { t, depth } = stack.pop()!;
    if (!t) continue;
    switch (t.type) {
      case "document":
        stack.push({ t: t.value, depth });
        break;
      case "block-map":
      case "block-seq":
      case "flow-collection": {
        if (depth + 1 > max) return t.offset;
        for (const it of t.items as CST.CollectionItem[]) {
          stack.push({ t: it.key, depth: depth + 1 });
          stack.push({ t: it.value, depth: depth + 1 });
        }
        break;
      }
      default:
        break;
    }
  }
  return undefined;
}

interface Frame {
  node: YamlNode;
  children: (YamlNode | null)[];
  i: number;
  /** Values below this node (aliases expanded) and levels of lists and mappings. */
  size: number;
  height: number;
}

/** Values below a node (aliases expanded) and its levels of lists and mappings. */
interface Measure {
  size: number;
  height: number;
}

/** What checkNodes finds and keeps while it walks the nodes. */
interface NodeCheck {
  limits: Pick<LoadLimits, "maxDepth" | "maxParamsValues">;
  errors: YAMLParseError[];
  aliases: Map<Alias, YamlNode>;
  /** The latest node that defined each anchor, and what it stands for once closed. */
  anchors: Map<string, YamlNode>;
  measured: Map<YamlNode, Measure>;
  /** Lists and mappings entered and not yet closed (an alias to one of them is a cycle). */
  open: Set<YamlNode>;
}

/**
 * One pass over the composed nodes: duplicate keys (as `yaml`'s `uniqueKeys` defines them:
 * scalars with the same value), and aliases that stand for too much (see the file comment).
 */
function checkNodes(
  doc: Document,
  limits: Pick<LoadLimits, "maxDepth" | "maxParamsValues">,
): { errors: YAMLParseError[]; aliases: Map<Alias, YamlNode> } {
  const s: NodeCheck = {
    limits,
    errors: [],
    aliases: new Map(),
    anchors: new Map(),
    measured: new Map(),
    open: new Set(),
  };
  const root = doc.contents as YamlNode | null;
  if (!root) return { errors: s.errors, aliases: s.aliases };
  const first = enterNode(s, root, 0);
  if ("children" in first) walkNodes(s, first);
  return { errors: s.errors, aliases: s.aliases };
}

/** Walks the nodes below `first` depth first, without recursion, measuring each as it closes. */
function walkNodes(s: NodeCheck, first: Frame): void {
  const stack: Frame[] = [first];
  while (stack.length > 0) {
    const f = stack[stack.length - 1]!;
    if (f.i < f.children.length) {
      const child = f.children[f.i++];
      if (!child) continue;
      const r = enterNode(s, child, stack.length);
      if ("children" in r) stack.push(r);
      else addChild(f, r);
      continue;
    }
    stack.pop();
    s.open.delete(f.node);
    if (f.node.anchor) s.measured.set(f.node, { size: f.size, height: f.height });
    const parent = stack[stack.length - 1];
    if (parent) addChild(parent, f);
  }
}

/** Counts a closed child into its parent's size and height. */
function addChild(parent: Frame, child: Measure): void {
  parent.size = Math.min(1e15, parent.size + child.size);
  parent.height = Math.max(parent.height, child.height + 1);
}

/**
 * Enters `node` (`depth`: lists and mappings around it): a frame to walk for a list or mapping,
 * else what it measures.
 */
function enterNode(s: NodeCheck, node: YamlNode, depth: number): Frame | Measure {
  if (node.anchor !== undefined && node.anchor !== null) s.anchors.set(node.anchor, node);
  if (isAlias(node)) return enterAlias(s, node, depth);
  const children = childrenOf(s, node);
  if (!children) {
    if (node.anchor) s.measured.set(node, { size: 1, height: 0 });
    return { size: 1, height: 0 };
  }
  s.open.add(node);
  return { node, children, i: 0, size: 1, height: 1 };
}

/** What an alias measures (its anchor's node); one value when it is refused or names no anchor. */
function enterAlias(s: NodeCheck, node: Alias, depth: number): Measure {
  const { limits } = s;
  const aliasBudget = limits.maxParamsValues;
  const target = s.anchors.get(node.source);
  const at = node.range?.[0] ?? 0;
  if (!target) {
    // `yaml` itself only notices when the value is read (and then the block's Params read as
    // nothing, or as a message without the alias's place): say it here, where it is.
    s.errors.push(
      new YAMLParseError(
        [at, at + 1],
        UNRESOLVED_ALIAS as ErrorCode,
        `alias *${node.source} has no anchor &${node.source} before it (an anchor must come before its aliases)`,
      ),
    );
    return { size: 1, height: 0 };
  }
  s.aliases.set(node, target);
  if (s.open.has(target)) {
    s.errors.push(
      new YAMLParseError(
        [at, at + 1],
        ALIAS_CYCLE as ErrorCode,
        `alias *${node.source} stands for a list or mapping that contains it`,
      ),
    );
    return { size: 1, height: 0 };
  }
  const m = s.measured.get(target) ?? { size: 1, height: 0 };
  if (m.size > aliasBudget || depth + m.height > limits.maxDepth) {
    s.errors.push(
      new YAMLParseError(
        [at, at + 1],
        (m.size > aliasBudget ? ALIAS_TOO_LARGE : TOO_DEEP) as ErrorCode,
        m.size > aliasBudget
          ? `alias *${node.source} stands for ${m.size >= 1e15 ? "too many" : m.size} values; an alias may stand for at most ${aliasBudget} (the values one block's Params may hold)`
          : `nesting too deep: alias *${node.source} stands for lists and mappings ${m.height} levels deep, ${depth + m.height} levels here; at most ${limits.maxDepth}`,
      ),
    );
    // Counted as one value from here on: one report per alias that is too large.
    return { size: 1, height: 0 };
  }
  return m;
}

/** The children of a list or mapping (a mapping's keys and values), reporting duplicate keys. */
function childrenOf(s: NodeCheck, node: YamlNode): (YamlNode | null)[] | undefined {
  if (isMap(node)) {
    const out: (YamlNode | null)[] = [];
    const seen = new Set<string>();
    for (const p of node.items) {
      const k = p.key as YamlNode | null;
      const id = keyIdentity(k);
      if (id !== undefined) {
        if (seen.has(id)) {
          const at = k?.range?.[0] ?? node.range?.[0] ?? 0;
          s.errors.push(
            new YAMLParseError([at, at + 1], "DUPLICATE_KEY", "Map keys must be unique"),
          );
        } else seen.add(id);
      }
      out.push(k, p.value as YamlNode | null);
    }
    return out;
  }
  if (isSeq(node)) return node.items as (YamlNode | null)[];
  return undefined;
}

/** What makes two keys the same for `yaml`'s `uniqueKeys` (undefined: only itself). */
function keyIdentity(k: YamlNode | null): string | undefined {
  if (k === null) return "(no key)";
  if (!isScalar(k)) return undefined;
  const v = k.value;
  if (v === null || v === undefined) return "null:";
  if (typeof v === "number" && Number.isNaN(v)) return undefined;
  if (typeof v === "object") return undefined;
  return `${typeof v}:${String(v)}`;
}

/** A line counter over `source` (1-based lines and columns for offsets). */
export function lineCounterOf(source: string): LineCounter {
  const lc = new LineCounter();
  lc.addNewLine(0);
  for (let i = source.indexOf("\n"); i >= 0; i = source.indexOf("\n", i + 1)) lc.addNewLine(i + 1);
  return lc;
}

export interface ParseStage {
  /** Undefined when the text could not be parsed at all. */
  doc: Document | undefined;
  /** See ParsedYaml. */
  aliases: Map<Alias, YamlNode>;
  /** False when the document has a syntax error (reported in `c`). */
  ok: boolean;
}

/** Stage 1: parses `source` and reports its first syntax error (the others are usually echoes). */
export function parseStage(
  c: Collector,
  source: string,
  limits: Pick<LoadLimits, "maxDepth" | "maxParamsValues"> = LOAD_LIMITS,
): ParseStage {
  let doc: Document;
  let aliases: Map<Alias, YamlNode>;
  try {
    ({ doc, aliases } = parsePipelineYaml(source, limits));
  } catch (e) {
    c.error(
      "yaml-syntax",
      { line: 0, col: 0 },
      `cannot parse YAML: ${e instanceof Error ? e.message : String(e)}`,
    );
    return { doc: undefined, ok: false, aliases: new Map() };
  }
  if (doc.errors.length === 0) return { doc, ok: true, aliases };
  const e = doc.errors[0]!;
  const d = syntaxDiagnostic(c, source, e.code, e.pos[0], e.message);
  c.error(d.code, d.at, d.message);
  return { doc, ok: false, aliases };
}

/** The diagnostic for one `yaml` error: its code, where it really is, and a readable message. */
export function syntaxDiagnostic(
  c: Collector,
  source: string,
  code: string,
  offset: number,
  message: string,
): { code: string; at: SourcePos; message: string } {
  let p = c.at(offset);
  const first = message.split("\n")[0] ?? message;
  let msg = `YAML syntax error: ${first}`;
  if (code === TOO_DEEP) {
    return { code: "nesting-too-deep", at: p, message: first };
  } else if (code === ALIAS_TOO_LARGE || code === ALIAS_CYCLE) {
    return { code: "alias-too-large", at: p, message: first };
  } else if (code === UNRESOLVED_ALIAS) {
    return { code: "unresolved-alias", at: p, message: first };
  } else if (/Maximum call stack size exceeded/.test(first)) {
    // What the composer says when a structure is too deep for the stack (kept as a net: the
    // depth limit refuses such files first).
    return { code: "nesting-too-deep", at: p, message: "nesting too deep here" };
  } else if (code === "DUPLICATE_KEY") {
    msg =
      "duplicate key: a block (or a key inside one) is defined twice; the second definition is here";
  } else if (code === "BLOCK_AS_IMPLICIT_KEY" || code === "MULTILINE_IMPLICIT_KEY") {
    // The parser notices this on the line above the culprit: point at the over-indented line.
    const lines = source.split(/\r?\n/);
    const indent = (l: string) => l.length - l.trimStart().length;
    const base = indent(lines[p.line - 1] ?? "");
    for (let i = p.line; i < lines.length; i++) {
      const l = lines[i]!;
      if (l.trim() === "" || l.trimStart().startsWith("#")) continue;
      if (indent(l) > base) p = { line: i + 1, col: indent(l) + 1 };
      break;
    }
    msg =
      "bad indentation: this line is indented further than the keys above it (the keys of one block must start in the same column)";
  } else if (code === "BAD_INDENT") {
    msg = `bad indentation: ${first}`;
  }
  return { code: code === "DUPLICATE_KEY" ? "duplicate-key" : "yaml-syntax", at: p, message: msg };
}
