/**
 * Issue 17, defect 4 (engine side): a `load` that fails leaves the loaded pipeline as it was —
 * still running, the same graph — whether the text does not parse or a block cannot be created;
 * a valid text replaces it. With nothing loaded, a failed load says the engine is empty.
 */
import { dirname } from "node:path";
import { beforeAll, describe, expect, test } from "vitest";
import { catalog } from "../../app/blocks/catalog";
import { VirtualClock } from "../../app/engine/clock";
import type { EngineMessage } from "../../app/engine/protocol";
import { EngineSession } from "../../app/engine/session";
import { nodeResources } from "../../app/host/resources";
import { loadDspFromDisk } from "../../app/host/validate";

const TIMER = "Timer: { Type: ScheduledTimer, DesiredRate: 100 }\n";
const GOOD =
  TIMER + "Emg: { Type: EmgSimulator, Inputs: [Timer] }\nOut: { Type: Sink, Inputs: [Emg] }\n";
const OTHER = TIMER + "Out: { Type: Sink, Inputs: [Timer] }\n";
const UNPARSED = TIMER + "Emg: { Type: EmgSimulatr, Inputs: [Timer] }\n";
/** Parses, but its FilePlayer cannot be created (the file it reads is missing). */
const UNCREATED =
  TIMER +
  "Play: { Type: FilePlayer, Inputs: [Timer], Params: { File: missing.csv } }\n" +
  "Out: { Type: Sink, Inputs: [Play] }\n";

type Reply = Extract<EngineMessage, { type: "reply" }>;

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

let nextId = 1;
async function request(
  t: { s: EngineSession; sent: EngineMessage[] },
  msg: Record<string, unknown>,
): Promise<Reply> {
  const id = nextId++;
  await t.s.handle({ ...msg, id });
  const r = t.sent.find((m): m is Reply => m.type === "reply" && m.id === id);
  if (!r) throw new Error(`no reply to ${String(msg.type)}`);
  return r;
}

const load = (
  t: { s: EngineSession; sent: EngineMessage[] },
  file: string,
  source: string,
): Promise<Reply> => request(t, { type: "load", file, source });

/** The states the session announced, in order. */
const states = (sent: EngineMessage[]): string[] =>
  sent.flatMap((m) => (m.type === "state" ? [`${m.state} ${m.file}`] : []));

describe("a load that fails keeps what runs", () => {
  beforeAll(() => {
    loadDspFromDisk();
  });

  test("a text that does not parse, then one whose block cannot be created: the first goes on", async () => {
    const t = session();
    expect((await load(t, "/tmp/good.yaml", GOOD)).ok).toBe(true);
    expect((await request(t, { type: "start" })).ok).toBe(true);
    const before = states(t.sent);
    expect(before.at(-1)).toBe("running /tmp/good.yaml");

    const unparsed = await load(t, "/tmp/broken.yaml", UNPARSED);
    expect(unparsed.ok).toBe(false);
    expect(unparsed.diagnostics?.map((d) => d.message).join("\n")).toContain("EmgSimulatr");
    const uncreated = await load(t, "/tmp/uncreated.yaml", UNCREATED);
    expect(uncreated.ok).toBe(false);
    expect(uncreated.diagnostics?.map((d) => d.message).join("\n")).toContain("missing.csv");
    // No state change was announced: the engine still runs the first pipeline, whose blocks
    // answer requests.
    expect(states(t.sent)).toEqual(before);
    expect((await request(t, { type: "watch", block: "Emg" })).ok).toBe(true);

    // A valid text replaces it.
    const other = await load(t, "/tmp/other.yaml", OTHER);
    expect(other.ok).toBe(true);
    expect(other.graph?.file).toBe("/tmp/other.yaml");
    expect(states(t.sent).at(-1)).toBe("loaded /tmp/other.yaml");
    expect((await request(t, { type: "watch", block: "Emg" })).ok).toBe(false);
  });

  test("with nothing loaded, a failed load leaves the engine empty", async () => {
    const t = session();
    const r = await load(t, "/tmp/broken.yaml", UNPARSED);
    expect(r.ok).toBe(false);
    expect(t.sent.flatMap((m) => (m.type === "state" ? [m.state] : []))).toEqual(["empty"]);
  });
});
