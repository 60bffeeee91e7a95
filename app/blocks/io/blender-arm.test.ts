import { describe, expect, test } from "vitest";
import { createCatalog, Frame, loadPipeline, vectorShape, type IoBridges } from "../../engine";
import { BlockHarness } from "../../engine/testing";
import { BlenderArm } from "./blender-arm";
import { blenderCommand, blenderText } from "./blender-format";

/** A UDP bridge that keeps every datagram sent (as text) and where it went. */
function fakeUdp() {
  const sent: string[] = [];
  const opened: unknown[] = [];
  const io: IoBridges = {
    udp: {
      open: (o) => {
        opened.push(o.remote);
        return { send: (d) => sent.push(new TextDecoder().decode(d)), close: () => {} };
      },
    },
  };
  return { io, sent, opened };
}

const frame = (rows: number[][], t0 = 1) =>
  Frame.from(
    vectorShape(rows[0]!.length),
    rows.map((_, i) => t0 + i * 0.04),
    rows,
  );

async function arm(width: number, params: Record<string, unknown> = {}) {
  const udp = fakeUdp();
  const h = await BlockHarness.create(
    BlenderArm,
    { Port: 3334, ...params },
    {
      inputs: [{ shape: vectorShape(width), rate: 25, type: "ControlAlgorithm" }],
      io: udp.io,
    },
  );
  h.start();
  return { h, udp };
}

describe("BlenderArm", () => {
  test("an actuation vector (a ControlAlgorithm's MOSAIC output) becomes the nine-value text", async () => {
    const { h, udp } = await arm(11);
    // ThumbFlexion … Little, WristFlexionExtension, WristUlnarRadialDeviation,
    // WristPronationSupination, ElbowFlexion, ElbowExtension.
    h.push(frame([[100, 50, 0, 25, 75, 10, 100, 0, 50, 30, 0]]));
    expect(udp.opened).toEqual([{ host: "127.0.0.1", port: 3334 }]);
    expect(udp.sent).toEqual(["[1,0.5,0,0.25,0.75,0.1,1,-1,0]"]);
    expect(h.output("command").v).toEqual([[1, 0.5, 0, 0.25, 0.75, 0.1, 1, -1, 0]]);
    expect(h.text).toMatch(/→ 127\.0\.0\.1:3334, actuation vector .* 1 datagram sent/);
  });

  test("the rest pose: open hand, wrist neutral (all zeros)", async () => {
    const { h, udp } = await arm(11);
    h.push(frame([[0, 0, 0, 0, 0, 0, 50, 50, 50, 0, 0]]));
    expect(udp.sent).toEqual(["[0,0,0,0,0,0,0,0,0]"]);
  });

  test("a plain 12-prediction vector is mapped as MOSAIC's DirectControl, one datagram per event", async () => {
    const { h, udp } = await arm(12);
    h.push(
      frame([
        // power grasp: six fingers closed
        [1, 1, 1, 1, 1, 1, 0, 0, 0, 0, 0, 0],
        // wrist flexion 0.5, pronation 1, radial 0.25; predictions beyond [0, 1] are clipped
        [-0.5, 1.5, 0, 0, 0, 0, 0.5, 0, 1, 0, 0, 0.25],
      ]),
    );
    expect(udp.sent).toEqual(["[1,1,1,1,1,1,0,0,0]", "[0,1,0,0,0,0,-0.5,-0.25,-1]"]);
    expect(h.output("command").t).toEqual([1, 1.04]);
  });

  test("a 9-value input is sent as it is; other widths are refused with what is expected", async () => {
    const { h, udp } = await arm(9);
    h.push(frame([[0.1, 0.2, 0.3, 0.4, 0.5, 0.6, -1, 0, 1]]));
    expect(udp.sent).toEqual(["[0.1,0.2,0.3,0.4,0.5,0.6,-1,0,1]"]);
    await expect(arm(5)).rejects.toThrow(/has shape \[1, 5\]; BlenderArm takes an actuation/);
    await expect(arm(12, { Input: "actuation" })).rejects.toThrow(/actuation vector has 11/);
    await expect(arm(11, { Input: "command" })).rejects.toThrow(/a command has 9/);
  });

  test("without UDP (the browser build) it says so and still outputs the command", async () => {
    const h = await BlockHarness.create(
      BlenderArm,
      { Port: 3333 },
      { inputs: [{ shape: vectorShape(11), rate: 25 }] },
    );
    h.start();
    h.push(frame([[0, 0, 0, 0, 0, 0, 50, 50, 50, 0, 0]]));
    expect(h.warnings[0]).toMatch(/UDP is unavailable/);
    expect(h.output("command").v).toHaveLength(1);
  });

  test("format helpers: pronation/supination sign, shortest numbers", () => {
    const out = new Float64Array(9);
    blenderCommand([0, 0, 0, 0, 0, 0, 0, 100, 100, 0, 0], out);
    expect(Array.from(out.subarray(6))).toEqual([-1, 1, -1]);
    expect(blenderText([1 / 3, -0, 0.1 + 0.2, 1e-7, 0, 0, 0, 0, 0])).toBe(
      "[0.3333333333333333,0,0.30000000000000004,1e-7,0,0,0,0,0]",
    );
  });

  test("MOSAIC's [host, port] loads; anything else says what it takes", () => {
    const catalog = createCatalog([BlenderArm]);
    const ok = loadPipeline(
      "A: { Type: BlenderArm, Inputs: [A], Params: [ localhost, 3334 ] }\n",
      "p.yaml",
      catalog,
    );
    expect(ok.spec?.blocks[0]!.params).toEqual({ Host: "localhost", Port: 3334, Input: "auto" });
    const bad = loadPipeline(
      "A: { Type: BlenderArm, Inputs: [A], Params: [ localhost ] }\n",
      "p.yaml",
      catalog,
    );
    expect(bad.diagnostics.find((d) => d.severity === "error")?.message).toMatch(
      /expected \[host, port\]/,
    );
  });
});
