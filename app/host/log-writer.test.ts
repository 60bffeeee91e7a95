import { mkdtempSync, readFileSync } from "node:fs";
import { tmpdir } from "node:os";
import { join } from "node:path";
import { afterEach, describe, expect, test, vi } from "vitest";
import { Frame, vectorShape } from "../engine/frame";
import { SabRing } from "../engine/runtime/sab-ring";

/** Failures injected into writeSync: each entry is the bytes a call writes before it throws. */
const faults: number[] = [];
vi.mock("node:fs", async (importOriginal) => {
  const fs = await importOriginal<typeof import("node:fs")>();
  return {
    ...fs,
    writeSync: (fd: number, buf: Buffer, off: number, len: number, pos: number | null) => {
      const f = faults.shift();
      if (f === undefined) return fs.writeSync(fd, buf, off, len, pos);
      if (f > 0) return fs.writeSync(fd, buf, off, Math.min(f, len), pos);
      throw Object.assign(new Error("ENOSPC: no space left on device, write"), { code: "ENOSPC" });
    },
  };
});

const { LogWriter, RETRY_S } = await import("./log-writer");

afterEach(() => {
  faults.length = 0;
  vi.useRealTimers();
});

function setup() {
  const dir = mkdtempSync(join(tmpdir(), "mosaic-logw-"));
  const errors: string[] = [];
  const w = new LogWriter(dir, { onError: (_f, m) => errors.push(m) });
  const init = SabRing.allocate(64, 1);
  const ring = new SabRing(init);
  const file = w.open("k", "A", "out", true, "a.txt", vectorShape(1), init);
  let t = 0;
  const put = (n: number) => {
    const ts = Array.from({ length: n }, () => ++t);
    ring.write(
      Frame.from(
        vectorShape(1),
        ts,
        ts.map((x) => [x]),
      ),
    );
  };
  return { w, errors, put, file };
}

describe("LogWriter", () => {
  test("writes lines; a partial write is completed", () => {
    const { w, put, file } = setup();
    put(3);
    faults.push(10); // the first call writes 10 bytes only; the rest follows
    w.drainAll();
    w.closeAll();
    expect(readFileSync(file, "utf8")).toBe("1.000000,1\n2.000000,2\n3.000000,3\n");
  });

  test("a write failing halfway: whole lines kept, the torn one cut off, the rest counted; retried after RETRY_S", () => {
    vi.useFakeTimers({ toFake: ["performance"] });
    const { w, errors, put, file } = setup();
    put(3);
    faults.push(15, -1); // 15 bytes: line 1 and part of line 2, then ENOSPC
    w.drainAll();
    expect(readFileSync(file, "utf8")).toBe("1.000000,1\n");
    expect(w.stats()[0]).toMatchObject({ lines: 1, lost: 2 });
    put(2);
    w.drainAll(); // not tried again yet: counted
    expect(w.stats()[0]).toMatchObject({ lines: 1, lost: 4 });
    vi.advanceTimersByTime(RETRY_S * 1000 + 1);
    put(1);
    w.drainAll(); // tried again: it goes
    expect(w.stats()[0]).toMatchObject({ lines: 2, lost: 4, error: undefined });
    w.closeAll();
    expect(readFileSync(file, "utf8")).toBe("1.000000,1\n6.000000,6\n");
    expect(errors).toEqual([
      "cannot write: ENOSPC: no space left on device, write; the log of 'A' counts its events as lost until a write succeeds again (tried every 5 s)",
      "the log of 'A' lost 4 events in all (2 lines written)",
    ]);
  });

  test("a full ring: one error when it first drops, the count at close", () => {
    const { w, errors, put } = setup();
    put(100); // 64 fit
    w.drainAll();
    put(80);
    w.drainAll();
    w.closeAll();
    expect(errors).toEqual([
      "the log of 'A' could not keep up and lost 36 events; the disk may be too slow (further losses are counted, and reported when the log closes)",
      "the log of 'A' lost 52 events in all (128 lines written)",
    ]);
  });
});
