/**
 * Draws the Status tab's history to fit its wrapper's width, and again (at most every 250 ms)
 * when the recorder has new telemetry, only while the tab is shown; each redraw renders the
 * figures again too.
 */
import { useCallback, useEffect, useRef, useState, type RefObject } from "react";
import { useWidth } from "./canvas";
import { onFrame } from "./frame";
import type { StatusRecorder } from "./status";
import { drawHistory } from "./status-draw";

const REFRESH_MS = 250;

export function useStatusDrawing(
  recorder: StatusRecorder,
  desiredRate: number,
  height: number,
  active: boolean,
): { canvas: RefObject<HTMLCanvasElement | null>; wrap: RefObject<HTMLDivElement | null> } {
  const [, setTick] = useState(0);
  const canvas = useRef<HTMLCanvasElement>(null);
  const wrap = useRef<HTMLDivElement>(null);
  const width = useRef(0);
  const seen = useRef(-1);
  const draw = useCallback(() => {
    const c = canvas.current;
    if (c && width.current > 0)
      drawHistory(c, width.current, height, recorder.history, desiredRate, recorder.lateMs);
  }, [recorder, desiredRate, height]);
  const onResize = useCallback(
    (w: number) => {
      width.current = w;
      draw();
    },
    [draw],
  );
  useWidth(wrap, onResize);
  useEffect(() => {
    if (!active) return undefined;
    let last = 0;
    return onFrame((now) => {
      if (recorder.version === seen.current || now - last < REFRESH_MS) return;
      seen.current = recorder.version;
      last = now;
      draw();
      setTick((x) => x + 1);
    });
  }, [active, recorder, draw]);
  return { canvas, wrap };
}
