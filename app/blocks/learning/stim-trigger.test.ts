import { beforeAll, describe, expect, test } from "vitest";
import {
  createCatalog,
  Frame,
  loadPipeline,
  Runtime,
  vectorShape,
  VirtualClock,
} from "../../engine";
import { BlockHarness, noResources, runVirtualPipeline } from "../../engine/testing";
import { initDspForTests } from "../../../tests/support/wasm";
import { BufferBlock } from "../flow/buffer";
import { Selector } from "../flow/selector";
import { ScheduledTimer } from "../timing/scheduled-timer";
import { Stimulus } from "./stimulus";
import { StimTrigger } from "./stim-trigger";

beforeAll(() => initDspForTests());

const catalog = createCatalog([ScheduledTimer, Stimulus, StimTrigger, BufferBlock, Selector]);

describe("StimTrigger", () => {
  test("forwards start and stop events, and says whether a capture is in progress", async () => {
    const h = await BlockHarness.create(StimTrigger, {}, { inputs: [{ shape: vectorShape(2) }] });
    expect(h.text).toBe("waiting for a capture");
    h.push(
      Frame.from(
        vectorShape(2),
        [1, 2],
        [
          [1, 0],
          [NaN, NaN],
        ],
      ),
    );
    expect(h.output("target").v).toEqual([
      [1, 0],
      [NaN, NaN],
    ]);
    expect(h.text).toBe("idle (1 capture)");
    h.push(Frame.from(vectorShape(2), [3], [[0, 1]]));
    expect(h.text).toBe("capturing [0, 1]");
  });

  test("a Stimulus's capture phases drive a Buffer (MOSAIC's cfg6 wiring, with the trigger port)", async () => {
    const yaml = `
timer: { Type: ScheduledTimer, DesiredRate: 10 }
stim: { Type: Stimulus, Inputs: [ -timer ], Params: { Tasks: [ { Label: a, Target: [1, 0] }, { Label: b, Target: [0, 1] } ], Rest: 0.5, Rise: 0.2, Hold: 0.3, Capture: 1, Fall: 0.2, Autostart: true } }
trig: { Type: StimTrigger, Inputs: [ stim.trigger ] }
shown: { Type: Selector, Inputs: [ stim ] }
store: { Type: Buffer, Inputs: [ trig, -shown ] }
`;
    const run = await runVirtualPipeline(yaml, { catalog, duration: 6, start: 100 });
    const t = run.outputs.get("trig")!;
    expect(t.v).toEqual([
      [1, 0],
      [NaN, NaN],
      [0, 1],
      [NaN, NaN],
    ]);
    // Captures start 1 s into each 2.2 s cue and last 1 s.
    expect(t.t.map((x) => Math.round((x - 100) * 10) / 10)).toEqual([1, 2, 3.2, 4.2]);
    // (a `-Data` input is subscribed by the start event, so the capture's first tick, delivered
    // in the same step, is not recorded: 9 of its 10 ticks)
    expect(run.runtime.invoke("store", "inspect")).toMatch(
      /2 clusters, 18 rows — \[1, 0\]: 1 cluster, 9 rows; \[0, 1\]: 1 cluster, 9 rows/,
    );
  });

  test("wired to the Stimulus's default output (MOSAIC's files): its capture phases, read by name", async () => {
    const yaml = `
timer: { Type: ScheduledTimer, DesiredRate: 10 }
stim: { Type: Stimulus, Inputs: [ -timer ], Params: { Tasks: [ { Label: a, Target: [1, 0] }, { Label: b, Target: [0, 1] } ], Rest: 0.5, Rise: 0.2, Hold: 0.3, Capture: 1, Fall: 0.2, Autostart: true } }
trig: { Type: StimTrigger, Inputs: [ stim ] }
direct: { Type: StimTrigger, Inputs: [ stim.trigger ] }
`;
    const run = await runVirtualPipeline(yaml, { catalog, duration: 6, start: 100 });
    const a = run.outputs.get("trig")!;
    const b = run.outputs.get("direct")!;
    expect(a.v).toEqual([
      [1, 0],
      [NaN, NaN],
      [0, 1],
      [NaN, NaN],
    ]);
    expect(a.t).toEqual(b.t);
    const phase = loadPipeline(
      `timer: { Type: ScheduledTimer, DesiredRate: 10 }
stim: { Type: Stimulus, Inputs: [ -timer ], Params: [ 3.0, 1;0, 0;1 ] }
trig: { Type: StimTrigger, Inputs: [ stim.phase ] }
`,
      "p.yaml",
      catalog,
    );
    const created = await Runtime.create({
      spec: phase.spec!,
      catalog,
      clock: new VirtualClock(0),
      virtual: true,
      resources: noResources,
    });
    expect(created.diagnostics.map((d) => d.message)).toEqual([
      expect.stringMatching(
        /the Stimulus's 'phase' output; write Inputs: \[stim\] or \[stim\.trigger\]/,
      ),
    ]);
  });
});
