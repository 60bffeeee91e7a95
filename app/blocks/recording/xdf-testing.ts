/** Test support for the XDF recorder: a file in memory. */
import type { FileWriteHandle } from "../../engine";
import { ByteBuffer } from "./xdf-writer";

/** A FileWriteHandle in memory. */
export class MemoryFile implements FileWriteHandle {
  private buf = new ByteBuffer(1024);
  closed = false;
  syncs = 0;
  constructor(readonly path = "mem.xdf") {}
  get size(): number {
    return this.buf.length;
  }
  get bytes(): Uint8Array {
    return this.buf.used.slice();
  }
  write(bytes: Uint8Array): void {
    if (this.closed) throw new Error(`${this.path} is closed`);
    this.buf.put(bytes);
  }
  writeAt(bytes: Uint8Array, position: number): void {
    this.buf.bytes.set(bytes, position);
  }
  sync(): void {
    this.syncs++;
  }
  close(): void {
    this.closed = true;
  }
}
