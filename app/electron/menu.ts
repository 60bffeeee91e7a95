/**
 * The native menu as plain objects (Electron's `MenuItemConstructorOptions`), built from
 * callbacks and the recent-files list; the main process passes the result to
 * `Menu.buildFromTemplate` and rebuilds it when the list or the "can save" state changes.
 * Pure: tested in Node by reading labels and calling `click`.
 */
import type { MenuItemConstructorOptions } from "electron";
import { basename } from "node:path";

export interface MenuActions {
  openPipeline(): void;
  openRecent(file: string): void;
  clearRecent(): void;
  savePipelineAs(): void;
  reload(): void;
  toggleDevTools(): void;
  about(): void;
  quit(): void;
}

export interface MenuState {
  /** Newest first (recent.ts). */
  recent: readonly string[];
  /** A pipeline is loaded, so "Save pipeline as…" has something to save. */
  canSave: boolean;
  /** Development build: View → Toggle Developer Tools is shown. */
  dev: boolean;
  /** `process.platform`: macOS gets the application menu and its conventions. */
  platform: string;
  appName?: string;
}

/** "demo.yaml — /path/to/pipelines" (the folder, so two files with one name differ). */
export function recentLabel(file: string): string {
  const name = basename(file);
  const folder = file.slice(0, Math.max(0, file.length - name.length - 1));
  // `&` marks a mnemonic on Windows and Linux; double it so it shows as itself.
  return `${name} — ${folder}`.replace(/&/g, "&&");
}

const sep: MenuItemConstructorOptions = { type: "separator" };

export function buildMenuTemplate(
  state: MenuState,
  actions: MenuActions,
): MenuItemConstructorOptions[] {
  const mac = state.platform === "darwin";
  const appName = state.appName ?? "MOSAIC";
  // One About and one Quit item: macOS shows them in the application menu too.
  const about = aboutItem(appName, actions);
  const quit = quitItem(mac, appName, actions);
  const menus = [
    fileMenu(state, actions, mac, quit),
    editMenu(),
    viewMenu(state, actions, mac),
    helpMenu(about),
  ];
  return mac ? [appMenu(appName, about, quit), ...menus] : menus;
}

function aboutItem(appName: string, actions: MenuActions): MenuItemConstructorOptions {
  return {
    id: "about",
    label: `About ${appName}`,
    click: () => actions.about(),
  };
}

function quitItem(mac: boolean, appName: string, actions: MenuActions): MenuItemConstructorOptions {
  return {
    id: "quit",
    label: mac ? `Quit ${appName}` : "Quit",
    accelerator: "CmdOrCtrl+Q",
    click: () => actions.quit(),
  };
}

/** macOS only: the application menu, named after the app. */
function appMenu(
  appName: string,
  about: MenuItemConstructorOptions,
  quit: MenuItemConstructorOptions,
): MenuItemConstructorOptions {
  return {
    id: "app",
    label: appName,
    submenu: [
      about,
      sep,
      { role: "services" },
      sep,
      { role: "hide" },
      { role: "hideOthers" },
      { role: "unhide" },
      sep,
      quit,
    ],
  };
}

/** Open, Open Recent, Save As, then Close Window (macOS) or Quit. */
function fileMenu(
  state: MenuState,
  actions: MenuActions,
  mac: boolean,
  quit: MenuItemConstructorOptions,
): MenuItemConstructorOptions {
  return {
    id: "file",
    label: "&File",
    submenu: [
      {
        id: "open",
        label: "&Open Pipeline…",
        accelerator: "CmdOrCtrl+O",
        click: () => actions.openPipeline(),
      },
      recentMenu(state.recent, actions),
      sep,
      {
        id: "save-as",
        label: "&Save Pipeline As…",
        accelerator: "CmdOrCtrl+Shift+S",
        enabled: state.canSave,
        click: () => actions.savePipelineAs(),
      },
      ...(mac ? [sep, { role: "close" } as MenuItemConstructorOptions] : [sep, quit]),
    ],
  };
}

/** File → Open Recent: the files newest first (or a disabled "none"), then Clear. */
function recentMenu(recent: readonly string[], actions: MenuActions): MenuItemConstructorOptions {
  return {
    id: "recent",
    label: "Open &Recent",
    submenu: [
      ...recentItems(recent, actions),
      sep,
      {
        id: "recent-clear",
        label: "Clear Recently Opened",
        enabled: recent.length > 0,
        click: () => actions.clearRecent(),
      },
    ],
  };
}

function recentItems(
  recent: readonly string[],
  actions: MenuActions,
): MenuItemConstructorOptions[] {
  if (recent.length === 0)
    return [{ id: "recent-none", label: "No recent pipelines", enabled: false }];
  return recent.map((file, i) => ({
    id: `recent-${i}`,
    label: recentLabel(file),
    toolTip: file,
    click: () => actions.openRecent(file),
  }));
}

/** Text fields (params forms) need the edit roles for copy and paste on macOS. */
function editMenu(): MenuItemConstructorOptions {
  return {
    id: "edit",
    label: "&Edit",
    submenu: [
      { role: "undo" },
      { role: "redo" },
      sep,
      { role: "cut" },
      { role: "copy" },
      { role: "paste" },
      { role: "selectAll" },
    ],
  };
}

/** Reload, Toggle Developer Tools (development builds), zoom and full screen. */
function viewMenu(
  state: MenuState,
  actions: MenuActions,
  mac: boolean,
): MenuItemConstructorOptions {
  return {
    id: "view",
    label: "&View",
    submenu: [
      { id: "reload", label: "&Reload", accelerator: "CmdOrCtrl+R", click: () => actions.reload() },
      ...(state.dev ? [devToolsItem(mac, actions)] : []),
      sep,
      { role: "resetZoom" },
      { role: "zoomIn" },
      { role: "zoomOut" },
      sep,
      { role: "togglefullscreen" },
    ],
  };
}

function devToolsItem(mac: boolean, actions: MenuActions): MenuItemConstructorOptions {
  return {
    id: "devtools",
    label: "Toggle &Developer Tools",
    accelerator: mac ? "Alt+Command+I" : "Ctrl+Shift+I",
    click: () => actions.toggleDevTools(),
  };
}

function helpMenu(about: MenuItemConstructorOptions): MenuItemConstructorOptions {
  return {
    id: "help",
    label: "&Help",
    role: "help",
    submenu: [about],
  };
}

/** Finds an item by id anywhere in a template (tests, and the main process for `enabled`). */
export function findMenuItem(
  items: readonly MenuItemConstructorOptions[],
  id: string,
): MenuItemConstructorOptions | undefined {
  for (const item of items) {
    if (item.id === id) return item;
    if (Array.isArray(item.submenu)) {
      const hit = findMenuItem(item.submenu, id);
      if (hit) return hit;
    }
  }
  return undefined;
}
