/**
 * Issue 14, item 6: a UdpSender never loses a datagram silently. Before, a host name that did not
 * resolve showed "598 sent, 1 failed" (one error for the failed lookup; the datagrams queued
 * meanwhile, and every later one, vanished), an overflowing queue was reported as one error, and
 * a send refused later (nothing listening) was dropped by Node without a word, because sends had
 * no completion callback. Now every datagram not sent is one `onError` call of the bridge, counted
 * by the block in its status text ("N datagrams sent, M not sent (reason)") and in its
 * rate-limited warnings (the count so far).
 */
import { createSocket } from "node:dgram";
import { describe, expect, test } from "vitest";
import { Frame, vectorShape, type UdpSocketHandle } from "../../app/engine";
import { BlockHarness } from "../../app/engine/testing";
import { UdpSender } from "../../app/blocks/io/udp-sender";
import { MAX_PENDING, nodeUdpBridge } from "../../native-bridges/udp";

const until = async (cond: () => boolean, ms = 5000): Promise<void> => {
  const end = Date.now() + ms;
  while (!cond()) {
    if (Date.now() > end) throw new Error("timed out");
    await new Promise((r) => setTimeout(r, 5));
  }
};

/** A loopback port with nothing listening on it (bound, read, closed). */
async function deadPort(): Promise<number> {
  const s = createSocket("udp4");
  await new Promise<void>((r) => s.bind(0, "127.0.0.1", r));
  const port = s.address().port;
  await new Promise<void>((r) => s.close(() => r()));
  return port;
}

/** `.invalid` never resolves (RFC 6761). */
const NOWHERE = "mosaic-no-such-host.invalid";

describe("UDP bridge: every datagram not sent is one error", () => {
  test("a host that does not resolve: the queued datagrams, the overflow and later ones", async () => {
    const errors: string[] = [];
    const h: UdpSocketHandle = nodeUdpBridge().open({
      remote: { host: NOWHERE, port: 9 },
      onError: (m) => errors.push(m),
    });
    try {
      for (let i = 0; i < 598; i++) h.send(new Uint8Array([i & 255]));
      // The overflow is counted at once, the queued ones when the lookup fails.
      expect(errors.length).toBe(598 - MAX_PENDING);
      await until(() => errors.length >= 598);
      for (let i = 0; i < 10; i++) h.send(new Uint8Array([1]));
      expect(errors.length).toBe(608);
      expect(errors.at(-1)).toMatch(/cannot resolve host 'mosaic-no-such-host\.invalid'/);
    } finally {
      h.close();
    }
  });

  test("the queue overflowing while connecting: each datagram over it counted, the rest sent", async () => {
    const rx = createSocket("udp4");
    let got = 0;
    rx.on("message", () => got++);
    await new Promise<void>((r) => rx.bind(0, "127.0.0.1", r));
    const errors: string[] = [];
    const h = nodeUdpBridge().open({
      remote: { host: "127.0.0.1", port: rx.address().port },
      onError: (m) => errors.push(m),
    });
    try {
      for (let i = 0; i < 1000; i++) h.send(new Uint8Array([i & 255]));
      await until(() => got === MAX_PENDING);
      expect(errors.length).toBe(1000 - MAX_PENDING);
      expect(errors[0]).toMatch(/more than 256 waiting while connecting/);
    } finally {
      h.close();
      rx.close();
    }
  });

  test("sends refused later (nothing listening): every one not sent is counted", async () => {
    const port = await deadPort();
    const errors: string[] = [];
    let ready = false;
    const h = nodeUdpBridge().open({
      remote: { host: "127.0.0.1", port },
      onReady: () => (ready = true),
      onError: (m) => errors.push(m),
    });
    try {
      await until(() => ready);
      // Bursts, as a busy engine worker sends (its event loop turns between them, not within):
      // the ICMP error of one datagram fails the next send, which Node dropped without a word
      // when the send had no callback.
      for (let b = 0; b < 20; b++) {
        for (let i = 0; i < 10; i++) h.send(new Uint8Array([i]));
        await new Promise((r) => setTimeout(r, 5));
      }
      await until(() => errors.length >= 50);
      expect(errors[0]).toMatch(/nothing is listening .*ECONNREFUSED/);
    } finally {
      h.close();
    }
  });
});

describe("UdpSender block: the status counts datagrams not sent", () => {
  test("598 events to a host that does not resolve: 0 sent, 598 not sent (not '598 sent, 1 failed')", async () => {
    const h = await BlockHarness.create(
      UdpSender,
      { Host: NOWHERE, Port: 9 },
      { inputs: [{ shape: vectorShape(1), rate: 100 }], io: { udp: nodeUdpBridge() } },
    );
    h.start();
    const t = Array.from({ length: 598 }, (_, i) => i / 100);
    h.push(
      Frame.from(
        vectorShape(1),
        t,
        t.map((x) => [x]),
      ),
    );
    await until(() => /598 not sent/.test(h.text));
    expect(h.text).toMatch(/: 0 datagrams sent, 598 not sent \(cannot resolve host/);
    expect(h.warnings.at(-1)).toMatch(/datagrams? not sent so far\)$/);
    h.instance.stop?.();
  });
});
