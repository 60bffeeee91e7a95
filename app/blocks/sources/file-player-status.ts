/** FilePlayer: its status text. */

/** Where a player is, as its status text tells it. */
export interface PlayState {
  /** The next row to play, from 0 (the rows played in this pass). */
  readonly row: number;
  /** Passes completed (Loop). */
  readonly loops: number;
  readonly done: boolean;
  readonly paused: boolean;
  /** Why playing stopped early: a bad line met in a streamed file. */
  readonly failed: string | undefined;
}

/** The status text of a player in `s`, with `total` rows in a pass (undefined while unknown). */
export function statusText(s: PlayState, total: number | undefined): string {
  if (s.failed !== undefined) return `stopped at row ${s.row}: ${s.failed}`;
  if (s.done) return `finished: ${total ?? s.row} rows played`;
  const of = total !== undefined ? ` / ${total}` : "";
  return `${s.paused ? "paused at " : ""}row ${s.row}${of}${s.loops > 0 ? ` (loop ${s.loops + 1})` : ""}`;
}
