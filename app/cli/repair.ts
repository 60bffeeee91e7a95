/**
 * `mosaic repair FILE...`: makes an interrupted recording (a killed process, a full disk) whole
 * again. One entry per file extension in `REPAIRS` plans the repair of its format (what of the
 * file to keep, what to append); this module writes the plan, as a copy beside the file
 * (`NAME.repaired.EXT`, never overwriting) or, with `--in-place`, into the file itself.
 */
import { closeSync, fdatasyncSync, openSync, truncateSync, writeSync } from "node:fs";
import { extname, resolve } from "node:path";
import { parseArgs } from "node:util";
import type { FileReadHandle } from "../engine/block";
import { openFileRead } from "../host/file-read";
import { openFileWrite } from "../host/file-write";
import { planEdfFileRepair, planXdfRepair, type RepairPlan } from "../host/recording-repair";

/** Bytes to overwrite in what a repair keeps (a header field, such as EDF's record count). */
interface Patch {
  at: number;
  bytes: Uint8Array;
}

type Plan = RepairPlan & { patches?: readonly Patch[] };

export interface Repairer {
  /** The format's name, for messages. */
  format: string;
  /** Scans the file and says how to repair it; throws when it is not a file of this format. */
  plan(src: FileReadHandle): Plan;
}

/** Repairs by file extension (lower case, with the dot). */
export const REPAIRS: Readonly<Record<string, Repairer>> = {
  ".xdf": { format: "XDF", plan: planXdfRepair },
  ".edf": { format: "EDF+", plan: planEdfFileRepair },
  ".bdf": { format: "BDF+", plan: planEdfFileRepair },
};

export function repairHelp(): string {
  return `  mosaic repair FILE... [--in-place | --out PATH] [--check]
      Makes an interrupted recording readable and whole again (formats: ${Object.keys(REPAIRS).join(", ")}).
      XDF: a torn last chunk is dropped and every stream without a StreamFooter gets one (first
      and last timestamp, sample count, clock offsets), as LabRecorder writes it at the end.
      EDF+/BDF+: a torn last data record is dropped and the header's number of data records is
      set from the file's size (-1 or a stale count, as older or killed recorders leave it).
      By default the repaired file is written beside the original as NAME.repaired.EXT (an
      existing file is never overwritten) and the original is left as it is.
        --in-place  repair the file itself: cut the torn tail, append the footers
        --out PATH  write the repaired copy to PATH (one FILE only)
        --check     only say what a repair would do; exit 1 when a file needs one
      Exit 0 when every file is whole or repaired, 1 when one could not be (or --check found
      one to repair), 2 on a usage error or a file of an unknown format.`;
}

/** NAME.xdf → NAME.repaired.xdf */
export function repairedName(file: string): string {
  const ext = extname(file);
  return `${file.slice(0, file.length - ext.length)}.repaired${ext}`;
}

const PIECE = 1 << 20;

/** Writes the first `plan.keep` bytes of `src` (patched) and `plan.append` to a new file `out`. */
function writeCopy(src: FileReadHandle, plan: Plan, out: string): void {
  const w = openFileWrite(out);
  try {
    const buf = new Uint8Array(PIECE);
    for (let pos = 0; pos < plan.keep;) {
      const want = Math.min(PIECE, plan.keep - pos);
      const n = src.read(buf.subarray(0, want), pos);
      if (n <= 0) throw new Error(`${src.path} ended at byte ${pos} while being copied`);
      w.write(buf.subarray(0, n));
      pos += n;
    }
    w.write(plan.append);
    for (const p of plan.patches ?? []) w.writeAt(p.bytes, p.at);
    w.sync();
  } finally {
    w.close();
  }
}

/** Cuts `file` to `plan.keep` bytes, applies `plan.patches` and appends `plan.append`. */
function writeInPlace(file: string, plan: Plan): void {
  truncateSync(file, plan.keep);
  const fd = openSync(file, "r+");
  try {
    for (const p of plan.patches ?? []) writeSync(fd, p.bytes, 0, p.bytes.length, p.at);
    for (let done = 0; done < plan.append.length;) {
      done += writeSync(fd, plan.append, done, plan.append.length - done, plan.keep + done);
    }
    fdatasyncSync(fd);
  } finally {
    closeSync(fd);
  }
}

interface Options {
  inPlace: boolean;
  out: string | undefined;
  check: boolean;
}

/** Repairs one file; returns its exit code (0, 1 or 2). */
function repairOne(
  given: string,
  o: Options,
  out: (s: string) => void,
  err: (s: string) => void,
): number {
  const file = resolve(given);
  const repairer = REPAIRS[extname(file).toLowerCase()];
  if (repairer === undefined) {
    err(
      `mosaic repair: ${given}: unknown format '${extname(file) || "(no extension)"}' (repairs: ${Object.keys(REPAIRS).join(", ")})`,
    );
    return 2;
  }
  let src: FileReadHandle;
  try {
    src = openFileRead(file);
  } catch (e) {
    err(`mosaic repair: ${(e as Error).message}`);
    return 1;
  }
  try {
    const plan = repairer.plan(src);
    for (const m of plan.messages) out(`${given}: ${m}`);
    if (!plan.changed) return 0;
    if (o.check) return 1;
    if (o.inPlace) {
      src.close();
      writeInPlace(file, plan);
      out(`${given}: repaired in place`);
    } else {
      const target = resolve(o.out ?? repairedName(file));
      writeCopy(src, plan, target);
      out(`${given}: repaired copy written to ${target}`);
    }
    return 0;
  } catch (e) {
    err(`mosaic repair: ${given}: ${(e as Error).message}`);
    return 1;
  } finally {
    src.close();
  }
}

export function cmdRepair(
  args: string[],
  out: (s: string) => void,
  err: (s: string) => void,
): number {
  let parsed;
  try {
    parsed = parseArgs({
      args,
      allowPositionals: true,
      options: {
        "in-place": { type: "boolean", default: false },
        out: { type: "string" },
        check: { type: "boolean", default: false },
        help: { type: "boolean", short: "h", default: false },
      },
    });
  } catch (e) {
    err(`mosaic repair: ${(e as Error).message}`);
    return 2;
  }
  const { values, positionals } = parsed;
  if (values.help) {
    out(repairHelp());
    return 0;
  }
  if (positionals.length === 0) {
    err("mosaic repair: give the recording(s) to repair, e.g. mosaic repair session.xdf");
    return 2;
  }
  if (values["in-place"] && values.out !== undefined) {
    err("mosaic repair: --in-place and --out exclude each other");
    return 2;
  }
  if (values.out !== undefined && positionals.length > 1) {
    err("mosaic repair: --out takes one FILE only");
    return 2;
  }
  const o: Options = { inPlace: values["in-place"], out: values.out, check: values.check };
  let code = 0;
  for (const f of positionals) code = Math.max(code, repairOne(f, o, out, err));
  return code;
}
