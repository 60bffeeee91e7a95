/**
 * What the main process and the preload share, free of imports: the sandboxed preload may only
 * `require("electron")`, so everything it bundles must be self-contained.
 */

/** The one IPC channel: UI messages renderer → main, engine messages main → renderer. */
export const ENGINE_CHANNEL = "mosaic:engine";

/**
 * The UI↔engine protocol version the preload announces as `mosaicHost.version`. It must equal
 * `PROTOCOL_VERSION` in app/engine/protocol.ts (a test checks; Electron may not import the engine).
 */
export const HOST_PROTOCOL_VERSION = 1;
