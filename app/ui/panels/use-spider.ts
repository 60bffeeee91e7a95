/**
 * The spider plot's hooks: the values it receives (smoothed, the newest row of each event) and
 * drawing them once per frame when new data arrived, on the fixed or autoscaled range.
 */
import { useCallback, useEffect, useRef, useState, type RefObject } from "react";
import type { BlockInfo, DataMessage } from "../../engine/protocol";
import { useBlockData } from "../client/hooks";
import { Smoother, StickyRange, channelLabel, finiteExtent, type Reduce } from "./channels";
import { readTheme, useWidth, type Theme } from "./canvas";
import { countDraw, onFrame, viewStats } from "./frame";
import type { SpiderSettings } from "./spider";
import { HEIGHT, drawBars, drawSpider } from "./spider-draw";
import { useSmoother } from "./use-smoother";
import type { OutputInfo } from "./view-props";

/** What the frame loop reads and writes between renders. */
interface SpiderLive {
  dirty: boolean;
  width: number;
  range: StickyRange;
  last: number;
  settings: SpiderSettings;
  theme: Theme | null;
}

type SpiderLiveRef = RefObject<SpiderLive>;

export interface SpiderCanvas {
  canvas: RefObject<HTMLCanvasElement | null>;
  wrap: RefObject<HTMLDivElement | null>;
  hasData: boolean;
}

/** The canvas and its wrapper, the `n` values watched and the frames drawn. */
export function useSpiderCanvas(
  block: BlockInfo,
  output: OutputInfo,
  active: boolean,
  settings: SpiderSettings,
  n: number,
  reduce: Reduce,
): SpiderCanvas {
  const statsKey = `spider:${block.name}.${output.name}`;
  const canvas = useRef<HTMLCanvasElement>(null);
  const wrap = useRef<HTMLDivElement>(null);
  const smoother = useSmoother(n, reduce, settings.tauS);
  const live = useSpiderLiveState(settings);
  const hasData = useSpiderData(block, output, active, reduce, smoother, live, statsKey);

  const onResize = useCallback((w: number) => {
    const l = live.current;
    l.width = w;
    l.dirty = true;
    if (canvas.current) l.theme = readTheme(canvas.current);
  }, []);
  useWidth(wrap, onResize);
  useSpiderFrames(canvas, live, smoother, output, n, active, statsKey);
  return { canvas, wrap, hasData };
}

/** The frame loop's state, told the latest settings. */
function useSpiderLiveState(settings: SpiderSettings): SpiderLiveRef {
  const live = useRef<SpiderLive>({
    dirty: false,
    width: 0,
    range: new StickyRange(3, 0),
    last: 0,
    settings,
    theme: null,
  });
  live.current.settings = settings;
  return live;
}

/**
 * Feeds the newest row of each event into the smoother while active (the first `n` values of
 * it: the smoother's size); true once data arrived.
 */
function useSpiderData(
  block: BlockInfo,
  output: OutputInfo,
  active: boolean,
  reduce: Reduce,
  smoother: Smoother,
  live: SpiderLiveRef,
  statsKey: string,
): boolean {
  const [hasData, setHasData] = useState(false);
  const onData = useCallback(
    (m: DataMessage) => {
      const stride = m.rows * m.cols;
      const rowOff = (m.rows - 1) * m.cols;
      for (let e = 0; e < m.t.length; e++) smoother.push(m.t[e]!, m.v, e * stride + rowOff);
      live.current.dirty = true;
      const s = viewStats(statsKey);
      s.messages++;
      s.events += m.t.length;
      s.skipped += m.skipped;
      if (!hasData) setHasData(true);
    },
    [smoother, statsKey, hasData, live],
  );
  const watched = active && output.shape.cols > 0;
  useBlockData(block.name, output.name, onData, watched, reduce === "latest" ? 30 : 200);
  return hasData;
}

/** Draws at most once per frame while active, when new data (or a new size) came: bars below 3. */
function useSpiderFrames(
  canvas: RefObject<HTMLCanvasElement | null>,
  live: SpiderLiveRef,
  smoother: Smoother,
  output: OutputInfo,
  n: number,
  active: boolean,
  statsKey: string,
): void {
  useEffect(() => {
    if (!active) return undefined;
    const l = live.current;
    const stats = viewStats(statsKey);
    return onFrame((now) => {
      const c = canvas.current;
      if (!l.dirty || !c || l.width <= 0) return;
      l.dirty = false;
      const t0 = performance.now();
      const [lo, hi] = spiderRange(l, smoother.out, now);
      l.last = now;
      l.theme ??= readTheme(c);
      const label = (k: number): string => channelLabel(output, k);
      if (n < 3) drawBars(c, l.theme, l.width, HEIGHT, smoother.out, lo, hi, label);
      else drawSpider(c, l.theme, l.width, HEIGHT, smoother.out, lo, hi, label);
      countDraw(stats, performance.now() - t0);
    });
  }, [active, smoother, statsKey, output, n, canvas, live]);
}

/** The fixed range, else the autoscaled one: the values and 0, widening at once, narrowing slowly. */
function spiderRange(l: SpiderLive, values: Float64Array, now: number): [number, number] {
  const s = l.settings;
  if (s.scale === "fixed" && s.max > s.min) return [s.min, s.max];
  const [a, z] = finiteExtent(values);
  return l.range.update(Math.min(0, a), Math.max(0, z), l.last ? (now - l.last) / 1000 : 0);
}
