/**
 * Status text without allocating on every event: a block asks `due(t)` with the event (or tick)
 * time and rebuilds its text only when it returns true (at most every `interval` seconds of
 * pipeline time, so the virtual clock gives the same texts on every run).
 */
export class TextThrottle {
  private last = -Infinity;

  constructor(readonly interval = 0.25) {}

  due(t: number): boolean {
    if (t - this.last >= this.interval || t < this.last) {
      this.last = t;
      return true;
    }
    return false;
  }

  /** The next `due` returns true. */
  reset(): void {
    this.last = -Infinity;
  }
}
