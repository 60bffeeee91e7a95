/**
 * What the preload exposes to the page as `window.mosaicHost`: the UI↔engine protocol over one
 * IPC channel, nothing else (no ipcRenderer, no Node, no event objects). Self-contained (the
 * sandboxed preload bundles it and may only require "electron"); tested with a fake ipcRenderer.
 */
import { ENGINE_CHANNEL, HOST_PROTOCOL_VERSION } from "./channel";

/** The parts of `ipcRenderer` used. */
export interface RendererIpc {
  send(channel: string, ...args: unknown[]): void;
  on(channel: string, listener: (event: unknown, ...args: unknown[]) => void): unknown;
  removeListener(channel: string, listener: (event: unknown, ...args: unknown[]) => void): unknown;
}

export interface MosaicHostApi {
  /** The UI↔engine protocol version spoken. */
  readonly version: number;
  /** A UI message to the engine (structured-cloned; the main process validates it). */
  send(msg: unknown): void;
  /** Engine messages; returns the function that stops them. */
  onMessage(callback: (msg: unknown) => void): () => void;
}

export function createHostApi(ipc: RendererIpc): MosaicHostApi {
  return Object.freeze({
    version: HOST_PROTOCOL_VERSION,
    send(msg: unknown): void {
      if (msg === null || typeof msg !== "object" || Array.isArray(msg)) {
        throw new TypeError("mosaicHost.send takes a protocol message (an object with a type)");
      }
      ipc.send(ENGINE_CHANNEL, msg);
    },
    onMessage(callback: (msg: unknown) => void): () => void {
      if (typeof callback !== "function") {
        throw new TypeError("mosaicHost.onMessage takes a function");
      }
      // The page never sees the IPC event (it holds the sender and its frames).
      const listener = (_event: unknown, msg: unknown): void => callback(msg);
      ipc.on(ENGINE_CHANNEL, listener);
      let on = true;
      return () => {
        if (!on) return;
        on = false;
        ipc.removeListener(ENGINE_CHANNEL, listener);
      };
    },
  });
}
