/**
 * Reading and writing pipeline files for the File menu, and the words shown when a pipeline does
 * not load. Plain Node; tested without Electron.
 */
import { readFile, stat, writeFile } from "node:fs/promises";
import { basename, extname } from "node:path";

/** The protocol's limit on a pipeline's source (app/engine/protocol.ts `load`). */
export const MAX_PIPELINE_BYTES = 4_000_000;

/** File filters of the open and save dialogs. */
export const PIPELINE_FILTERS = [
  { name: "MOSAIC pipeline (YAML)", extensions: ["yaml", "yml"] },
  { name: "All files", extensions: ["*"] },
];

/** Reads a pipeline file as UTF-8 text; throws an Error whose message says what is wrong. */
export async function readPipelineFile(file: string): Promise<string> {
  let size: number;
  try {
    const info = await stat(file);
    if (!info.isFile()) throw new Error("not a file");
    size = info.size;
  } catch (e) {
    throw new Error(`cannot open ${file}: ${(e as Error).message}`);
  }
  if (size > MAX_PIPELINE_BYTES) {
    throw new Error(
      `${basename(file)} is ${size} bytes; a pipeline file may have at most ${MAX_PIPELINE_BYTES}`,
    );
  }
  const source = await readFile(file, "utf8");
  if (source.includes("\0")) throw new Error(`${basename(file)} is not a text (YAML) file`);
  return source;
}

/** Adds ".yaml" when the chosen name has no extension. */
export function withYamlExtension(file: string): string {
  return extname(file) === "" ? `${file}.yaml` : file;
}

/** Writes a pipeline's source; returns the path written. */
export async function writePipelineFile(file: string, source: string): Promise<string> {
  const target = withYamlExtension(file);
  await writeFile(target, source, "utf8");
  return target;
}

/** The parts of a load reply (and its diagnostics) the message reads. */
export interface LoadReply {
  ok: boolean;
  message?: string;
  diagnostics?: readonly {
    severity: string;
    message: string;
    file: string;
    line: number;
    col: number;
    expected?: string;
    suggestion?: string;
  }[];
}

/** The detail text of the "cannot load" dialog: the errors first, at most `max` lines. */
export function loadFailureText(reply: LoadReply, max = 8): string {
  const lines: string[] = [];
  if (reply.message) lines.push(reply.message);
  const diags = [...(reply.diagnostics ?? [])].sort(
    (a, b) => Number(b.severity === "error") - Number(a.severity === "error"),
  );
  for (const d of diags) {
    const where = d.line > 0 ? `line ${d.line}:${d.col}` : basename(d.file);
    let s = `${where}: ${d.severity}: ${d.message}`;
    if (d.expected !== undefined) s += ` (expected ${d.expected})`;
    if (d.suggestion !== undefined) s += `; did you mean '${d.suggestion}'?`;
    lines.push(s);
  }
  if (lines.length === 0) lines.push("the engine did not say why");
  if (lines.length > max) {
    const more = lines.length - max;
    return [...lines.slice(0, max), `… and ${more} more`].join("\n");
  }
  return lines.join("\n");
}
