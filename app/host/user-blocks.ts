/**
 * Loads a user's block module in Node (docs/writing-blocks.md): esbuild bundles the file with
 * what it imports (TypeScript transpiled, `.wasm` files as bytes, `mosaic/sdk` bound to this
 * engine's own SDK object), and the bundle is imported from a file in the temp folder (named by
 * its content, source-mapped). A module that fails names
 * the reason, with the line and column of a syntax error. Results are kept per file until one of
 * the files the module was built from changes (the editor validates on every pause in typing).
 */
import { createHash } from "node:crypto";
import { existsSync, mkdirSync, statSync, writeFileSync } from "node:fs";
import { tmpdir } from "node:os";
import { basename, dirname, isAbsolute, join, resolve } from "node:path";
import { pathToFileURL } from "node:url";
import type { Message, Plugin } from "esbuild";
import { errorMessage } from "../engine/diagnostics";
import {
  installSdk as installEngineSdk,
  sdkModuleSource,
  SDK_IMPORT,
  userFrame,
  type ModuleLoadResult,
} from "../engine/user-blocks";

/** Makes `mosaic/sdk` resolvable for modules loaded in this thread (stacks source-mapped). */
export function installSdk(): void {
  installEngineSdk();
  // Stack traces at the user's lines (the bundle carries its source map).
  process.setSourceMapsEnabled(true);
}

const sdkPlugin: Plugin = {
  name: "mosaic-sdk",
  setup(b) {
    b.onResolve({ filter: SDK_IMPORT }, () => ({ path: "sdk", namespace: "mosaic-sdk" }));
    b.onLoad({ filter: /.*/, namespace: "mosaic-sdk" }, () => ({
      contents: sdkModuleSource(),
      loader: "js",
    }));
  },
};

interface CacheEntry {
  stamps: Map<string, string>;
  result: ModuleLoadResult;
}
const cache = new Map<string, CacheEntry>();

/** A file's size and modification time, "" when it is gone. */
function stamp(file: string): string {
  try {
    const s = statSync(file);
    return `${s.size}:${s.mtimeMs}`;
  } catch {
    return "";
  }
}

function fresh(e: CacheEntry): boolean {
  for (const [f, s] of e.stamps) if (stamp(f) !== s) return false;
  return true;
}

/** Says why a file may not be part of a module (outside the allowed folders), or undefined. */
export type RefuseFile = (file: string) => string | undefined;

/**
 * Loads the module `path` (absolute), or says why it cannot. With `refuse`, every file the module
 * is built from is checked before any of its code runs.
 */
export async function loadBlockModule(
  path: string,
  refuse?: RefuseFile,
): Promise<ModuleLoadResult> {
  const file = isAbsolute(path) ? path : resolve(path);
  const hit = cache.get(file);
  if (hit && fresh(hit)) return refused(hit.result.inputs, refuse) ?? hit.result;
  const result = await loadUncached(file, refuse);
  if (result.ok || !result.refused) {
    cache.set(file, { stamps: new Map(result.inputs.map((f) => [f, stamp(f)])), result });
  }
  return result;
}

function refused(
  inputs: string[],
  refuse: RefuseFile | undefined,
): (ModuleLoadResult & { refused: true }) | undefined {
  for (const f of inputs) {
    const why = refuse?.(f);
    if (why !== undefined) return { ok: false, message: why, inputs, refused: true };
  }
  return undefined;
}

async function loadUncached(
  file: string,
  refuse: RefuseFile | undefined,
): Promise<ModuleLoadResult & { refused?: true }> {
  if (!existsSync(file)) return { ok: false, message: "no such file", inputs: [file] };
  const first = refused([file], refuse);
  if (first) return first;
  installSdk();
  const built = await bundle(file);
  if (!built.ok) return built;
  const inside = refused(built.inputs, refuse);
  if (inside) return inside;
  try {
    const exports = (await import(bundleFile(file, built.code))) as Record<string, unknown>;
    return { ok: true, exports, inputs: built.inputs };
  } catch (e) {
    return {
      ok: false,
      message: `its top level threw: ${errorMessage(e)}`,
      ...stackPosition(e, file),
      inputs: built.inputs,
    };
  }
}

/**
 * The bundle as a file (named by its content: the same code is one module) whose URL the
 * import takes; a file, not a data: URL, so that Node maps stack traces to the user's lines.
 */
function bundleFile(file: string, code: string): string {
  const dir = join(tmpdir(), "mosaic-block-modules");
  mkdirSync(dir, { recursive: true });
  const hash = createHash("sha256").update(file).update("\0").update(code).digest("hex");
  const out = join(dir, `${basename(file).replace(/\.[^.]+$/, "")}-${hash.slice(0, 16)}.mjs`);
  if (!existsSync(out)) writeFileSync(out, code);
  return pathToFileURL(out).href;
}

/** Where in the user's file an error was thrown (from its source-mapped stack), if there. */
function stackPosition(e: unknown, file: string): { line?: number; col?: number } {
  const at = userFrame(e, basename(file));
  return at ? { line: at.line, col: at.col } : {};
}

type Bundled =
  { ok: true; code: string; inputs: string[] } | Extract<ModuleLoadResult, { ok: false }>;

/** esbuild, or why this MOSAIC cannot load block modules (a package without it). */
async function esbuildOrWhy(): Promise<typeof import("esbuild") | string> {
  try {
    return await import("esbuild");
  } catch (e) {
    return `this MOSAIC has no esbuild to load block modules with (${errorMessage(e)}); run it from the repository after npm install`;
  }
}

async function bundle(file: string): Promise<Bundled> {
  const esbuild = await esbuildOrWhy();
  if (typeof esbuild === "string") return { ok: false, message: esbuild, inputs: [file] };
  const dir = dirname(file);
  try {
    const r = await esbuild.build({
      entryPoints: [file],
      absWorkingDir: dir,
      bundle: true,
      write: false,
      format: "esm",
      platform: "node",
      target: "node20",
      sourcemap: "inline",
      sourceRoot: `${pathToFileURL(dir).href}/`,
      metafile: true,
      logLevel: "silent",
      plugins: [sdkPlugin],
      loader: { ".wasm": "binary" },
      banner: {
        js: `import { createRequire as __mosaicRequire } from "node:module"; const require = __mosaicRequire(${JSON.stringify(pathToFileURL(file).href)});`,
      },
    });
    const inputs = Object.keys(r.metafile.inputs)
      .filter((k) => !/^[a-z-]+:/.test(k))
      .map((k) => resolve(dir, k));
    return { ok: true, code: r.outputFiles[0]!.text, inputs: inputs.length > 0 ? inputs : [file] };
  } catch (e) {
    const errors = (e as { errors?: Message[] }).errors ?? [];
    return buildFailure(file, dir, errors, e);
  }
}

/** The first build error: at its line in the module, or naming the imported file it is in. */
function buildFailure(
  file: string,
  dir: string,
  errors: Message[],
  e: unknown,
): Extract<ModuleLoadResult, { ok: false }> {
  const first = errors[0];
  const more = errors.length > 1 ? ` (and ${errors.length - 1} more)` : "";
  if (!first) return { ok: false, message: errorMessage(e), inputs: [file] };
  const loc = first.location;
  const inputs = [file];
  if (!loc) return { ok: false, message: `${first.text}${more}`, inputs };
  const where = resolve(dir, loc.file);
  if (where === file) {
    return {
      ok: false,
      message: `${first.text}${more}`,
      line: loc.line,
      col: loc.column + 1,
      inputs,
    };
  }
  inputs.push(where);
  return {
    ok: false,
    message: `${loc.file}:${loc.line}:${loc.column + 1}: ${first.text}${more}`,
    inputs,
  };
}
