/**
 * `mosaic serve` through the real CLI: the UI files over HTTP (cross-origin isolated), the engine
 * over a WebSocket that refuses requests without the session token or from another origin, and a
 * pipeline that keeps running when a client goes away.
 */
import type { ChildProcess } from "node:child_process";
import { afterAll, beforeAll, describe, expect, test } from "vitest";
import WebSocket from "ws";
import type { EngineMessage } from "../../app/engine/protocol";
import {
  CLOSE_BAD_TOKEN,
  CLOSE_FOREIGN_ORIGIN,
  decodeWire,
  encodeWire,
} from "../../app/engine/protocol-wire";
import { requireBuild, startCli } from "./helpers";

let cli: ChildProcess;
let url: URL;

beforeAll(async () => {
  requireBuild();
  cli = startCli(["serve", "pipelines/demo.yaml", "--port", "0"]);
  let out = "";
  cli.stderr!.on("data", (d: Buffer) => (out += d.toString()));
  url = await new Promise<URL>((resolve, reject) => {
    const t = setTimeout(() => reject(new Error(`no URL printed: ${out}`)), 20_000);
    cli.stdout!.on("data", (d: Buffer) => {
      out += d.toString();
      const m = /MOSAIC is at (\S+)/.exec(out);
      if (m) {
        clearTimeout(t);
        resolve(new URL(m[1]!));
      }
    });
  });
}, 30_000);

afterAll(async () => {
  if (!cli || cli.exitCode !== null) return;
  cli.kill("SIGINT");
  await new Promise((r) => cli.once("exit", r));
});

function wsUrl(token: string | null): string {
  const u = new URL("/ws", url);
  u.protocol = "ws:";
  if (token !== null) u.searchParams.set("token", token);
  return u.href;
}

/** Opens a socket; resolves with the HTTP status it was refused with, or the open socket. */
function open(target: string, origin = url.origin): Promise<WebSocket | number> {
  return new Promise((resolve) => {
    const ws = new WebSocket(target, { origin });
    ws.once("open", () => resolve(ws));
    ws.once("unexpected-response", (_req, res) => resolve(res.statusCode ?? 0));
    ws.once("error", () => resolve(-1));
  });
}

/** Opens a socket the host turns away: resolves with the close code and reason it sent. */
function refusal(target: string, origin = url.origin): Promise<{ code: number; reason: string }> {
  return new Promise((resolve, reject) => {
    const ws = new WebSocket(target, { origin });
    const t = setTimeout(() => {
      ws.terminate();
      reject(new Error(`no close within 10 s for ${target} from ${origin.slice(0, 40)}`));
    }, 10_000);
    ws.once("close", (code, reason) => {
      clearTimeout(t);
      resolve({ code, reason: String(reason) });
    });
    ws.once("error", () => resolve({ code: -1, reason: "" }));
  });
}

function collect(ws: WebSocket): EngineMessage[] {
  const got: EngineMessage[] = [];
  ws.on("message", (d) => got.push(decodeWire(String(d)) as EngineMessage));
  return got;
}

async function until(cond: () => boolean, ms = 5000): Promise<void> {
  const end = Date.now() + ms;
  while (!cond()) {
    if (Date.now() > end) throw new Error("timed out");
    await new Promise((r) => setTimeout(r, 20));
  }
}

describe("mosaic serve", () => {
  test("serves the UI on 127.0.0.1, cross-origin isolated, and prints a URL with a token", async () => {
    expect(url.hostname).toBe("127.0.0.1");
    const token = url.searchParams.get("token")!;
    expect(token.length).toBeGreaterThanOrEqual(32);
    const r = await fetch(new URL("/", url));
    expect(r.status).toBe(200);
    expect(r.headers.get("cross-origin-opener-policy")).toBe("same-origin");
    expect(r.headers.get("cross-origin-embedder-policy")).toBe("require-corp");
    expect(await r.text()).toMatch(/<div id="root">/);
  });

  test("the WebSocket refuses a missing or wrong token and a foreign origin, saying why", async () => {
    const token = url.searchParams.get("token")!;
    const badToken = { code: CLOSE_BAD_TOKEN, reason: "wrong or missing token" };
    expect(await refusal(wsUrl(null))).toEqual(badToken);
    // One character changed: a token that already starts with "x" (1 run in 64) must not stay right.
    const wrong = (token.startsWith("x") ? "y" : "x") + token.slice(1);
    expect(await refusal(wsUrl(wrong))).toEqual(badToken);
    expect(await refusal(wsUrl(token), "http://evil.example")).toEqual({
      code: CLOSE_FOREIGN_ORIGIN,
      reason: `a page from http://evil.example (not ${url.origin})`,
    });
    // A long foreign origin still gets a close with its reason (at most 123 bytes).
    const long = await refusal(wsUrl(token), `http://${"e".repeat(300)}.example`);
    expect(long.code).toBe(CLOSE_FOREIGN_ORIGIN);
    expect(Buffer.byteLength(long.reason)).toBeLessThanOrEqual(123);
  }, 60_000);

  test("clients share the running demo; the engine survives a closed client", async () => {
    const token = url.searchParams.get("token")!;
    const a = (await open(wsUrl(token))) as WebSocket;
    const got = collect(a);
    a.send(encodeWire({ type: "hello", version: 1 }));
    await until(() => got.some((m) => m.type === "state"));
    expect(got.map((m) => m.type).slice(0, 3)).toEqual(["hello", "graph", "state"]);
    expect(got.find((m) => m.type === "state")).toMatchObject({ state: "running" });
    a.send(encodeWire({ type: "watch", id: 1, block: "Emg", maxRate: 50 }));
    await until(() => got.filter((m) => m.type === "data").length > 2);
    const data = got.find((m) => m.type === "data") as Extract<EngineMessage, { type: "data" }>;
    expect(data.v).toBeInstanceOf(Float64Array);
    expect(data.v.length).toBe(data.t.length * 8);
    // Garbage is answered, not fatal.
    a.send("{not json");
    a.send(encodeWire({ type: "setParam", id: 2, block: "Nope", param: "X", value: 1 }));
    await until(() => got.some((m) => m.type === "reply" && m.id === 2));
    expect(got.find((m) => m.type === "reply" && m.id === 2)).toMatchObject({ ok: false });
    a.terminate(); // the tab is gone, without a goodbye

    const b = (await open(wsUrl(token))) as WebSocket;
    const got2 = collect(b);
    b.send(encodeWire({ type: "hello", version: 1 }));
    await until(() => got2.filter((m) => m.type === "telemetry").length > 3);
    const tel = got2.filter((m) => m.type === "telemetry").at(-1) as Extract<
      EngineMessage,
      { type: "telemetry" }
    >;
    // Still producing (on a loaded machine it may lag; what matters is that it was not stopped).
    const emg = tel.telemetry.blocks.find((x) => x.name === "Emg")!;
    expect(emg.status).not.toBe("idle");
    expect(emg.events).toBeGreaterThan(0);
    b.close();
  }, 30_000);
});
