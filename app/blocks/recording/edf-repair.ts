/**
 * Repairs an EDF(+)/BDF(+) file whose recording was interrupted: the header's number of data
 * records (which the EDF spec allows to be -1 while recording, and which an older or killed
 * recorder may have left behind) is set from the file's size, and a torn last record (the bytes
 * after the last complete one) is cut off. Pure: the caller gives the file's bytes access.
 */
import { headerSize, parseEdfHeader, type EdfHeader } from "./edf-reader";
import { recordsField, RECORDS_OFFSET } from "./edf-writer";

/** What `repairEdf` needs of a file opened for reading and writing. */
export interface RepairableFile {
  readonly size: number;
  read(into: Uint8Array, position: number): number;
  writeAt(bytes: Uint8Array, position: number): void;
  truncate(length: number): void;
}

export interface EdfRepairPlan {
  header: EdfHeader;
  /** Complete data records the file holds. */
  records: number;
  /** The header's count before. */
  was: number;
  /** Bytes after the last complete record (cut off). */
  tornBytes: number;
  /** True when nothing needs changing. */
  intact: boolean;
}

/** What to change, from the header's bytes and the file's size. */
export function planEdfRepair(header: Uint8Array, fileSize: number): EdfRepairPlan {
  const h = parseEdfHeader(header);
  if (h.recordBytes <= 0) throw new Error("the header's signals hold no samples: not a recording");
  const data = Math.max(0, fileSize - h.headerBytes);
  const records = Math.floor(data / h.recordBytes);
  const tornBytes = data - records * h.recordBytes;
  return {
    header: h,
    records,
    was: h.records,
    tornBytes,
    intact: tornBytes === 0 && h.records === records,
  };
}

function readAll(f: Pick<RepairableFile, "read">, into: Uint8Array, position: number): void {
  let done = 0;
  while (done < into.length) {
    const n = f.read(into.subarray(done), position + done);
    if (n <= 0) throw new Error(`the file ends at byte ${position + done}, inside its header`);
    done += n;
  }
}

/** Reads the header of `f` and plans its repair. */
function planFile(f: Pick<RepairableFile, "size" | "read">): EdfRepairPlan {
  if (f.size < 256) {
    throw new Error(
      `${f.size} bytes: too short for an EDF/BDF header (256 bytes at least), nothing to repair`,
    );
  }
  const first = new Uint8Array(256);
  readAll(f, first, 0);
  const header = new Uint8Array(headerSize(first));
  readAll(f, header, 0);
  return planEdfRepair(header, f.size);
}

/** Bytes to overwrite in what a repair keeps. */
export interface EdfPatch {
  at: number;
  bytes: Uint8Array;
}

/**
 * The repair as `mosaic repair` writes it (app/cli/repair.ts's table by extension): keep the
 * header and the whole records, append nothing, patch the header's record count.
 */
export function planEdfFileRepair(f: Pick<RepairableFile, "size" | "read">): {
  keep: number;
  append: Uint8Array;
  patches: EdfPatch[];
  changed: boolean;
  messages: string[];
} {
  const plan = planFile(f);
  const h = plan.header;
  const seconds = (plan.records * h.recordDuration).toFixed(3);
  const messages = [
    `${h.format.toUpperCase()}+ with ${h.signals.length} signals: ${plan.records} whole data records of ${h.recordDuration} s (${seconds} s)`,
  ];
  if (plan.tornBytes > 0) messages.push(`drops a torn last record (${plan.tornBytes} bytes)`);
  const patches: EdfPatch[] = [];
  if (plan.was !== plan.records) {
    patches.push({ at: RECORDS_OFFSET, bytes: recordsField(plan.records) });
    messages.push(`sets the header's number of data records from ${plan.was} to ${plan.records}`);
  }
  return {
    keep: h.headerBytes + plan.records * h.recordBytes,
    append: new Uint8Array(0),
    patches,
    changed: !plan.intact,
    messages,
  };
}

/** Repairs `f` in place; returns one line saying what was done. */
export function repairEdf(f: RepairableFile): string {
  const plan = planFile(f);
  const d = plan.header.recordDuration;
  const what = `${plan.records} data records (${(plan.records * d).toFixed(3)} s)`;
  if (plan.intact) return `intact: ${what}`;
  const done: string[] = [];
  if (plan.tornBytes > 0) {
    f.truncate(plan.header.headerBytes + plan.records * plan.header.recordBytes);
    done.push(`cut a torn last record (${plan.tornBytes} bytes)`);
  }
  if (plan.was !== plan.records) {
    f.writeAt(recordsField(plan.records), RECORDS_OFFSET);
    done.push(`set the number of data records from ${plan.was} to ${plan.records}`);
  }
  return `repaired: ${done.join(", ")}; ${what}`;
}
