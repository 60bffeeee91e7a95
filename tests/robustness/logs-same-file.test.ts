/**
 * Issue 14, item 7: two writers on one log file tore lines and lost some, without a word. The
 * loader now refuses two blocks whose `Path`s name one file (a positioned error at the second
 * block's Path naming the first: app/engine/pipeline/paths.ts), and the log writer refuses, at
 * run time, a log whose file another open log already writes by any name (a Logger's file and a
 * block's Path, a relative and an absolute name, two pipelines): one error naming both, the first
 * log intact, the second's events counted as lost.
 */
import { readFileSync, symlinkSync, writeFileSync } from "node:fs";
import { join } from "node:path";
import { describe, expect, test } from "vitest";
import { catalog } from "../../app/blocks/catalog";
import { formatDiagnostic } from "../../app/engine/diagnostics";
import { Frame, vectorShape } from "../../app/engine/frame";
import { loadPipeline } from "../../app/engine/pipeline/loader";
import { SabRing } from "../../app/engine/runtime/sab-ring";
import { LogWriter } from "../../app/host/log-writer";
import { jsonLines, requireBuild, runCli, tempDir } from "../integration/helpers";

describe("two blocks with the same Path", () => {
  test("are refused when the file loads, at the second Path, naming both blocks", () => {
    const src = [
      "Timer: { Type: ScheduledTimer, DesiredRate: 100 }",
      "Emg: { Type: EmgSimulator, Inputs: [Timer], Params: { Channels: 2 }, Path: rec/both.txt }",
      "Env: { Type: Function, Inputs: [Emg], Params: { Operation: abs }, Path: ./rec//both.txt }",
      "",
    ].join("\n");
    const r = loadPipeline(src, "p.yaml", catalog);
    expect(r.ok).toBe(false);
    expect(r.diagnostics.filter((d) => d.severity === "error").map(formatDiagnostic)).toEqual([
      "p.yaml:3:73: error: block 'Env': its log 'rec/both.txt' is also written by block 'Emg' " +
        "(Path at 2:76); two writers on one file tear and lose lines (expected a Path of its own " +
        "for 'Env' or 'Emg' (another folder or file name))",
    ]);
  });

  test("a folder Path meeting another block's file Path is refused too", () => {
    const src = [
      "Timer: { Type: ScheduledTimer, DesiredRate: 100 }",
      "A: { Type: EmgSimulator, Inputs: [Timer], Path: logs/B.txt }",
      "B: { Type: EmgSimulator, Inputs: [Timer], Path: logs }",
      "",
    ].join("\n");
    const r = loadPipeline(src, "p.yaml", catalog);
    expect(r.diagnostics.map((d) => d.message)).toEqual([
      "block 'B': its log of output 'emg', 'logs/B.txt', is also written by block 'A' (Path at 2:49); two writers on one file tear and lose lines",
    ]);
  });
});

/** A ring with `n` one-value events at t = 1, 2, …, written from `first`. */
function ringWith(n: number, first = 0) {
  const init = SabRing.allocate(4096, 1);
  const ring = new SabRing(init);
  const t = Array.from({ length: n }, (_, i) => first + i + 1);
  ring.write(
    Frame.from(
      vectorShape(1),
      t,
      t.map((x) => [x]),
    ),
  );
  return init;
}

describe("the log writer: one writer per real file", () => {
  test("a second log on the same file by another name is refused; the first stays whole", () => {
    const dir = tempDir("mosaic-logs-");
    const errors: string[] = [];
    const w = new LogWriter(dir, { onError: (f, m) => errors.push(`${f}: ${m}`) });
    const shape = vectorShape(1);
    w.open("a", "A", "out", true, "rec/x.txt", shape, ringWith(300));
    w.open("b", "B", "out", true, join(dir, "rec/./x.txt"), shape, ringWith(200, 1000));
    symlinkSync(join(dir, "rec/x.txt"), join(dir, "link.txt"));
    // Another writer (another pipeline) in the same process, through a link.
    const other = new LogWriter(dir, { onError: (f, m) => errors.push(`${f}: ${m}`) });
    other.open("c", "C", "out", true, "link.txt", shape, ringWith(100, 2000));
    w.closeAll();
    other.closeAll();
    const lines = readFileSync(join(dir, "rec/x.txt"), "utf8").trimEnd().split("\n");
    expect(lines.length).toBe(300);
    expect(lines[0]).toBe("1.000000,1");
    expect(lines.every((l) => /^\d+\.000000,\d+$/.test(l))).toBe(true);
    expect(errors[0]).toBe(
      `${join(dir, "rec/x.txt")}: the log of 'B' cannot be written: ${join(dir, "rec/x.txt")} is ` +
        "already written by the log of 'A'; two writers on one file tear and lose lines: give one " +
        "of them another Path (its events are counted as lost)",
    );
    expect(errors[1]).toMatch(
      /link\.txt: the log of 'C' cannot be written: .*link\.txt is already written by the log of 'A' \(as .*rec\/x\.txt\)/,
    );
    expect(errors[2]).toMatch(/: the log of 'B' lost 200 events in all \(0 lines written\)$/);
    expect(errors[3]).toMatch(/: the log of 'C' lost 100 events in all \(0 lines written\)$/);
    expect(errors.length).toBe(4);
  });

  test("a Logger writing the file of a block's Path (mosaic run): one error, no torn lines", () => {
    requireBuild();
    const dir = tempDir("mosaic-logs-");
    const file = join(dir, "p.yaml");
    writeFileSync(
      file,
      [
        "Timer: { Type: ScheduledTimer, DesiredRate: 500 }",
        "Emg: { Type: EmgSimulator, Inputs: [Timer], Params: { Channels: 4 }, Path: rec/ }",
        "Log: { Type: Logger, Inputs: [Emg], Params: { Folder: rec/ } }",
        "",
      ].join("\n"),
    );
    const r = runCli(["run", file, "--clock", "virtual", "--duration", "4", "--json"]);
    const out = jsonLines(r.stdout);
    const events = out.filter((l) => l.type === "event").map((l) => String(l.message));
    const summary = out.find((l) => l.type === "summary") as {
      blocks: { name: string; events: number }[];
    };
    const emitted = summary.blocks.find((b) => b.name === "Emg")!.events;
    expect(emitted).toBe(2001);
    expect(events.filter((m) => /already written by the log of 'Emg'/.test(m)).length).toBe(1);
    expect(events).toContain(`the log of 'Emg' lost ${emitted} events in all (0 lines written)`);
    const lines = readFileSync(join(dir, "rec/Emg.txt"), "utf8").trimEnd().split("\n");
    expect(lines.length).toBe(emitted);
    expect(lines.every((l) => l.split(",").length === 5)).toBe(true);
    expect(r.code).toBe(1);
  });
});
