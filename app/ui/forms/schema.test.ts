import { describe as suite, expect, it } from "vitest";
import {
  InvalidText,
  describe,
  describeParams,
  describeType,
  emptyValue,
  formatText,
  hasInvalid,
  issueText,
  issuesUnder,
  parseMatrix,
  parseNumber,
  parseNumberList,
  parseText,
  summarize,
  validate,
  type Field,
  type JsonSchema,
} from "./schema";

const messages = (schema: JsonSchema, v: unknown): string[] => validate(schema, v).map(issueText);

suite("describe", () => {
  it("numbers: integer, bounds, step, default; zod's safe-integer bounds are hidden", () => {
    const f = describe({
      type: "integer",
      minimum: 1,
      maximum: 4096,
      default: 8,
      description: "Channels",
    });
    expect(f).toMatchObject({
      kind: "number",
      integer: true,
      min: 1,
      max: 4096,
      step: 1,
      default: 8,
      hasDefault: true,
      description: "Channels",
    });
    const g = describe({ type: "integer", minimum: 0, maximum: Number.MAX_SAFE_INTEGER });
    expect(g).toMatchObject({ kind: "number", min: 0 });
    expect((g as { max?: number }).max).toBeUndefined();
    expect(describeType(g)).toBe("integer ≥ 0");
    expect(describe({ type: "number", exclusiveMinimum: 0 })).toMatchObject({
      exclusiveMin: 0,
      step: "any",
    });
  });

  it("infinities: .inf in the description, a null default (JSON's Infinity), or x-infinity", () => {
    expect(describe({ type: "number", description: "Upper bound (.inf allowed)" })).toMatchObject({
      allowInfinity: true,
    });
    expect(describe({ type: "number", default: null })).toMatchObject({
      allowInfinity: true,
      default: Infinity,
    });
    expect(describe({ type: "number", "x-infinity": true })).toMatchObject({ allowInfinity: true });
    expect(describe({ type: "number", description: "information" })).toMatchObject({
      allowInfinity: false,
    });
  });

  it("enums from enum, const unions and const|boolean unions", () => {
    expect(describe({ type: "string", enum: ["a", "b"] })).toMatchObject({
      kind: "enum",
      options: [
        { value: "a", label: "a" },
        { value: "b", label: "b" },
      ],
    });
    const hum = describe({
      default: 50,
      anyOf: [
        { type: "number", const: 50 },
        { type: "number", const: 60 },
      ],
    });
    expect(hum).toMatchObject({ kind: "enum", default: 50 });
    expect((hum as { options: unknown[] }).options).toHaveLength(2);
    const header = describe({ anyOf: [{ type: "string", const: "auto" }, { type: "boolean" }] });
    expect(header.kind).toBe("enum");
    expect((header as { options: { value: unknown }[] }).options.map((o) => o.value)).toEqual([
      "auto",
      true,
      false,
    ]);
    expect(describe({ type: "string", enum: [" ", "\t"] })).toMatchObject({
      options: [{ label: "' ' (space)" }, { label: "tab" }],
    });
  });

  it("lists of numbers, matrices, number-or-list unions", () => {
    const list = describe({ type: "array", minItems: 1, items: { type: "number", minimum: 0 } });
    expect(list).toMatchObject({
      kind: "numberList",
      minItems: 1,
      item: { kind: "number", min: 0 },
    });
    const m = describe({
      type: "array",
      minItems: 1,
      items: { type: "array", minItems: 1, items: { type: "number" } },
    });
    expect(m).toMatchObject({ kind: "matrix", minRows: 1, row: { kind: "numberList" } });
    const u = describe({
      default: 1,
      anyOf: [{ type: "number" }, { type: "array", minItems: 1, items: { type: "number" } }],
    });
    expect(u).toMatchObject({ kind: "numberOrList", default: 1 });
  });

  it("objects (required, nested), lists of objects, records, $ref, nullable", () => {
    const o = describeParams({
      type: "object",
      properties: {
        A: { type: "number" },
        Seq: {
          type: "array",
          items: {
            type: "object",
            properties: { G: { type: "string" }, S: { type: "number" } },
            required: ["G"],
          },
        },
        Map: {
          type: "object",
          propertyNames: { type: "string", minLength: 1 },
          additionalProperties: { type: "array", items: { type: "number" } },
        },
        R: { $ref: "#/$defs/pos" },
        N: { anyOf: [{ type: "number" }, { type: "null" }], description: "maybe" },
      },
      required: ["A"],
      $defs: { pos: { type: "number", minimum: 0 } },
    });
    expect(o.fields.map((f) => [f.name, f.kind, f.required])).toEqual([
      ["A", "number", true],
      ["Seq", "list", false],
      ["Map", "record", false],
      ["R", "number", false],
      ["N", "number", false],
    ]);
    const seq = o.fields[1] as Extract<Field, { kind: "list" }>;
    expect(seq.item).toMatchObject({ kind: "object" });
    expect((seq.item as Extract<Field, { kind: "object" }>).fields.map((f) => f.required)).toEqual([
      true,
      false,
    ]);
    expect(o.fields[2]).toMatchObject({
      keySchema: { minLength: 1 },
      value: { kind: "numberList" },
    });
    expect(o.fields[3]).toMatchObject({ min: 0 });
    expect(o.fields[4]).toMatchObject({ nullable: true, description: "maybe" });
  });

  it("falls back to JSON for what it cannot lay out", () => {
    expect(describe({}).kind).toBe("json");
    expect(describe({ type: "array", prefixItems: [{ type: "number" }] }).kind).toBe("json");
    const choice = describe({
      anyOf: [
        { type: "array", items: { type: "object", properties: { a: { type: "number" } } } },
        { type: "object", properties: { b: { type: "number" } } },
      ],
    });
    expect(choice.kind).toBe("json");
  });
});

suite("parsing text", () => {
  const real = { integer: false, allowInfinity: false };
  it("numbers", () => {
    expect(parseNumber(" 1.5 ", real)).toEqual({ ok: true, value: 1.5 });
    expect(parseNumber("-2e-3", real)).toEqual({ ok: true, value: -0.002 });
    expect(parseNumber(".5", real)).toEqual({ ok: true, value: 0.5 });
    expect(parseNumber("", real)).toEqual({ ok: true, value: undefined });
    expect(parseNumber("abc", real)).toEqual({ ok: false, error: "not a number" });
    expect(parseNumber("0,5", real)).toEqual({
      ok: false,
      error: "not a number (use a point for decimals)",
    });
    expect(parseNumber("1.5", { integer: true, allowInfinity: false }).ok).toBe(true); // range/integer: validate()
    expect(parseNumber("x", { integer: true, allowInfinity: false })).toEqual({
      ok: false,
      error: "must be a whole number",
    });
    expect(parseNumber(".inf", real)).toEqual({ ok: false, error: "must be a finite number" });
    expect(parseNumber("NaN", real).ok).toBe(false);
    const inf = { integer: false, allowInfinity: true };
    expect(parseNumber(".inf", inf)).toEqual({ ok: true, value: Infinity });
    expect(parseNumber("-.inf", inf)).toEqual({ ok: true, value: -Infinity });
    expect(parseNumber("Infinity", inf)).toEqual({ ok: true, value: Infinity });
  });

  it("lists and matrices", () => {
    expect(parseNumberList("1, 2;3  4", real)).toEqual({ ok: true, value: [1, 2, 3, 4] });
    expect(parseNumberList("[1, -0.5]", real)).toEqual({ ok: true, value: [1, -0.5] });
    expect(parseNumberList("[]", real)).toEqual({ ok: true, value: [] });
    expect(parseNumberList("", real)).toEqual({ ok: true, value: undefined });
    expect(parseNumberList("1, x", real)).toEqual({ ok: false, error: "item 2 'x': not a number" });
    expect(parseNumberList("1,,2", real).ok).toBe(false);
    const index = { integer: true, allowInfinity: false, min: 0 };
    expect(parseNumberList("0-3, 8", index)).toEqual({ ok: true, value: [0, 1, 2, 3, 8] });
    expect(parseNumberList("3-1", index).ok).toBe(false);
    expect(parseNumberList("0-3", real).ok).toBe(false);
    expect(parseMatrix("1, 2\n3, 4\n", real)).toEqual({
      ok: true,
      value: [
        [1, 2],
        [3, 4],
      ],
    });
    expect(parseMatrix("[[1,2],[3,4]]", real)).toEqual({
      ok: true,
      value: [
        [1, 2],
        [3, 4],
      ],
    });
    expect(parseMatrix("1, 2\n3, y", real)).toEqual({
      ok: false,
      error: "row 2: item 2 'y': not a number",
    });
  });

  it("round-trips through formatText", () => {
    const fields: [JsonSchema, unknown][] = [
      [{ type: "number" }, -1.25],
      [{ type: "number", description: ".inf ok" }, Infinity],
      [{ type: "array", items: { type: "number" } }, [1, 2, 3]],
      [{ type: "array", items: { type: "number" } }, []],
      [{ type: "array", items: { type: "array", items: { type: "number" } } }, [[1, 2], [3]]],
      [{ anyOf: [{ type: "number" }, { type: "array", items: { type: "number" } }] }, 5],
      [{ anyOf: [{ type: "number" }, { type: "array", items: { type: "number" } }] }, [5, 6]],
      [
        {
          anyOf: [
            { type: "string", enum: ["rest", "hold"] },
            { type: "array", items: { type: "number" } },
          ],
        },
        "hold",
      ],
      [
        {
          anyOf: [
            { type: "string", enum: ["rest", "hold"] },
            { type: "array", items: { type: "number" } },
          ],
        },
        [1, 2],
      ],
      [{ anyOf: [{ type: "string", minLength: 1 }, { type: "integer" }, { const: false }] }, 3],
      [{ anyOf: [{ type: "string", minLength: 1 }, { type: "integer" }, { const: false }] }, false],
      [
        { anyOf: [{ type: "string", minLength: 1 }, { type: "integer" }, { const: false }] },
        "time_s",
      ],
      [{ type: "object", properties: { a: { type: "number" } } }, { a: 1 }],
    ];
    for (const [s, v] of fields) {
      const f = describe(s);
      const text = formatText(f, v);
      const back =
        f.kind === "object" ? parseText({ ...f, kind: "json" }, text) : parseText(f, text);
      expect(back, `${JSON.stringify(s)} ${text}`).toEqual({ ok: true, value: v });
    }
  });

  it("empty text means not given; a number-or-list tells one number from a list", () => {
    const f = describe({
      anyOf: [{ type: "number" }, { type: "array", items: { type: "number" } }],
    });
    expect(parseText(f, "")).toEqual({ ok: true, value: undefined });
    expect(parseText(f, "2")).toEqual({ ok: true, value: 2 });
    expect(parseText(f, "2, 3")).toEqual({ ok: true, value: [2, 3] });
    expect(parseText(f, "[2]")).toEqual({ ok: true, value: [2] });
    expect(parseText(describe({ type: "string" }, "s", false), "")).toEqual({
      ok: true,
      value: undefined,
    });
    expect(parseText(describe({ type: "string" }, "s", true), "")).toEqual({ ok: true, value: "" });
    expect(parseText(describe({ type: "string" }), " a ")).toEqual({ ok: true, value: " a " });
    expect(parseText(describe({}), "{bad")).toMatchObject({ ok: false });
  });

  it("summarizes values for read-only display", () => {
    expect(summarize([{ Gesture: "rest", Seconds: 2 }])).toBe('[{Gesture: "rest", Seconds: 2}]');
    expect(summarize(Infinity)).toBe(".inf");
    expect(summarize(undefined)).toBe("—");
    expect(summarize("x".repeat(200), 10)).toHaveLength(10);
  });
});

suite("validate", () => {
  it("numbers in the schema's terms", () => {
    const s: JsonSchema = { type: "integer", minimum: 1, maximum: 4096 };
    expect(messages(s, 8)).toEqual([]);
    expect(messages(s, 0)).toEqual(["must be ≥ 1"]);
    expect(messages(s, 5000)).toEqual(["must be ≤ 4096"]);
    expect(messages(s, 1.5)).toEqual(["must be a whole number"]);
    expect(messages(s, "8")).toEqual(["must be a whole number"]);
    expect(messages({ type: "number", exclusiveMinimum: 0 }, 0)).toEqual(["must be > 0"]);
    expect(messages({ type: "number", exclusiveMaximum: 1 }, 1)).toEqual(["must be < 1"]);
    expect(messages({ type: "number", multipleOf: 0.5 }, 0.75)).toEqual([
      "must be a multiple of 0.5",
    ]);
    expect(messages({ type: "number" }, NaN)).toEqual(["must be a number"]);
  });

  it("strings, enums, consts", () => {
    expect(messages({ type: "string", minLength: 1 }, "")).toEqual(["must not be empty"]);
    expect(messages({ type: "string", pattern: "^[a-z]+$" }, "A1")).toEqual([
      "must match ^[a-z]+$",
    ]);
    expect(messages({ type: "string", enum: ["add", "abs"] }, "mul")).toEqual([
      "must be one of add, abs",
    ]);
    expect(messages({ const: 50 }, 60)).toEqual(["must be 50"]);
  });

  it("objects: required, unknown keys, nested paths", () => {
    const s: JsonSchema = {
      type: "object",
      properties: {
        Gesture: { type: "string", minLength: 1 },
        Seconds: { type: "number", exclusiveMinimum: 0 },
      },
      required: ["Gesture", "Seconds"],
      additionalProperties: false,
    };
    expect(messages(s, { Gesture: "fist", Seconds: 2 })).toEqual([]);
    expect(messages(s, { Gesture: "fist" })).toEqual(["Seconds: required"]);
    expect(messages(s, { Gesture: "fist", Seconds: 2, Extra: 1 })).toEqual([
      "Extra: unknown key 'Extra' (allowed: Gesture, Seconds)",
    ]);
    const list: JsonSchema = { type: "array", minItems: 1, items: s };
    expect(messages(list, [])).toEqual(["needs at least 1 item"]);
    expect(
      validate(list, [
        { Gesture: "a", Seconds: 1 },
        { Gesture: "", Seconds: -1 },
      ]),
    ).toEqual([
      { path: [1, "Gesture"], message: "must not be empty" },
      { path: [1, "Seconds"], message: "must be > 0" },
    ]);
  });

  it("records: key names and values", () => {
    const s: JsonSchema = {
      type: "object",
      propertyNames: { type: "string", pattern: "^[A-Za-z0-9_-]+$" },
      additionalProperties: { type: "array", minItems: 1, items: { type: "integer", minimum: 0 } },
    };
    expect(messages(s, { flexors: [0, 1] })).toEqual([]);
    expect(messages(s, { "bad name": [0], ok: [] })).toEqual([
      "bad name: name 'bad name' must match ^[A-Za-z0-9_-]+$",
      "ok: needs at least 1 item",
    ]);
  });

  it("unions: the branch of the value's type speaks, else what is expected", () => {
    const gain: JsonSchema = {
      anyOf: [
        { type: "number", exclusiveMinimum: 0 },
        { type: "array", minItems: 1, items: { type: "number", exclusiveMinimum: 0 } },
      ],
    };
    expect(messages(gain, 2)).toEqual([]);
    expect(messages(gain, [1, 2])).toEqual([]);
    expect(messages(gain, -1)).toEqual(["must be > 0"]);
    expect(messages(gain, [1, 0])).toEqual(["[1]: must be > 0"]);
    expect(messages(gain, "x")).toEqual(["must be a number > 0, or list of numbers > 0 (≥ 1)"]);
    const header: JsonSchema = { anyOf: [{ type: "string", const: "auto" }, { type: "boolean" }] };
    expect(messages(header, true)).toEqual([]);
    expect(messages(header, "yes")).toEqual(["must be auto, or true or false"]);
  });

  it("reports text that did not parse, and nothing for values not given", () => {
    expect(messages({ type: "number" }, new InvalidText("x", "not a number"))).toEqual([
      "not a number",
    ]);
    expect(messages({ type: "number" }, undefined)).toEqual([]);
    const v = { a: [1, new InvalidText("?", "not a number")] };
    expect(hasInvalid(v)).toBe(true);
    expect(
      messages(
        { type: "object", properties: { a: { type: "array", items: { type: "number" } } } },
        v,
      ),
    ).toEqual(["a[1]: not a number"]);
    expect(hasInvalid({ a: [1, 2] })).toBe(false);
  });

  it("issuesUnder makes paths relative", () => {
    const issues = [
      { path: ["Seq", 1, "G"], message: "m1" },
      { path: ["Other"], message: "m2" },
    ];
    expect(issuesUnder(issues, ["Seq"])).toEqual([{ path: [1, "G"], message: "m1" }]);
    expect(issuesUnder(issues, ["Seq", 1, "G"])).toEqual([{ path: [], message: "m1" }]);
  });

  it("emptyValue gives a new item its default or the required keys", () => {
    const f = describe({
      type: "object",
      properties: { Name: { type: "string" }, Rest: { type: "number", default: 0 } },
      required: ["Name"],
    });
    expect(emptyValue(f)).toEqual({ Name: "" });
    expect(emptyValue(describe({ type: "number", default: 3 }))).toBe(3);
    expect(emptyValue(describe({ type: "string", enum: ["a", "b"] }))).toBe("a");
  });
});

suite("describe: the remaining shapes", () => {
  it("booleans, strings with bounds, lists and matrices with bounds", () => {
    expect(describe({ type: "boolean", default: true })).toMatchObject({
      kind: "boolean",
      default: true,
    });
    expect(describe({ type: "string", minLength: 1, maxLength: 8, pattern: "^a" })).toMatchObject({
      kind: "string",
      minLength: 1,
      maxLength: 8,
      pattern: "^a",
    });
    expect(describe({ type: "array", maxItems: 3, items: { type: "string" } })).toMatchObject({
      kind: "list",
      maxItems: 3,
      item: { kind: "string" },
    });
    expect(
      describe({ type: "array", minItems: 2, maxItems: 3, items: { type: "number" } }),
    ).toMatchObject({ kind: "numberList", minItems: 2, maxItems: 3 });
    const m = describe({
      type: "array",
      maxItems: 4,
      items: { type: "array", items: { type: "number" } },
    });
    expect(m).toMatchObject({ kind: "matrix", maxRows: 4 });
    expect("minRows" in m).toBe(false);
    expect(describe({ type: "array", items: [{ type: "number" }] }).kind).toBe("json");
  });

  it("objects, records and the JSON fallbacks for types", () => {
    const rec = describe({ type: "object", additionalProperties: { type: "number" } });
    expect(rec).toMatchObject({ kind: "record", value: { kind: "number" } });
    expect("keySchema" in rec).toBe(false);
    expect(describe({ type: "object" }).kind).toBe("json");
    expect(describe({ type: "object", additionalProperties: true }).kind).toBe("json");
    expect(describe({ type: "object", additionalProperties: false })).toMatchObject({
      kind: "object",
      fields: [],
    });
    expect(describe({ type: ["string", "number"] }).kind).toBe("json");
    expect(describe({ type: "null" }).kind).toBe("json");
    expect(describeParams({ type: "number" })).toMatchObject({ kind: "object", fields: [] });
  });

  it("unions: scalar unions, nullable constants, allOf, annotations of the outer schema", () => {
    const u = describe({ anyOf: [{ type: "string" }, { type: "integer" }], description: "d" });
    expect(u).toMatchObject({ kind: "scalarUnion", description: "d" });
    expect((u as { branches: Field[] }).branches.map((b) => b.kind)).toEqual(["string", "number"]);
    const safe = describe({
      anyOf: [
        { type: "string", enum: ["rest"] },
        { type: "array", items: { type: "number" } },
      ],
    });
    expect(safe.kind).toBe("scalarUnion");
    const nc = describe({
      anyOf: [{ const: "x" }, { type: "null" }],
      description: "outer",
      default: "x",
    });
    expect(nc).toMatchObject({
      kind: "enum",
      nullable: true,
      description: "outer",
      default: "x",
      options: [{ value: "x", label: "x" }],
    });
    expect(
      describe({ allOf: [{ type: "integer" }, { minimum: 2 }], description: "both" }),
    ).toMatchObject({ kind: "number", integer: true, min: 2, description: "both" });
    expect(describe({ oneOf: [{ type: "null" }] })).toMatchObject({
      kind: "json",
      nullable: true,
    });
    const two = describe({ anyOf: [{ type: "number" }, { type: "number" }] });
    expect(two.kind).toBe("scalarUnion");
  });
});

suite("validate: the remaining checks, in order", () => {
  it("types, allOf, infinities and zod's safe-integer bounds", () => {
    expect(messages({ type: ["number", "null"] }, "x")).toEqual(["must be a number or empty"]);
    expect(messages({ type: "custom" }, 1)).toEqual([]);
    expect(messages({ allOf: [{ type: "number", minimum: 2 }, { maximum: 0 }] }, 1)).toEqual([
      "must be ≥ 2",
      "must be ≤ 0",
    ]);
    expect(messages({ type: "number" }, Infinity)).toEqual(["must be a finite number"]);
    expect(messages({ type: "number", "x-infinity": true }, -Infinity)).toEqual([]);
    expect(messages({ type: "number", maximum: 1 }, Infinity)).toEqual([
      "must be a finite number",
      "must be ≤ 1",
    ]);
    const SAFE = Number.MAX_SAFE_INTEGER;
    const int: JsonSchema = { type: "integer", minimum: -SAFE, maximum: SAFE };
    expect(messages(int, 2 ** 60)).toEqual([`must be ≤ ${SAFE}`]);
    expect(messages(int, -(2 ** 60))).toEqual([`must be ≥ ${-SAFE}`]);
    expect(messages({ type: "number", multipleOf: 0 }, 0.3)).toEqual([]);
    expect(messages({ const: 1, enum: [2, 3], minimum: 5 }, 1)).toEqual([
      "must be one of 2, 3",
      "must be ≥ 5",
    ]);
    expect(messages({ const: [1, { a: 2 }] }, [1, { a: 2, b: undefined }])).toEqual([]);
  });

  it("strings: length in code points, maxLength, a bad pattern is ignored", () => {
    expect(messages({ type: "string", minLength: 3 }, "ab")).toEqual([
      "must have at least 3 characters",
    ]);
    expect(messages({ type: "string", maxLength: 2 }, "😀😀")).toEqual([]);
    expect(messages({ type: "string", maxLength: 2, pattern: "^z" }, "abc")).toEqual([
      "must have at most 2 characters",
      "must match ^z",
    ]);
    expect(messages({ type: "string", pattern: "(" }, "abc")).toEqual([]);
  });

  it("arrays: bounds, missing items, prefixItems and tuple items", () => {
    expect(messages({ type: "array", minItems: 2 }, [1])).toEqual(["needs at least 2 items"]);
    expect(messages({ type: "array", maxItems: 1 }, [1, 2])).toEqual(["must have at most 1 items"]);
    expect(messages({ type: "array", items: { type: "number" } }, [1, undefined, "x"])).toEqual([
      "[1]: item is missing",
      "[2]: must be a number",
    ]);
    const tuple: JsonSchema = {
      type: "array",
      prefixItems: [{ type: "string" }],
      items: { type: "number" },
    };
    expect(messages(tuple, [1, "x"])).toEqual(["[0]: must be text", "[1]: must be a number"]);
    expect(messages({ type: "array", items: [{ type: "string" }] }, [1, 2])).toEqual([
      "[0]: must be text",
    ]);
  });

  it("objects: checks only for object schemas, key order, unknown keys without properties", () => {
    expect(messages({ required: ["a"] }, {})).toEqual([]);
    expect(
      messages({ properties: { a: { type: "number" } }, required: ["b"] }, { a: "x" }),
    ).toEqual(["b: required", "a: must be a number"]);
    expect(messages({ type: "object", additionalProperties: false }, { k: 1 })).toEqual([
      "k: unknown key 'k'",
    ]);
    expect(
      messages(
        { type: "object", properties: { a: { type: "number" } }, additionalProperties: false },
        { a: undefined, z: undefined },
      ),
    ).toEqual([]);
    const keys: JsonSchema = {
      type: "object",
      propertyNames: { type: "string", minLength: 2 },
      properties: { a: { type: "number" } },
    };
    expect(messages(keys, { a: "x", bb: 1 })).toEqual([
      "a: name 'a' must have at least 2 characters",
      "a: must be a number",
    ]);
    expect(messages({ type: "object" }, new InvalidText("{", "not valid JSON"))).toEqual([
      "not valid JSON",
    ]);
    expect(messages({ type: "object" }, [1])).toEqual(["must be a mapping"]);
  });

  it("unions: allOf issues first; several branches of the value's type: what is expected", () => {
    const s: JsonSchema = {
      allOf: [{ minimum: 10 }],
      anyOf: [
        { type: "number", maximum: 1 },
        { type: "integer", maximum: 2 },
      ],
    };
    expect(messages(s, 5)).toEqual(["must be ≥ 10", "must be a number ≤ 1, or a whole number ≤ 2"]);
    expect(messages({ allOf: [{ minimum: 10 }], anyOf: [{ type: "number" }] }, 5)).toEqual([
      "must be ≥ 10",
    ]);
    expect(
      messages({ oneOf: [{ type: "string" }, { type: "array", items: { type: "number" } }] }, [
        "x",
      ]),
    ).toEqual(["[0]: must be a number"]);
    expect(messages({ anyOf: [{ const: "a" }, { const: "a" }] }, "b")).toEqual(["must be a"]);
    expect(
      validate({ $ref: "#/$defs/n", $defs: { n: { type: "number", minimum: 0 } } }, -1, undefined, [
        "p",
      ]),
    ).toEqual([{ path: ["p"], message: "must be ≥ 0" }]);
  });
});
