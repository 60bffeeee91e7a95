/**
 * The Python bridge: framing in TypeScript (against the layout of mosaic_sidecar/protocol.py),
 * and real sidecar processes (the uv environment's interpreter, started directly for speed):
 * load, calls in order, errors, restart after kill -9 with backoff, clean close, start failures.
 */
import { existsSync, mkdtempSync, readFileSync, writeFileSync } from "node:fs";
import { getPriority, tmpdir } from "node:os";
import { join } from "node:path";
import { describe, expect, test } from "vitest";
import type { PythonCallError, PythonLoadOptions, PythonSidecarState } from "../app/engine/io";
import {
  createPythonBridge,
  decodeArrayInto,
  encodeCall,
  encodeMessage,
  MessageReader,
  MSG,
  PythonLoadError,
  SIDECAR_NICE,
} from "./python";

/** This process's nice value. */
const osPriorityNice = (): number => getPriority();

const ROOT = join(import.meta.dirname, "..");
const PROJECT = join(ROOT, "native-bridges", "python");
const VENV_PYTHON = join(PROJECT, ".venv", "bin", "python");
const haveVenv = existsSync(VENV_PYTHON);

describe("framing", () => {
  test("a call message: header, array prefix padded to 8 bytes, raw f64 values", () => {
    const v = new Float64Array([NaN, -0, 5e-324, Infinity, -1e308, 0.1]);
    const b = encodeCall(7, v, 2, 3);
    expect(b.subarray(0, 4).toString("latin1")).toBe("MSPY");
    expect([b.readUInt16LE(4), b.readUInt16LE(6), b.readUInt32LE(8), b.readUInt32LE(12)]).toEqual([
      1,
      MSG.call,
      7,
      16 + 48,
    ]);
    expect([b[16], b[17], b.readUInt32LE(20), b.readUInt32LE(24)]).toEqual([1, 2, 2, 3]);
    expect(Buffer.from(b.subarray(32)).equals(Buffer.from(v.buffer))).toBe(true);
  });

  test("arrays decode bit for bit (NaN payloads and -0 included); f32 converts; errors are words", () => {
    const raw = new BigUint64Array([0x7ff8000000000001n, 0x8000000000000000n, 1n]);
    const src = new Float64Array(raw.buffer);
    const msg = encodeCall(1, src, 1, 3);
    const out = new Float64Array(3);
    expect(decodeArrayInto(msg.subarray(16), 0, out)).toBe(3);
    expect([...new BigUint64Array(out.buffer)]).toEqual([...raw]);
    const f32 = Buffer.alloc(16 + 8);
    f32.writeUInt8(2, 0);
    f32.writeUInt8(2, 1);
    f32.writeUInt32LE(1, 4);
    f32.writeUInt32LE(2, 8);
    f32.writeFloatLE(1.5, 16);
    f32.writeFloatLE(-2, 20);
    const two = new Float64Array(2);
    expect(decodeArrayInto(f32, 0, two)).toBe(2);
    expect([...two]).toEqual([1.5, -2]);
    expect(decodeArrayInto(f32, 0, new Float64Array(3))).toBe("2 values, expected 3");
    expect(decodeArrayInto(f32.subarray(0, 20), 0, two)).toMatch(/does not match/);
  });

  test("the reader splits a stream cut anywhere into messages, and refuses garbage", () => {
    const got: [number, number, string][] = [];
    const r = new MessageReader((t, id, p) => got.push([t, id, p.toString()]));
    const stream = Buffer.concat([
      encodeMessage(MSG.ok, 1, Buffer.from('{"a":1}')),
      encodeMessage(MSG.hello, 2),
      encodeMessage(MSG.error, 3, Buffer.from("x")),
    ]);
    for (let i = 0; i < stream.length; i += 5)
      expect(r.push(stream.subarray(i, i + 5))).toBeUndefined();
    expect(got).toEqual([
      [MSG.ok, 1, '{"a":1}'],
      [MSG.hello, 2, ""],
      [MSG.error, 3, "x"],
    ]);
    expect(new MessageReader(() => {}).push(Buffer.from("hello world, not a frame"))).toMatch(
      /bad magic/,
    );
  });
});

interface Recorder {
  results: { id: number; values: number[]; us: number }[];
  errors: { id: number; e: PythonCallError }[];
  states: [PythonSidecarState, string | undefined][];
  output: string[];
}

function options(dir: string, o: Partial<PythonLoadOptions> = {}): [PythonLoadOptions, Recorder] {
  const rec: Recorder = { results: [], errors: [], states: [], output: [] };
  return [
    {
      module: "m.py",
      function: "f",
      params: {},
      inputShape: { rows: 1, cols: 3 },
      cwd: dir,
      label: "block 'Py'",
      onResult: (id, values, us) => rec.results.push({ id, values: [...values], us }),
      onError: (id, e) => rec.errors.push({ id, e }),
      onStatus: (s, m) => rec.states.push([s, m]),
      onOutput: (l) => rec.output.push(l),
      ...o,
    },
    rec,
  ];
}

const direct = createPythonBridge({
  command: (cwd) => ({
    file: VENV_PYTHON,
    args: ["-m", "mosaic_sidecar"],
    env: { PYTHONPATH: [PROJECT, cwd].join(":") },
  }),
  backoffMs: { first: 100, max: 400 },
});

async function until(cond: () => boolean, ms = 20_000): Promise<void> {
  const t0 = Date.now();
  while (!cond()) {
    if (Date.now() - t0 > ms) throw new Error("timed out");
    await new Promise((r) => setTimeout(r, 10));
  }
}

const alive = (pid: number): boolean => {
  try {
    process.kill(pid, 0);
    return true;
  } catch {
    return false;
  }
};

describe.skipIf(!haveVenv)("real sidecar processes", () => {
  const dir = mkdtempSync(join(tmpdir(), "mosaic-pybridge-"));
  writeFileSync(
    join(dir, "m.py"),
    [
      "import numpy as np",
      "def init(p):",
      "    return {'n': 0, 'k': p.get('k', 1)}",
      "def f(x, s):",
      "    s['n'] += 1",
      "    if x[0, 0] < 0:",
      "        raise ValueError('negative')",
      "    if x[0, 0] == 7:",
      "        print('seven!')",
      "    return x * s['k'] + s['n']",
    ].join("\n"),
  );

  test("load, calls answered in order with compute times, exceptions, print, reset", async () => {
    const [o, rec] = options(dir, { init: "init", params: { k: 10 } });
    const sc = await direct.load(o);
    expect(sc.outputShape).toEqual({ rows: 1, cols: 3 });
    expect(sc.version).toMatch(/^Python 3\.11\.\d+, NumPy \d/);
    expect(sc.ready).toBe(true);
    const ids = [1, 2, -1, 7].map((v) => sc.call(new Float64Array([v, 0, 0])));
    await until(() => rec.results.length + rec.errors.length === 4);
    expect(rec.results.map((r) => [r.id, r.values])).toEqual([
      [ids[0], [11, 1, 1]],
      [ids[1], [22, 2, 2]],
      [ids[3], [74, 4, 4]],
    ]);
    expect(rec.results.every((r) => r.us >= 0 && r.us < 1e6)).toBe(true);
    expect(rec.errors[0]!.id).toBe(ids[2]);
    expect(rec.errors[0]!.e.message).toMatch(/^ValueError: negative \(at .*m\.py:7, in f\)$/);
    expect(rec.errors[0]!.e.traceback).toMatch(/Traceback[\s\S]*line 7, in f[\s\S]*ValueError/);
    await until(() => rec.output.includes("seven!"));
    sc.reset();
    sc.call(new Float64Array([1, 1, 1]));
    await until(() => rec.results.length === 4);
    expect(rec.results[3]!.values).toEqual([11, 11, 11]);
    const pid = sc.pid!;
    sc.close();
    expect(sc.ready).toBe(false);
    await until(() => !alive(pid));
    expect(rec.states.at(-1)![0]).toBe("closed");
  });

  test("kill -9: in-flight calls fail as crashes, the process is restarted with a fresh state", async () => {
    const [o, rec] = options(dir, { init: "init" });
    const sc = await direct.load(o);
    const first = sc.pid!;
    sc.call(new Float64Array([1, 0, 0]));
    await until(() => rec.results.length === 1);
    process.kill(first, "SIGKILL");
    await until(() => rec.states.some(([s]) => s === "restarting"));
    expect(sc.ready).toBe(false);
    expect(sc.call(new Float64Array([1, 0, 0]))).toBe(-1);
    expect(rec.states.find(([s]) => s === "restarting")![1]).toMatch(
      new RegExp(`pid ${first}\\) killed by SIGKILL; restarting in 0\\.1 s`),
    );
    await until(() => sc.ready);
    expect(sc.pid).not.toBe(first);
    expect(rec.states.at(-1)).toEqual(["ready", `restarted (pid ${sc.pid})`]);
    sc.call(new Float64Array([1, 0, 0]));
    await until(() => rec.results.length === 2);
    expect(rec.results[1]!.values).toEqual([2, 1, 1]); // n restarted at 1: a fresh init
    sc.close();
  });

  test("load errors reject with their kind and message", async () => {
    const [o] = options(dir, { module: "nowhere.py" });
    const e = await direct.load(o).catch((x: unknown) => x);
    expect(e).toBeInstanceOf(PythonLoadError);
    expect((e as PythonLoadError).kind).toBe("missing-module");
    expect((e as Error).message).toMatch(/module file not found: .*nowhere\.py/);
    const [o2] = options(dir, { function: "g" });
    await expect(direct.load(o2)).rejects.toMatchObject({
      kind: "missing-function",
      message: expect.stringMatching(/has no function 'g' \(it defines: f, init\)/),
    });
  });

  test("hard limit: a hung call is reported late, then its process is killed and restarted", async () => {
    writeFileSync(
      join(dir, "hang.py"),
      "import time\ndef f(x):\n    if x[0, 0] < 0:\n        time.sleep(1e6)\n    return x\n",
    );
    const late: number[] = [];
    const [o, rec] = options(dir, {
      module: "hang.py",
      hardLimitMs: 400,
      lateAfterMs: 50,
      onLate: (_id, ms) => late.push(ms),
    });
    const sc = await direct.load(o);
    const first = sc.pid!;
    const hung = sc.call(new Float64Array([-1, 0, 0]));
    const behind = sc.call(new Float64Array([1, 0, 0]));
    await until(() => rec.states.some(([s]) => s === "restarting"));
    expect(late.length).toBeGreaterThan(2);
    expect(late.every((ms) => ms > 50 && ms <= 700)).toBe(true);
    expect(rec.errors.map((e) => [e.id, e.e.kind])).toEqual([
      [hung, "timeout"],
      [behind, "crash"],
    ]);
    expect(rec.errors[0]!.e.message).toMatch(/call ran longer than its hard limit of 0\.4 s/);
    expect(rec.states.find(([s]) => s === "restarting")![1]).toMatch(
      new RegExp(
        `^a call ran longer than its hard limit of 0\\.4 s \\(HardLimit\\): the Python process \\(pid ${first}\\) was killed; restarting in 0\\.1 s$`,
      ),
    );
    await until(() => !alive(first));
    await until(() => sc.ready);
    expect(sc.pid).not.toBe(first);
    sc.call(new Float64Array([2, 0, 0]));
    await until(() => rec.results.length === 1);
    sc.close();
  });

  test("a slow init on reset does not count against the calls that wait behind it", async () => {
    // init runs twice at load (the probe's state, then the real one), then sleeps on reset.
    writeFileSync(
      join(dir, "slowinit.py"),
      "import time\nn = [0]\ndef init(p):\n    n[0] += 1\n    if n[0] > 2:\n        time.sleep(0.6)\n    return 0\ndef f(x, s):\n    return x\n",
    );
    const [o, rec] = options(dir, { module: "slowinit.py", init: "init", hardLimitMs: 300 });
    const sc = await direct.load(o);
    sc.reset(); // init sleeps 0.6 s: longer than the hard limit
    sc.call(new Float64Array([1, 0, 0]));
    await until(() => rec.results.length === 1);
    expect(rec.states.some(([s]) => s === "restarting")).toBe(false);
    sc.close();
  });

  test("close() ends a process stuck in a call at once", async () => {
    const [o] = options(dir, { module: "hang.py" });
    const sc = await direct.load(o);
    const pid = sc.pid!;
    sc.call(new Float64Array([-1, 0, 0]));
    await new Promise((r) => setTimeout(r, 200));
    const t0 = Date.now();
    sc.close();
    await until(() => !alive(pid), 3000);
    expect(Date.now() - t0).toBeLessThan(1500);
  });

  test("the sidecar runs niced, with its memory limited; a MemoryError says which limit", async () => {
    writeFileSync(
      join(dir, "mem.py"),
      "import numpy as np\ndef f(x):\n    return x + np.empty(int(x[0, 0]) * 131072)[:1].size * 0\n",
    );
    const [o, rec] = options(dir, { module: "mem.py", memoryLimitMb: 250 });
    const sc = await direct.load(o);
    const stat = readFileSync(`/proc/${sc.pid!}/stat`, "utf8");
    const nice = Number(stat.slice(stat.lastIndexOf(")") + 2).split(" ")[16]);
    expect(nice).toBe(Math.min(19, osPriorityNice() + SIDECAR_NICE));
    sc.call(new Float64Array([300, 0, 0]));
    sc.call(new Float64Array([10, 0, 0]));
    await until(() => rec.errors.length + rec.results.length === 2);
    expect(rec.errors[0]!.e.kind).toBe("memory");
    expect(rec.errors[0]!.e.message).toMatch(
      /^MemoryError: .* the sidecar's memory limit \(MemoryLimit: 250 MB\) was reached/,
    );
    expect(rec.results.map((r) => r.values[0])).toEqual([10]);
    sc.close();
  });

  test("the default command starts the uv environment's interpreter as the host's own child", async () => {
    const bridge = createPythonBridge();
    const [o, rec] = options(dir, { init: "init" });
    const sc = await bridge.load(o);
    const pid = sc.pid!;
    const stat = readFileSync(`/proc/${pid}/stat`, "utf8");
    const ppid = Number(stat.slice(stat.lastIndexOf(")") + 2).split(" ")[1]);
    expect(ppid).toBe(process.pid);
    expect(readFileSync(`/proc/${pid}/cmdline`, "utf8").split("\0").slice(1, 3)).toEqual([
      "-m",
      "mosaic_sidecar",
    ]);
    sc.call(new Float64Array([1, 2, 3]));
    await until(() => rec.results.length === 1);
    sc.close();
    await until(() => !alive(pid));
  });

  test("a sidecar that cannot start says why", async () => {
    const broken = createPythonBridge({
      command: () => ({ file: join(dir, "no-such-python"), args: [], env: {} }),
    });
    const [o] = options(dir);
    await expect(broken.load(o)).rejects.toMatchObject({
      kind: "start",
      message: expect.stringMatching(
        /did not start: cannot start .*no-such-python: spawn .* ENOENT/,
      ),
    });
  });
});
