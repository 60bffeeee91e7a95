/**
 * The control-panel form generator (app/ui/forms/schema.ts) on the real block schemas, as the
 * engine sends them (`z.toJSONSchema(def.params, { io: "input", unrepresentable: "any" })`, see
 * app/engine/session.ts). Here rather than next to the form: UI tests may not import blocks.
 *
 * Besides the field kinds, it checks that the form's validator agrees with zod: it never refuses
 * a value the engine would accept, and what it accepts the engine accepts too, except for rules
 * JSON Schema cannot express (refinements), which the engine's reply reports.
 */
import { describe, expect, it } from "vitest";
import { z } from "zod";
import type { AnyBlockDefinition } from "../../app/engine";
import { BLOCKS } from "../../app/blocks/catalog";
import {
  describeParams,
  describeType,
  formatText,
  parseText,
  summarize,
  validate,
  type Field,
  type JsonSchema,
  type ObjectField,
} from "../../app/ui/forms/schema";

const byType = new Map(BLOCKS.map((d) => [d.type, d]));

function schemaOf(type: string): {
  def: AnyBlockDefinition;
  schema: JsonSchema;
  form: ObjectField;
} {
  const def = byType.get(type);
  if (!def) throw new Error(`no block ${type}`);
  const schema = z.toJSONSchema(def.params, { io: "input", unrepresentable: "any" }) as JsonSchema;
  return { def, schema, form: describeParams(schema) };
}

const field = (form: ObjectField, name: string): Field => {
  const f = form.fields.find((x) => x.name === name);
  if (!f) throw new Error(`no field ${name}`);
  return f;
};

describe("every block's params become a form", () => {
  for (const def of BLOCKS) {
    it(def.type, () => {
      const { schema, form } = schemaOf(def.type);
      const props = Object.keys(schema.properties ?? {});
      expect(form.fields.map((f) => f.name)).toEqual(props);
      for (const f of form.fields) {
        expect(describeType(f).length).toBeGreaterThan(0);
        // Defaults are valid values of their own field and survive the editor's text.
        if (f.hasDefault && f.default !== undefined) {
          expect(validate(f.schema, f.default, schema), `${def.type}.${f.name}`).toEqual([]);
          if (
            f.kind !== "object" &&
            f.kind !== "list" &&
            f.kind !== "record" &&
            f.kind !== "boolean" &&
            f.kind !== "enum"
          ) {
            expect(parseText(f, formatText(f, f.default)), `${def.type}.${f.name}`).toEqual({
              ok: true,
              value: f.default,
            });
          }
        }
      }
    });
  }
});

describe("field kinds of the real schemas", () => {
  it("EmgSimulator: integers with bounds, a mapping of gestures, a list of steps, 50|60", () => {
    const { form } = schemaOf("EmgSimulator");
    expect(field(form, "Channels")).toMatchObject({
      kind: "number",
      integer: true,
      min: 1,
      max: 4096,
      default: 8,
    });
    expect(field(form, "Seed")).toMatchObject({ kind: "number", integer: true, min: 0 });
    expect(field(form, "Gesture")).toMatchObject({ kind: "string", minLength: 1, default: "rest" });
    expect(field(form, "Gestures")).toMatchObject({
      kind: "record",
      value: { kind: "numberList", item: { min: 0, max: 1 }, minItems: 1 },
    });
    const seq = field(form, "Sequence");
    expect(seq).toMatchObject({ kind: "list", minItems: 1, item: { kind: "object" } });
    const step = (seq as Extract<Field, { kind: "list" }>).item as ObjectField;
    expect(step.fields.map((f) => [f.name, f.kind, f.required])).toEqual([
      ["Gesture", "string", true],
      ["Seconds", "number", true],
    ]);
    expect(field(form, "HumHz")).toMatchObject({
      kind: "enum",
      options: [{ value: 50 }, { value: 60 }],
    });
    expect(field(form, "Modulation")).toMatchObject({ min: 0, max: 1 });
    expect(field(form, "BandHighHz")).toMatchObject({ exclusiveMin: 0 });
  });

  it("Function: an enum, a number or one per channel, infinite bounds", () => {
    const { form } = schemaOf("Function");
    expect(field(form, "Operation")).toMatchObject({ kind: "enum", required: true });
    expect(field(form, "Value")).toMatchObject({ kind: "numberOrList", required: false });
    expect(field(form, "Min")).toMatchObject({ kind: "number", allowInfinity: true });
    expect(field(form, "Exponent")).toMatchObject({ kind: "number", allowInfinity: false });
    expect(parseText(field(form, "Max"), "-.inf")).toEqual({ ok: true, value: -Infinity });
    expect(parseText(field(form, "Exponent"), ".inf")).toMatchObject({ ok: false });
  });

  it("Filter, LinearMap: lists and matrices of numbers", () => {
    expect(field(schemaOf("Filter").form, "Numerator")).toMatchObject({
      kind: "numberList",
      required: true,
    });
    expect(field(schemaOf("Filter").form, "Denominator")).toMatchObject({
      kind: "numberList",
      default: [1],
    });
    const lm = schemaOf("LinearMap").form;
    expect(field(lm, "Weights")).toMatchObject({
      kind: "matrix",
      minRows: 1,
      row: { minItems: 1 },
    });
    expect(parseText(field(lm, "Weights"), "1, 0\n0, 1")).toEqual({
      ok: true,
      value: [
        [1, 0],
        [0, 1],
      ],
    });
  });

  it("ControlAlgorithm: a list of DoF objects, .inf default, a choice or a list", () => {
    const { form } = schemaOf("ControlAlgorithm");
    const dofs = field(form, "DoFs") as Extract<Field, { kind: "list" }>;
    expect(dofs.item.kind).toBe("object");
    expect((dofs.item as ObjectField).fields.filter((f) => f.required).map((f) => f.name)).toEqual([
      "Name",
      "Positive",
    ]);
    expect(field(form, "SlewRate")).toMatchObject({ allowInfinity: true, default: Infinity });
    const safe = field(form, "Safe");
    expect(safe.kind).toBe("scalarUnion");
    expect(parseText(safe, "hold")).toEqual({ ok: true, value: "hold" });
    expect(parseText(safe, "0, 50")).toEqual({ ok: true, value: [0, 50] });
  });

  it("FilePlayer: header auto|true|false, delimiters with names, a column name or index", () => {
    const { form } = schemaOf("FilePlayer");
    expect(field(form, "Header")).toMatchObject({
      kind: "enum",
      options: [{ value: "auto" }, { value: true }, { value: false }],
    });
    expect(field(form, "Delimiter")).toMatchObject({ kind: "enum" });
    const tc = field(form, "TimeColumn");
    expect(parseText(tc, "3")).toEqual({ ok: true, value: 3 });
    expect(parseText(tc, "false")).toEqual({ ok: true, value: false });
    expect(parseText(tc, "time_s")).toEqual({ ok: true, value: "time_s" });
  });

  it("Trigger and TAC: objects, and JSON for unions of structures", () => {
    const trig = schemaOf("Trigger").form;
    expect(field(trig, "Condition")).toMatchObject({ kind: "object" });
    expect(field(trig, "Schedule").kind).toBe("json");
    expect(field(trig, "Labels")).toMatchObject({ kind: "record", required: true });
    expect(field(schemaOf("TAC").form, "Tolerance")).toMatchObject({ kind: "numberOrList" });
    expect(field(schemaOf("ChannelSelector").form, "Active")).toMatchObject({
      kind: "numberList",
      item: { integer: true, min: 0 },
    });
  });
});

/** Valid params of each block to vary one param of. */
const BASE: Record<string, Record<string, unknown>> = {
  EmgSimulator: {},
  SinGenerator: {},
  Function: { Operation: "clip" },
  Amplification: {},
  Filter: { Numerator: [1] },
  LinearMap: { Outputs: 2 },
  AdaptiveFilter: {},
  ControlAlgorithm: {},
  ChannelSelector: {},
  SlidingWindow: { Length: 10 },
  FeatureSet: {},
  ArtifactRejection: {},
  Busy: {},
  Switch: {},
  Trigger: { Labels: { rest: [0], fist: [1] } },
  Stimulus: { Labels: { rest: [0], fist: [1] } },
  TAC: {},
  Buffer: {},
  Selector: {},
  FilePlayer: { File: "x.csv" },
};

const CANDIDATES: unknown[] = [
  -1,
  0,
  0.5,
  1,
  2,
  1.5e9,
  -Infinity,
  Infinity,
  "",
  "x",
  "rest",
  "auto",
  true,
  false,
  [],
  [0],
  [1, 2],
  [-1, 0.5],
  [[1, 2]],
  [[]],
  {},
  { Gesture: "rest", Seconds: 2 },
  [{ Gesture: "rest", Seconds: 2 }],
  [{ Gesture: "", Seconds: 0 }],
  [{ Name: "wrist", Positive: 0 }],
  { Channel: 0, Above: 0.5 },
  { a: [0.5] },
  { a: [2] },
  null,
];

/** Where zod is stricter than the JSON Schema (refinements and custom checks): the engine says so. */
const REFINED = new Set([
  "EmgSimulator.Gesture", // a name of Gestures
  "EmgSimulator.Gestures", // one value per channel, rest included
  "EmgSimulator.BandLowHz", // below BandHighHz
  "EmgSimulator.BandHighHz",
  "Filter.Denominator", // starts with 1
  "LinearMap.Weights", // Outputs rows
  "LinearMap.Bias", // Outputs values
  "ControlAlgorithm.Min", // Min ≤ Max
  "ControlAlgorithm.Max",
  "ArtifactRejection.JumpFactor", // positive (extended number)
  "Trigger.Labels", // at least one, all of one length
  "Trigger.Initial", // a name of Labels
  "Trigger.Condition", // Above and/or Below
  "Stimulus.Labels", // at least one
  "TAC.TimeLimit", // positive (extended number)
]);

describe("the form's validator agrees with the engine's zod schema", () => {
  for (const [type, base] of Object.entries(BASE)) {
    it(type, () => {
      const { def, schema, form } = schemaOf(type);
      expect(def.params.safeParse(base).success, `${type} base params`).toBe(true);
      const falseRejections: string[] = [];
      const laxer: string[] = [];
      for (const f of form.fields) {
        for (const v of CANDIDATES) {
          const mine = validate(f.schema, v, schema).length === 0;
          const zodOk = def.params.safeParse({ ...base, [f.name]: v }).success;
          const what = `${type}.${f.name} = ${summarize(v)}`;
          if (zodOk && !mine) falseRejections.push(what);
          if (mine && !zodOk && !REFINED.has(`${type}.${f.name}`)) laxer.push(what);
        }
      }
      // Never refuse what the engine accepts.
      expect(falseRejections).toEqual([]);
      // Accept only what the engine accepts, up to refinements the engine reports itself.
      expect(laxer).toEqual([]);
    });
  }
});
