/**
 * One requestAnimationFrame loop for every open panel (each plot redraws at most once per frame,
 * only while it has something new to show), and the draw counters the UI benchmark reads from
 * `window.__mosaicPanelStats`.
 */

export interface ViewStats {
  /** setData/draw calls. */
  draws: number;
  /** Time spent in them, ms (total and the longest one). */
  drawMs: number;
  maxDrawMs: number;
  /** Data messages and events received. */
  messages: number;
  events: number;
  /** Events the engine left out to honour the watch's maxRate. */
  skipped: number;
}

export interface MosaicPanelStats {
  /** Animation frames the shared loop ran. */
  frames: number;
  /** Draw tasks on the shared loop now (0 once every panel is hidden or closed). */
  tasks: number;
  /** Per view: `scope:Block.port`, `spider:…`, `heatmap:…`. */
  views: Record<string, ViewStats>;
}

declare global {
  interface Window {
    __mosaicPanelStats?: MosaicPanelStats;
  }
}

function globalStats(): MosaicPanelStats {
  const w = (typeof window !== "undefined" ? window : globalThis) as unknown as Window;
  return (w.__mosaicPanelStats ??= { frames: 0, tasks: 0, views: {} });
}

/** The counters of one view (created on first use, kept after it closes). */
export function viewStats(key: string): ViewStats {
  const s = globalStats();
  return (s.views[key] ??= {
    draws: 0,
    drawMs: 0,
    maxDrawMs: 0,
    messages: 0,
    events: 0,
    skipped: 0,
  });
}

export function countDraw(stats: ViewStats, ms: number): void {
  stats.draws++;
  stats.drawMs += ms;
  if (ms > stats.maxDrawMs) stats.maxDrawMs = ms;
}

type Task = (now: number) => void;
const tasks = new Set<Task>();
let handle = 0;

function tick(now: number): void {
  handle = 0;
  globalStats().frames++;
  for (const t of tasks) t(now);
  if (tasks.size > 0 && handle === 0) handle = requestAnimationFrame(tick);
}

/** Runs `fn` on every animation frame until the returned function is called. */
export function onFrame(fn: Task): () => void {
  tasks.add(fn);
  globalStats().tasks = tasks.size;
  if (handle === 0) handle = requestAnimationFrame(tick);
  return () => {
    tasks.delete(fn);
    globalStats().tasks = tasks.size;
    if (tasks.size === 0 && handle !== 0) {
      cancelAnimationFrame(handle);
      handle = 0;
    }
  };
}

/** Tasks on the shared loop (for leak checks in tests and the benchmark). */
export function frameTasks(): number {
  return tasks.size;
}
