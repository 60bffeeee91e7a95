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

/** A whole number with thousands separators: 3400 → "3,400" (the same in every locale). */
export function formatCount(n: number): string {
  const s = String(Math.trunc(Math.abs(n)));
  const grouped = s.replace(/\B(?=(\d{3})+(?!\d))/g, ",");
  return n < 0 ? `-${grouped}` : grouped;
}

/** "1 row", "3,400 rows". */
export const plural = (n: number, noun: string): string =>
  `${formatCount(n)} ${noun}${n === 1 ? "" : "s"}`;

/** A short vector for status texts: [1, 0, 0.5] (values in shortest round-trip form). */
export function formatVector(v: ArrayLike<number>, max = 8): string {
  const parts: string[] = [];
  const n = Math.min(v.length, max);
  for (let i = 0; i < n; i++) parts.push(String(v[i]));
  if (v.length > max) parts.push(`… (${v.length} values)`);
  return `[${parts.join(", ")}]`;
}
