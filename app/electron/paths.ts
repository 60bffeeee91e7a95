/**
 * Where the desktop app finds its parts, from the folder of the bundled main process
 * (`<app>/dist/electron/main.cjs`):
 *
 *   <app>/dist/electron/preload.cjs   the window's preload (Electron reads it, asar is fine)
 *   <app>/dist/web/                   the UI (the browser build), served on app://mosaic/
 *   <app>/dist/session.worker.mjs     the engine session, in a worker thread of the main process
 *   <app>/dist/mosaic_core_bg.wasm    the WASM core, read by the engine
 *   pipelines/                        the example pipelines: the repository's in development,
 *                                     `resources/pipelines` (extraResources) when packaged
 *
 * In a packaged app `<app>` is `resources/app.asar`. Worker threads and the files they read do
 * not go through Electron's asar support, so electron-builder.yml unpacks them (asarUnpack) and
 * these paths point into `app.asar.unpacked`.
 */
import { dirname, join, sep } from "node:path";

/** `…/app.asar/…` → `…/app.asar.unpacked/…` (other paths unchanged). */
export function unpackedPath(path: string): string {
  const marker = `${sep}app.asar${sep}`;
  const i = path.indexOf(marker);
  if (i < 0) return path.endsWith(`${sep}app.asar`) ? `${path}.unpacked` : path;
  return `${path.slice(0, i)}${sep}app.asar.unpacked${sep}${path.slice(i + marker.length)}`;
}

export interface AppLayout {
  preload: string;
  webRoot: string;
  sessionWorker: string;
  wasm: string;
  /**
   * The folder the UI's pipeline names ("pipelines/demo.yaml", from pipelines/index.json) are
   * relative to: the repository root in development, `resources` when packaged.
   */
  pipelinesBase: string;
}

export function appLayout(opts: {
  /** `__dirname` of main.cjs: `<app>/dist/electron`. */
  mainDir: string;
  isPackaged: boolean;
  /** `process.resourcesPath` (packaged app). */
  resourcesPath?: string;
}): AppLayout {
  const dist = dirname(opts.mainDir);
  const unpacked = opts.isPackaged ? unpackedPath : (p: string) => p;
  return {
    preload: join(opts.mainDir, "preload.cjs"),
    webRoot: unpacked(join(dist, "web")),
    sessionWorker: unpacked(join(dist, "session.worker.mjs")),
    wasm: unpacked(join(dist, "mosaic_core_bg.wasm")),
    pipelinesBase:
      opts.isPackaged && opts.resourcesPath !== undefined ? opts.resourcesPath : dirname(dist),
  };
}
