import { readFileSync } from "node:fs";
import { join } from "node:path";
import { describe, expect, test } from "vitest";
import { ENGINE_CHANNEL, HOST_PROTOCOL_VERSION } from "./channel";
import { createHostApi, type RendererIpc } from "./host-api";

type Listener = (event: unknown, ...args: unknown[]) => void;

function fakeIpc() {
  const sent: [string, unknown[]][] = [];
  const listeners = new Map<string, Set<Listener>>();
  const ipc: RendererIpc = {
    send: (channel, ...args) => void sent.push([channel, args]),
    on(channel, l) {
      const set = listeners.get(channel) ?? new Set();
      set.add(l);
      listeners.set(channel, set);
    },
    removeListener(channel, l) {
      listeners.get(channel)?.delete(l);
    },
  };
  const emit = (channel: string, event: unknown, msg: unknown): void => {
    for (const l of listeners.get(channel) ?? []) l(event, msg);
  };
  return { ipc, sent, listeners, emit };
}

describe("the preload's mosaicHost", () => {
  test("exposes version, send and onMessage only, frozen", () => {
    const api = createHostApi(fakeIpc().ipc);
    expect(Object.keys(api).sort()).toEqual(["onMessage", "send", "version"]);
    expect(Object.isFrozen(api)).toBe(true);
    expect(api.version).toBe(HOST_PROTOCOL_VERSION);
  });

  test("send puts protocol messages on the engine channel; refuses non-objects", () => {
    const { ipc, sent } = fakeIpc();
    const api = createHostApi(ipc);
    api.send({ type: "start", id: 1 });
    expect(sent).toEqual([[ENGINE_CHANNEL, [{ type: "start", id: 1 }]]]);
    for (const bad of [null, "start", 3, [1]]) expect(() => api.send(bad)).toThrow(TypeError);
    expect(sent).toHaveLength(1);
  });

  test("onMessage gives the message without the IPC event; unsubscribe stops it", () => {
    const { ipc, emit, listeners } = fakeIpc();
    const api = createHostApi(ipc);
    const got: unknown[][] = [];
    const off = api.onMessage((...args) => got.push(args));
    const event = { sender: "secret", ports: [] };
    emit(ENGINE_CHANNEL, event, { type: "state", state: "running" });
    emit("other-channel", event, { type: "state", state: "x" });
    expect(got).toEqual([[{ type: "state", state: "running" }]]);
    off();
    off();
    expect(listeners.get(ENGINE_CHANNEL)?.size).toBe(0);
    emit(ENGINE_CHANNEL, event, { type: "state", state: "stopped" });
    expect(got).toHaveLength(1);
    expect(() => api.onMessage("nope" as never)).toThrow(TypeError);
  });

  test("announces the engine protocol's version (app/engine/protocol.ts)", () => {
    // Electron may not import the engine (DESIGN.md §4), so the constant is read from its source.
    const src = readFileSync(join(__dirname, "..", "engine", "protocol.ts"), "utf8");
    const m = /export const PROTOCOL_VERSION = (\d+);/.exec(src);
    expect(m).not.toBeNull();
    expect(HOST_PROTOCOL_VERSION).toBe(Number(m![1]));
  });
});
