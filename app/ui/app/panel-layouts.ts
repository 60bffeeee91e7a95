/**
 * Saved panel layouts per pipeline (issue 17): which control panels are open, docked or floating,
 * where and how big, collapsed or not, and each one's view (tab, output, the view's settings such
 * as the scope's watched channels). Kept in the browser's localStorage under the pipeline's file
 * name (`mosaic.panels.v1:<file>`), so they need no write access to the pipeline file and work
 * the same in the browser build, with `mosaic serve` and in the desktop app: opening the same
 * pipeline again in that browser (same origin: same host and port) opens the same panels.
 * A layout is also what the pipeline file is not: personal to a screen and a user.
 * Pure (a Storage is passed in): no React, no DOM.
 */

/** A panel's view, as BlockPanel reports it (block-panel.tsx). */
export interface PanelView {
  tab?: string;
  port?: string;
  /** Per view kind ("scope", "spider", "heatmap"): that view's settings. */
  settings?: Record<string, Record<string, unknown>>;
}

export interface SavedPanel {
  name: string;
  /** The block's type when saved: a panel comes back only on a block of the same type. */
  type: string;
  floating: boolean;
  collapsed: boolean;
  x: number;
  y: number;
  width?: number;
  height?: number;
  view?: PanelView;
}

export interface PanelLayout {
  version: 1;
  panels: SavedPanel[];
}

const PREFIX = "mosaic.panels.v1:";
/** At most this many panels are kept (far more than fit on a screen). */
const MAX_PANELS = 64;

/** What is used of the browser's localStorage (a Storage). */
export interface KeyValueStore {
  getItem(key: string): string | null;
  setItem(key: string, value: string): void;
  removeItem(key: string): void;
}

export const storageKey = (file: string): string => PREFIX + file;

const isObj = (v: unknown): v is Record<string, unknown> =>
  v !== null && typeof v === "object" && !Array.isArray(v);
const isNum = (v: unknown): v is number => typeof v === "number" && Number.isFinite(v);

/** A plain value a view setting may have: number, string, boolean or a list of numbers. */
function isSettingValue(v: unknown): boolean {
  return (
    isNum(v) ||
    typeof v === "string" ||
    typeof v === "boolean" ||
    (Array.isArray(v) && v.length <= 4096 && v.every(isNum))
  );
}

/** Settings with only plain values (anything else dropped). */
function cleanSettings(v: unknown): Record<string, Record<string, unknown>> | undefined {
  if (!isObj(v)) return undefined;
  const out: Record<string, Record<string, unknown>> = {};
  for (const [kind, s] of Object.entries(v)) {
    if (!isObj(s)) continue;
    out[kind] = Object.fromEntries(Object.entries(s).filter(([, x]) => isSettingValue(x)));
  }
  return out;
}

function cleanView(v: unknown): PanelView | undefined {
  if (!isObj(v)) return undefined;
  const settings = cleanSettings(v.settings);
  return {
    ...(typeof v.tab === "string" ? { tab: v.tab } : {}),
    ...(typeof v.port === "string" ? { port: v.port } : {}),
    ...(settings ? { settings } : {}),
  };
}

function cleanPanel(v: unknown): SavedPanel | undefined {
  if (!isObj(v) || typeof v.name !== "string" || typeof v.type !== "string") return undefined;
  if (!isNum(v.x) || !isNum(v.y)) return undefined;
  const view = cleanView(v.view);
  return {
    name: v.name,
    type: v.type,
    floating: v.floating === true,
    collapsed: v.collapsed === true,
    x: v.x,
    y: v.y,
    ...(isNum(v.width) && v.width > 0 ? { width: v.width } : {}),
    ...(isNum(v.height) && v.height > 0 ? { height: v.height } : {}),
    ...(view ? { view } : {}),
  };
}

/** A stored layout read back; undefined when there is none or it is not one. */
export function parseLayout(text: string | null): PanelLayout | undefined {
  if (text === null) return undefined;
  let v: unknown;
  try {
    v = JSON.parse(text);
  } catch {
    return undefined;
  }
  if (!isObj(v) || v.version !== 1 || !Array.isArray(v.panels)) return undefined;
  const panels = v.panels
    .slice(0, MAX_PANELS)
    .map(cleanPanel)
    .filter((p): p is SavedPanel => p !== undefined);
  return { version: 1, panels };
}

export function readLayout(
  storage: KeyValueStore | undefined,
  file: string,
): PanelLayout | undefined {
  try {
    return parseLayout(storage?.getItem(storageKey(file)) ?? null);
  } catch {
    return undefined; // storage refused (privacy settings): no saved layouts
  }
}

/** Stores the layout of `file` (an empty one removes the entry). */
export function writeLayout(
  storage: KeyValueStore | undefined,
  file: string,
  panels: readonly SavedPanel[],
): void {
  try {
    if (panels.length === 0) storage?.removeItem(storageKey(file));
    else {
      const layout: PanelLayout = { version: 1, panels: panels.slice(0, MAX_PANELS) };
      storage?.setItem(storageKey(file), JSON.stringify(layout));
    }
  } catch {
    /* full or refused: the layout is not kept */
  }
}

/** The saved panels that fit the loaded blocks (same name, same type), in their saved order. */
export function panelsFor(
  layout: PanelLayout | undefined,
  blocks: ReadonlyMap<string, { type: string }>,
): SavedPanel[] {
  return (layout?.panels ?? []).filter((p) => blocks.get(p.name)?.type === p.type);
}

/** A view setting saved over its default, when it has the default's kind (or no default). */
export function restoreSettings<T extends object>(defaults: T, saved: unknown): T {
  if (!isObj(saved)) return defaults;
  const d = defaults as unknown as Record<string, unknown>;
  const out: Record<string, unknown> = { ...d };
  for (const [k, v] of Object.entries(saved)) {
    if (!isSettingValue(v)) continue;
    const known = d[k];
    if (
      known !== undefined &&
      (typeof known !== typeof v || Array.isArray(known) !== Array.isArray(v))
    )
      continue;
    out[k] = v;
  }
  return out as unknown as T;
}
