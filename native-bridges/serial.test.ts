/**
 * The Node serial bridge on a real pty pair (socat): open, data both ways, unplug reported,
 * reopened when the device is back, a path that does not exist reported and retried, close stops
 * retrying.
 */
import { spawn, spawnSync, type ChildProcess } from "node:child_process";
import { closeSync, existsSync, mkdtempSync, openSync, readSync, writeSync } from "node:fs";
import { tmpdir } from "node:os";
import { join } from "node:path";
import { afterEach, describe, expect, test } from "vitest";
import type { SerialStatus } from "../app/engine/io";
import { createSerialBridge } from "./serial";

const haveSocat = spawnSync("socat", ["-V"]).status === 0;
const children: ChildProcess[] = [];
afterEach(() => {
  for (const c of children.splice(0)) c.kill("SIGKILL");
});

const sleep = (ms: number) => new Promise((r) => setTimeout(r, ms));
async function waitFor(cond: () => boolean, ms: number, what: string): Promise<void> {
  const end = Date.now() + ms;
  while (!cond()) {
    if (Date.now() > end) throw new Error(`timed out waiting for ${what}`);
    await sleep(20);
  }
}

async function ptyPair(dir: string): Promise<ChildProcess> {
  const p = spawn("socat", [
    `pty,raw,echo=0,link=${join(dir, "dev")}`,
    `pty,raw,echo=0,link=${join(dir, "peer")}`,
  ]);
  children.push(p);
  await waitFor(() => existsSync(join(dir, "dev")) && existsSync(join(dir, "peer")), 5000, "socat");
  return p;
}

const options = (path: string) => ({
  path,
  baudRate: 115200,
  dataBits: 8 as const,
  stopBits: 1 as const,
  parity: "none" as const,
});

describe.skipIf(!haveSocat)("native serial bridge (serialport on a socat pty pair)", () => {
  test("data both ways, unplug reported, reopened when the device is back", async () => {
    const dir = mkdtempSync(join(tmpdir(), "mosaic-serial-"));
    let socat = await ptyPair(dir);
    const statuses: string[] = [];
    let received = "";
    const handle = createSerialBridge().open({
      ...options(join(dir, "dev")),
      reconnectMs: 200,
      onData: (d) => (received += String.fromCharCode(...d)),
      onStatus: (s: SerialStatus, m?: string) => statuses.push(m ? `${s}: ${m}` : s),
    });
    await waitFor(() => statuses.includes("open"), 5000, "open");
    expect(statuses.slice(0, 2)).toEqual(["opening", "open"]);

    let peer = openSync(join(dir, "peer"), "r+");
    writeSync(peer, "1,2,3\n");
    await waitFor(() => received === "1,2,3\n", 3000, "data from the device");
    handle.write(Uint8Array.from("hello\n", (c) => c.charCodeAt(0)));
    const buf = Buffer.alloc(64);
    await waitFor(
      () => {
        try {
          return readSync(peer, buf, 0, 64, null) > 0;
        } catch {
          return false;
        }
      },
      3000,
      "data to the device",
    );
    expect(buf.toString("latin1")).toMatch(/^hello\n/);
    closeSync(peer);

    // Unplug: the pty pair disappears.
    socat.kill("SIGTERM");
    await waitFor(
      () => statuses.some((s) => s.startsWith("error: disconnected")),
      5000,
      "the unplug",
    );
    expect(statuses.find((s) => s.startsWith("error: disconnected"))).toBe(
      "error: disconnected (unplugged?); retrying every 0.2 s",
    );
    // While it is away, the reopen attempts fail with a clear reason.
    await waitFor(
      () => statuses.some((s) => s.startsWith("error: no such device")),
      3000,
      "retries",
    );

    // Back: the bridge reopens the same path and data flows again.
    socat = await ptyPair(dir);
    const opens = statuses.filter((s) => s === "open").length;
    await waitFor(() => statuses.filter((s) => s === "open").length > opens, 5000, "the reopen");
    peer = openSync(join(dir, "peer"), "r+");
    writeSync(peer, "4,5,6\n");
    await waitFor(() => received.endsWith("4,5,6\n"), 3000, "data after the reopen");
    closeSync(peer);

    handle.close();
    expect(statuses.at(-1)).toBe("closed");
    const n = statuses.length;
    await sleep(500);
    expect(statuses.length).toBe(n);
  }, 30_000);

  test("a path that does not exist is reported and, with reconnect 0, not retried", async () => {
    const statuses: string[] = [];
    const handle = createSerialBridge().open({
      ...options("/dev/does-not-exist-mosaic"),
      reconnectMs: 0,
      onData: () => {},
      onStatus: (s, m) => statuses.push(m ? `${s}: ${m}` : s),
    });
    await waitFor(() => statuses.length >= 2, 3000, "the failure");
    await sleep(300);
    expect(statuses).toEqual(["opening", "error: no such device (unplugged?)"]);
    handle.close();
  });
});
