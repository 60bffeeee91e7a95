/**
 * The stage's mechanics with stand-in blocks (the engine cannot see the real catalog); the table
 * with the real blocks is tested in app/blocks/devices/simulated-devices.test.ts.
 */
import { describe, expect, test } from "vitest";
import { z } from "zod";
import { defineBlock, type AnyBlockDefinition } from "../block";
import { createCatalog } from "../catalog";
import { EMPTY_SHAPE, vectorShape } from "../frame";
import { TEST_BLOCKS } from "../test-blocks";
import { loadPipeline } from "./loader";
import { simulateDevices, withSimulatedDevices } from "./simulate";

const stub = (
  type: string,
  params: z.ZodType,
  outputs: string[],
  inputs = { min: 0, max: 1 },
  timer = false,
): AnyBlockDefinition =>
  defineBlock({
    type,
    category: "Testing",
    summary: type,
    help: type,
    params,
    inputs,
    outputs,
    timer,
    create(ctx) {
      for (const o of outputs) ctx.output(timer ? EMPTY_SHAPE : vectorShape(1), o);
      return {};
    },
  });

const catalog = createCatalog([
  ...TEST_BLOCKS,
  stub("ScheduledTimer", z.strictObject({}), ["out"], { min: 0, max: 0 }, true),
  stub("Myo", z.strictObject({ Address: z.string().optional() }), ["emg", "imu"]),
  stub("EmgSimulator", z.looseObject({}), ["emg", "gesture"], { min: 1, max: 9 }),
  stub("ImuSimulator", z.looseObject({}), ["imu"], { min: 1, max: 1 }),
  stub("BlenderArm", z.strictObject({ Host: z.string(), Port: z.number() }), [], {
    min: 1,
    max: 1,
  }),
  stub("SimulatedOutput", z.looseObject({}), [], { min: 1, max: 9 }),
]);

const load = (yaml: string) => {
  const r = loadPipeline(yaml, "p.yaml", catalog);
  if (!r.spec) throw new Error(r.diagnostics.map((d) => d.message).join("\n"));
  return r;
};

describe("simulateDevices", () => {
  const yaml = [
    "t: { Type: Tick, DesiredRate: 100 }",
    "arm: { Type: Myo, Inputs: [t] }",
    "arm_imu: { Type: Counter, Inputs: [t] }",
    "g: { Type: Gain, Inputs: [arm], Params: { Gain: 2 } }",
    "i: { Type: Gain, Inputs: [arm.imu], Params: { Gain: 2 } }",
    "out: { Type: BlenderArm, Inputs: [g], Params: { Host: localhost, Port: 3334 } }",
  ].join("\n");

  test("devices become their simulators; inputs follow the ports; names stay unique", () => {
    const r = simulateDevices(load(yaml).spec!, catalog);
    expect(r.spec.blocks.map((b) => `${b.name}:${b.type}`)).toEqual([
      "t:Tick",
      "arm_imu_clock:ScheduledTimer",
      "arm:EmgSimulator",
      "arm_imu2:ImuSimulator",
      "arm_imu:Counter",
      "g:Gain",
      "i:Gain",
      "out:SimulatedOutput",
    ]);
    const by = r.spec.byName;
    expect(by.get("g")!.inputs[0]).toMatchObject({ source: "arm", block: "arm", port: "emg" });
    expect(by.get("i")!.inputs[0]).toMatchObject({
      source: "arm_imu2",
      block: "arm_imu2",
      port: "imu",
    });
    expect(by.get("arm_imu2")!.inputs[0]).toMatchObject({ block: "arm_imu_clock", port: "out" });
    expect(by.get("out")!.params).toEqual({
      Device: "BlenderArm",
      Destination: "localhost:3334",
      Unit: "datagram",
      Count: "events",
    });
    expect(r.substituted).toEqual(["arm", "out"]);
    expect(r.diagnostics.map((d) => [d.severity, d.block, d.line])).toEqual([
      ["info", "arm", 2],
      ["info", "out", 6],
    ]);
  });

  test("the block in a device's place keeps its name, position and Path", () => {
    const r = simulateDevices(
      load(yaml.replace("{ Type: Myo, Inputs: [t] }", "{ Type: Myo, Inputs: [t], Path: rec }"))
        .spec!,
      catalog,
    );
    expect(r.spec.byName.get("arm")).toMatchObject({ path: "rec", pos: { line: 2, col: 1 } });
  });

  test("keepNetwork leaves network outputs; undefined options leave the result as it is", () => {
    const loaded = load(yaml);
    expect(withSimulatedDevices(loaded, catalog, undefined)).toBe(loaded);
    const r = withSimulatedDevices(loaded, catalog, { keepNetwork: true });
    expect(r.spec!.byName.get("out")!.type).toBe("BlenderArm");
    expect(r.spec!.byName.get("arm")!.type).toBe("EmgSimulator");
    expect(r.diagnostics.at(-1)).toMatchObject({ severity: "info", code: "simulated-device" });
  });
});
