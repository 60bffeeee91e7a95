// The steps of HannesGUI's create that hannes.test.ts does not reach: the status texts (and their
// pace), send and open errors, reset, stop and dispose, the browser build without UDP, the rate.
import { describe, expect, test } from "vitest";
import { BlockConfigError, Frame, vectorShape, type IoBridges } from "../../engine";
import { BlockHarness, type HarnessOptions } from "../../engine/testing";
import { HannesGUI } from "./hannes-gui";

/** A UDP bridge that records opens, sends (by first payload byte) and closes. */
function fakeUdp(throwOnOpen?: unknown) {
  const log: string[] = [];
  let onError: (message: string) => void = () => {};
  const io: IoBridges = {
    udp: {
      open: (o) => {
        log.push("open");
        if (throwOnOpen !== undefined) throw throwOnOpen;
        onError = o.onError!;
        return { send: (d) => log.push(`send ${d[1]}`), close: () => log.push("close") };
      },
    },
  };
  return { io, log, fail: (m: string) => onError(m) };
}

const frame = (size: number, times: number[]) =>
  Frame.from(
    vectorShape(size),
    times,
    times.map(() => Array.from({ length: size }, () => 50)),
  );

function gui(inputs: number[], io: IoBridges | undefined, opts: HarnessOptions = {}) {
  return BlockHarness.create(
    HannesGUI,
    { Port: 8889 },
    {
      inputs: inputs.map((size) => ({ shape: vectorShape(size), rate: 25 })),
      ...(io ? { io } : {}),
      ...opts,
    },
  );
}

const HEAD = "→ 127.0.0.1:8889, actuation vector (ControlAlgorithm)";
const NO_UDP = "UDP is unavailable here (the browser build has no network sockets)";

describe("HannesGUI steps", () => {
  test("status: counts per kind at the throttle's pace, failures, reset, stop and dispose", async () => {
    const udp = fakeUdp();
    const h = await gui([11, 2, 1], udp.io);
    expect(h.text).toBe(`${HEAD}: 0 activations, 0 raw EMG datagrams, 0 ARV datagrams`);
    expect(h.desiredRate).toBe(0);
    h.push(frame(11, [0.5]), 0); // before start: no socket, nothing sent
    expect(h.text).toBe(`${HEAD}: 0 activations, 0 raw EMG datagrams, 0 ARV datagrams`);
    h.start();
    h.start();
    h.push(frame(11, [1, 1.04]), 0);
    expect(h.text).toBe(`${HEAD}: 6 activations, 0 raw EMG datagrams, 0 ARV datagrams`);
    h.push(frame(2, [1.1]), 1); // within 0.25 s of the last status: not shown yet
    expect(h.text).toBe(`${HEAD}: 6 activations, 0 raw EMG datagrams, 0 ARV datagrams`);
    h.push(frame(1, [1.3]), 2);
    expect(h.text).toBe(`${HEAD}: 6 activations, 1 raw EMG datagram, 1 ARV datagram`);
    expect(udp.log).toEqual([
      "open",
      "send 15",
      "send 15",
      "send 15",
      "send 15",
      "send 15",
      "send 15",
      "send 16",
      "send 32",
    ]);
    udp.fail("ECONNREFUSED");
    expect(h.warnings).toEqual(["UDP to 127.0.0.1:8889: ECONNREFUSED"]);
    expect(h.text).toBe(
      `${HEAD}: 6 activations, 1 raw EMG datagram, 1 ARV datagram; 1 failed (ECONNREFUSED)`,
    );
    udp.fail("again");
    expect(h.warnings).toHaveLength(1);
    h.instance.reset!();
    expect(h.text).toBe(`${HEAD}: 0 activations, 0 raw EMG datagrams, 0 ARV datagrams`);
    h.push(frame(11, [1.31]), 0); // the throttle was reset: shown at once
    expect(h.text).toBe(`${HEAD}: 3 activations, 0 raw EMG datagrams, 0 ARV datagrams`);
    udp.fail("after reset");
    expect(h.warnings).toHaveLength(2);
    h.instance.stop!();
    expect(udp.log.slice(-1)).toEqual(["close"]);
    expect(h.text).toBe(
      `${HEAD}: 3 activations, 0 raw EMG datagrams, 0 ARV datagrams; 1 failed (after reset)`,
    );
    h.instance.dispose!();
    expect(udp.log.filter((l) => l === "close")).toHaveLength(1);
    h.start();
    h.instance.dispose!();
    expect(udp.log.filter((l) => l === "open" || l === "close")).toEqual([
      "open",
      "close",
      "open",
      "close",
    ]);
  });

  test("open throwing (an Error or not) counts as a failure; a declared rate is kept", async () => {
    const h = await gui([11], fakeUdp(new Error("bad host")).io, { desiredRate: 7 });
    expect(h.desiredRate).toBe(7);
    h.start();
    expect(h.warnings).toEqual(["UDP to 127.0.0.1:8889: bad host"]);
    expect(h.text).toBe(`${HEAD}: 0 activations; 1 failed (bad host)`);
    const p = await gui([11], fakeUdp("plain").io);
    p.start();
    expect(p.text).toBe(`${HEAD}: 0 activations; 1 failed (plain)`);
  });

  test("without UDP: the status says so, counts events not sent, warns at start", async () => {
    const h = await gui([11, 2], undefined);
    expect(h.text).toBe(`${NO_UDP}: run the pipeline with the desktop app or \`mosaic run\``);
    h.start();
    expect(h.warnings).toEqual([`${NO_UDP}: the Hannes GUI gets nothing`]);
    h.push(frame(11, [1, 1.04]), 0);
    expect(h.text).toBe(`${NO_UDP}: 2 events not sent`);
    h.push(frame(2, [1.1]), 1);
    expect(h.text).toBe(`${NO_UDP}: 2 events not sent`);
    h.instance.stop!();
    expect(h.text).toBe(`${NO_UDP}: 3 events not sent`);
    h.instance.reset!();
    expect(h.text).toBe(`${NO_UDP}: 0 events not sent`);
  });

  test("RawEmgBytes or ArvBytes without their input: the error names the param", async () => {
    for (const [param, inputs, position] of [
      ["RawEmgBytes", [11], 2],
      ["ArvBytes", [11, 2], 3],
    ] as const) {
      const err = await BlockHarness.create(
        HannesGUI,
        { Port: 8889, [param]: 64 },
        { inputs: inputs.map((size) => ({ shape: vectorShape(size) })) },
      ).then(
        () => undefined,
        (x: unknown) => x as BlockConfigError,
      );
      expect(err).toBeInstanceOf(BlockConfigError);
      expect(err!.message).toBe(
        `${param} is given but there is no input at position ${position} (Inputs: [control, rawEmg, arv])`,
      );
      expect(err!.param).toBe(param);
    }
  });
});
