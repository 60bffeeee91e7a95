/**
 * The browser build's engine: a dedicated Web Worker running one EngineSession (the whole
 * pipeline) with the WASM core. The page talks to it with the UI protocol (postMessage).
 * Cross-origin isolated pages get the precise loop (shared memory + Atomics.wait); others fall
 * back to timers (less precise ticks, shown as lagging when the browser cannot keep up).
 */
/// <reference lib="webworker" />
import { catalog } from "../blocks/catalog";
import { sessionRecordingFormats } from "../blocks/recording/session-formats";
import type { FileWriteHandle, Resources } from "../engine/block";
import { MonotonicClock } from "../engine/clock";
import { initDsp } from "../engine/dsp";
import type { EngineMessage } from "../engine/protocol";
import { resolveInFolder, type LocalFolder } from "../engine/protocol-folder";
import { MemoryFile } from "../engine/recording/memory-file";
import { CoarseLoop } from "../engine/runtime/coarse-loop";
import { RealtimeLoop } from "../engine/runtime/loop";
import { EngineSession, type LoopHooks, type SessionPlatform } from "../engine/session";
import type { Runtime } from "../engine/runtime/runtime";
import { loadBrowserBlockModule } from "./block-modules";

declare const self: DedicatedWorkerGlobalScope;

const shared = typeof SharedArrayBuffer === "function" && self.crossOriginIsolated === true;

/** A turn of the event loop without the 4 ms clamping of nested timeouts. */
const channel = new MessageChannel();
const queue: (() => void)[] = [];
channel.port1.onmessage = () => {
  const fn = queue.shift();
  fn?.();
};
const yieldNow = (fn: () => void): void => {
  queue.push(fn);
  channel.port2.postMessage(0);
};

/** The last part of a path: the name a download gets. */
const fileName = (p: string, fallback: string): string => p.split(/[/\\]/).pop() || fallback;

/**
 * A file a block writes (an XdfRecorder's, an EdfRecorder's), kept in memory and handed to the
 * page as a download when the block closes it (at stop, or when its recording is switched off).
 */
function downloadOnClose(p: string): FileWriteHandle {
  const file = new MemoryFile(p);
  let sent = false;
  return {
    path: p,
    get size() {
      return file.size;
    },
    write: (b) => file.write(b),
    writeAt: (b, at) => file.writeAt(b, at),
    sync: () => {},
    close() {
      file.close();
      if (sent) return;
      sent = true;
      const bytes = file.bytes;
      const msg: EngineMessage = {
        type: "download",
        name: fileName(p, "recording"),
        mime: "application/octet-stream",
        bytes,
      };
      self.postMessage(msg, [bytes.buffer]);
    },
  };
}

/**
 * Files are fetched relative to the pipeline file's URL (pipelines and their data are static);
 * for a pipeline opened from this computer, from the files of its folder that the page handed
 * over (app/engine/protocol-folder.ts: one clear error when the file is not there).
 */
function fetchResources(file: string, folder?: LocalFolder): Resources {
  const base = new URL(file, self.location.href);
  const where = (p: string) =>
    folder
      ? resolveInFolder(folder, file, p)
      : { ok: true as const, path: p, url: new URL(p, base).href };
  return {
    resolve: (p) => {
      const w = where(p);
      return w.ok && !folder ? w.url : w.path;
    },
    async readText(p: string) {
      const w = where(p);
      if (!w.ok) throw new Error(w.message);
      const r = await fetch(w.url);
      if (!r.ok) throw new Error(`cannot read ${w.path}: HTTP ${r.status}`);
      return r.text();
    },
    // No files here: a recorder block's file is kept in memory and downloaded when it closes.
    openWrite(p: string) {
      return downloadOnClose(p);
    },
    // No files here: the page downloads what a block saves (a Buffer's rows, a model).
    writeText(p: string, text: string) {
      const name = fileName(p, "mosaic.txt");
      const bytes = new TextEncoder().encode(text);
      const msg: EngineMessage = { type: "download", name, mime: "text/plain", bytes };
      self.postMessage(msg, [bytes.buffer]);
      return Promise.resolve();
    },
  };
}

function startLoop(rt: Runtime, hooks: LoopHooks) {
  if (shared) {
    const loop = new RealtimeLoop({
      runtime: rt,
      yieldNow,
      clock: rt.clock,
      doorbell: new Int32Array(new SharedArrayBuffer(8)),
      precision: false,
      ...hooks,
    });
    loop.start();
    return loop;
  }
  const loop = new CoarseLoop({
    runtime: rt,
    clock: rt.clock,
    sleep: (fn, ms) => setTimeout(fn, ms),
    yieldNow,
    ...hooks,
  });
  loop.start();
  return loop;
}

const platform: SessionPlatform = {
  engine: shared
    ? "browser worker (shared memory)"
    : "browser worker (no shared memory: coarse timing)",
  sharedMemory: shared,
  clock: () => new MonotonicClock(),
  resources: fetchResources,
  // Recordings are kept in memory (no openWrite) and downloaded when they stop.
  recordingFormats: sessionRecordingFormats,
  // Users' block modules served beside the pipeline (self-contained JavaScript).
  blockModules: loadBrowserBlockModule,
  startLoop,
  post: (msg: EngineMessage, transfer?: ArrayBuffer[]) => self.postMessage(msg, transfer ?? []),
};

let session: EngineSession | undefined;
const pending: unknown[] = [];

async function boot(): Promise<void> {
  const r = await fetch(new URL("mosaic_core_bg.wasm", self.location.href));
  if (!r.ok) throw new Error(`cannot load the DSP core: HTTP ${r.status}`);
  initDsp(await r.arrayBuffer());
  session = new EngineSession(catalog, platform);
  for (const m of pending.splice(0)) await session.handle(m);
}

self.onmessage = (e: MessageEvent) => {
  if (session) void session.handle(e.data);
  else pending.push(e.data);
};

boot().catch((e: unknown) => {
  self.postMessage({
    type: "event",
    event: { t: Date.now() / 1000, level: "error", block: "engine", message: String(e) },
  });
});
