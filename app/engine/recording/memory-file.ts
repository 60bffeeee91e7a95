/**
 * A file kept in memory: where the runtime cannot write files (the browser build), a session
 * recording goes here and its bytes are handed to the page when it stops (a download).
 */
import type { FileWriteHandle } from "../block";

/** Bytes a recording kept in memory may take before it stops (1 GiB). */
export const MEMORY_FILE_LIMIT = 1 << 30;

export class MemoryFile implements FileWriteHandle {
  private buf = new Uint8Array(1 << 16);
  private used = 0;
  private closed = false;

  constructor(
    readonly path: string,
    private readonly limit = MEMORY_FILE_LIMIT,
  ) {}

  get size(): number {
    return this.used;
  }

  /** A copy of the bytes written. */
  get bytes(): Uint8Array {
    return this.buf.slice(0, this.used);
  }

  write(bytes: Uint8Array): void {
    if (this.closed) throw new Error(`${this.path} is closed`);
    const need = this.used + bytes.length;
    if (need > this.limit) {
      throw new Error(
        `the recording kept in memory would exceed ${Math.round(this.limit / 2 ** 20)} MiB`,
      );
    }
    if (need > this.buf.length) this.grow(need);
    this.buf.set(bytes, this.used);
    this.used = need;
  }

  writeAt(bytes: Uint8Array, position: number): void {
    if (this.closed) throw new Error(`${this.path} is closed`);
    if (!(position >= 0 && position + bytes.length <= this.used)) {
      throw new Error(`${this.path}: cannot overwrite bytes that were not written`);
    }
    this.buf.set(bytes, position);
  }

  sync(): void {}

  close(): void {
    this.closed = true;
  }

  private grow(need: number): void {
    let cap = this.buf.length;
    while (cap < need) cap *= 2;
    const next = new Uint8Array(Math.min(cap, this.limit));
    next.set(this.buf.subarray(0, this.used));
    this.buf = next;
  }
}
