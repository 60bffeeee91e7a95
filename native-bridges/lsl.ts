/**
 * The Lab Streaming Layer bridge for Node: liblsl (the reference implementation, sccn/liblsl)
 * called through the `koffi` FFI, given to blocks as `ctx.io.lsl` (app/engine/io.ts). The library
 * is the one the `pylsl` wheel ships, installed by setup into the Python sidecar's environment;
 * `MOSAIC_LIBLSL=/path/to/liblsl.so` uses another. Nothing is loaded until a block asks: without
 * the library only the LSL blocks fail, each saying where the library was looked for.
 *
 * Functions and their C signatures are those of liblsl's C API (`include/lsl_c.h` and
 * `include/lsl/*.h` in github.com/sccn/liblsl). No call here waits: resolution is a continuous
 * resolver read with `lsl_resolver_results`, pulls use timeout 0, the time correction is asked
 * with timeout 0 (liblsl obtains it in the background). koffi loads inside worker_threads (each
 * engine worker loads its own binding; liblsl itself is loaded once per process by the OS).
 */
import { existsSync, readdirSync } from "node:fs";
import { createRequire } from "node:module";
import { dirname, join } from "node:path";
import { fileURLToPath } from "node:url";
import type {
  LslBridge,
  LslFormat,
  LslInletHandle,
  LslOutletHandle,
  LslResolverHandle,
  LslStreamInfo,
} from "../app/engine/io";

/** liblsl's channel formats (lsl_channel_format_t). */
const FORMAT_CODE: Record<LslFormat, number> = {
  float32: 1,
  double64: 2,
  string: 3,
  int32: 4,
  int16: 5,
};
const FORMAT_NAME: Record<number, LslFormat> = {
  1: "float32",
  2: "double64",
  3: "string",
  4: "int32",
  5: "int16",
};
/** lsl_error_code_t: the stream's source is lost (and cannot be recovered). */
const LSL_LOST_ERROR = -2;

/** A C pointer as koffi 3 passes it (a BigInt; null for NULL). */
type Ptr = bigint | null;
// eslint-disable-next-line @typescript-eslint/no-explicit-any
type Fn = (...args: any[]) => any;

interface Api {
  library_version: Fn;
  local_clock: Fn;
  create_streaminfo: Fn;
  destroy_streaminfo: Fn;
  get_desc: Fn;
  append_child: Fn;
  append_child_value: Fn;
  get_name: Fn;
  get_type: Fn;
  get_channel_count: Fn;
  get_nominal_srate: Fn;
  get_channel_format: Fn;
  get_source_id: Fn;
  get_hostname: Fn;
  get_uid: Fn;
  create_outlet: Fn;
  destroy_outlet: Fn;
  push_chunk_ftnp: Fn;
  push_chunk_dtnp: Fn;
  push_chunk_itnp: Fn;
  push_chunk_stnp: Fn;
  push_chunk_strtnp: Fn;
  have_consumers: Fn;
  create_continuous_resolver_bypred: Fn;
  resolver_results: Fn;
  destroy_continuous_resolver: Fn;
  create_inlet: Fn;
  destroy_inlet: Fn;
  pull_chunk_d: Fn;
  pull_chunk_str: Fn;
  destroy_string: Fn;
  time_correction_ex: Fn;
  last_error: Fn;
}

const SIGNATURES: Record<keyof Api, string> = {
  library_version: "int32_t lsl_library_version()",
  local_clock: "double lsl_local_clock()",
  create_streaminfo:
    "void *lsl_create_streaminfo(const char *name, const char *type, int32_t channel_count, double nominal_srate, int32_t channel_format, const char *source_id)",
  destroy_streaminfo: "void lsl_destroy_streaminfo(void *info)",
  get_desc: "void *lsl_get_desc(void *info)",
  append_child: "void *lsl_append_child(void *e, const char *name)",
  append_child_value: "void *lsl_append_child_value(void *e, const char *name, const char *value)",
  get_name: "const char *lsl_get_name(void *info)",
  get_type: "const char *lsl_get_type(void *info)",
  get_channel_count: "int32_t lsl_get_channel_count(void *info)",
  get_nominal_srate: "double lsl_get_nominal_srate(void *info)",
  get_channel_format: "int32_t lsl_get_channel_format(void *info)",
  get_source_id: "const char *lsl_get_source_id(void *info)",
  get_hostname: "const char *lsl_get_hostname(void *info)",
  get_uid: "const char *lsl_get_uid(void *info)",
  create_outlet: "void *lsl_create_outlet(void *info, int32_t chunk_size, int32_t max_buffered)",
  destroy_outlet: "void lsl_destroy_outlet(void *out)",
  push_chunk_ftnp:
    "int32_t lsl_push_chunk_ftnp(void *out, const float *data, unsigned long data_elements, const double *timestamps, int32_t pushthrough)",
  push_chunk_dtnp:
    "int32_t lsl_push_chunk_dtnp(void *out, const double *data, unsigned long data_elements, const double *timestamps, int32_t pushthrough)",
  push_chunk_itnp:
    "int32_t lsl_push_chunk_itnp(void *out, const int32_t *data, unsigned long data_elements, const double *timestamps, int32_t pushthrough)",
  push_chunk_stnp:
    "int32_t lsl_push_chunk_stnp(void *out, const int16_t *data, unsigned long data_elements, const double *timestamps, int32_t pushthrough)",
  push_chunk_strtnp:
    "int32_t lsl_push_chunk_strtnp(void *out, const char **data, unsigned long data_elements, const double *timestamps, int32_t pushthrough)",
  have_consumers: "int32_t lsl_have_consumers(void *out)",
  create_continuous_resolver_bypred:
    "void *lsl_create_continuous_resolver_bypred(const char *pred, double forget_after)",
  resolver_results:
    "int32_t lsl_resolver_results(void *res, _Out_ void **buffer, uint32_t buffer_elements)",
  destroy_continuous_resolver: "void lsl_destroy_continuous_resolver(void *res)",
  create_inlet:
    "void *lsl_create_inlet(void *info, int32_t max_buflen, int32_t max_chunklen, int32_t recover)",
  destroy_inlet: "void lsl_destroy_inlet(void *in)",
  pull_chunk_d:
    "unsigned long lsl_pull_chunk_d(void *in, _Out_ double *data_buffer, _Out_ double *timestamp_buffer, unsigned long data_buffer_elements, unsigned long timestamp_buffer_elements, double timeout, _Out_ int32_t *ec)",
  pull_chunk_str:
    "unsigned long lsl_pull_chunk_str(void *in, void *data_buffer, _Out_ double *timestamp_buffer, unsigned long data_buffer_elements, unsigned long timestamp_buffer_elements, double timeout, _Out_ int32_t *ec)",
  destroy_string: "void lsl_destroy_string(void *s)",
  time_correction_ex:
    "double lsl_time_correction_ex(void *in, _Out_ double *remote_time, _Out_ double *uncertainty, double timeout, _Out_ int32_t *ec)",
  last_error: "const char *lsl_last_error()",
};

const LIB_NAMES: Record<string, string> = {
  linux: "liblsl.so",
  darwin: "liblsl.dylib",
  win32: "lsl.dll",
};

function repoRoots(): string[] {
  const roots: string[] = [];
  let d = dirname(fileURLToPath(import.meta.url));
  for (let i = 0; i < 6; i++) {
    if (existsSync(join(d, "native-bridges", "python"))) roots.push(d);
    d = dirname(d);
  }
  const resources = (process as { resourcesPath?: string }).resourcesPath;
  if (resources) roots.push(resources, join(resources, "app.asar.unpacked"));
  roots.push(process.cwd());
  return [...new Set(roots)];
}

/** site-packages folders of the sidecar's environment below `root` (any Python 3 version). */
function sitePackages(root: string): string[] {
  const venv = join(root, "native-bridges", "python", ".venv");
  const found = [join(venv, "Lib", "site-packages")];
  const lib = join(venv, "lib");
  if (existsSync(lib)) {
    for (const v of readdirSync(lib).sort().reverse()) {
      if (v.startsWith("python3")) found.push(join(lib, v, "site-packages"));
    }
  } else {
    found.push(join(lib, "python3.11", "site-packages"));
  }
  return found;
}

/**
 * Where liblsl is looked for, in order: MOSAIC_LIBLSL alone when set; else pylsl's copy in the
 * sidecar's environment (below the repository, or the app's resources), then the desktop app's
 * `resources/liblsl/`.
 */
export function liblslCandidates(env: NodeJS.ProcessEnv = process.env): string[] {
  const own = env.MOSAIC_LIBLSL;
  if (own) return [own];
  const name = LIB_NAMES[process.platform] ?? "liblsl.so";
  const found = repoRoots().flatMap((r) =>
    sitePackages(r).map((s) => join(s, "pylsl", "lib", name)),
  );
  // The desktop app: a copy packaged beside its resources (electron-builder's extraResources).
  const resources = (process as { resourcesPath?: string }).resourcesPath;
  if (resources) found.push(join(resources, "liblsl", name));
  return found;
}

/** The message for a library that is not there. */
export function liblslMissing(tried: readonly string[]): string {
  return (
    `liblsl not found (looked for ${tried.join(", ")}): run setup (npm run setup installs pylsl, ` +
    `which ships liblsl, into native-bridges/python/.venv) or set MOSAIC_LIBLSL to the path of ` +
    `liblsl (${LIB_NAMES[process.platform] ?? "liblsl.so"})`
  );
}

interface Loaded {
  api: Api;
  koffi: typeof import("koffi");
  path: string;
}

let loaded: Loaded | undefined;
let loadError: string | undefined;

/** Loads koffi and liblsl once per thread; throws with what to do when either is missing. */
function load(): Loaded {
  if (loaded) return loaded;
  if (loadError !== undefined) throw new Error(loadError);
  const tried = liblslCandidates();
  const path = tried.find((p) => existsSync(p));
  if (!path) {
    loadError = liblslMissing(tried);
    throw new Error(loadError);
  }
  try {
    const koffi = createRequire(import.meta.url)("koffi") as typeof import("koffi");
    const lib = koffi.load(path);
    const api = {} as Api;
    for (const [k, sig] of Object.entries(SIGNATURES)) api[k as keyof Api] = lib.func(sig);
    loaded = { api, koffi, path };
    return loaded;
  } catch (e) {
    loadError = `cannot load liblsl from ${path}: ${e instanceof Error ? e.message : String(e)}`;
    throw new Error(loadError);
  }
}

function lastError(api: Api): string {
  try {
    const s = api.last_error() as string | null;
    return s ? `: ${s}` : "";
  } catch {
    return "";
  }
}

function describeInfo(api: Api, info: Ptr): LslStreamInfo {
  const code = api.get_channel_format(info) as number;
  return {
    name: api.get_name(info) as string,
    type: api.get_type(info) as string,
    channels: api.get_channel_count(info) as number,
    rate: api.get_nominal_srate(info) as number,
    format: FORMAT_NAME[code] ?? "other",
    sourceId: api.get_source_id(info) as string,
    hostname: api.get_hostname(info) as string,
    uid: api.get_uid(info) as string,
  };
}

/** Writes channel labels into the stream's description as the LSL meta-data conventions say. */
function describeChannels(api: Api, info: Ptr, labels: readonly string[]): void {
  const channels = api.append_child(api.get_desc(info), "channels") as Ptr;
  for (const label of labels) {
    const ch = api.append_child(channels, "channel") as Ptr;
    api.append_child_value(ch, "label", label);
  }
  const acq = api.append_child(api.get_desc(info), "acquisition") as Ptr;
  api.append_child_value(acq, "manufacturer", "MOSAIC");
}

class Outlet implements LslOutletHandle {
  private f32 = new Float32Array(0);
  private i32 = new Int32Array(0);
  private i16 = new Int16Array(0);
  private closed = false;

  constructor(
    private readonly api: Api,
    private handle: Ptr,
    private readonly channels: number,
    private readonly format: LslFormat,
  ) {}

  push(values: Float64Array, n: number, timestamps: Float64Array): void {
    if (this.closed || n <= 0) return;
    const m = n * this.channels;
    const a = this.api;
    let ec: number;
    switch (this.format) {
      case "float32":
        if (this.f32.length < m) this.f32 = new Float32Array(m * 2);
        for (let i = 0; i < m; i++) this.f32[i] = values[i]!;
        ec = a.push_chunk_ftnp(this.handle, this.f32, m, timestamps, 1) as number;
        break;
      case "int32":
        if (this.i32.length < m) this.i32 = new Int32Array(m * 2);
        for (let i = 0; i < m; i++) this.i32[i] = values[i]!;
        ec = a.push_chunk_itnp(this.handle, this.i32, m, timestamps, 1) as number;
        break;
      case "int16":
        if (this.i16.length < m) this.i16 = new Int16Array(m * 2);
        for (let i = 0; i < m; i++) this.i16[i] = values[i]!;
        ec = a.push_chunk_stnp(this.handle, this.i16, m, timestamps, 1) as number;
        break;
      case "double64":
        ec = a.push_chunk_dtnp(this.handle, values, m, timestamps, 1) as number;
        break;
      default:
        throw new Error("a string outlet takes strings (pushStrings)");
    }
    if (ec !== 0) throw new Error(`lsl_push_chunk failed (error ${ec}${lastError(a)})`);
  }

  pushStrings(values: readonly string[], timestamps: Float64Array): void {
    if (this.closed || values.length === 0) return;
    const ec = this.api.push_chunk_strtnp(this.handle, values, values.length, timestamps, 1);
    if (ec !== 0)
      throw new Error(`lsl_push_chunk_strtnp failed (error ${ec}${lastError(this.api)})`);
  }

  haveConsumers(): boolean {
    return !this.closed && (this.api.have_consumers(this.handle) as number) !== 0;
  }

  close(): void {
    if (this.closed) return;
    this.closed = true;
    this.api.destroy_outlet(this.handle);
    this.handle = null;
  }
}

class Inlet implements LslInletHandle {
  private readonly ec = [0];
  private readonly remote = [0];
  private readonly uncertainty = [0];
  private strBuf: Ptr = null;
  private strCap = 0;
  private closed = false;

  constructor(
    private readonly lib: Loaded,
    private handle: Ptr,
    private readonly channels: number,
  ) {}

  pull(values: Float64Array, timestamps: Float64Array, max: number): number {
    if (this.closed) return 0;
    const cap = Math.min(max, timestamps.length, Math.floor(values.length / this.channels));
    const got = this.lib.api.pull_chunk_d(
      this.handle,
      values,
      timestamps,
      cap * this.channels,
      cap,
      0.0,
      this.ec,
    ) as number;
    if (this.ec[0] === LSL_LOST_ERROR) return -1;
    return got / this.channels;
  }

  pullStrings(into: string[], timestamps: Float64Array, max: number): number {
    if (this.closed) return 0;
    const { api, koffi } = this.lib;
    const cap = Math.min(max, timestamps.length) * this.channels;
    if (this.strCap < cap) {
      if (this.strBuf !== null) koffi.free(this.strBuf);
      this.strBuf = koffi.alloc("void *", cap) as Ptr;
      this.strCap = cap;
    }
    const got = api.pull_chunk_str(
      this.handle,
      this.strBuf,
      timestamps,
      cap,
      cap / this.channels,
      0.0,
      this.ec,
    ) as number;
    if (this.ec[0] === LSL_LOST_ERROR) return -1;
    into.length = 0;
    if (got > 0) {
      const ptrs = koffi.decode(this.strBuf, "void *", got) as Ptr[];
      for (const p of ptrs) {
        into.push(p === null ? "" : (koffi.decode(p, "char", -1) as string));
        if (p !== null) api.destroy_string(p);
      }
    }
    return got / this.channels;
  }

  timeCorrection(): { offset: number; uncertainty: number } | undefined {
    if (this.closed) return undefined;
    const offset = this.lib.api.time_correction_ex(
      this.handle,
      this.remote,
      this.uncertainty,
      0.0,
      this.ec,
    ) as number;
    if (this.ec[0] !== 0) return undefined;
    return { offset, uncertainty: this.uncertainty[0]! };
  }

  close(): void {
    if (this.closed) return;
    this.closed = true;
    this.lib.api.destroy_inlet(this.handle);
    this.handle = null;
    if (this.strBuf !== null) this.lib.koffi.free(this.strBuf);
    this.strBuf = null;
  }
}

/** How many streams one look at a resolver reads at most. */
const MAX_RESULTS = 64;

class Resolver implements LslResolverHandle {
  private readonly buffer: Ptr[] = new Array<Ptr>(MAX_RESULTS).fill(null);
  /** Infos of the last `results()` call by uid (destroyed at the next call or at close). */
  private infos = new Map<string, Ptr>();
  private closed = false;

  constructor(
    private readonly lib: Loaded,
    private handle: Ptr,
  ) {}

  results(): LslStreamInfo[] {
    if (this.closed) return [];
    const { api } = this.lib;
    this.release();
    const n = api.resolver_results(this.handle, this.buffer, MAX_RESULTS) as number;
    const out: LslStreamInfo[] = [];
    for (let i = 0; i < n; i++) {
      const info = this.buffer[i]!;
      const d = describeInfo(api, info);
      if (this.infos.has(d.uid!)) {
        api.destroy_streaminfo(info);
        continue;
      }
      this.infos.set(d.uid!, info);
      out.push(d);
    }
    return out;
  }

  openInlet(stream: LslStreamInfo, options: { bufferS: number; recover: boolean }): Inlet {
    const info = stream.uid === undefined ? undefined : this.infos.get(stream.uid);
    if (info === undefined) throw new Error(`stream '${stream.name}' is no longer listed`);
    const { api } = this.lib;
    const buf = Math.max(1, Math.ceil(options.bufferS));
    const handle = api.create_inlet(info, buf, 0, options.recover ? 1 : 0) as Ptr;
    if (handle === null) throw new Error(`lsl_create_inlet failed${lastError(api)}`);
    return new Inlet(this.lib, handle, stream.channels);
  }

  private release(): void {
    for (const info of this.infos.values()) this.lib.api.destroy_streaminfo(info);
    this.infos.clear();
  }

  close(): void {
    if (this.closed) return;
    this.closed = true;
    this.release();
    this.lib.api.destroy_continuous_resolver(this.handle);
    this.handle = null;
  }
}

function createOutlet(info: LslStreamInfo, options: { bufferS: number }): LslOutletHandle {
  const lib = load();
  const { api } = lib;
  if (info.format === "other") throw new Error("an outlet needs one of the formats");
  const handle = api.create_streaminfo(
    info.name,
    info.type,
    info.channels,
    info.rate,
    FORMAT_CODE[info.format],
    info.sourceId,
  ) as Ptr;
  if (handle === null) throw new Error(`lsl_create_streaminfo failed${lastError(api)}`);
  try {
    if (info.labels && info.labels.length > 0) describeChannels(api, handle, info.labels);
    const buf = Math.max(1, Math.ceil(options.bufferS));
    const out = api.create_outlet(handle, 0, buf) as Ptr;
    if (out === null) throw new Error(`lsl_create_outlet failed${lastError(api)}`);
    return new Outlet(api, out, info.channels, info.format);
  } finally {
    // The outlet keeps its own copy of the info.
    api.destroy_streaminfo(handle);
  }
}

function resolve(predicate: string): LslResolverHandle {
  const lib = load();
  // A stream not seen for 5 s is forgotten (liblsl's default).
  const handle = lib.api.create_continuous_resolver_bypred(predicate, 5.0) as Ptr;
  if (handle === null) {
    throw new Error(
      `cannot resolve by '${predicate}'${lastError(lib.api)} (a valid XPath 1.0 predicate?)`,
    );
  }
  return new Resolver(lib, handle);
}

/** The bridge (nothing is loaded until a block uses it). */
export function nodeLslBridge(): LslBridge {
  return {
    get version() {
      const { api, path } = load();
      const v = api.library_version() as number;
      return `liblsl ${Math.floor(v / 100)}.${v % 100} (${path})`;
    },
    localClock: () => load().api.local_clock() as number,
    createOutlet,
    resolve,
  };
}
