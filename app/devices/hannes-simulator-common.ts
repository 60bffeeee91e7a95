/**
 * What the three Hannes simulators share (hannes-dongle-simulator.ts, hannes-gui-simulator.ts,
 * hannes-emg-simulator.ts): the packet frame as docs/protocols.md ("Hannes") describes it, a
 * reporter that prints a live state on change at most a few times a second, and the checks of
 * `mosaic simulate hannes…`'s options. Written from the protocol, not from the blocks' code.
 */

/** A packet's first byte (`%`) and its end (`&`, CR, LF). */
export const FRAME_START = 0x25;
export const FRAME_END = [0x26, 0x0d, 0x0a] as const;

/** The options of `mosaic simulate`, as `node:util` parseArgs gives them. */
export type SimulatorValues = Record<string, string | boolean | undefined>;

/**
 * An error that `mosaic simulate` ends with exit status 1 (the device or port is not available:
 * missing, busy) rather than 2 (a bad option).
 */
export class DeviceUnavailableError extends Error {
  readonly exitCode = 1;
}

/** A number option, checked: `--name` must be a (whole) number in [min, max]. */
export function numberOption(
  v: SimulatorValues,
  name: string,
  o: { integer: boolean; min: number; max: number; unit?: string },
): number | undefined {
  const raw = v[name];
  if (raw === undefined) return undefined;
  const n = Number(raw);
  const what = o.integer ? "a whole number" : "a number";
  const range = `${o.min}…${o.max}${o.unit ? ` ${o.unit}` : ""}`;
  if (typeof raw !== "string" || raw.trim() === "" || !Number.isFinite(n)) {
    throw new Error(`--${name} must be ${what} (${range}), not '${String(raw)}'`);
  }
  if ((o.integer && !Number.isInteger(n)) || n < o.min || n > o.max) {
    throw new Error(`--${name} must be ${what} in ${range}, not '${raw}'`);
  }
  return n;
}

/** A UDP port number: 0…65535 (0: any free port). */
export function checkPort(port: number, what: string): void {
  if (!Number.isInteger(port) || port < 0 || port > 65535) {
    throw new Error(`${what} must be a port number 0…65535, not ${port}`);
  }
}

/** `HOST:PORT` (IPv6 in brackets: `[::1]:11000`) → host and port; throws saying what is wrong. */
export function hostPort(text: string, option: string): { host: string; port: number } {
  const m = /^(?:\[([^\]]+)\]|([^:[\]]+)):(\d{1,5})$/.exec(text.trim());
  const port = m ? Number(m[3]) : NaN;
  if (!m || port < 1 || port > 65535) {
    throw new Error(
      `--${option} takes HOST:PORT with a port 1…65535, e.g. 127.0.0.1:11000; not '${text}'`,
    );
  }
  return { host: (m[1] ?? m[2])!, port };
}

/** The message of a socket or port error, without Node's "Error: " and errno prefixes. */
export function errorText(e: unknown): string {
  return (e instanceof Error ? e.message : String(e)).replace(/^Error:\s*/, "");
}

/**
 * Prints a state line when it changed, at most once per `intervalMs`; a change inside the
 * interval is printed when the interval ends, so the last state is always shown.
 */
export class StateReporter {
  private last = "";
  private pending: string | undefined;
  private lastAt = -Infinity;
  private timer: ReturnType<typeof setTimeout> | undefined;

  constructor(
    private readonly print: (line: string) => void,
    private readonly intervalMs = 250,
  ) {}

  /** Offers the current state; prints it now, later or not at all (unchanged). */
  update(line: string): void {
    if (line === this.last) {
      this.pending = undefined;
      return;
    }
    const now = performance.now();
    if (now - this.lastAt >= this.intervalMs && this.timer === undefined) {
      this.emit(line, now);
      return;
    }
    this.pending = line;
    this.timer ??= setTimeout(
      () => {
        this.timer = undefined;
        const p = this.pending;
        this.pending = undefined;
        if (p !== undefined && p !== this.last) this.emit(p, performance.now());
      },
      Math.max(0, this.intervalMs - (now - this.lastAt)),
    );
  }

  /** Prints a waiting state now and stops the timer. */
  flush(): void {
    if (this.timer) clearTimeout(this.timer);
    this.timer = undefined;
    const p = this.pending;
    this.pending = undefined;
    if (p !== undefined && p !== this.last) this.emit(p, performance.now());
  }

  private emit(line: string, now: number): void {
    this.last = line;
    this.lastAt = now;
    this.print(line);
  }
}

/**
 * Whether the n-th malformed input (from 1) is printed: the first ten, then every hundredth, so
 * that garbage (a wrong baud rate) does not flood the terminal; the state line counts them all.
 */
export const logsFault = (n: number): boolean => n <= 10 || n % 100 === 0;

/** Bytes as hex ("25 1E 00 …"), at most `max` of them. */
export function hex(b: ArrayLike<number>, max = 32): string {
  const n = Math.min(b.length, max);
  let s = "";
  for (let i = 0; i < n; i++)
    s += (i ? " " : "") + b[i]!.toString(16).toUpperCase().padStart(2, "0");
  return b.length > max ? `${s} … (${b.length} bytes)` : s;
}

/** A signed byte from its two's complement (206 → −50). */
export const int8 = (b: number): number => (b > 127 ? b - 256 : b);
