import { describe, expect, test } from "vitest";
import { Frame, vectorShape, type IoBridges } from "../../engine";
import { BlockHarness } from "../../engine/testing";
import { BlenderArm } from "./blender-arm";

/** A UDP bridge that records opens, sends and closes; `throwOnOpen` makes open throw. */
function fakeUdp(throwOnOpen?: unknown) {
  const log: string[] = [];
  let onError: (message: string) => void = () => {};
  const io: IoBridges = {
    udp: {
      open: (o) => {
        log.push("open");
        if (throwOnOpen !== undefined) throw throwOnOpen;
        onError = o.onError!;
        return {
          send: (d) => log.push(new TextDecoder().decode(d)),
          close: () => log.push("close"),
        };
      },
    },
  };
  return { io, log, fail: (m: string) => onError(m) };
}

const frame = (rows: number[][], t0 = 1) =>
  Frame.from(
    vectorShape(rows[0]!.length),
    rows.map((_, i) => t0 + i * 0.04),
    rows,
  );

const REST = [0, 0, 0, 0, 0, 0, 0, 0, 0];

async function arm(io: IoBridges | undefined, opts: { desiredRate?: number } = {}) {
  return BlockHarness.create(
    BlenderArm,
    { Port: 3334, Input: "command" },
    {
      inputs: [{ shape: vectorShape(9), rate: 25 }],
      ...(io ? { io } : {}),
      ...opts,
    },
  );
}

const HEAD = "→ 127.0.0.1:3334, 9 values as they are";

describe("BlenderArm steps: status texts, errors, reset, stop", () => {
  test("status at creation, after sends, send errors (warned), reset and stop", async () => {
    const udp = fakeUdp();
    const h = await arm(udp.io);
    expect(h.text).toBe(`${HEAD}: 0 datagrams sent`);
    expect(h.desiredRate).toBe(0);
    h.start();
    h.start();
    expect(udp.log).toEqual(["open"]);
    h.push(frame([REST, REST]));
    expect(h.text).toBe(`${HEAD}: 2 datagrams sent`);
    udp.fail("ECONNREFUSED");
    expect(h.warnings).toEqual(["UDP to 127.0.0.1:3334: ECONNREFUSED"]);
    expect(h.text).toBe(`${HEAD}: 2 datagrams sent, 1 failed (ECONNREFUSED)`);
    udp.fail("again");
    expect(h.warnings).toHaveLength(1);
    expect(h.text).toBe(`${HEAD}: 2 datagrams sent, 2 failed (again)`);
    h.instance.reset?.();
    expect(h.text).toBe(`${HEAD}: 0 datagrams sent`);
    udp.fail("after reset");
    expect(h.warnings).toEqual([
      "UDP to 127.0.0.1:3334: ECONNREFUSED",
      "UDP to 127.0.0.1:3334: after reset",
    ]);
    h.instance.stop?.();
    expect(udp.log).toEqual(["open", "[0,0,0,0,0,0,0,0,0]", "[0,0,0,0,0,0,0,0,0]", "close"]);
    expect(h.text).toBe(`${HEAD}: 0 datagrams sent, 1 failed (after reset)`);
    h.push(frame([REST]));
    expect(h.output("command").v).toHaveLength(3);
    h.instance.dispose?.();
    expect(udp.log.filter((l) => l === "close")).toHaveLength(1);
    h.start();
    expect(udp.log.filter((l) => l === "open")).toHaveLength(2);
    h.instance.dispose?.();
    expect(udp.log.filter((l) => l === "close")).toHaveLength(2);
  });

  test("the head of the status names the destination and what the input carries", async () => {
    const h = await arm(fakeUdp().io);
    expect(h.text).toBe(`${HEAD}: 0 datagrams sent`);
  });

  test("open throwing (an Error or not) counts as a failure with its message", async () => {
    const udp = fakeUdp(new Error("bad host"));
    const h = await arm(udp.io);
    h.start();
    expect(h.warnings).toEqual(["UDP to 127.0.0.1:3334: bad host"]);
    expect(h.text).toBe(`${HEAD}: 0 datagrams sent, 1 failed (bad host)`);
    h.push(frame([REST]));
    expect(udp.log).toEqual(["open"]);
    h.start();
    expect(udp.log).toEqual(["open", "open"]);
    const h2 = await arm(fakeUdp("plain").io);
    h2.start();
    expect(h2.text).toBe(`${HEAD}: 0 datagrams sent, 1 failed (plain)`);
  });

  test("a declared rate is kept", async () => {
    const h = await arm(fakeUdp().io, { desiredRate: 7 });
    expect(h.desiredRate).toBe(7);
  });

  test("without UDP: the status says so, counts commands not sent, warns at start", async () => {
    const h = await arm(undefined);
    expect(h.text).toBe(
      "UDP is unavailable here (the browser build has no network sockets): run the pipeline with the desktop app or `mosaic run`",
    );
    h.start();
    expect(h.warnings).toEqual([
      "UDP is unavailable here (the browser build has no network sockets): the Blender arm gets nothing",
    ]);
    h.push(frame([REST, REST]));
    expect(h.text).toBe(
      "UDP is unavailable here (the browser build has no network sockets): 2 commands not sent",
    );
    h.instance.reset?.();
    expect(h.text).toBe(
      "UDP is unavailable here (the browser build has no network sockets): 0 commands not sent",
    );
    h.push(frame([REST]));
    h.instance.stop?.();
    expect(h.text).toBe(
      "UDP is unavailable here (the browser build has no network sockets): 1 command not sent",
    );
  });
});
