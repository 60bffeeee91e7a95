import { describe, expect, it } from "vitest";
import type { BleBridge, BleConnection } from "../../engine";
import { addressKey, claimsOf, connectAttempt } from "./ble";

/** A bridge whose `connect` resolves or rejects as the test says; it records what it was given. */
function bridge(result: () => Promise<BleConnection>) {
  const seen: { address: string; onLost: (reason: string) => void }[] = [];
  const b: BleBridge = {
    watchState: () => ({ close() {} }),
    scan: () => ({ stop() {} }),
    connect: (address, onLost) => {
      seen.push({ address, onLost });
      return result();
    },
  };
  return { b, seen };
}

function connection(log: string[]): BleConnection {
  return { disconnect: () => log.push("disconnect") } as unknown as BleConnection;
}

describe("shared BLE helpers", () => {
  it("addressKey drops ':' and '-' and lower-cases; one claims registry per bridge", () => {
    expect(addressKey("AA:bb-CC:dd")).toBe("aabbccdd");
    const one = bridge(() => Promise.reject(new Error("x"))).b;
    const two = bridge(() => Promise.reject(new Error("x"))).b;
    claimsOf(one).add("aabb");
    expect(claimsOf(one).has("aabb")).toBe(true);
    expect(claimsOf(two).has("aabb")).toBe(false);
  });

  it("connectAttempt: a connection to a current attempt is handed over; onLost is passed on", async () => {
    const log: string[] = [];
    const c = connection(log);
    const { b, seen } = bridge(() => Promise.resolve(c));
    await connectAttempt(b, "aa:bb", {
      onLost: (r) => log.push(`lost ${r}`),
      current: () => true,
      fail: (r) => log.push(`fail ${r}`),
      connected: (got) => {
        log.push(got === c ? "connected" : "other");
        return Promise.resolve();
      },
    });
    expect(seen.map((s) => s.address)).toEqual(["aa:bb"]);
    seen[0]!.onLost("out of range");
    expect(log).toEqual(["connected", "lost out of range"]);
  });

  it("connectAttempt: a stale connection is disconnected, a failure is reported only while current", async () => {
    const log: string[] = [];
    const attempt = (current: boolean) => ({
      onLost: () => log.push("lost"),
      current: () => current,
      fail: (r: string) => log.push(`fail ${r}`),
      connected: () => {
        log.push("connected");
        return Promise.resolve();
      },
    });
    await connectAttempt(bridge(() => Promise.resolve(connection(log))).b, "a", attempt(false));
    expect(log).toEqual(["disconnect"]);
    const refused = bridge(() => Promise.reject(new Error("refused"))).b;
    await connectAttempt(refused, "a", attempt(false));
    expect(log).toEqual(["disconnect"]);
    await connectAttempt(refused, "a", attempt(true));
    expect(log).toEqual(["disconnect", "fail connection failed: refused"]);
  });
});
