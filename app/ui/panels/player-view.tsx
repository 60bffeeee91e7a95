/**
 * A FilePlayer's transport (issue 17): a seek bar with the position and the recording's
 * duration (from the block's `position` output, watched while the view is open), restart,
 * pause and resume, and its live `Speed` and `Loop` params.
 */
import { useCallback, useEffect, useRef, useState, type ReactNode } from "react";
import type { BlockInfo, DataMessage } from "../../engine/protocol";
import { useBlockData, useEngine } from "../client/hooks";
import { StatusText } from "./labels";
import { PlayerSettings } from "./player-settings";
import "./player.css";

/** The latest `position` event: seconds from the first row, duration, row, rows. */
export interface PlayPosition {
  seconds: number;
  duration: number;
  row: number;
  rows: number;
}

/** "1:02.5" for 62.5 s; "–" when unknown. */
export function clockText(s: number): string {
  if (!Number.isFinite(s)) return "–";
  const m = Math.floor(s / 60);
  const rest = s - m * 60;
  return `${m}:${rest.toFixed(1).padStart(4, "0")}`;
}

function usePosition(block: string, active: boolean): PlayPosition | null {
  const [pos, setPos] = useState<PlayPosition | null>(null);
  const onData = useCallback((m: DataMessage) => {
    const n = m.t.length;
    if (n === 0) return;
    const v = m.v.subarray((n - 1) * 4, n * 4);
    setPos({ seconds: v[0]!, duration: v[1]!, row: v[2]!, rows: v[3]! });
  }, []);
  useBlockData(block, "position", onData, active, 10);
  return pos;
}

export function PlayerView({ block, active }: { block: BlockInfo; active: boolean }): ReactNode {
  const client = useEngine();
  const pos = usePosition(block.name, active);
  const [reply, setReply] = useState<{ ok: boolean; message: string } | null>(null);
  const act = async (action: string, arg?: unknown): Promise<void> => {
    const r = await client.invoke(block.name, action, arg);
    setReply({ ok: r.ok, message: r.message ?? (r.ok ? "done" : "failed") });
  };
  return (
    <div className="mp-player" data-view="player" data-block={block.name}>
      <StatusText block={block.name} />
      <SeekBar pos={pos} onSeek={(s) => void act("seek", s)} />
      <div className="mp-toolbar">
        <button type="button" className="mp-btn" onClick={() => void act("restart")}>
          Restart
        </button>
        <button type="button" className="mp-btn" onClick={() => void act("pause")}>
          Pause
        </button>
        <button type="button" className="mp-btn" onClick={() => void act("resume")}>
          Resume
        </button>
      </div>
      <PlayerSettings block={block} onReply={setReply} />
      {reply && (
        <p className={reply.ok ? "mp-ok" : "mp-error"} role={reply.ok ? "status" : "alert"}>
          {reply.message}
        </p>
      )}
    </div>
  );
}

/**
 * The position on a range input: dragging shows where it will go, letting go (the input's
 * change event: mouse up, a key, a tap) seeks there.
 */
function SeekBar({
  pos,
  onSeek,
}: {
  pos: PlayPosition | null;
  onSeek: (seconds: number) => void;
}): ReactNode {
  const input = useRef<HTMLInputElement>(null);
  const [dragging, setDragging] = useState<number | null>(null);
  const seek = useRef(onSeek);
  seek.current = onSeek;
  useEffect(() => {
    const el = input.current;
    if (!el) return undefined;
    const onChange = (): void => {
      setDragging(null);
      seek.current(Number(el.value));
    };
    el.addEventListener("change", onChange);
    return () => el.removeEventListener("change", onChange);
  }, []);
  const timed = pos !== null && Number.isFinite(pos.duration);
  const shown = dragging ?? pos?.seconds ?? 0;
  const rows = pos && Number.isFinite(pos.rows) ? ` / ${pos.rows}` : "";
  return (
    <div className="mp-seek">
      <input
        ref={input}
        type="range"
        aria-label="Position (seconds)"
        min={0}
        max={timed ? pos.duration : 1}
        step="any"
        disabled={!timed}
        value={timed ? shown : 0}
        onChange={(e) => setDragging(Number(e.target.value))}
      />
      <span className="mp-seek__time" data-seconds={pos?.seconds} data-duration={pos?.duration}>
        {pos === null
          ? "no row played yet"
          : `${clockText(shown)} / ${clockText(pos.duration)} · row ${pos.row}${rows}`}
      </span>
    </div>
  );
}
