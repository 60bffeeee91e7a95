/**
 * Issue 14, item 9: a client of `mosaic serve` that stops reading does not make the host buffer
 * without bound. With a real socket that never reads (a raw TCP connection that does the WebSocket
 * handshake, then pauses): once bytes pile up on its socket its telemetry is dropped and counted;
 * when nothing of it is read for `stalledMs`, or more than `maxBufferedBytes` wait, it is
 * disconnected with close code 1008 and a reason (which it reads once it reads again). Another
 * client meanwhile gets everything.
 */
import { randomBytes } from "node:crypto";
import { mkdtempSync } from "node:fs";
import { connect, type Socket } from "node:net";
import { tmpdir } from "node:os";
import { join } from "node:path";
import { afterAll, beforeAll, describe, expect, test } from "vitest";
import WebSocket from "ws";
import { decodeWire, encodeWire } from "../../app/engine/protocol-wire";
import { CLOSE_TOO_SLOW, serve, type Served } from "../../app/host/serve";
import { requireBuild, ROOT } from "../integration/helpers";

const LIMITS = {
  dropAboveBytes: 64 * 1024,
  maxBufferedBytes: 8 * 1024 * 1024,
  stalledMs: 1500,
  closeGraceMs: 10_000,
};

/** A WebSocket client on a bare TCP socket: it reads only when told to. */
class RawClient {
  private buf: Buffer = Buffer.alloc(0);
  closed: { code: number; reason: string } | undefined;
  ended = false;

  private constructor(readonly sock: Socket) {
    sock.on("data", (d: Buffer) => {
      this.buf = Buffer.concat([this.buf, d]);
      this.frames();
    });
    sock.on("end", () => (this.ended = true));
    sock.on("close", () => (this.ended = true));
    sock.on("error", () => (this.ended = true));
  }

  static async open(served: Served): Promise<RawClient> {
    const sock = connect(served.port, "127.0.0.1");
    await new Promise<void>((r) => sock.once("connect", () => r()));
    const key = randomBytes(16).toString("base64");
    sock.write(
      `GET /ws?token=${encodeURIComponent(served.token)} HTTP/1.1\r\n` +
        `Host: 127.0.0.1:${served.port}\r\nOrigin: http://127.0.0.1:${served.port}\r\n` +
        `Upgrade: websocket\r\nConnection: Upgrade\r\nSec-WebSocket-Key: ${key}\r\n` +
        "Sec-WebSocket-Version: 13\r\n\r\n",
    );
    const rest = await new Promise<Buffer>((resolve, reject) => {
      let head = Buffer.alloc(0);
      const onData = (d: Buffer): void => {
        head = Buffer.concat([head, d]);
        const end = head.indexOf("\r\n\r\n");
        if (end < 0) return;
        sock.off("data", onData);
        if (!head.subarray(0, 12).toString().includes("101")) reject(new Error(String(head)));
        else resolve(head.subarray(end + 4));
      };
      sock.on("data", onData);
    });
    const c = new RawClient(sock);
    c.buf = rest;
    return c;
  }

  /** A masked text frame (clients must mask). */
  send(msg: object): void {
    const payload = Buffer.from(JSON.stringify(msg));
    const mask = randomBytes(4);
    const len = payload.length;
    const head =
      len < 126
        ? Buffer.from([0x81, 0x80 | len])
        : len < 65536
          ? Buffer.from([0x81, 0x80 | 126, len >> 8, len & 255])
          : (() => {
              const h = Buffer.alloc(10);
              h[0] = 0x81;
              h[1] = 0x80 | 127;
              h.writeBigUInt64BE(BigInt(len), 2);
              return h;
            })();
    for (let i = 0; i < len; i++) payload[i]! ^= mask[i & 3]!;
    this.sock.write(Buffer.concat([head, mask, payload]));
  }

  /** Reads the frames received so far; a close frame sets `closed`. */
  private frames(): void {
    for (;;) {
      if (this.buf.length < 2) return;
      const op = this.buf[0]! & 15;
      let len = this.buf[1]! & 127;
      let at = 2;
      if (len === 126) {
        if (this.buf.length < 4) return;
        len = this.buf.readUInt16BE(2);
        at = 4;
      } else if (len === 127) {
        if (this.buf.length < 10) return;
        len = Number(this.buf.readBigUInt64BE(2));
        at = 10;
      }
      if (this.buf.length < at + len) return;
      const payload = this.buf.subarray(at, at + len);
      this.buf = this.buf.subarray(at + len);
      if (op === 8) {
        this.closed = {
          code: payload.length >= 2 ? payload.readUInt16BE(0) : 1005,
          reason: payload.subarray(2).toString(),
        };
      }
    }
  }
}

async function until(cond: () => boolean, ms = 20_000): Promise<void> {
  const end = Date.now() + ms;
  while (!cond()) {
    if (Date.now() > end) throw new Error("timed out");
    await new Promise((r) => setTimeout(r, 20));
  }
}

describe("clients that stop reading", () => {
  let served: Served;
  beforeAll(async () => {
    requireBuild();
    served = await serve({
      webRoot: mkdtempSync(join(tmpdir(), "mosaic-web-")),
      port: 0,
      pipelinesDir: ROOT,
      workerPath: join(ROOT, "dist", "session.worker.mjs"),
      wasmPath: join(ROOT, "dist", "mosaic_core_bg.wasm"),
      slowClients: LIMITS,
    });
    const { readFileSync } = await import("node:fs");
    const source = readFileSync(join(ROOT, "pipelines", "demo.yaml"), "utf8");
    const r = await served.hub.request({ type: "load", file: "pipelines/demo.yaml", source });
    expect(r.ok).toBe(true);
    await served.hub.request({ type: "start" });
  }, 60_000);
  afterAll(async () => {
    await served?.close();
  });

  /** A reading client: counts the telemetry it gets. */
  async function reader(): Promise<{ ws: WebSocket; telemetry: () => number }> {
    const u = new URL(served.url);
    const ws = new WebSocket(`ws://127.0.0.1:${served.port}/ws?token=${served.token}`, {
      origin: u.origin,
    });
    let n = 0;
    ws.on("message", (d) => {
      if ((decodeWire(String(d)) as { type: string }).type === "telemetry") n++;
    });
    await new Promise((r) => ws.once("open", r));
    ws.send(JSON.stringify({ type: "hello", version: 1 }));
    return { ws, telemetry: () => n };
  }

  test("a stalled client: its telemetry is dropped and counted, then it is disconnected with 1008", async () => {
    const good = await reader();
    const before = served.stats();
    const raw = await RawClient.open(served);
    raw.send({ type: "hello", version: 1 });
    raw.sock.pause(); // never reads from here on
    // Catalog replies (large, never dropped) fill the kernel's buffers until bytes wait here.
    let id = 1;
    while (!served.stats().waiting.some((w) => w > LIMITS.dropAboveBytes)) {
      raw.send({ type: "catalog", id: id++ });
      await new Promise((r) => setTimeout(r, 50));
      expect(id).toBeLessThan(200);
    }
    const t0 = Date.now();
    await until(() => served.stats().disconnected.length > before.disconnected.length);
    const after = served.stats();
    expect(Date.now() - t0).toBeGreaterThanOrEqual(LIMITS.stalledMs - 600);
    expect(after.dropped.telemetry).toBeGreaterThan(before.dropped.telemetry);
    const reason = after.disconnected.at(-1)!;
    expect(reason).toMatch(/^stalled: read nothing of \d+\.\d MiB for 1\.5 s$/);
    expect(Math.max(...after.waiting)).toBeLessThan(LIMITS.maxBufferedBytes);
    // When it reads again, the close frame is at the end of what waited.
    raw.sock.resume();
    await until(() => raw.closed !== undefined || raw.ended);
    expect(raw.closed).toEqual({ code: CLOSE_TOO_SLOW, reason });
    // The reading client got its telemetry all along and is still connected.
    const n = good.telemetry();
    await until(() => good.telemetry() > n + 5);
    expect(good.ws.readyState).toBe(WebSocket.OPEN);
    good.ws.close();
  }, 60_000);

  test("a client with more than maxBufferedBytes waiting is disconnected at once", async () => {
    const before = served.stats();
    const raw = await RawClient.open(served);
    raw.send({ type: "hello", version: 1 });
    raw.sock.pause();
    for (let id = 1; id <= 150; id++) raw.send({ type: "catalog", id });
    await until(() => served.stats().disconnected.length > before.disconnected.length);
    // The size rule, not the stall rule (which would say "stalled: …" after stalledMs): how long
    // the host takes to answer 150 catalog requests depends on the machine, so it is not timed.
    expect(served.stats().disconnected.at(-1)).toMatch(
      /^too slow: \d+\.\d MiB waiting to be sent$/,
    );
    // Destroyed once the grace is over (it never reads); the host holds nothing for it.
    raw.sock.resume();
    await until(() => raw.closed !== undefined || raw.ended);
    expect(raw.closed?.code).toBe(CLOSE_TOO_SLOW);
  }, 60_000);

  test("a reading client that is sent more than maxBufferedBytes at once (a large graph) stays", async () => {
    const before = served.stats();
    const good = await reader();
    const replies: { id: number; ok: boolean }[] = [];
    good.ws.on("message", (d) => {
      const m = decodeWire(String(d)) as { type: string; id: number; ok: boolean };
      if (m.type === "reply") replies.push(m);
    });
    const lines = [
      "T: { Type: ScheduledTimer, DesiredRate: 10 }",
      "E: { Type: EmgSimulator, Inputs: [T], Params: { Channels: 2 } }",
    ];
    for (let i = 1; i < 6000; i++)
      lines.push(
        `F${i}: { Type: Filter, Inputs: [${i === 1 ? "E" : `F${i - 1}`}], Params: { Numerator: [1, 2, 3], Denominator: [1] } }`,
      );
    const sent = encodeWire({
      type: "load",
      id: 1,
      file: "pipelines/big.yaml",
      source: lines.join("\n"),
    });
    good.ws.send(sent);
    await until(() => replies.some((r) => r.id === 1), 30_000);
    expect(replies.find((r) => r.id === 1)!.ok).toBe(true);
    await new Promise((r) => setTimeout(r, LIMITS.stalledMs));
    expect(good.ws.readyState).toBe(WebSocket.OPEN);
    expect(served.stats().disconnected).toEqual(before.disconnected);
    good.ws.close();
  }, 60_000);
});
