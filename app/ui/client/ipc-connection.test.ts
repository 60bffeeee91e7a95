import { describe, expect, test } from "vitest";
import type { EngineMessage, UiMessage } from "../../engine/protocol";
import { EngineClient } from "./engine-client";
import { desktopHost, ipcConnection, type MosaicHost } from "./ipc-connection";

/** A fake preload host: records what the page sends, lets the test push engine messages. */
function fakeHost() {
  const sent: UiMessage[] = [];
  const listeners = new Set<(m: EngineMessage) => void>();
  const host: MosaicHost & { push(m: EngineMessage): void; listeners: typeof listeners } = {
    version: 1,
    send: (m) => void sent.push(structuredClone(m)),
    onMessage(cb) {
      listeners.add(cb);
      return () => listeners.delete(cb);
    },
    push(m) {
      // IPC structured-clones, like the real channel.
      for (const l of [...listeners]) l(structuredClone(m));
    },
    listeners,
  };
  return { host, sent };
}

describe("ipcConnection", () => {
  test("sends UI messages to the host and fans engine messages out to handlers", () => {
    const { host, sent } = fakeHost();
    const conn = ipcConnection(host);
    const a: EngineMessage[] = [];
    const b: EngineMessage[] = [];
    const offA = conn.onMessage((m) => a.push(m));
    conn.onMessage((m) => b.push(m));
    conn.send({ type: "start", id: 3 });
    expect(sent).toEqual([{ type: "start", id: 3 }]);
    host.push({ type: "state", state: "running" });
    offA();
    host.push({ type: "state", state: "stopped" });
    expect(a).toEqual([{ type: "state", state: "running" }]);
    expect(b.map((m) => m.type === "state" && m.state)).toEqual(["running", "stopped"]);
  });

  test("Float64Arrays in panel data arrive as Float64Arrays", () => {
    const { host } = fakeHost();
    const conn = ipcConnection(host);
    const got: EngineMessage[] = [];
    conn.onMessage((m) => got.push(m));
    host.push({
      type: "data",
      block: "emg",
      port: "out",
      rows: 1,
      cols: 2,
      t: new Float64Array([1.5]),
      v: new Float64Array([NaN, -Infinity]),
      skipped: 0,
    });
    const d = got[0] as Extract<EngineMessage, { type: "data" }>;
    expect(d.v).toBeInstanceOf(Float64Array);
    expect([...d.v]).toEqual([NaN, -Infinity]);
  });

  test("close unsubscribes from the host and stops sending", () => {
    const { host, sent } = fakeHost();
    const conn = ipcConnection(host);
    const got: EngineMessage[] = [];
    conn.onMessage((m) => got.push(m));
    expect(host.listeners.size).toBe(1);
    conn.close();
    conn.close();
    expect(host.listeners.size).toBe(0);
    conn.send({ type: "stop", id: 1 });
    expect(sent).toEqual([]);
    expect(got).toEqual([]);
  });

  test("a send the host refuses becomes an error event, not an exception", () => {
    const conn = ipcConnection({
      send: () => {
        throw new Error("An object could not be cloned.");
      },
      onMessage: () => () => {},
    });
    const got: EngineMessage[] = [];
    conn.onMessage((m) => got.push(m));
    expect(() => conn.send({ type: "start", id: 1 })).not.toThrow();
    expect(got[0]).toMatchObject({
      type: "event",
      event: { level: "error", message: expect.stringContaining("could not be cloned") },
    });
  });

  test("drives an EngineClient: hello, request/reply", async () => {
    const { host, sent } = fakeHost();
    const client = new EngineClient(ipcConnection(host));
    expect(sent[0]).toEqual({ type: "hello", version: 1 });
    host.push({ type: "hello", version: 1, engine: "node host", sharedMemory: true });
    expect(client.connected).toBe(true);
    expect(client.engineName).toBe("node host");
    const reply = client.start();
    const req = sent.at(-1) as Extract<UiMessage, { type: "start" }>;
    expect(req.type).toBe("start");
    host.push({ type: "reply", id: req.id, ok: true });
    await expect(reply).resolves.toMatchObject({ ok: true });
  });

  test("desktopHost finds the preload's object and nothing else", () => {
    const { host } = fakeHost();
    expect(desktopHost({ mosaicHost: host })).toBe(host);
    expect(desktopHost({})).toBeUndefined();
    expect(desktopHost({ mosaicHost: { send: 1, onMessage: 2 } })).toBeUndefined();
    expect(desktopHost(undefined)).toBeUndefined();
    expect(desktopHost(globalThis)).toBeUndefined();
  });
});
