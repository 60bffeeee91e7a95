import { describe, expect, test } from "vitest";
import type { HubClient, HubConnection } from "../host/session-hub";
import { createWindowLink, type HostMessage, type LoadedPipeline } from "./window-link";

/** A fake hub: records connections and what each received; the test answers for the engine. */
function fakeHub() {
  const conns: { sink: HubClient; got: unknown[]; closed: boolean }[] = [];
  return {
    conns,
    connect(sink: HubClient): HubConnection {
      const c = { sink, got: [] as unknown[], closed: false };
      conns.push(c);
      return {
        receive: (raw) => void c.got.push(raw),
        close: () => {
          c.closed = true;
        },
      };
    },
  };
}

describe("window link", () => {
  test("relays both ways over one hub connection", () => {
    const hub = fakeHub();
    const page: HostMessage[] = [];
    const link = createWindowLink(hub, (m) => page.push(m));
    expect(hub.conns).toHaveLength(0); // connects on the page's first message
    link.receive({ type: "hello", version: 1 });
    link.receive({ type: "start", id: 1 });
    expect(hub.conns).toHaveLength(1);
    expect(hub.conns[0]!.got).toEqual([
      { type: "hello", version: 1 },
      { type: "start", id: 1 },
    ]);
    const data: HostMessage = {
      type: "data",
      block: "b",
      port: "out",
      rows: 1,
      cols: 1,
      t: new Float64Array([1]),
      v: new Float64Array([2]),
      skipped: 0,
    };
    hub.conns[0]!.sink.send(data);
    expect(page).toEqual([data]);
  });

  test("passes anything on for the hub to validate (it answers bad messages)", () => {
    const hub = fakeHub();
    const link = createWindowLink(hub, () => {});
    link.receive({ type: "nonsense" });
    link.receive(null);
    expect(hub.conns[0]!.got).toEqual([{ type: "nonsense" }, null]);
  });

  test("a second hello (reloaded page) replaces the connection; the old one goes quiet", () => {
    const hub = fakeHub();
    const page: HostMessage[] = [];
    const link = createWindowLink(hub, (m) => page.push(m));
    link.receive({ type: "hello", version: 1 });
    link.receive({ type: "watch", id: 2, block: "emg" });
    link.receive({ type: "hello", version: 1 });
    expect(hub.conns).toHaveLength(2);
    expect(hub.conns[0]!.closed).toBe(true);
    expect(hub.conns[1]!.got).toEqual([{ type: "hello", version: 1 }]);
    hub.conns[0]!.sink.send({ type: "state", state: "running" });
    expect(page).toEqual([]);
    hub.conns[1]!.sink.send({ type: "state", state: "stopped" });
    expect(page).toEqual([{ type: "state", state: "stopped" }]);
  });

  test("close closes the hub connection and drops later traffic", () => {
    const hub = fakeHub();
    const page: HostMessage[] = [];
    const link = createWindowLink(hub, (m) => page.push(m));
    link.receive({ type: "hello", version: 1 });
    link.close();
    link.close();
    expect(hub.conns[0]!.closed).toBe(true);
    link.receive({ type: "start", id: 3 });
    hub.conns[0]!.sink.send({ type: "state", state: "running" });
    expect(hub.conns[0]!.got).toHaveLength(1);
    expect(page).toEqual([]);
  });

  test("notes the pipeline the page loaded when its load succeeds", () => {
    const hub = fakeHub();
    const loaded: LoadedPipeline[] = [];
    const link = createWindowLink(
      hub,
      () => {},
      (p) => loaded.push(p),
    );
    link.receive({ type: "hello", version: 1 });
    link.receive({ type: "load", id: 4, file: "pipelines/bad.yaml", source: "x" });
    link.receive({ type: "load", id: 5, file: "pipelines/demo.yaml", source: "Blocks: {}" });
    const sink = hub.conns[0]!.sink;
    sink.send({ type: "reply", id: 4, ok: false, message: "no" });
    expect(loaded).toEqual([]);
    sink.send({ type: "reply", id: 5, ok: true });
    expect(loaded).toEqual([{ file: "pipelines/demo.yaml", source: "Blocks: {}" }]);
    // A reply is used once.
    sink.send({ type: "reply", id: 5, ok: true });
    expect(loaded).toHaveLength(1);
  });
});
