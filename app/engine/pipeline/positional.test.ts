import { parseDocument, type YAMLSeq } from "yaml";
import { describe, expect, test } from "vitest";
import { Collector } from "./collector";
import { lineCounterOf } from "./parse";
import { decimalCommaItem, decimalCommaWarning, positionalArgs, scalarText } from "./positional";

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
      "0.7",
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

describe("decimal commas (files from the original's de-DE era)", () => {
  test("numbers and vectors are read as their authors meant; the original's reading is kept", () => {
    expect(decimalCommaItem("0,7")).toEqual({ read: "0.7", original: "7" });
    expect(decimalCommaItem("-0,5")).toEqual({ read: "-0.5", original: "-5" });
    expect(decimalCommaItem("0,00002206;0,00004412;0,00002206")).toEqual({
      read: "0.00002206;0.00004412;0.00002206",
      original: "2206;4412;2206",
    });
    expect(decimalCommaItem("1;-1,9867; 0,9868")).toEqual({
      read: "1;-1.9867;0.9868",
      original: "1;-19867;9868",
    });
    expect(decimalCommaItem("rest:0,5;0;1")).toEqual({
      read: "rest:0.5;0;1",
      original: "rest:5;0;1",
    });
    expect(decimalCommaItem("1,5e-3")).toEqual({ read: "1.5e-3", original: "0.015" });
  });

  test("anything else is left alone", () => {
    for (const s of [
      "0.7",
      "a,b",
      "1,2,3",
      "timerBlockName:raw,1",
      "0,7;x",
      "",
      "localhost",
      "1;2",
    ]) {
      expect(decimalCommaItem(s), s).toBeUndefined();
    }
  });

  test("one warning per block, at the first such item, with what was read", () => {
    const src = "P: [ '0,7', '-1', '0,00002206;0,00004412', 4 ]";
    const c = new Collector("f.yaml", lineCounterOf(src));
    const seq = parseDocument(src, { lineCounter: undefined }).get("P", true) as YAMLSeq;
    expect(positionalArgs(seq)).toEqual(["0.7", "-1", "0.00002206;0.00004412", "4"]);
    decimalCommaWarning(c, "af1", seq);
    expect(c.list).toEqual([
      {
        severity: "warning",
        code: "decimal-comma",
        file: "f.yaml",
        line: 1,
        col: 6,
        block: "af1",
        message:
          "block 'af1': Params with decimal commas read as the author meant: '0,7' as 0.7, " +
          "'0,00002206;0,00004412' as 0.00002206;0.00004412 (the original MOSAIC parsed numbers " +
          "en-US and read the comma as a thousands separator: 7, 2206;4412)",
      },
    ]);
    const none = parseDocument("P: [ 0.7, abs:0 ]").get("P", true) as YAMLSeq;
    decimalCommaWarning(c, "x", none);
    expect(c.list).toHaveLength(1);
  });
});
