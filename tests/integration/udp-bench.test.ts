/**
 * The UDP latency benchmark (app/cli/bench-udp.ts) runs end to end on loopback through the real
 * host. A smoke test only: figures are printed by the benchmark, never asserted here (DESIGN.md §5).
 */
import { expect, test } from "vitest";
import { measureUdpLatency, udpLatencyLine } from "../../app/cli/bench-udp";
import { requireBuild } from "./helpers";

test("measureUdpLatency times every datagram through Rx → Abs → Tx", async () => {
  requireBuild();
  const r = await measureUdpLatency({ samples: 200, rate: 200, warmup: 0.2, timerHz: 100 });
  expect(r.samples).toBe(200);
  expect(r.received + r.lost).toBe(200);
  expect(r.received).toBeGreaterThan(190);
  for (const x of [r.p50Ms, r.p99Ms, r.inP50Ms, r.outP50Ms]) expect(Number.isFinite(x)).toBe(true);
  expect(r.p50Ms).toBeGreaterThan(0);
  expect(r.p50Ms).toBeLessThanOrEqual(r.p99Ms);
  expect(udpLatencyLine(r)).toMatch(/^UDP in → pipeline → UDP out \(8 ch f64 @ 200 Hz/);
}, 60_000);
