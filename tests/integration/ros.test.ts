/**
 * The ROS block through the real CLI (`mosaic run --json`, engine workers, the Node ROS bridge on
 * roslib + ws) against the rosbridge v2 test server (tests/support/rosbridge-server.ts; no ROS is
 * installed here): a sine published to one topic arrives at the server value for value, messages
 * the server publishes on another topic arrive in the block's log exactly, a message of the wrong
 * length is counted in the status; then the server is killed (every client dropped, no close
 * frame) and restarted on the same port: both blocks report the loss, count down to attempts
 * spaced by a doubling backoff, reconnect by themselves, and traffic resumes both ways.
 */
import { existsSync, readFileSync, writeFileSync } from "node:fs";
import { join } from "node:path";
import type { ChildProcess } from "node:child_process";
import { afterEach, describe, expect, test } from "vitest";
import { RosbridgeTestServer } from "../support/rosbridge-server";
import { jsonLines, requireBuild, startCli, tempDir } from "./helpers";

const cleanup: (() => unknown)[] = [];
afterEach(async () => {
  for (const c of cleanup.splice(0).reverse()) await c();
});

const sleep = (ms: number): Promise<void> => new Promise((r) => setTimeout(r, ms));

async function waitFor(cond: () => boolean, ms: number, what: string): Promise<void> {
  const end = Date.now() + ms;
  while (!cond()) {
    if (Date.now() > end) throw new Error(`timed out waiting for ${what}`);
    await sleep(20);
  }
}

/** A `Path` log: the values of each line (the timestamp left out). */
function readLog(file: string): number[][] {
  if (!existsSync(file)) return [];
  return readFileSync(file, "utf8")
    .split("\n")
    .filter((l) => l !== "")
    .map((l) => l.split(",").slice(1).map(Number));
}

interface Telemetry {
  blocks: { name: string; text: string }[];
}

/** What the server feeds to /mosaic/in, message k. */
const fed = (k: number): number[] => [k, Math.sin(k) / 3];

const multiArray = (data: number[]) => ({
  layout: { dim: [{ label: "values", size: data.length, stride: data.length }], data_offset: 0 },
  data,
});

describe("ROS block with a rosbridge v2 server", () => {
  requireBuild();

  test("exact values both ways; the server killed and restarted: backoff, reconnect, traffic resumes", async () => {
    const server = await RosbridgeTestServer.start();
    cleanup.push(() => server.stop());
    const url = server.url;
    const dir = tempDir("mosaic-ros-");
    const logs = join(dir, "logs");
    const file = join(dir, "ros.yaml");
    writeFileSync(
      file,
      `Timer: { Type: ScheduledTimer, DesiredRate: 50 }
Sine:
  Type: SinGenerator
  Inputs: [Timer]
  Params: { Components: 3, Amplitude: 2, Frequency: 0.7 }
  Path: ${logs}
ToRos:
  Type: ROS
  Inputs: [Sine]
  Params: { Url: "${url}", Topic: /mosaic/out, ReconnectSeconds: 0.2, ReconnectMaxSeconds: 1 }
FromRos:
  Type: ROS
  Params:
    Url: "${url}"
    Topic: /mosaic/in
    Direction: subscribe
    Channels: 2
    ReconnectSeconds: 0.2
    ReconnectMaxSeconds: 1
  Path: ${logs}
`,
    );
    const run: ChildProcess = startCli(["run", file, "--json", "--duration", "40"]);
    cleanup.push(() => run.kill("SIGKILL"));
    let out = "";
    run.stdout!.on("data", (d: Buffer) => (out += d.toString()));
    run.stderr!.on("data", (d: Buffer) => (out += d.toString()));
    const texts = (block: string): string[] =>
      jsonLines(out)
        .filter((m) => m.type === "telemetry")
        .map((m) => (m as unknown as Telemetry).blocks.find((b) => b.name === block)?.text ?? "");
    const fromLog = join(logs, "FromRos.txt");
    const published = (): number[][] =>
      server.published("/mosaic/out").map((m) => (m as { data: number[] }).data);

    // Connected: the sine flows out, the server's messages flow in (one of the wrong length).
    await waitFor(
      () => server.subscribers("/mosaic/in") === 1 && published().length >= 25,
      10_000,
      "the subscription and 25 published messages",
    );
    expect(server.typeOf("/mosaic/out")).toBe("std_msgs/Float64MultiArray");
    expect(server.typeOf("/mosaic/in")).toBe("std_msgs/Float64MultiArray");
    for (let k = 0; k < 30; k++) {
      server.publish("/mosaic/in", multiArray(fed(k)));
      if (k === 10) server.publish("/mosaic/in", multiArray([1, 2, 3]));
      await sleep(4);
    }
    await waitFor(() => readLog(fromLog).length >= 30, 5000, "30 received messages in the log");
    await waitFor(
      () => texts("FromRos").some((t) => /1 malformed \(last: 3 values, expected 2\)/.test(t)),
      3000,
      "the malformed count",
    );

    // The server dies: both blocks say so and retry with a doubling wait.
    await server.stop();
    const killedAt = Date.now();
    for (const block of ["ToRos", "FromRos"]) {
      await waitFor(
        () =>
          texts(block).some((t) =>
            t.startsWith(
              `disconnected from ${url}: connection lost: the connection was closed, code 1006`,
            ),
          ),
        5000,
        `${block} reporting the loss`,
      );
    }
    await waitFor(
      () => texts("ToRos").some((t) => /ECONNREFUSED.*reconnecting in .* \(attempt 4\)/.test(t)),
      5000,
      "three failed attempts",
    );
    const down = texts("ToRos").filter((t) => t.startsWith("disconnected"));
    const refused = down.find((t) => /ECONNREFUSED/.test(t))!;
    expect(refused).toMatch(
      /nothing is listening at 127\.0\.0\.1:\d+ \(ECONNREFUSED\): start rosbridge/,
    );
    // The wait doubles: 0.2 s before attempt 2, 0.4 s before 3, 0.8 s before 4.
    const waitBefore = (attempt: number): string | undefined =>
      /reconnecting in ([\d.]+ s)/.exec(
        down.find((t) => t.includes(`(attempt ${attempt})`)) ?? "",
      )?.[1];
    // (The 0.2 s one may fall between two telemetry samples on a loaded machine.)
    expect([undefined, "0.2 s"]).toContain(waitBefore(2));
    expect([3, 4].map(waitBefore)).toEqual(["0.4 s", "0.8 s"]);
    const publishedBefore = published().length;

    // Back on the same port: both reconnect by themselves and traffic resumes.
    await server.start();
    const restartedAt = Date.now();
    await waitFor(
      () => server.subscribers("/mosaic/in") === 1 && published().length >= publishedBefore + 25,
      10_000,
      "the resubscription and 25 more published messages",
    );
    for (let k = 1000; k < 1020; k++) {
      server.publish("/mosaic/in", multiArray(fed(k)));
      await sleep(4);
    }
    await waitFor(() => readLog(fromLog).length >= 50, 5000, "20 more received messages");
    await waitFor(
      () =>
        /^connected to .* · 1 reconnect · \d+ dropped while disconnected/.test(
          texts("ToRos").at(-1)!,
        ),
      3000,
      "ToRos connected again, counting the drops",
    );
    run.kill("SIGINT");
    await new Promise((r) => run.on("exit", r));

    // In: exactly what the server sent, in order; the wrong-length message is not among them.
    const want = [...Array.from({ length: 30 }, (_, k) => fed(k))];
    for (let k = 1000; k < 1020; k++) want.push(fed(k));
    expect(readLog(fromLog)).toEqual(want);

    // Out: two unbroken runs of the logged sine (before the kill, after the restart), exact.
    const sine = readLog(join(logs, "Sine.txt"));
    const key = (v: number[]): string => v.join(",");
    const rowOf = new Map(sine.map((v, i) => [key(v), i]));
    const msgs = server.messages.filter((m) => m.topic === "/mosaic/out");
    const before = msgs.filter((m) => m.at < killedAt);
    const after = msgs.filter((m) => m.at >= restartedAt);
    expect(before.length + after.length).toBe(msgs.length);
    for (const part of [before, after]) {
      const rows = part.map((m) => rowOf.get(key((m.msg as { data: number[] }).data)));
      expect(rows.every((r) => r !== undefined)).toBe(true);
      const first = rows[0]!;
      expect(rows).toEqual(rows.map((_, i) => first + i));
    }
    const gap =
      rowOf.get(key((after[0]!.msg as { data: number[] }).data))! -
      rowOf.get(key((before.at(-1)!.msg as { data: number[] }).data))!;
    // The events of the 1.4 s and more the server was down were dropped, not queued and sent late.
    expect(gap).toBeGreaterThan(10);
    expect((msgs[0]!.msg as { layout: unknown }).layout).toEqual({
      dim: [{ label: "values", size: 3, stride: 3 }],
      data_offset: 0,
    });
    // Each connection advertised once; no publish was refused by the server.
    expect(server.ops.filter((o) => o.op === "advertise")).toHaveLength(2);
    expect(server.ops.filter((o) => o.op === "subscribe")).toHaveLength(2);
    expect(server.statuses).toEqual([]);
    console.log(
      `ros: ${msgs.length} published (gap ${gap} events), ${readLog(fromLog).length} received; ` +
        `"${refused}"`,
    );
  }, 60_000);
});
