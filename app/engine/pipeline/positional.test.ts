import { parseDocument, type YAMLSeq } from "yaml";
import { describe, expect, test } from "vitest";
import { positionalArgs, scalarText } from "./positional";

const args = (list: string) =>
  positionalArgs(parseDocument(`P: ${list}`).get("P", true) as YAMLSeq);

describe("positional Params: the strings the original's blocks received", () => {
  test("numbers keep their source text", () => {
    expect(args("[ 20.0, 1., 0x10, 1e3, .5, +1, 010, 1_000, 3 ]")).toEqual([
      "20.0",
      "1.",
      "0x10",
      "1e3",
      ".5",
      "+1",
      "010",
      "1_000",
      "3",
    ]);
    expect(args("[ 8.76e-05; 1.75e-04, 1.; -1.97 ]")).toEqual(["8.76e-05; 1.75e-04", "1.; -1.97"]);
  });

  test("`key: value` items (one-pair mappings in YAML) are the string key:value", () => {
    expect(args("[ rest:   0;0;1, power:  1;1;0, 2.50: 1 ]")).toEqual([
      "rest:0;0;1",
      "power:1;1;0",
      "2.50:1",
    ]);
    expect(args("[ algorithm: DirectControl ]")).toEqual(["algorithm:DirectControl"]);
    expect(args("[ timerBlockName: raw_EMG ]")).toEqual(["timerBlockName:raw_EMG"]);
    // Without the space they are plain strings already.
    expect(args("[ multiply:5, df:68:f3:9a:ed:0e ]")).toEqual(["multiply:5", "df:68:f3:9a:ed:0e"]);
  });

  test("quoted strings, empty items, booleans and nested lists", () => {
    expect(args("[ '0,7', \"a b\", '', ~, true, [1.0, 2] ]")).toEqual([
      "0,7",
      "a b",
      "",
      "",
      "true",
      "1.0;2",
    ]);
    expect(args("[ 'c:\\temp' ]")).toEqual(["c:\\temp"]);
    expect(scalarText(undefined)).toBeUndefined();
  });
});
