import { describe, expect, test } from "vitest";
import { parseBenchOptions } from "./bench-options";
import type { ChildRun } from "./bench-proc";
import { MEMORY_SETTLE_S, rssFigures, senderCounts, soakFigures, soakMarkdown } from "./bench-soak";
import type { PipelineResult } from "./bench-types";
import { WORKLOADS, type SoakDef } from "./bench-workloads";

const def = WORKLOADS.find((w): w is SoakDef => w.kind === "soak")!;

/** A run with these steady RSS samples (MiB), the Sender's text and the datagrams received. */
function fake(rss: number[], text: string, received: number, errors = 0, exitCode = 0) {
  const child = {
    samples: rss.map((m, i) => ({
      t: i,
      dt: 1,
      ticksPct: 1,
      nsPct: 1,
      rssKiB: m * 1024,
      childrenPct: 0,
      childrenRssKiB: 0,
      steady: true,
    })),
    summary: {
      exitCode,
      blocks: [
        { name: "Sender", type: "UdpSender", text, errors: 0, lastError: "" },
        { name: "DL", type: "Python", text: "", errors, lastError: errors ? "boom" : "" },
      ],
    },
    eventsByLevel: errors ? { error: 1 } : {},
    exitCode,
  } as unknown as ChildRun;
  const run = {
    udp: { datagramsAll: received, malformed: 0 },
    timers: [{ missed: 0 }],
    dropsAllTime: 0,
    killedAfterSummary: false,
    cpu: null,
    acquisitionOnTimePct: 100,
  } as unknown as PipelineResult;
  return soakFigures(def, { warmup: 25, steady: 60 }, run, child, [0, 0, 0]);
}

describe("soak", () => {
  test("is not in the default suite, only with --only soak; --duration overrides its length", () => {
    const all = parseBenchOptions([]);
    expect("selected" in all && all.selected.some((w) => w.id === "soak")).toBe(false);
    const only = parseBenchOptions(["--only", "soak", "--duration", "120"]);
    expect("selected" in only && only.selected.map((w) => w.id)).toEqual(["soak"]);
    expect("durationGiven" in only && only.durationGiven).toBe(true);
    expect(def.steadySeconds).toBe(1800);
  });

  test("the Sender's counts from its status", () => {
    expect(
      senderCounts("→ 127.0.0.1:50521 (control serializer, f64, category 1): 1,234 datagrams sent"),
    ).toEqual({ sent: 1234, notSent: 0, reason: "" });
    expect(
      senderCounts(
        "→ x:1 (raw f64): 1 datagram sent, 2,000 not sent (cannot resolve host 'x' (ENOTFOUND): check it)",
      ),
    ).toEqual({ sent: 1, notSent: 2000, reason: "cannot resolve host 'x' (ENOTFOUND): check it" });
    expect(senderCounts("UDP is unavailable here")).toBeNull();
  });

  test("passes when memory is flat, every datagram is accounted for and no error", () => {
    const r = fake(
      [80, 81, 80.5, 82],
      "→ a:1 (vector serializer, f64, category 0): 100 datagrams sent",
      100,
    );
    expect(r.pass).toBe(true);
    expect(r.rss).toMatchObject({
      startMiB: 80,
      endMiB: 82,
      maxMiB: 82,
      settleSamples: 1,
      settleGrowthPct: 1.25,
      driftPct: 1.23,
      flat: true,
    });
    expect(r.udp.uncounted).toBe(0);
    expect(soakMarkdown(r).join("\n")).toMatch(/\*\*Soak passed\.\*\*/);
  });

  test("memory that grows while V8 sizes its heaps, then stays, is flat; memory that keeps growing is not", () => {
    // The shape of the 30-minute soak of 2026-11-24: +8 % over the first 7 minutes, flat after.
    const settling = Array.from({ length: 1800 }, (_, i) => (i < 420 ? 81 + (i / 420) * 7 : 88));
    const ok = rssFigures(settling, 5);
    expect(ok).toMatchObject({ settleSamples: MEMORY_SETTLE_S, firstMedianMiB: 88, flat: true });
    expect(ok.settleGrowthPct).toBeCloseTo(8.64, 2);
    // A leak of 8 % over the run: 4.9 % over the 20 minutes after settling, 7.8 % at that slope
    // over the 30.
    const leak = Array.from({ length: 1800 }, (_, i) => 81 * (1 + (0.08 * i) / 1800));
    expect(rssFigures(leak, 5)).toMatchObject({ flat: false });
    expect(rssFigures(leak, 5).runDriftPct).toBeCloseTo(7.74, 1);
    // A shorter run settles for a third of it.
    expect(rssFigures([80, 81, 82, 82, 82, 82], 5)).toMatchObject({ settleSamples: 2, flat: true });
  });

  test("fails on memory growth, datagrams that vanished, and block errors (named)", () => {
    const r = fake(
      [80, 85, 90],
      "→ a:1 (vector serializer, f64, category 0): 100 datagrams sent, 3 not sent (nothing is listening)",
      97,
      2,
      1,
    );
    expect(r.pass).toBe(false);
    expect(r.failures).toEqual([
      "VmRSS moved beyond ±5 % over the run: median 85 MiB over the first 1 s after 1 s of settling, 90 over the last (5.88 %, 17.65 % at that slope over the whole run)",
      "3 datagrams the Sender counts as sent did not arrive",
      "2 block errors (DL)",
    ]);
    expect(r.errors.consistent).toBe(true);
    expect(soakMarkdown(r).join("\n")).toMatch(/\*\*NOT FLAT\*\*/);
  });
});
