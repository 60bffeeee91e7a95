import { parseDocument, type YAMLSeq } from "yaml";
import { describe, expect, test } from "vitest";
import { positionalArgs, scalarText } from "./positional";

const args = (list: string) =>
  positionalArgs(parseDocument(`P: ${list}`).get("P", true) as YAMLSeq);

describe("positional Params: the strings a block's legacyParams receives", () => {
  test("scalars, one-pair mappings, nested lists", () => {
    expect(args("[ 3, 2.5, multiply:5, '4;5;6', \"a b\", '', ~, true ]")).toEqual([
      "3",
      "2.5",
      "multiply:5",
      "4;5;6",
      "a b",
      "",
      "",
      "true",
    ]);
    expect(args("[ rest: 0;0;1, [1, 2] ]")).toEqual(["rest:0;0;1", "1;2"]);
    expect(scalarText(undefined)).toBeUndefined();
  });
});
