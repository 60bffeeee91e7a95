/**
 * What the Lab Streaming Layer blocks share: the bridge (or why there is none), params, the
 * resolution predicate, the number formats' conversion and the outlet side's clock.
 */
import { z } from "zod";
import {
  BlockConfigError,
  type BlockContext,
  type BlockInstance,
  type Frame,
  type LslBridge,
  type LslFormat,
  type LslOutletHandle,
  type LslStreamInfo,
} from "../../engine";
import { ClockMap, measureOffset } from "./clock-map";

/** The bridge, or undefined after saying in the status why there is none. */
export function lslBridge(ctx: BlockContext): LslBridge | undefined {
  const lsl = ctx.io.lsl;
  if (lsl) return lsl;
  ctx.setText(
    "Lab Streaming Layer is unavailable here (the browser build has no liblsl): run the " +
      "pipeline with the desktop app or `mosaic run`",
  );
  return undefined;
}

export const nameParam = (what: string) => z.string().max(200).optional().describe(what);

export const bufferParam = z
  .number()
  .positive()
  .max(3600)
  .default(60)
  .describe("Seconds of data liblsl may hold for a slow or absent peer before it drops the oldest");

/** How often the clock offset between the pipeline and LSL is checked again, s. */
export const CLOCK_CHECK_S = 5;

/** A source id that stays the same across restarts (so that inlets recover the stream). */
export const defaultSourceId = (ctx: BlockContext, name: string): string =>
  `mosaic:${ctx.name}:${name}`;

/** A string literal in an XPath 1.0 predicate (which has no escapes: the other quote is used). */
export function xpathLiteral(value: string, param: string): string {
  if (!value.includes("'")) return `'${value}'`;
  if (!value.includes('"')) return `"${value}"`;
  throw new BlockConfigError(
    `${param} cannot contain both ' and " (XPath 1.0 has no escapes)`,
    param,
  );
}

/**
 * The predicate streams are resolved by: `Predicate` as written, else Name, Type and SourceId
 * joined with `and` (at least one of the four is needed).
 */
export function streamPredicate(p: {
  Name?: string | undefined;
  Type?: string | undefined;
  SourceId?: string | undefined;
  Predicate?: string | undefined;
}): string {
  const predicate = p.Predicate?.trim() ?? "";
  if (predicate !== "") return predicate;
  const parts: string[] = [];
  if (p.Name) parts.push(`name=${xpathLiteral(p.Name, "Name")}`);
  if (p.Type) parts.push(`type=${xpathLiteral(p.Type, "Type")}`);
  if (p.SourceId) parts.push(`source_id=${xpathLiteral(p.SourceId, "SourceId")}`);
  if (parts.length === 0) {
    throw new BlockConfigError(
      "say which stream to read: Name, Type, SourceId or a Predicate such as name='EMG'",
      "Name",
    );
  }
  return parts.join(" and ");
}

/** Integer ranges of the integer formats. */
const RANGE: Partial<Record<LslFormat, [number, number]>> = {
  int32: [-2147483648, 2147483647],
  int16: [-32768, 32767],
};

/**
 * Rounds `values[0, m)` in place to the integer format's range (nearest, ties away from zero;
 * NaN becomes 0); returns how many values were out of range or NaN. Other formats: 0, untouched.
 */
export function toIntegerFormat(values: Float64Array, m: number, format: LslFormat): number {
  const range = RANGE[format];
  if (!range) return 0;
  const [lo, hi] = range;
  let bad = 0;
  for (let i = 0; i < m; i++) {
    const v = values[i]!;
    if (Number.isNaN(v)) {
      values[i] = 0;
      bad++;
      continue;
    }
    const r = v < 0 ? -Math.round(-v) : Math.round(v);
    if (r < lo) {
      values[i] = lo;
      bad++;
    } else if (r > hi) {
      values[i] = hi;
      bad++;
    } else values[i] = r;
  }
  return bad;
}

/**
 * An outlet with the pipeline→LSL clock map, opened at `start` and checked every CLOCK_CHECK_S
 * of pipeline time. `open` returns an error text (shown in the status) instead of throwing.
 */
export class OutletLink {
  outlet: LslOutletHandle | undefined;
  readonly clock = new ClockMap();
  failure = "";
  private lastCheck = Number.NEGATIVE_INFINITY;

  constructor(
    private readonly ctx: BlockContext,
    private readonly info: LslStreamInfo,
    private readonly bufferS: number,
  ) {}

  open(): boolean {
    const lsl = lslBridge(this.ctx);
    if (!lsl) {
      this.failure = "no Lab Streaming Layer in this build";
      return false;
    }
    try {
      this.outlet = lsl.createOutlet(this.info, { bufferS: this.bufferS });
      this.check(lsl, true);
      this.failure = "";
      return true;
    } catch (e) {
      this.failure = `cannot open the LSL outlet '${this.info.name}': ${e instanceof Error ? e.message : String(e)}`;
      this.ctx.error(this.failure);
      this.ctx.setText(this.failure);
      return false;
    }
  }

  /** Measures the clock offset again when due (or now with `force`). */
  check(lsl: LslBridge | undefined = this.ctx.io.lsl, force = false): void {
    // Under the virtual clock the pipeline's time runs ahead of LSL's: measured at start only.
    if (!lsl || (!force && this.ctx.virtual)) return;
    const now = this.ctx.now();
    if (!force && now - this.lastCheck < CLOCK_CHECK_S && now >= this.lastCheck) return;
    this.lastCheck = now;
    this.clock.adopt(
      measureOffset(
        () => this.ctx.now(),
        () => lsl.localClock(),
      ),
    );
  }

  close(): void {
    this.outlet?.close();
    this.outlet = undefined;
  }

  /**
   * The block instance of an outlet block (LslOutlet, LslMarkers): the outlet opens at start (the
   * status then shows it), closes at stop after the last status, and at dispose.
   */
  instance(run: { process(f: Frame): void; describe(): void; reset(): void }): BlockInstance {
    return {
      start: () => {
        if (this.open()) run.describe();
      },
      process: (f: Frame) => run.process(f),
      stop: () => {
        run.describe();
        this.close();
      },
      reset: () => run.reset(),
      dispose: () => this.close(),
    };
  }
}

/** "32 ch float32 @ 2000 Hz" or "1 ch string, irregular". */
export function describeStream(info: { channels: number; format: string; rate: number }): string {
  const rate = info.rate > 0 ? ` @ ${+info.rate.toFixed(3)} Hz` : ", irregular";
  return `${info.channels} ch ${info.format}${rate}`;
}

export const ms = (s: number): string => `${(s * 1000).toFixed(2)} ms`;
