/**
 * Blocks written by users (docs/writing-blocks.md): a pipeline names ES modules in
 * `Pipeline: { Blocks: [...] }`; the host loads each (app/host/user-blocks.ts: esbuild, then an
 * import) and this module turns what they export into block definitions, checks them, guards them
 * against returning garbage, and adds them to the built-in catalog for that pipeline. Every
 * problem is a diagnostic at the module's line in the pipeline's `Blocks:` list, naming the module
 * file and the reason. Runs anywhere (no `node:`): the platform brings the module loader.
 */
import { isMap, type YAMLMap } from "yaml";
import type { AnyBlockDefinition, BlockInstance } from "./block";
import { createCatalog, type Catalog } from "./catalog";
import { errorMessage, type Diagnostic } from "./diagnostics";
import { Collector, scalarString } from "./pipeline/collector";
import { isSettingsEntry, readSettings } from "./pipeline/keys";
import { lineCounterOf, parseStage } from "./pipeline/parse";
import { BLOCK_NAME_RE, type BlockModuleRef, type PipelineSettings } from "./pipeline/spec";
import * as sdk from "./sdk";
import { BLOCK_CATEGORIES } from "./sdk";

/** Where a loaded module finds the SDK (the engine's own instance: its zod, its error classes). */
const SDK_KEY = Symbol.for("mosaic.sdk");

/** The import names that mean the SDK. */
export const SDK_IMPORT = /^(mosaic\/sdk|@mosaic\/sdk)$/;

/** Makes `mosaic/sdk` resolvable (through `sdkModuleSource`) for modules loaded in this thread. */
export function installSdk(): void {
  (globalThis as Record<symbol, unknown>)[SDK_KEY] = sdk;
}

/** The module text that stands for `mosaic/sdk` inside a user's module: this thread's SDK. */
export function sdkModuleSource(): string {
  const names = Object.keys(sdk).filter((n) => n !== "default");
  return (
    `const sdk = globalThis[Symbol.for("mosaic.sdk")];\n` +
    `if (!sdk) throw new Error("mosaic/sdk is provided by MOSAIC when it loads a block module");\n` +
    `export const { ${names.join(", ")} } = sdk;\n`
  );
}

/** What a platform's module loader gives back for one module file. */
export type ModuleLoadResult =
  | {
      ok: true;
      /** The module's namespace object (its exports). */
      exports: Record<string, unknown>;
      /** Every file the module was built from (itself, its imports): what a watcher watches. */
      inputs: string[];
    }
  | {
      ok: false;
      /** Why, in words; with `line`/`col` inside the module when the reason has a place. */
      message: string;
      line?: number;
      col?: number;
      inputs: string[];
    };

/** Loads one module by its absolute path (the host's: esbuild + import). */
export type ModuleLoader = (absPath: string) => Promise<ModuleLoadResult>;

/** One module of a pipeline's `Blocks:` list, loaded. */
export interface LoadedBlockModule {
  ref: BlockModuleRef;
  /** Absolute path of the module. */
  path: string;
  defs: AnyBlockDefinition[];
  inputs: string[];
}

export interface PipelineCatalog {
  /** The built-in catalog plus the pipeline's own blocks (the built-in one when it has none). */
  catalog: Catalog;
  modules: LoadedBlockModule[];
  /** Problems of the `Blocks:` list and its modules (errors: the pipeline must not load). */
  diagnostics: Diagnostic[];
}

/** Which module each user block type came from (for docs, the palette and messages). */
const origins = new WeakMap<AnyBlockDefinition, string>();

/** The module file a block definition was loaded from; undefined for a built-in block. */
export function userBlockOrigin(def: AnyBlockDefinition): string | undefined {
  return origins.get(def);
}

/**
 * The entries of the pipeline's `Pipeline: { Blocks: [...] }` (none when the text has no such
 * list; problems with the list itself are the loader's to report).
 */
export function blockModuleRefs(source: string, file: string): BlockModuleRef[] {
  if (!source.includes("Blocks")) return [];
  const c = new Collector(file, lineCounterOf(source));
  const parsed = parseStage(c, source);
  const root = parsed.doc?.contents;
  if (!parsed.ok || !isMap(root)) return [];
  const settings: PipelineSettings = { batchingMs: undefined };
  for (const pair of (root as YAMLMap).items) {
    if (isSettingsEntry(scalarString(pair.key), pair.value)) {
      readSettings(c, pair.value as YAMLMap, settings);
    }
  }
  return settings.blocks ?? [];
}

/** `dir` + `rel` with '/' separators ('..' and '.' resolved); `rel` may be absolute already. */
export function joinModulePath(dir: string, rel: string): string {
  const norm = rel.replace(/\\/g, "/");
  const abs = norm.startsWith("/") || /^[A-Za-z]:\//.test(norm);
  const parts = (abs ? norm : `${dir.replace(/\\/g, "/")}/${norm}`).split("/");
  const out: string[] = [];
  for (const p of parts) {
    if (p === "..") {
      const last = out[out.length - 1];
      if (last === undefined || last === "..") out.push(p);
      else if (last !== "") out.pop();
    } else if (p !== "." && (p !== "" || out.length === 0)) out.push(p);
  }
  return out.join("/");
}

/** The folder of a file path ('/' or '\' separated). */
export function folderOfPath(file: string): string {
  const i = Math.max(file.lastIndexOf("/"), file.lastIndexOf("\\"));
  return i < 0 ? "." : i === 0 ? "/" : file.slice(0, i);
}

/**
 * The catalog a pipeline runs with: `base` plus the blocks of the modules its `Blocks:` list
 * names, loaded with `load`. `file` is the pipeline's path (its folder resolves the entries).
 */
export async function pipelineCatalog(
  source: string,
  file: string,
  base: Catalog,
  load: ModuleLoader | undefined,
): Promise<PipelineCatalog> {
  const refs = blockModuleRefs(source, file);
  if (refs.length === 0) return { catalog: base, modules: [], diagnostics: [] };
  const diagnostics: Diagnostic[] = [];
  const error = (ref: BlockModuleRef, message: string, code = "user-blocks"): void => {
    diagnostics.push({
      severity: "error",
      code,
      message,
      file,
      line: ref.pos.line,
      col: ref.pos.col,
    });
  };
  if (!load) {
    for (const ref of refs) {
      error(
        ref,
        `cannot load user blocks from ${ref.path}: this engine cannot load block modules (the browser build); use mosaic serve or mosaic run`,
      );
    }
    return { catalog: base, modules: [], diagnostics };
  }
  const modules: LoadedBlockModule[] = [];
  const seen = new Map<string, BlockModuleRef>();
  for (const ref of refs) {
    const path = joinModulePath(folderOfPath(file), ref.path);
    const first = seen.get(path);
    if (first) {
      error(ref, `${ref.path} is listed twice in Blocks: (also at line ${first.pos.line})`);
      continue;
    }
    seen.set(path, ref);
    const r = await load(path);
    if (!r.ok) {
      const where = r.line !== undefined ? `${ref.path}:${r.line}:${r.col ?? 0}` : ref.path;
      error(ref, `cannot load user blocks from ${where}: ${r.message}`);
      continue;
    }
    const found = blockDefinitions(r.exports);
    const bad = [...found.problems];
    const defs: AnyBlockDefinition[] = [];
    for (const d of found.defs) {
      const problem = definitionProblem(d);
      if (problem) bad.push(problem);
      else defs.push(guardUserBlock(d, ref.path));
    }
    if (found.defs.length === 0 && bad.length === 0) {
      bad.push("it exports no block definition (export default defineBlock({...}))");
    }
    for (const p of bad) error(ref, `user blocks in ${ref.path}: ${p}`);
    if (bad.length === 0) modules.push({ ref, path, defs, inputs: r.inputs });
  }
  return { ...mergeCatalogs(base, modules, file, diagnostics), modules, diagnostics };
}

/** `base` plus every module's blocks; a name taken twice is an error at the later module. */
function mergeCatalogs(
  base: Catalog,
  modules: LoadedBlockModule[],
  file: string,
  diagnostics: Diagnostic[],
): { catalog: Catalog } {
  const taken = new Map<string, string>();
  const defs: AnyBlockDefinition[] = [];
  for (const m of modules) {
    for (const d of m.defs) {
      const clash = [d.type, ...(d.aliases ?? [])].find((n) => base.has(n) || taken.has(n));
      if (clash !== undefined) {
        const other = taken.get(clash);
        diagnostics.push({
          severity: "error",
          code: "user-blocks",
          message: `user block type '${clash}' in ${m.ref.path} is ${other !== undefined ? `also defined in ${other}` : "a built-in block type"}: pick another name`,
          file,
          line: m.ref.pos.line,
          col: m.ref.pos.col,
        });
        continue;
      }
      for (const n of [d.type, ...(d.aliases ?? [])]) taken.set(n, m.ref.path);
      defs.push(d);
    }
  }
  if (defs.length === 0) return { catalog: base };
  const builtIn = [...base].filter(([n, d]) => n === d.type).map(([, d]) => d);
  return { catalog: createCatalog([...builtIn, ...defs]) };
}

const isObject = (v: unknown): v is Record<string, unknown> => typeof v === "object" && v !== null;

/** Looks like a block definition (what `defineBlock` returns). */
function looksLikeBlock(v: unknown): v is AnyBlockDefinition {
  return isObject(v) && typeof v.type === "string" && typeof v.create === "function";
}

/**
 * The definitions a module exports: its default export (one definition or an array of them) and
 * its named exports that are definitions; `contract` is the test setups (not a block).
 */
export function blockDefinitions(exports: Record<string, unknown>): {
  defs: AnyBlockDefinition[];
  problems: string[];
} {
  const defs: AnyBlockDefinition[] = [];
  const problems: string[] = [];
  const add = (v: unknown): void => {
    if (!defs.includes(v as AnyBlockDefinition)) defs.push(v as AnyBlockDefinition);
  };
  const dflt = exports.default;
  if (dflt !== undefined) {
    const list = Array.isArray(dflt) ? (dflt as unknown[]) : [dflt];
    list.forEach((v, i) => {
      if (looksLikeBlock(v)) add(v);
      else {
        const what = Array.isArray(dflt) ? `item ${i} of its default export` : "its default export";
        problems.push(
          `${what} is not a block definition (${describeExport(v)}; expected defineBlock({ type, create, ... }))`,
        );
      }
    });
  }
  for (const [name, v] of Object.entries(exports)) {
    if (name !== "default" && looksLikeBlock(v)) add(v);
  }
  return { defs, problems };
}

function describeExport(v: unknown): string {
  if (v === null) return "null";
  if (Array.isArray(v)) return "an array";
  if (typeof v === "object")
    return `an object with keys ${Object.keys(v).slice(0, 6).join(", ") || "none"}`;
  return `a ${typeof v}`;
}

/** What is wrong with a definition that the type checker would have said (a JS module, `as any`). */
export function definitionProblem(d: AnyBlockDefinition): string | undefined {
  const t = d.type;
  const where = `block '${t}'`;
  if (!BLOCK_NAME_RE.test(t))
    return `block type '${t}' is not a valid name (letters, digits, '_' or '-', starting with a letter)`;
  if (!(BLOCK_CATEGORIES as readonly string[]).includes(d.category as string)) {
    return `${where}: category ${JSON.stringify(d.category)} is not one of ${BLOCK_CATEGORIES.join(", ")}`;
  }
  if (typeof d.summary !== "string" || d.summary.trim() === "")
    return `${where}: summary must be one line of text`;
  if (typeof d.help !== "string") return `${where}: help must be text`;
  const params = d.params as unknown;
  if (!isObject(params) || typeof params.safeParse !== "function") {
    return `${where}: params must be a zod schema (z.strictObject({...}) from mosaic/sdk)`;
  }
  const ins = d.inputs as unknown;
  if (
    !isObject(ins) ||
    typeof ins.min !== "number" ||
    typeof ins.max !== "number" ||
    ins.min > ins.max ||
    ins.min < 0
  ) {
    return `${where}: inputs must be { min, max } with 0 ≤ min ≤ max`;
  }
  if (d.aliases !== undefined && !Array.isArray(d.aliases))
    return `${where}: aliases must be a list of names`;
  for (const k of ["live", "views"] as const) {
    const v = d[k] as unknown;
    if (v !== undefined && !(Array.isArray(v) && v.every((x) => typeof x === "string"))) {
      return `${where}: ${k} must be a list of names`;
    }
  }
  return undefined;
}

const INSTANCE_METHODS = [
  "process",
  "flush",
  "start",
  "stop",
  "reset",
  "dispose",
  "setParam",
] as const;

/** Why what `create` returned is not a block instance; undefined when it is one. */
export function instanceProblem(inst: unknown): string | undefined {
  if (!isObject(inst))
    return `create() returned ${inst === null ? "null" : typeof inst} instead of an object such as { process(frame) {...} }`;
  for (const m of INSTANCE_METHODS) {
    if (inst[m] !== undefined && typeof inst[m] !== "function")
      return `create() returned an object whose '${m}' is ${typeof inst[m]}, not a function`;
  }
  const actions = inst.actions;
  if (actions !== undefined) {
    if (!isObject(actions)) return "create() returned actions that are not an object";
    for (const [name, a] of Object.entries(actions)) {
      if (!isObject(a) || typeof a.run !== "function")
        return `action '${name}' has no run() function`;
      if (typeof a.label !== "string") return `action '${name}' has no label`;
    }
  }
  return undefined;
}

/** The first stack frame of an error in the file named `name` (a source-mapped stack). */
export function userFrame(e: unknown, name: string): { line: number; col: number } | undefined {
  const stack = e instanceof Error ? (e.stack ?? "") : "";
  const escaped = name.replace(/[.*+?^${}()|[\]\\]/g, "\\$&");
  const m = new RegExp(`[/\\\\]${escaped}:(\\d+):(\\d+)`).exec(stack);
  return m ? { line: Number(m[1]), col: Number(m[2]) } : undefined;
}

/**
 * The instance with its `process` errors located: "… (at blocks/mine.ts:12:7)" when the error
 * was thrown in the module's own file, so the event names the file and line besides the block.
 */
function located(inst: BlockInstance, module: string): BlockInstance {
  const process = inst.process;
  if (!process) return inst;
  const name = module.split(/[/\\]/).pop() ?? module;
  const wrapped: BlockInstance["process"] = function (this: BlockInstance, frame, port) {
    try {
      process.call(this, frame, port);
    } catch (e) {
      const at = userFrame(e, name);
      if (!at) throw e;
      throw new Error(`${errorMessage(e)} (at ${module}:${at.line}:${at.col})`, { cause: e });
    }
  };
  try {
    inst.process = wrapped;
  } catch {
    // A frozen instance: its errors go out without the position.
  }
  return inst;
}

/**
 * The definition with its `create` checked: an instance that is not one (garbage from a user's
 * module) is refused at load, at the block's line, instead of failing later inside the runtime.
 */
function guardUserBlock(def: AnyBlockDefinition, module: string): AnyBlockDefinition {
  const create = def.create.bind(def);
  const guarded: AnyBlockDefinition = {
    ...def,
    help:
      def.help.trim() === ""
        ? `${def.summary} (from ${module})`
        : `${def.help}\n\n(User block from ${module}.)`,
    async create(ctx, params): Promise<BlockInstance> {
      const inst = (await create(ctx, params)) as unknown;
      const problem = instanceProblem(inst);
      if (problem) throw new Error(`user block '${def.type}' (${module}): ${problem}`);
      return located(inst as BlockInstance, module);
    },
  };
  origins.set(guarded, module);
  return guarded;
}
