import { createSocket, type Socket } from "node:dgram";
import { afterEach, describe, expect, test } from "vitest";
import type { Endpoint, UdpSocketHandle } from "../app/engine/io";
import { describeUdpError, nodeUdpBridge } from "./udp";

const cleanup: (() => void)[] = [];
afterEach(() => {
  for (const c of cleanup.splice(0)) c();
});

/** A plain dgram socket bound to an ephemeral loopback port. */
async function peer(): Promise<{ socket: Socket; port: number; got: Buffer[] }> {
  const socket = createSocket("udp4");
  const got: Buffer[] = [];
  socket.on("message", (m) => got.push(m));
  await new Promise<void>((r) => socket.bind(0, "127.0.0.1", r));
  cleanup.push(() => socket.close());
  return { socket, port: socket.address().port, got };
}

const until = async (cond: () => boolean, ms = 3000): Promise<void> => {
  const end = Date.now() + ms;
  while (!cond()) {
    if (Date.now() > end) throw new Error("timed out");
    await new Promise((r) => setTimeout(r, 5));
  }
};

const keep = (h: UdpSocketHandle): UdpSocketHandle => {
  cleanup.push(() => h.close());
  return h;
};

describe("node UDP bridge", () => {
  test("a sender connects and sends copies (the block may reuse its buffer at once)", async () => {
    const p = await peer();
    const errors: string[] = [];
    let ready: Endpoint | undefined;
    const h = keep(
      nodeUdpBridge().open({
        remote: { host: "127.0.0.1", port: p.port },
        onReady: (l) => (ready = l),
        onError: (m) => errors.push(m),
      }),
    );
    const buf = new Uint8Array([1, 2, 3]);
    h.send(buf); // before the connection is made: queued
    buf[0] = 9;
    await until(() => ready !== undefined);
    h.send(buf);
    buf[0] = 7;
    await until(() => p.got.length === 2);
    expect(p.got.map((b) => [...b])).toEqual([
      [1, 2, 3],
      [9, 2, 3],
    ]);
    expect(ready!.port).toBeGreaterThan(0);
    expect(errors).toEqual([]);
  });

  test("a host name is resolved once", async () => {
    const p = await peer();
    const errors: string[] = [];
    const h = keep(
      nodeUdpBridge().open({
        remote: { host: "localhost", port: p.port },
        onError: (m) => errors.push(m),
      }),
    );
    h.send(new Uint8Array([4]));
    await until(() => p.got.length === 1);
    expect(errors).toEqual([]);
  });

  test("a receiver binds and gets datagrams with their source", async () => {
    const p = await peer();
    const got: { data: number[]; from: Endpoint }[] = [];
    let local: Endpoint | undefined;
    keep(
      nodeUdpBridge().open({
        bind: { host: "127.0.0.1", port: 0 },
        onMessage: (d, from) => got.push({ data: [...d], from }),
        onReady: (l) => (local = l),
        onError: (m) => {
          throw new Error(m);
        },
      }),
    );
    await until(() => local !== undefined);
    p.socket.send(Buffer.from([5, 6]), local!.port, "127.0.0.1");
    await until(() => got.length === 1);
    expect(got[0]).toEqual({ data: [5, 6], from: { host: "127.0.0.1", port: p.port } });
  });

  test("a port in use: a clear error naming the port, nothing thrown", async () => {
    const p = await peer();
    const errors: string[] = [];
    keep(
      nodeUdpBridge().open({
        bind: { host: "127.0.0.1", port: p.port },
        onMessage: () => {},
        onError: (m) => errors.push(m),
      }),
    );
    await until(() => errors.length > 0);
    expect(errors[0]).toBe(
      `port ${p.port} is already in use on 127.0.0.1 (EADDRINUSE): another program or block is ` +
        "listening there; choose another Port or stop the other one",
    );
  });

  test("error texts", () => {
    const at = { host: "10.1.2.3", port: 80 };
    const e = (code: string) => Object.assign(new Error(code), { code });
    expect(describeUdpError(e("EACCES"), "bind", at)).toMatch(/below 1024/);
    expect(describeUdpError(e("EADDRNOTAVAIL"), "bind", at)).toMatch(
      /10\.1\.2\.3 is not an address of this machine/,
    );
    expect(describeUdpError(e("ECONNREFUSED"), "send", at)).toMatch(
      /nothing is listening at 10\.1\.2\.3:80/,
    );
    expect(describeUdpError(e("ENOTFOUND"), "resolve", { host: "nohost", port: 1 })).toMatch(
      /cannot resolve host 'nohost'/,
    );
    expect(describeUdpError(new Error("boom"), "send", { host: "::1", port: 9 })).toBe(
      "send [::1]:9 failed: boom",
    );
  });
});
