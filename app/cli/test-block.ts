/**
 * `mosaic test-block FILE...`: the block contract on a user's block modules, PASS/FAIL per check.
 * Each module is tested in a child process (this command with `--in-process`) under a time limit:
 * a block whose `process` never returns fails the check it hangs in instead of hanging the command.
 */
import { spawn } from "node:child_process";
import { parseArgs } from "node:util";
import { CHECK_NAMES, type CheckResult } from "../engine/block-contract";
import { testBlockFile } from "../host/test-block";

export function testBlockHelp(): string {
  return `  mosaic test-block FILE... [--timeout S]
      Runs the contract every built-in block passes on each block a user's module defines
      (docs/writing-blocks.md): docs, defaults validate, frame splitting, reset repeats,
      dispose twice, garbage params. Prints PASS or FAIL per check; exit 0 when all pass, 1 when
      a check fails, 2 when a module cannot be loaded. The module's \`contract\` export gives
      each block's params and inputs (default: its defaults, 2 channels at 100 Hz). A module
      whose checks take longer than --timeout S (default 60) fails the check that hangs.`;
}

type Print = (s: string) => void;

const resultLine = (r: CheckResult): string => `  ${r.ok ? "PASS" : "FAIL"} ${r.name}: ${r.detail}`;

/** Tests one module here (but the `skip` blocks), printing as it goes; the exit code (0, 1 or 2). */
async function inProcess(
  file: string,
  skip: ReadonlySet<string>,
  out: Print,
  err: Print,
): Promise<number> {
  let current = "";
  let failed = 0;
  let count = 0;
  const close = (): void => {
    if (!current) return;
    out(
      failed === 0
        ? `  ${current}: all ${count} checks pass`
        : `  ${current}: ${failed} of ${count} checks fail`,
    );
  };
  const r = await testBlockFile(file, {
    skip,
    block(type) {
      close();
      current = type;
      failed = count = 0;
      out(`${file}: ${type}`);
    },
    result(c) {
      count++;
      if (!c.ok) failed++;
      out(resultLine(c));
    },
  });
  if (!r.ok) {
    for (const p of r.problems) err(p);
    return 2;
  }
  close();
  return r.blocks.some((b) => b.checks.some((c) => !c.ok)) ? 1 : 0;
}

/**
 * Tests one module in child processes: past `timeoutS` the check a block hangs in fails and a
 * new child goes on with the module's next blocks.
 */
async function inChild(file: string, timeoutS: number, out: Print, err: Print): Promise<number> {
  const tested = new Set<string>();
  let code = 0;
  for (;;) {
    const r = await child(file, tested, timeoutS, out, err);
    code = Math.max(code, r.code);
    if (!r.stuck) return code;
  }
}

/** One child run; `stuck`: the block it stopped in (undefined: it ended by itself). */
function child(
  file: string,
  tested: Set<string>,
  timeoutS: number,
  out: Print,
  err: Print,
): Promise<{ code: number; stuck?: string }> {
  const skip = [...tested].flatMap((t) => ["--skip", t]);
  const args = [process.argv[1]!, "test-block", "--in-process", ...skip, file];
  const child = spawn(process.execPath, args, { stdio: ["ignore", "pipe", "pipe"] });
  let block = "";
  let done = 0;
  let rest = "";
  child.stdout.on("data", (d: Buffer) => {
    const lines = (rest + d.toString()).split("\n");
    rest = lines.pop() ?? "";
    for (const l of lines) {
      if (!l.startsWith(" ")) {
        [block, done] = [l.slice(l.lastIndexOf(": ") + 2), 0];
        tested.add(block);
      } else if (/^ {2}(PASS|FAIL) /.test(l)) done++;
      out(l);
    }
  });
  child.stderr.on("data", (d: Buffer) => err(d.toString().replace(/\n$/, "")));
  return new Promise((resolve) => {
    const timer = setTimeout(() => {
      child.kill("SIGKILL");
      const check = CHECK_NAMES[done] ?? "the module's checks";
      out(
        `  FAIL ${check}: did not finish within ${timeoutS} s — a block that never returns (an endless loop in process, create or a timer?)`,
      );
      if (block) out(`  ${block}: stopped in ${check}`);
      resolve(block ? { code: 1, stuck: block } : { code: 1 });
    }, timeoutS * 1000);
    child.on("exit", (code) => {
      clearTimeout(timer);
      resolve({ code: code ?? 1 });
    });
  });
}

export async function cmdTestBlock(args: string[], out: Print, err: Print): Promise<number> {
  const { values, positionals: files } = parseArgs({
    args,
    allowPositionals: true,
    options: {
      timeout: { type: "string", default: "60" },
      "in-process": { type: "boolean", default: false },
      skip: { type: "string", multiple: true, default: [] },
    },
  });
  const timeoutS = Number(values.timeout);
  if (!(timeoutS > 0)) {
    err(`mosaic test-block: --timeout must be a number of seconds, not '${values.timeout}'`);
    return 2;
  }
  if (files.length === 0) {
    err("mosaic test-block: name a block module, e.g. mosaic test-block blocks/smoother.ts");
    return 2;
  }
  let code = 0;
  for (const file of files) {
    const c = values["in-process"]
      ? await inProcess(file, new Set(values.skip), out, err)
      : await inChild(file, timeoutS, out, err);
    code = Math.max(code, c);
  }
  return code;
}
