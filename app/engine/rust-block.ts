/**
 * Blocks written in Rust: `rustBlock({...})` turns a WebAssembly module built from the template
 * `templates/rust-block/` (`mosaic new-block --rust NAME`) into a block definition, the same kind
 * `defineBlock` returns. The module speaks MOSAIC's Rust block ABI (docs/rust-block-abi.md): plain
 * exported functions, no imports, no wasm-bindgen glue.
 *
 * The block takes one input of any shape (its `rows × cols` values are the kernel's channels) and
 * emits one event per input event, with the input's timestamp, on its output `out` (the input's
 * shape when the kernel keeps the number of values, else `[1, outputChannels]`). The module is
 * compiled once, when `rustBlock` is called (the user's module loads: a module that is not a Rust
 * block, or of another ABI version, fails there with the reason); every block of the type gets its
 * own instance, so blocks share nothing and a trap (a Rust panic) harms only its own block.
 *
 * Runs anywhere the engine runs: no `node:` imports, no DOM.
 */
import type { z } from "zod";
import {
  defineBlock,
  type BlockContext,
  type BlockDefinition,
  type BlockInstance,
  type OutputPort,
} from "./block";
import { BlockConfigError, errorMessage } from "./diagnostics";
import { vectorShape, type Frame, type Shape } from "./frame";

/** The version of the Rust block ABI this MOSAIC speaks (`mosaic_abi_version()` must return it). */
export const RUST_BLOCK_ABI_VERSION = 1;

/** Where the ABI is described, for messages. */
const ABI_DOC = "docs/rust-block-abi.md";

/** The functions (and memory) a module of ABI version 1 exports. */
const REQUIRED_EXPORTS = [
  "memory",
  "mosaic_abi_version",
  "mosaic_alloc",
  "mosaic_free",
  "mosaic_create",
  "mosaic_output_channels",
  "mosaic_process",
  "mosaic_reset",
  "mosaic_destroy",
  "mosaic_error_ptr",
  "mosaic_error_len",
] as const;

/** The module's exports as the wrapper calls them (wasm32: pointers and sizes are i32). */
interface RustExports {
  memory: { buffer: ArrayBuffer };
  mosaic_abi_version(): number;
  mosaic_alloc(bytes: number): number;
  mosaic_free(ptr: number, bytes: number): void;
  mosaic_create(params: number, nParams: number, channels: number): number;
  mosaic_output_channels(handle: number): number;
  mosaic_process(
    handle: number,
    input: number,
    frames: number,
    channels: number,
    output: number,
  ): number;
  mosaic_reset(handle: number): number;
  mosaic_destroy(handle: number): number;
  mosaic_error_ptr(): number;
  mosaic_error_len(): number;
}

/**
 * The part of the `WebAssembly` global the wrapper uses. Declared here because the engine is
 * type-checked without the DOM and webworker libraries, which are the ones that declare it.
 */
interface WasmApi {
  Module: {
    new (bytes: ArrayBuffer | ArrayBufferView): object;
    exports(module: object): { name: string; kind: string }[];
    imports(module: object): { module: string; name: string; kind: string }[];
  };
  Instance: new (module: object, imports: object) => { exports: Record<string, unknown> };
  RuntimeError: new (...args: never[]) => Error;
}

/** UTF-8 decoding: TextDecoder exists wherever the engine runs (Node, browsers, workers). */
const utf8 = new (
  globalThis as unknown as { TextDecoder: new () => { decode(b: Uint8Array): string } }
).TextDecoder();

function wasmApi(): WasmApi {
  const api = (globalThis as { WebAssembly?: WasmApi }).WebAssembly;
  if (api === undefined) throw new Error("this JavaScript runtime has no WebAssembly");
  return api;
}

/** What a Rust block's definition says besides what the ABI fixes. */
export interface RustBlockOptions<S extends z.ZodType> extends Omit<
  BlockDefinition<S>,
  "create" | "inputs" | "outputs" | "live" | "timer" | "requiresRate" | "finite" | "eventLoop"
> {
  /**
   * The module: its bytes (`import wasm from "./target/wasm32-unknown-unknown/release/x.wasm"`
   * gives them as a `Uint8Array`) or a compiled `WebAssembly.Module`.
   */
  wasm: ArrayBuffer | ArrayBufferView | object;
  /**
   * The params handed to the kernel's `new(params, channels)`, in this order; each must be a
   * number or a boolean (1 or 0) after validation. Default: every key of the `params` object
   * schema, in the order written (a schema that is not a `z.object`, e.g. one with a
   * `.transform`, needs this list).
   */
  kernelParams?: readonly string[];
  /** Names the module in messages (default: "<type>'s WebAssembly module"). */
  wasmName?: string;
}

/** A compiled module whose exports and ABI version were checked. */
interface CheckedModule {
  readonly module: object;
  readonly name: string;
}

function compile(wasm: RustBlockOptions<z.ZodType>["wasm"], name: string): object {
  const api = wasmApi();
  if (wasm instanceof ArrayBuffer || ArrayBuffer.isView(wasm)) {
    try {
      return new api.Module(wasm);
    } catch (e) {
      throw new Error(`${name} is not a valid WebAssembly module: ${errorMessage(e)}`, {
        cause: e,
      });
    }
  }
  if (wasm !== null && typeof wasm === "object") {
    try {
      api.Module.exports(wasm);
      return wasm;
    } catch {
      // falls through: not a compiled module
    }
  }
  throw new Error(
    `${name}: 'wasm' must be the module's bytes (a Uint8Array, e.g. from ` +
      `'import wasm from "./….wasm"') or a WebAssembly.Module`,
  );
}

/** Checks that `module` is a Rust block of this ABI version; throws a message saying what to do. */
function checkModule(module: object, name: string): CheckedModule {
  const api = wasmApi();
  const exported = new Set(api.Module.exports(module).map((e) => e.name));
  if (!exported.has("mosaic_abi_version")) {
    throw new Error(
      `${name} is not a MOSAIC Rust block: it exports no mosaic_abi_version (build it from the ` +
        `template of 'mosaic new-block --rust NAME', which exports the ABI of ${ABI_DOC})`,
    );
  }
  const imports = api.Module.imports(module);
  if (imports.length > 0) {
    const first = imports[0]!;
    throw new Error(
      `${name} imports ${imports.length} item(s) from its host (first: ${first.module}.${first.name}); ` +
        `a Rust block must import nothing (no wasm-bindgen, no WASI: build it for ` +
        `wasm32-unknown-unknown as the template does)`,
    );
  }
  const probe = new api.Instance(module, {}).exports as unknown as RustExports;
  const version = probe.mosaic_abi_version();
  if (version !== RUST_BLOCK_ABI_VERSION) {
    const what =
      version > RUST_BLOCK_ABI_VERSION
        ? "update MOSAIC, or rebuild the block from this MOSAIC's template"
        : "rebuild it from this MOSAIC's template (mosaic new-block --rust NAME) and move your kernel over";
    throw new Error(
      `${name} speaks Rust block ABI version ${version}, but this MOSAIC speaks version ` +
        `${RUST_BLOCK_ABI_VERSION} (${ABI_DOC}): ${what}`,
    );
  }
  const missing = REQUIRED_EXPORTS.filter((e) => !exported.has(e));
  if (missing.length > 0) {
    throw new Error(
      `${name} says it speaks Rust block ABI version ${version} but does not export ` +
        `${missing.join(", ")} (${ABI_DOC})`,
    );
  }
  return { module, name };
}

/** The kernel params in ABI order: the named params as f64 (booleans 1 or 0). */
function kernelParamValues(params: unknown, names: readonly string[], type: string): Float64Array {
  const values = new Float64Array(names.length);
  const record = (params ?? {}) as Record<string, unknown>;
  names.forEach((key, i) => {
    const v = record[key];
    if (typeof v === "number") values[i] = v;
    else if (typeof v === "boolean") values[i] = v ? 1 : 0;
    else
      throw new BlockConfigError(
        `${type}: param ${key} must be a number or a boolean for the Rust kernel, got ${v === undefined ? "nothing" : typeof v}`,
        key,
      );
  });
  return values;
}

/** The keys of an object schema, in the order written (the default kernel params). */
function schemaKeys(params: z.ZodType, type: string): readonly string[] {
  const shape = (params as { shape?: unknown }).shape;
  if (shape !== null && typeof shape === "object") return Object.keys(shape);
  throw new Error(
    `${type}: its params schema is not a z.object (a transform, a union…): ` +
      "say which params the Rust kernel gets, in order, with kernelParams: [...]",
  );
}

/**
 * One block's instance of the module: its kernel handle and scratch buffers in the module's
 * memory. Nothing is allocated per call in steady state: the buffers grow (doubling) only when a
 * frame brings more events than ever before, and the memory views are re-created only when the
 * module's memory has grown.
 */
class KernelInstance {
  private exports: RustExports;
  private handle = 0;
  readonly outputChannels: number;
  private capacity = 0;
  private inPtr = 0;
  private outPtr = 0;
  private buffer: ArrayBuffer | null = null;
  private heap = new Float64Array(0);

  constructor(
    private readonly checked: CheckedModule,
    private readonly params: Float64Array,
    readonly channels: number,
  ) {
    this.exports = this.instantiate();
    this.handle = this.trapped("mosaic_create", () => this.create());
    this.outputChannels = this.exports.mosaic_output_channels(this.handle);
    if (this.outputChannels < 1) throw new Error(this.fail("mosaic_output_channels"));
  }

  private instantiate(): RustExports {
    return new (wasmApi().Instance)(this.checked.module, {}).exports as unknown as RustExports;
  }

  private create(): number {
    const x = this.exports;
    const bytes = Math.max(8, this.params.length * 8);
    const ptr = x.mosaic_alloc(bytes);
    if (ptr === 0) throw new Error(`${this.checked.name}: out of memory for the params`);
    this.view().set(this.params, ptr / 8);
    const handle = x.mosaic_create(ptr, this.params.length, this.channels);
    x.mosaic_free(ptr, bytes);
    if (handle === 0) throw new BlockConfigError(this.lastError());
    return handle;
  }

  /**
   * Runs `call` (a call into the module named `fn`); a trap (a Rust panic with panic = "abort",
   * an out-of-bounds access) becomes an error that says so. With `restart`, the instance is
   * replaced first, since its memory may be inconsistent after a trap.
   */
  private trapped<T>(fn: string, call: () => T, restart = false): T {
    try {
      return call();
    } catch (e) {
      if (!(e instanceof wasmApi().RuntimeError)) throw e;
      if (restart) this.restart();
      throw new Error(
        `${this.checked.name} trapped in ${fn} (a Rust panic or an out-of-bounds access: ` +
          `${errorMessage(e)})${restart ? "; the kernel was created anew, its history lost" : ""}`,
        { cause: e },
      );
    }
  }

  /** The module's last error message. */
  private lastError(): string {
    const x = this.exports;
    const len = x.mosaic_error_len();
    const bytes = new Uint8Array(x.memory.buffer, x.mosaic_error_ptr(), len);
    return utf8.decode(bytes.slice());
  }

  private fail(fn: string): string {
    return `${this.checked.name}: ${fn} failed: ${this.lastError()}`;
  }

  private view(): Float64Array {
    const buffer = this.exports.memory.buffer;
    if (buffer !== this.buffer) {
      this.buffer = buffer;
      this.heap = new Float64Array(buffer);
    }
    return this.heap;
  }

  private ensureCapacity(frames: number): void {
    if (frames <= this.capacity) return;
    let cap = Math.max(16, this.capacity);
    while (cap < frames) cap *= 2;
    const x = this.exports;
    this.freeBuffers();
    this.inPtr = x.mosaic_alloc(cap * this.channels * 8);
    this.outPtr = x.mosaic_alloc(cap * this.outputChannels * 8);
    if (this.inPtr === 0 || this.outPtr === 0) {
      throw new Error(`${this.checked.name}: out of memory for ${frames} events`);
    }
    this.capacity = cap;
  }

  private freeBuffers(): void {
    const x = this.exports;
    if (this.inPtr !== 0) x.mosaic_free(this.inPtr, this.capacity * this.channels * 8);
    if (this.outPtr !== 0) x.mosaic_free(this.outPtr, this.capacity * this.outputChannels * 8);
    this.inPtr = 0;
    this.outPtr = 0;
    this.capacity = 0;
  }

  /** Runs the kernel on `frames` events of `input` (row-major) into `output`. */
  process(input: Float64Array, frames: number, output: Float64Array): void {
    if (frames === 0) return;
    this.trapped("mosaic_process", () => this.processFrames(input, frames, output), true);
  }

  private processFrames(input: Float64Array, frames: number, output: Float64Array): void {
    this.ensureCapacity(frames);
    const nIn = frames * this.channels;
    this.view().set(input.subarray(0, nIn), this.inPtr / 8);
    const status = this.exports.mosaic_process(
      this.handle,
      this.inPtr,
      frames,
      this.channels,
      this.outPtr,
    );
    if (status !== 0) throw new Error(this.fail("mosaic_process"));
    const start = this.outPtr / 8;
    output.set(this.view().subarray(start, start + frames * this.outputChannels));
  }

  reset(): void {
    const status = this.trapped("mosaic_reset", () => this.exports.mosaic_reset(this.handle), true);
    if (status !== 0) throw new Error(this.fail("mosaic_reset"));
  }

  destroy(): void {
    this.freeBuffers();
    this.exports.mosaic_destroy(this.handle);
  }

  /**
   * After a trap the module's memory may be inconsistent: replace the whole instance with a fresh
   * one (the kernel's history starts over, as after a reset).
   */
  private restart(): void {
    this.exports = this.instantiate();
    this.buffer = null;
    this.capacity = 0;
    this.inPtr = 0;
    this.outPtr = 0;
    this.handle = this.create();
  }
}

/** The input's shape, or a message saying why the block cannot take it. */
function inputShape(ctx: BlockContext, type: string): Shape {
  const input = ctx.inputs[0];
  if (input === undefined) throw new BlockConfigError(`${type} needs one input`);
  if (input.isTimer) {
    throw new BlockConfigError(
      `${type} processes a signal; its input ${input.source} is a timer (its events carry no values)`,
    );
  }
  if (input.shape === null) {
    throw new BlockConfigError(
      `${type} needs to know its input's shape when it is created (${input.source} is created ` +
        "later, in a feedback cycle)",
    );
  }
  return input.shape;
}

function createInstance(kernel: KernelInstance, out: OutputPort): BlockInstance {
  let live: KernelInstance | null = kernel;
  return {
    process(frame: Frame): void {
      if (live === null || frame.n === 0) return;
      const o = out.frame(frame.n);
      for (let e = 0; e < frame.n; e++) o.t[e] = frame.t[e]!;
      live.process(frame.v, frame.n, o.v);
      out.emit(o);
    },
    reset: () => live?.reset(),
    dispose: () => {
      live?.destroy();
      live = null;
    },
  };
}

/**
 * A block whose kernel is a Rust WebAssembly module (docs/writing-blocks.md, "Rust blocks").
 * Compiles the module and checks its ABI version at once: a module of another version throws
 * here, with what to do.
 */
export function rustBlock<S extends z.ZodType>(options: RustBlockOptions<S>): BlockDefinition<S> {
  const { wasm, kernelParams, wasmName, ...definition } = options;
  const name = wasmName ?? `${definition.type}'s WebAssembly module`;
  const checked = checkModule(compile(wasm, name), name);
  const keys = kernelParams ?? schemaKeys(definition.params, definition.type);
  return defineBlock<S>({
    ...definition,
    inputs: { min: 1, max: 1, labels: ["signal"] },
    outputs: ["out"],
    create(ctx, params) {
      const shape = inputShape(ctx, definition.type);
      const values = kernelParamValues(params, keys, definition.type);
      const kernel = new KernelInstance(checked, values, shape.rows * shape.cols);
      const sameSize = kernel.outputChannels === kernel.channels;
      const out = ctx.output(sameSize ? shape : vectorShape(kernel.outputChannels));
      return createInstance(kernel, out);
    },
  });
}
