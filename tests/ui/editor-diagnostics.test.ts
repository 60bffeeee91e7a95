/**
 * The editor's problems are `mosaic validate`'s (issue 17, defect 7): for the same text, the
 * lines the editor lists (line:col and text, from the engine session's `validate` reply) are the
 * lines the CLI prints, every one at once, with "did you mean", and the running pipeline is not
 * touched.
 */
import { mkdtempSync, writeFileSync } from "node:fs";
import { tmpdir } from "node:os";
import { dirname, join } from "node:path";
import { beforeAll, describe, expect, test } from "vitest";
import { catalog } from "../../app/blocks/catalog";
import { VirtualClock } from "../../app/engine/clock";
import { formatDiagnostic } from "../../app/engine/diagnostics";
import type { EngineMessage } from "../../app/engine/protocol";
import { EngineSession } from "../../app/engine/session";
import { nodeResources } from "../../app/host/resources";
import { loadDspFromDisk, validatePipelineFile } from "../../app/host/validate";
import type { Reply } from "../../app/ui/client/engine-client";
import { issuesFromReply } from "../../app/ui/editor/validation-issues";

const TIMER = "Timer: { Type: ScheduledTimer, DesiredRate: 200 }\n";

const CASES: Record<string, { text: string; expect: string[] }> = {
  "unknown type with a near name": {
    text:
      TIMER + "Emg: { Type: EmgSimulatr, Inputs: [Timer] }\nOut: { Type: Sink, Inputs: [Emg] }\n",
    expect: [
      "2:14: error: block 'Emg': unknown block type 'EmgSimulatr'; did you mean 'EmgSimulator'?",
    ],
  },
  "a dangling input": {
    text:
      TIMER + "Emg: { Type: EmgSimulator, Inputs: [Timer] }\nOut: { Type: Sink, Inputs: [Emgg] }\n",
    expect: [
      "3:29: error: block 'Out': input 'Emgg' is not a block in this pipeline; did you mean 'Emg'?",
    ],
  },
  "a wrong param": {
    text:
      TIMER +
      "Emg: { Type: EmgSimulator, Inputs: [Timer] }\n" +
      "Rect: { Type: Function, Inputs: [Emg], Params: { Operation: abz } }\n" +
      "Out: { Type: Sink, Inputs: [Rect] }\n",
    expect: [
      `3:61: error: block 'Rect' (Function): param 'Operation' has the string "abz" (expected one of add, multiply, abs, power, clip); did you mean 'abs'?`,
    ],
  },
  "errors of every stage at once, the noun agreeing with its number": {
    text:
      TIMER +
      "Emg: { Type: EmgSimulatr, Inputs: [Timer] }\n" +
      "Amp: { Type: Function, Inputs: [Timr], Params: { Operation: multiply, Value: 5 } }\n" +
      "Out: { Type: Sink }\n",
    expect: [
      "2:14: error: block 'Emg': unknown block type 'EmgSimulatr'; did you mean 'EmgSimulator'?",
      "3:33: error: block 'Amp': input 'Timr' is not a block in this pipeline; did you mean 'Timer'?",
      "4:1: error: block 'Out' (Sink) has 0 inputs (expected at least 1 input)",
    ],
  },
  "a file a block reads (found when the blocks are instantiated)": {
    text:
      TIMER +
      "Play: { Type: FilePlayer, Inputs: [Timer], Params: { File: missing.csv } }\n" +
      "Out: { Type: Sink, Inputs: [Play] }\n",
    expect: ["2:54: error: block 'Play' (FilePlayer): cannot read '"],
  },
};

/** An engine session as the editor talks to it (no loop: nothing is started here). */
function session(): { s: EngineSession; sent: EngineMessage[] } {
  const sent: EngineMessage[] = [];
  const s = new EngineSession(catalog, {
    engine: "test",
    sharedMemory: false,
    clock: () => new VirtualClock(0),
    resources: (file) => nodeResources(dirname(file)),
    startLoop: () => ({ stop: () => {}, wake: () => {} }),
    post: (m) => sent.push(m),
  });
  return { s, sent };
}

/** What the editor lists for `text` (file:line:col: severity: text, as the CLI prints it). */
async function editorLines(file: string, text: string): Promise<string[]> {
  const { s, sent } = session();
  await s.handle({ type: "validate", id: 1, file, source: text });
  const reply = sent.find((m) => m.type === "reply") as (Reply & { type: "reply" }) | undefined;
  expect(reply).toBeDefined();
  // Checking loads nothing: the engine still has no pipeline.
  expect(sent.some((m) => m.type === "state" || m.type === "graph")).toBe(false);
  return issuesFromReply(reply!).map(
    (i) => `${file}:${i.line}:${i.col}: ${i.severity}: ${i.message}`,
  );
}

describe("editor diagnostics are mosaic validate's", () => {
  let dir: string;
  beforeAll(() => {
    loadDspFromDisk();
    dir = mkdtempSync(join(tmpdir(), "mosaic-editor-diag-"));
  });

  for (const [name, c] of Object.entries(CASES)) {
    test(name, async () => {
      const file = join(dir, `${name.replace(/\W+/g, "-")}.yaml`);
      writeFileSync(file, c.text);
      const cli = (await validatePipelineFile(file)).map(formatDiagnostic);
      const editor = await editorLines(file, c.text);
      expect(editor).toEqual(cli);
      expect(editor).toHaveLength(c.expect.length);
      c.expect.forEach((want, i) => expect(editor[i]).toContain(`${file}:${want}`));
    });
  }

  test("a text that does not parse: the loader's positioned YAML error", async () => {
    const file = join(dir, "syntax.yaml");
    const text = "Timer: { Type: ScheduledTimer, DesiredRate: 200\n";
    writeFileSync(file, text);
    const cli = (await validatePipelineFile(file)).map(formatDiagnostic);
    expect(cli.length).toBeGreaterThan(0);
    expect(await editorLines(file, text)).toEqual(cli);
  });
});
