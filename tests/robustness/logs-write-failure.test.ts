/**
 * Issue 14, item 11: a log whose writes fail (`Path: /dev/full`, a full disk) repeated its error
 * every 100 ms, and the events already taken from the ring for a failed write were lost without
 * being counted. Now a failing log is one error; every event it does not write is counted (the
 * writer's `stats()`, and one closing error with the count in all), and it tries again every
 * RETRY_S instead of on every drain.
 */
import { existsSync, readFileSync, symlinkSync, writeFileSync } from "node:fs";
import { join } from "node:path";
import { describe, expect, test } from "vitest";
import { Frame, vectorShape } from "../../app/engine/frame";
import { SabRing } from "../../app/engine/runtime/sab-ring";
import { LogWriter } from "../../app/host/log-writer";
import { jsonLines, requireBuild, runCli, tempDir } from "../integration/helpers";

const FULL = "/dev/full";

/** A folder with `full.log`, a link to /dev/full (every write fails with ENOSPC). */
function fullDisk(): { dir: string; file: string } {
  const dir = tempDir("mosaic-logs-");
  symlinkSync(FULL, join(dir, "full.log"));
  return { dir, file: join(dir, "full.log") };
}

describe.skipIf(!existsSync(FULL))("a log that cannot be written", () => {
  test("one error, then every event counted as lost (not an error every drain)", () => {
    const errors: string[] = [];
    const full = fullDisk();
    const w = new LogWriter(full.dir, {
      onError: (f, m) => errors.push(`${f}: ${m}`),
    });
    const init = SabRing.allocate(4096, 2);
    const ring = new SabRing(init);
    w.open("k", "Emg", "out", true, "full.log", vectorShape(2), init);
    let written = 0;
    for (let d = 0; d < 20; d++) {
      const t = Array.from({ length: 50 }, (_, i) => written + i);
      ring.write(
        Frame.from(
          vectorShape(2),
          t,
          t.map((x) => [x, -x]),
        ),
      );
      written += 50;
      w.drainAll();
    }
    expect(errors).toEqual([
      `${full.file}: cannot write: ENOSPC: no space left on device, write; the log of 'Emg' counts ` +
        "its events as lost until a write succeeds again (tried every 5 s)",
    ]);
    expect(w.stats()).toEqual([
      {
        key: "k",
        block: "Emg",
        file: full.file,
        lines: 0,
        lost: 1000,
        error: "cannot write: ENOSPC: no space left on device, write",
      },
    ]);
    w.closeAll();
    expect(errors.length).toBe(2);
    expect(errors[1]).toBe(
      `${full.file}: the log of 'Emg' lost 1000 events in all (0 lines written)`,
    );
  });

  test("mosaic run with a Path on /dev/full: one write error, and the closing count equals the block's events", () => {
    requireBuild();
    const { dir, file: log } = fullDisk();
    const file = join(dir, "full.yaml");
    writeFileSync(
      file,
      [
        "Timer: { Type: ScheduledTimer, DesiredRate: 1000 }",
        `Emg: { Type: EmgSimulator, Inputs: [Timer], Params: { Channels: 4 }, Path: full.log }`,
        "Env: { Type: Function, Inputs: [Emg], Params: { Operation: abs }, Path: rec/ }",
        "",
      ].join("\n"),
    );
    const r = runCli(["run", file, "--clock", "virtual", "--duration", "5", "--json"]);
    const out = jsonLines(r.stdout);
    const events = out
      .filter((l) => l.type === "event" && l.block === log)
      .map((l) => String(l.message));
    const summary = out.find((l) => l.type === "summary") as {
      blocks: { name: string; events: number }[];
    };
    const emitted = summary.blocks.find((b) => b.name === "Emg")!.events;
    expect(emitted).toBe(5001);
    expect(events).toEqual([
      "cannot write: ENOSPC: no space left on device, write; the log of 'Emg' counts its events " +
        "as lost until a write succeeds again (tried every 5 s)",
      `the log of 'Emg' lost ${emitted} events in all (0 lines written)`,
    ]);
    // The other log is whole.
    expect(readFileSync(join(dir, "rec/Env.txt"), "utf8").trimEnd().split("\n").length).toBe(
      emitted,
    );
    expect(r.code).toBe(1);
  });
});
