/**
 * nativeStreamSource with a fake link: the samples of each chunk go out as one frame on the
 * device's clock, the status counts them, a link that leaves streaming drops what it held, and a
 * host without TCP is said.
 */
import { describe, expect, test } from "vitest";
import { z } from "zod";
import { defineBlock, type BlockContext } from "../../engine";
import { BlockHarness } from "../../engine/testing";
import { nativeStreamSource, noTcpMessage, type LinkEvents } from "./stream-link";

/** A block around nativeStreamSource whose link is driven by the test through `link.ev`. */
function streamBlock(available: boolean) {
  const link: { ev?: LinkEvents; opens: number; closes: number } = { opens: 0, closes: 0 };
  const def = defineBlock({
    type: "StreamTest",
    category: "Devices",
    summary: "test",
    help: "test",
    params: z.strictObject({}),
    inputs: { min: 0, max: 0 },
    outputs: ["emg"],
    create: (ctx: BlockContext) =>
      nativeStreamSource(ctx, {
        rate: 100,
        maxLead: 0.1,
        channels: 2,
        target: "the device at here",
        available: () => available,
        open(_ctx, ev) {
          link.ev = ev;
          link.opens++;
          return { close: () => link.closes++ };
        },
        convert(raw, out, at) {
          out[at] = raw[0]!;
          out[at + 1] = raw[1]! * 2;
        },
      }),
  });
  return { def, link };
}

describe("nativeStreamSource", () => {
  test("each chunk's samples go out as one frame; the status counts them", async () => {
    const { def, link } = streamBlock(true);
    const h = await BlockHarness.create(def, {}, { now: 10 });
    expect(h.text).toBe("stopped");
    h.start();
    expect(link.opens).toBe(1);
    const ev = link.ev!;
    ev.state("streaming", "streaming 2 channels");
    expect(h.text).toBe("streaming 2 channels");
    // More samples than the first batch holds (64): it grows.
    for (let i = 0; i < 70; i++) ev.samples(Int16Array.of(i, -i));
    ev.chunkEnd!();
    const out = h.output("emg");
    expect(out.frames).toEqual([70]);
    expect(out.v[0]).toEqual([0, 0]);
    expect(out.v[69]).toEqual([69, -138]);
    expect(out.t[69]).toBeCloseTo(10);
    expect(out.t[68]).toBeCloseTo(9.99);
    expect(h.text).toBe("streaming 2 channels · 70 samples");
    // An empty chunk emits nothing.
    ev.chunkEnd!();
    expect(out.frames).toEqual([70]);
    // Samples held when the link leaves streaming are dropped.
    ev.samples(Int16Array.of(1, 1));
    ev.state("lost", "lost the device");
    ev.chunkEnd!();
    expect(out.frames).toEqual([70]);
    expect(h.text).toBe("lost the device · 70 samples");
    ev.warn("a warning");
    expect(h.warnings).toEqual(["a warning"]);
    h.instance.reset?.();
    expect(h.text).toBe("lost the device");
    h.instance.stop?.();
    expect(link.closes).toBe(1);
    expect(h.text).toBe("stopped");
    h.instance.dispose?.();
    expect(link.closes).toBe(1);
  });

  test("without TCP: said in the status and once as a warning, no link", async () => {
    const { def, link } = streamBlock(false);
    const h = await BlockHarness.create(def, {});
    h.start();
    expect(link.opens).toBe(0);
    expect(h.text).toBe("TCP not available in the browser build; use --simulate-devices");
    expect(h.warnings).toEqual([noTcpMessage("the device at here")]);
    h.instance.stop?.();
    expect(h.text).toBe("stopped");
  });
});
