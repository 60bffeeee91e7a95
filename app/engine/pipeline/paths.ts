/**
 * Loader stage after wiring, log paths: no two blocks may write the same log file. A block's
 * `Path` is a folder (its log is `<Path>/<block>.txt`, `<block>.<port>.txt` for a named port) or a
 * file (runtime/logsink.ts: logFileName), so `A: { Path: logs/B.txt }` and `B: { Path: logs/ }`
 * meet in one file, where two writers tear lines and lose them. Each such block gets one
 * positioned error (at its `Path`) naming the block it collides with. Names are compared as
 * written, after the folder part is normalised (`./`, `a/../`, doubled and back slashes); names
 * that differ only in case are a warning (one file on Windows and macOS). What only the disk can
 * tell (an absolute and a relative name for one file, links, two pipelines) is the log writer's
 * to refuse at run time (app/host/log-writer.ts).
 */
import { isMap, isScalar, type Document, type Node as YamlNode } from "yaml";
import { logFileName } from "../runtime/logsink";
import type { Collector } from "./collector";
import type { BlockSpec, SourcePos } from "./spec";

/** `a/./b//../c.txt` → `a/c.txt`; back slashes as slashes; a leading `/` kept. */
export function normalizeLogPath(p: string): string {
  const abs = /^[\\/]/.test(p);
  const out: string[] = [];
  for (const part of p.split(/[\\/]+/)) {
    if (part === "" || part === ".") continue;
    if (part === ".." && out.length > 0 && out[out.length - 1] !== "..") out.pop();
    else if (part !== ".." || !abs) out.push(part);
  }
  return (abs ? "/" : "") + out.join("/");
}

/** Every log file a block writes: one per output port, as the runtime opens them. */
export function logFilesOf(b: BlockSpec): { port: string; file: string }[] {
  if (b.path === undefined) return [];
  return b.outputs.map((port, i) => ({
    port,
    file: normalizeLogPath(logFileName(b.path!, b.name, port, i === 0)),
  }));
}

/** The blocks' entries of the document by name, indexed once per document (an error per block of a big file stays linear). */
const entriesByDoc = new WeakMap<Document, Map<unknown, YamlNode>>();

function blockEntry(doc: Document, name: string): YamlNode | undefined {
  let index = entriesByDoc.get(doc);
  if (!index) {
    index = new Map();
    const root = doc.contents;
    if (isMap(root))
      for (const p of root.items)
        if (isScalar(p.key) && !index.has(p.key.value)) index.set(p.key.value, p.value as YamlNode);
    entriesByDoc.set(doc, index);
  }
  return index.get(name);
}

/** The position of a block's `Path` value (the block's own position when it cannot be found). */
function pathPos(c: Collector, doc: Document | undefined, b: BlockSpec): SourcePos {
  const entry = doc ? blockEntry(doc, b.name) : undefined;
  if (!entry || !isMap(entry)) return b.pos;
  const path = entry.items.find((p) => isScalar(p.key) && p.key.value === "Path");
  return path ? c.pos((path.value ?? path.key) as YamlNode) : b.pos;
}

const fileText = (block: BlockSpec, port: string, file: string): string =>
  block.outputs.length > 1 ? `its log of output '${port}', '${file}',` : `its log '${file}'`;

/** The stage: one error per block whose log file (the first of its outputs') another block already writes. */
export function checkPaths(
  c: Collector,
  blocks: readonly BlockSpec[],
  doc: Document | undefined,
): void {
  const owner = new Map<string, { block: BlockSpec; port: string }>();
  const folded = new Map<string, { block: BlockSpec; file: string }>();
  for (const b of blocks) {
    for (const { port, file } of logFilesOf(b)) {
      const first = owner.get(file);
      if (first) {
        const self = first.block === b;
        const at = pathPos(c, doc, first.block);
        c.error(
          "same-log-file",
          pathPos(c, doc, b),
          `block '${b.name}': ${fileText(b, port, file)} is also written by ${
            self
              ? `its output '${first.port}'`
              : `block '${first.block.name}' (Path at ${at.line}:${at.col})`
          }; two writers on one file tear and lose lines`,
          {
            block: b.name,
            param: "Path",
            expected: self
              ? "a folder as Path (each output gets <block>.<port>.txt)"
              : `a Path of its own for '${b.name}' or '${first.block.name}' (another folder or file name)`,
          },
        );
        break; // one error per block
      }
      owner.set(file, { block: b, port });
      const key = file.toLowerCase();
      const other = folded.get(key);
      if (other && other.block !== b) {
        c.warn(
          "log-file-case",
          pathPos(c, doc, b),
          `block '${b.name}': its log '${file}' and block '${other.block.name}''s '${other.file}' differ only in case: one file on Windows and macOS, where they would tear each other's lines`,
          { block: b.name, param: "Path" },
        );
      } else if (!other) folded.set(key, { block: b, file });
    }
  }
}
