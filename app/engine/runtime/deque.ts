/** A growable ring-buffer FIFO (amortised O(1), no allocation in steady state). */
export class Deque<T> {
  private buf: (T | undefined)[];
  private head = 0;
  private size = 0;

  constructor(capacity = 16) {
    let c = 1;
    while (c < capacity) c *= 2;
    this.buf = new Array<T | undefined>(c);
  }

  get length(): number {
    return this.size;
  }

  push(x: T): void {
    if (this.size === this.buf.length) this.grow();
    this.buf[(this.head + this.size) & (this.buf.length - 1)] = x;
    this.size++;
  }

  shift(): T | undefined {
    if (this.size === 0) return undefined;
    const x = this.buf[this.head];
    this.buf[this.head] = undefined;
    this.head = (this.head + 1) & (this.buf.length - 1);
    this.size--;
    return x;
  }

  peek(): T | undefined {
    return this.size === 0 ? undefined : this.buf[this.head];
  }

  /** The i-th element from the front. */
  at(i: number): T | undefined {
    if (i < 0 || i >= this.size) return undefined;
    return this.buf[(this.head + i) & (this.buf.length - 1)];
  }

  clear(): void {
    while (this.size > 0) this.shift();
  }

  private grow(): void {
    const old = this.buf;
    const nb = new Array<T | undefined>(old.length * 2);
    for (let i = 0; i < this.size; i++) nb[i] = old[(this.head + i) & (old.length - 1)];
    this.buf = nb;
    this.head = 0;
  }
}
