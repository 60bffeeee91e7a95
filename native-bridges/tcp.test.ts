/**
 * The TCP bridge on real loopback sockets: bytes both ways across chunk boundaries, a refused
 * connect, a peer that closes or resets, and a caller's close that still delivers its last write.
 */
import { createConnection, createServer, type Server, type Socket } from "node:net";
import { afterEach, describe, expect, test } from "vitest";
import type { TcpSocketHandle } from "../app/engine/io";
import { describeTcpError, nodeTcpBridge } from "./tcp";

const cleanup: (() => void)[] = [];
afterEach(() => {
  for (const c of cleanup.splice(0)) c();
});

/** A loopback server on an ephemeral port; resolves with it and its port. */
async function server(onSocket: (s: Socket) => void): Promise<{ srv: Server; port: number }> {
  const srv = createServer(onSocket);
  await new Promise<void>((r) => srv.listen(0, "127.0.0.1", r));
  cleanup.push(() => srv.close());
  const addr = srv.address();
  if (addr === null || typeof addr === "string") throw new Error("no port");
  return { srv, port: addr.port };
}

/** A port that was free a moment ago (nothing listens there now). */
async function closedPort(): Promise<number> {
  const { srv, port } = await server(() => {});
  await new Promise<void>((r) => srv.close(() => r()));
  return port;
}

const until = async (ok: () => boolean, ms = 3000): Promise<void> => {
  const t0 = Date.now();
  while (!ok()) {
    if (Date.now() - t0 > ms) throw new Error("timed out waiting");
    await new Promise((r) => setTimeout(r, 5));
  }
};

describe("nodeTcpBridge", () => {
  test("connects, receives every byte in order (any chunking) and sends copies of what it writes", async () => {
    const got: number[] = [];
    const { port } = await server((s) => {
      s.on("data", (b) => got.push(...b));
      // 10 000 bytes in pieces of odd sizes.
      const all = Buffer.alloc(10_000);
      for (let i = 0; i < all.length; i++) all[i] = (i * 7) & 255;
      for (let at = 0; at < all.length; at += 333) s.write(all.subarray(at, at + 333));
    });
    const received: number[] = [];
    let connected: { local: number; remote: number } | undefined;
    const h = nodeTcpBridge().connect(
      { host: "127.0.0.1", port },
      {
        onConnect: (l, r) => (connected = { local: l.port, remote: r.port }),
        onData: (d) => received.push(...d),
        onClose: () => {},
      },
    );
    cleanup.push(() => h.close());
    await until(() => received.length === 10_000);
    expect(connected?.remote).toBe(port);
    expect(connected?.local).toBeGreaterThan(0);
    expect(received.every((v, i) => v === ((i * 7) & 255))).toBe(true);
    const buf = new Uint8Array([1, 2, 3]);
    expect(h.write(buf)).toBe(true);
    buf[0] = 99; // the bridge copied it
    expect(h.write("OK\r\n")).toBe(true);
    await until(() => got.length === 7);
    expect(got).toEqual([1, 2, 3, 79, 75, 13, 10]);
  });

  test("a refused connect is one onClose with the port and what to do; writes before it return false", async () => {
    const port = await closedPort();
    const closes: [string, boolean][] = [];
    const h = nodeTcpBridge().connect(
      { host: "127.0.0.1", port },
      { onData: () => {}, onClose: (r, open) => closes.push([r, open]) },
    );
    expect(h.write("x")).toBe(false);
    await until(() => closes.length === 1);
    await new Promise((r) => setTimeout(r, 50));
    expect(closes).toHaveLength(1);
    expect(closes[0]![0]).toBe(
      `nothing is listening at 127.0.0.1:${port} (ECONNREFUSED): start the server there, or check Host and Port`,
    );
    expect(closes[0]![1]).toBe(false);
  });

  test("the peer closing or resetting is reported once, as an open connection that ended", async () => {
    const { port } = await server((s) => {
      s.once("data", (b) => {
        if (b.toString() === "reset") s.resetAndDestroy();
        else s.end();
      });
    });
    for (const how of ["end", "reset"]) {
      const closes: [string, boolean][] = [];
      const h: TcpSocketHandle = nodeTcpBridge().connect(
        { host: "127.0.0.1", port },
        {
          onConnect: () => h.write(how),
          onData: () => {},
          onClose: (r, open) => closes.push([r, open]),
        },
      );
      await until(() => closes.length === 1);
      await new Promise((r) => setTimeout(r, 30));
      expect(closes).toHaveLength(1);
      expect(closes[0]![1]).toBe(true);
      expect(closes[0]![0]).toMatch(
        how === "end"
          ? new RegExp(`^127\\.0\\.0\\.1:${port} closed the connection$`)
          : /reset the connection \(ECONNRESET\)/,
      );
      expect(h.write("more")).toBe(false);
    }
  });

  test("close() delivers the last write, then no callback follows", async () => {
    let last = "";
    let peerClosed = false;
    const { port } = await server((s) => {
      s.on("data", (b) => (last += b.toString()));
      s.on("end", () => {
        peerClosed = true;
        s.end();
      });
    });
    let closes = 0;
    let opened = false;
    const h = nodeTcpBridge().connect(
      { host: "127.0.0.1", port },
      { onConnect: () => (opened = true), onData: () => {}, onClose: () => closes++ },
    );
    await until(() => opened);
    h.write("STOP\r\n\r\n");
    h.close();
    h.close();
    await until(() => peerClosed);
    await new Promise((r) => setTimeout(r, 30));
    expect(last).toBe("STOP\r\n\r\n");
    expect(closes).toBe(0);
    expect(h.write("late")).toBe(false);
  });

  test("error lines name the endpoint and the cause", () => {
    const at = { host: "::1", port: 50040 };
    expect(describeTcpError({ code: "ECONNREFUSED" }, at, false)).toMatch(
      /^nothing is listening at \[::1\]:50040 \(ECONNREFUSED\)/,
    );
    expect(describeTcpError({ code: "ENOTFOUND" }, { host: "trigno", port: 1 }, false)).toMatch(
      /cannot resolve host 'trigno' \(ENOTFOUND\)/,
    );
    expect(describeTcpError(new Error("boom"), at, true)).toBe(
      "connection to [::1]:50040 failed: boom",
    );
  });
});

describe("nodeTcpBridge.listen", () => {
  /** A server on an ephemeral loopback port: resolves with its handle, its port and what it saw. */
  async function listening() {
    const seen: string[] = [];
    const data: number[] = [];
    const peers: { remote: number; write: (s: string) => boolean }[] = [];
    let port = 0;
    const srv = nodeTcpBridge().listen!(
      { host: "127.0.0.1", port: 0 },
      {
        onListening: (l) => (port = l.port),
        onPeer: (remote, peer) => {
          peers.push({ remote: remote.port, write: (s) => peer.write(s) });
          seen.push(`peer ${remote.host}`);
          return {
            onData: (d) => data.push(...d),
            onClose: (reason, wasOpen) => seen.push(`close ${wasOpen}: ${reason}`),
          };
        },
        onError: (r) => seen.push(`error: ${r}`),
      },
    );
    cleanup.push(() => srv.close());
    await until(() => port > 0);
    return { srv, port: () => port, seen, data, peers };
  }

  /** A client socket (node:net) to the port; resolves once connected. */
  async function client(port: number): Promise<{ s: Socket; got: number[] }> {
    const got: number[] = [];
    const s = createConnection({ host: "127.0.0.1", port });
    s.on("data", (b) => got.push(...b));
    s.on("error", () => {});
    cleanup.push(() => s.destroy());
    await new Promise<void>((r) => s.once("connect", () => r()));
    return { s, got };
  }

  test("accepts a peer, reports its address, bytes both ways; the peer's end is one onClose", async () => {
    const l = await listening();
    const c = await client(l.port());
    await until(() => l.peers.length === 1);
    expect(l.peers[0]!.remote).toBe(c.s.localPort);
    expect(l.seen[0]).toBe("peer 127.0.0.1");
    expect(l.peers[0]!.write("\x09")).toBe(true);
    await until(() => c.got.length === 1);
    expect(c.got).toEqual([9]);
    const all = Buffer.alloc(5000);
    for (let i = 0; i < all.length; i++) all[i] = (i * 13) & 255;
    for (let at = 0; at < all.length; at += 777) c.s.write(all.subarray(at, at + 777));
    await until(() => l.data.length === 5000);
    expect(l.data.every((v, i) => v === ((i * 13) & 255))).toBe(true);
    c.s.end();
    await until(() => l.seen.length === 2);
    expect(l.seen[1]).toMatch(/^close true: 127\.0\.0\.1:\d+ closed the connection$/);
  });

  test("a new peer replaces the current one (its onClose says so); close() ends both sides", async () => {
    const l = await listening();
    const a = await client(l.port());
    await until(() => l.peers.length === 1);
    const aPort = a.s.localPort;
    let aClosed = false;
    a.s.on("close", () => (aClosed = true));
    const b = await client(l.port());
    await until(() => l.peers.length === 2 && aClosed);
    // The old peer's end comes first, then the new peer.
    expect(l.seen[2]).toBe("peer 127.0.0.1");
    expect(l.seen[1]).toMatch(
      new RegExp(
        `^close true: 127\\.0\\.0\\.1:${aPort} was replaced by a new connection from 127\\.0\\.0\\.1:${b.s.localPort}$`,
      ),
    );
    let bClosed = false;
    b.s.on("close", () => (bClosed = true));
    l.srv.close();
    await until(() => bClosed);
    expect(l.seen).toHaveLength(3); // no callback after close()
    expect(l.peers[1]!.write("x")).toBe(false);
  });

  test("a port in use is one onError naming the port and what to do", async () => {
    const l = await listening();
    const errors: string[] = [];
    const again = nodeTcpBridge().listen!(
      { host: "127.0.0.1", port: l.port() },
      { onPeer: () => ({ onData: () => {}, onClose: () => {} }), onError: (r) => errors.push(r) },
    );
    cleanup.push(() => again.close());
    await until(() => errors.length === 1);
    expect(errors[0]).toBe(
      `cannot listen at 127.0.0.1:${l.port()}: the port is in use (EADDRINUSE) — another program (or another block) listens there; choose another Port or stop it`,
    );
  });
});
