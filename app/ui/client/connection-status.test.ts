import { describe, expect, test } from "vitest";
import type { EngineMessage } from "../../engine/protocol";
import { CLOSE_BAD_TOKEN, CLOSE_FOREIGN_ORIGIN } from "../../engine/protocol-wire";
import { engineDetail, engineLabel, explainClose } from "./connection-status";
import { wsConnection, type SocketLike } from "./ws-connection";

describe("which engine, and why the connection ended", () => {
  test("the toolbar names the engine's place", () => {
    expect(engineLabel({ kind: "host", address: "127.0.0.1:8321" })).toBe(
      "engine: mosaic serve at 127.0.0.1:8321",
    );
    expect(engineLabel({ kind: "page" })).toBe("engine: in this page (browser build)");
    expect(engineLabel({ kind: "desktop" })).toMatch(/desktop app/);
  });

  test("the in-page engine's detail says how to reach mosaic serve's engine instead", () => {
    const d = engineDetail({ kind: "page" }, "browser worker");
    expect(d).toMatch(/browser worker/);
    expect(d).toMatch(/no \?token=/);
    expect(engineDetail({ kind: "host", address: "h:1" }, "node host")).toMatch(/h:1.*node host/);
  });

  test("a refusal names its cause and what to do", () => {
    const bad = explainClose(CLOSE_BAD_TOKEN, "wrong or missing token", false);
    expect(bad.refused).toBe(true);
    expect(bad.message).toBe(
      "mosaic serve refused this page: wrong or missing token — open the URL mosaic serve printed",
    );
    const foreign = explainClose(
      CLOSE_FOREIGN_ORIGIN,
      "a page from http://x (not http://y)",
      false,
    );
    expect(foreign).toMatchObject({ refused: true });
    expect(foreign.message).toMatch(/refused this page: a page from http:\/\/x/);
    // A refusal without a reason still says which.
    expect(explainClose(CLOSE_BAD_TOKEN, "", false).message).toMatch(/wrong or missing token/);
  });

  test("a socket that never opened, and one that closed later, say so", () => {
    const never = explainClose(1006, "", false);
    expect(never.refused).toBe(true);
    expect(never.message).toMatch(/could not connect to mosaic serve.*still running/);
    const later = explainClose(1006, "", true);
    expect(later.refused).toBe(false);
    expect(later.message).toMatch(/connection to mosaic serve closed.*still running/);
    expect(explainClose(1008, "too slow: 70.0 MiB waiting to be sent", true).message).toBe(
      "mosaic serve closed the connection: too slow: 70.0 MiB waiting to be sent",
    );
  });
});

describe("the WebSocket transport reports its end", () => {
  function socket(): SocketLike {
    return {
      readyState: 0,
      send: () => {},
      close: () => {},
      onopen: null,
      onmessage: null,
      onclose: null,
      onerror: null,
    };
  }

  test("a refused socket: lost names the cause, onLost hears it, the log gets it", () => {
    const s = socket();
    const c = wsConnection(s);
    const events: EngineMessage[] = [];
    const heard: string[] = [];
    c.onMessage((m) => events.push(m));
    c.onLost((l) => heard.push(l.message));
    expect(c.lost).toBeUndefined();
    s.onclose!({ code: CLOSE_BAD_TOKEN, reason: "wrong or missing token" });
    expect(c.lost).toMatchObject({ refused: true });
    expect(heard).toEqual([c.lost!.message]);
    expect(events).toMatchObject([
      { type: "event", event: { level: "error", message: c.lost!.message } },
    ]);
  });

  test("a socket that opened and then closed is a loss, not a refusal", () => {
    const s = socket();
    const c = wsConnection(s);
    s.onopen!({});
    s.onclose!({ code: 1006, reason: "" });
    expect(c.lost).toMatchObject({ refused: false });
  });
});
