import { describe, expect, test } from "vitest";
import type { EngineMessage } from "../../engine/protocol";
import { decodeWire, encodeWire } from "../../engine/protocol-wire";
import { hostSocketUrl, wsConnection, type SocketLike } from "./ws-connection";

function fakeSocket() {
  const sent: unknown[] = [];
  const s: SocketLike & { sent: unknown[]; closed: boolean } = {
    readyState: 0,
    sent,
    closed: false,
    send: (d) => void sent.push(decodeWire(d)),
    close() {
      this.closed = true;
    },
    onopen: null,
    onmessage: null,
    onclose: null,
    onerror: null,
  };
  return s;
}

describe("WebSocket transport", () => {
  test("the socket URL comes from the page's token; no token, no host", () => {
    expect(hostSocketUrl({ href: "http://127.0.0.1:8321/?token=abc%2B1&pipeline=demo.yaml" })).toBe(
      "ws://127.0.0.1:8321/ws?token=abc%2B1",
    );
    expect(hostSocketUrl({ href: "https://lab.example/mosaic/?token=t" })).toBe(
      "wss://lab.example/ws?token=t",
    );
    expect(hostSocketUrl({ href: "http://127.0.0.1:8321/" })).toBeNull();
  });

  test("queues until open, decodes typed arrays, reports a lost connection", () => {
    const s = fakeSocket();
    const c = wsConnection(s);
    const got: EngineMessage[] = [];
    c.onMessage((m) => got.push(m));
    c.send({ type: "hello", version: 1 });
    expect(s.sent).toEqual([]);
    s.onopen!({});
    expect(s.sent).toEqual([{ type: "hello", version: 1 }]);
    s.onmessage!({
      data: encodeWire({
        type: "data",
        block: "B",
        port: "out",
        rows: 1,
        cols: 1,
        t: new Float64Array([1]),
        v: new Float64Array([NaN]),
        skipped: 0,
      }),
    });
    s.onmessage!({ data: "not json" });
    expect(got).toHaveLength(1);
    expect((got[0] as { v: Float64Array }).v[0]).toBeNaN();
    s.onclose!({ code: 1006, reason: "" });
    expect(got[1]).toMatchObject({ type: "event", event: { level: "error" } });
    expect((got[1] as { event: { message: string } }).event.message).toMatch(/mosaic serve/);
    c.close();
    expect(s.closed).toBe(true);
  });
});
