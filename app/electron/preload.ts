/**
 * The window's preload (sandboxed, bundled to CommonJS: dist/electron/preload.cjs). Exposes the
 * UI↔engine protocol as `window.mosaicHost` and nothing else; see host-api.ts.
 */
import { contextBridge, ipcRenderer } from "electron";
import { createHostApi } from "./host-api";

contextBridge.exposeInMainWorld("mosaicHost", createHostApi(ipcRenderer));
