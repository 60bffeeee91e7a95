/**
 * The desktop app's main process (bundled to dist/electron/main.cjs). Thin on purpose: it starts
 * the host in this process (a SessionHub: the engine session runs in a worker thread, devices are
 * opened here), serves the UI on the privileged `app://mosaic/` scheme, opens one sandboxed
 * window (and, when its page asks, the participant window, on a second display) and relays the
 * UI↔engine protocol between each window and the hub over one IPC channel. The
 * logic lives in plain modules tested without Electron: security.ts, protocol-files.ts,
 * window-link.ts, menu.ts, recent.ts, pipeline-files.ts, paths.ts, participant-window.ts. See
 * docs/desktop.md.
 */
import {
  app,
  BrowserWindow,
  dialog,
  ipcMain,
  Menu,
  protocol,
  screen,
  session,
  type IpcMainEvent,
  type WebContents,
} from "electron";
import { existsSync } from "node:fs";
import { isAbsolute, join, resolve } from "node:path";
import { defaultAllowedDirs, SessionHub } from "../host/session-hub";
import { ENGINE_CHANNEL, HOST_PROTOCOL_VERSION } from "./channel";
import { buildMenuTemplate } from "./menu";
import { appLayout } from "./paths";
import {
  loadFailureText,
  PIPELINE_FILTERS,
  readPipelineFile,
  writePipelineFile,
} from "./pipeline-files";
import { isParticipantUrl, participantPlacement } from "./participant-window";
import { serveAppRequest } from "./protocol-files";
import { RECENT_FILE, RecentFiles } from "./recent";
import {
  APP_ENTRY,
  APP_SCHEME,
  APP_SCHEME_PRIVILEGES,
  isAllowedNavigation,
  isAllowedPermission,
  isTrustedIpcSender,
  windowWebPreferences,
} from "./security";
import { createWindowLink, type LoadedPipeline, type WindowLink } from "./window-link";

// Before `ready`: the UI's scheme behaves like https (fetch, module workers, streaming wasm).
protocol.registerSchemesAsPrivileged([{ scheme: APP_SCHEME, privileges: APP_SCHEME_PRIVILEGES }]);

const dev = !app.isPackaged;
const layout = appLayout({
  mainDir: __dirname,
  isPackaged: app.isPackaged,
  resourcesPath: process.resourcesPath,
});

let hub: SessionHub | undefined;
let recent: RecentFiles | undefined;
/** The pipeline last loaded (from the menu or by the page): what "Save Pipeline As…" writes. */
let lastLoaded: LoadedPipeline | undefined;
const windows = new Map<number, { win: BrowserWindow; link: WindowLink }>();
/** Participant windows by URL (one per Stimulus block): a second click brings it forward. */
const participants = new Map<string, BrowserWindow>();
/** Files named on the command line or by the OS before the hub was up. */
const pendingFiles: string[] = [];
/** Set when the app quits: the engine worker's exit is expected then. */
let quitting = false;

function problem(message: string): void {
  console.error(`MOSAIC: ${message}`);
}

function focusedWindow(): BrowserWindow | undefined {
  return BrowserWindow.getFocusedWindow() ?? [...windows.values()][0]?.win;
}

function errorBox(title: string, detail: string): void {
  const win = focusedWindow();
  const options = { type: "error" as const, title, message: title, detail };
  void (win ? dialog.showMessageBox(win, options) : dialog.showMessageBox(options));
}

function rebuildMenu(): void {
  const template = buildMenuTemplate(
    {
      recent: recent?.files ?? [],
      canSave: lastLoaded !== undefined,
      dev,
      platform: process.platform,
      appName: "MOSAIC",
    },
    {
      openPipeline: () => void openPipelineDialog(),
      openRecent: (file) => void openPipeline(file),
      clearRecent: () => {
        recent?.clear();
        rebuildMenu();
      },
      savePipelineAs: () => void savePipelineAs(),
      reload: () => focusedWindow()?.webContents.reload(),
      toggleDevTools: () => {
        if (dev) focusedWindow()?.webContents.toggleDevTools();
      },
      about: () => void showAbout(),
      quit: () => app.quit(),
    },
  );
  Menu.setApplicationMenu(Menu.buildFromTemplate(template));
}

function noteLoaded(p: LoadedPipeline): void {
  lastLoaded = p;
  if (isAbsolute(p.file)) recent?.add(p.file);
  rebuildMenu();
}

/** Loads a pipeline file through the hub (every window gets its graph) and starts it. */
async function openPipeline(file: string): Promise<void> {
  if (!hub) {
    pendingFiles.push(file);
    return;
  }
  let source: string;
  try {
    source = await readPipelineFile(file);
  } catch (e) {
    recent?.remove(file);
    rebuildMenu();
    errorBox("Cannot open the pipeline", (e as Error).message);
    return;
  }
  const reply = await hub.request({ type: "load", file, source });
  if (!reply.ok) {
    errorBox(`Cannot load ${file}`, loadFailureText(reply));
    return;
  }
  noteLoaded({ file, source });
  // As `mosaic serve FILE` and the UI's own picker do: a loaded pipeline starts.
  const started = await hub.request({ type: "start" });
  if (!started.ok) errorBox(`Cannot start ${file}`, loadFailureText(started));
}

async function openPipelineDialog(): Promise<void> {
  const win = focusedWindow();
  const options = {
    title: "Open pipeline",
    properties: ["openFile" as const],
    filters: PIPELINE_FILTERS,
  };
  const r = await (win ? dialog.showOpenDialog(win, options) : dialog.showOpenDialog(options));
  const file = r.filePaths[0];
  if (!r.canceled && file) await openPipeline(file);
}

/**
 * Saves the source of the pipeline last loaded (by the menu, or by the page: the page's `load`
 * carries the text it loaded, with the layout it wrote into it when it re-loads). The UI's own
 * "Save layout…" is a download, which Electron turns into a save dialog (see will-download).
 */
async function savePipelineAs(): Promise<void> {
  const current = lastLoaded;
  if (!current) return;
  const win = focusedWindow();
  const options = {
    title: "Save pipeline as",
    defaultPath: isAbsolute(current.file)
      ? current.file
      : join(app.getPath("documents"), "pipeline.yaml"),
    filters: PIPELINE_FILTERS,
  };
  const r = await (win ? dialog.showSaveDialog(win, options) : dialog.showSaveDialog(options));
  if (r.canceled || !r.filePath) return;
  try {
    const written = await writePipelineFile(r.filePath, current.source);
    noteLoaded({ file: written, source: current.source });
  } catch (e) {
    errorBox("Cannot save the pipeline", (e as Error).message);
  }
}

async function showAbout(): Promise<void> {
  const win = focusedWindow();
  const options = {
    type: "info" as const,
    title: "About MOSAIC",
    message: `MOSAIC ${app.getVersion()}`,
    detail: [
      "Modular, Open-Source Suite for Assistive Intelligent Control:",
      "biosignals to assistive-device control in soft real time.",
      "",
      `Electron ${process.versions.electron}, Chromium ${process.versions.chrome}, Node ${process.versions.node}`,
      `UI↔engine protocol ${HOST_PROTOCOL_VERSION}`,
    ].join("\n"),
  };
  await (win ? dialog.showMessageBox(win, options) : dialog.showMessageBox(options));
}

/** Sends an engine message to a window's page (structured clone: Float64Arrays pass as they are). */
function toPage(contents: WebContents, msg: unknown): void {
  if (contents.isDestroyed() || !isAllowedNavigation(contents.getURL())) return;
  contents.send(ENGINE_CHANNEL, msg);
}

function onIpc(event: IpcMainEvent, raw: unknown): void {
  const entry = windows.get(event.sender.id);
  if (!entry || entry.win.isDestroyed()) return;
  if (!isTrustedIpcSender(event.senderFrame, entry.win.webContents.mainFrame)) return;
  entry.link.receive(raw);
}

/** A window on the app's page `url` with the preload, linked to the hub like the first one. */
function createWindow(
  url = APP_ENTRY,
  options: Electron.BrowserWindowConstructorOptions = {},
): BrowserWindow | undefined {
  if (!hub) return undefined;
  const win = new BrowserWindow({
    width: 1400,
    height: 900,
    minWidth: 800,
    minHeight: 500,
    show: false,
    title: "MOSAIC",
    backgroundColor: "#ffffff",
    ...options,
    webPreferences: windowWebPreferences(layout.preload, dev),
  });
  const contents = win.webContents;
  const id = contents.id;
  const link = createWindowLink(hub, (msg) => toPage(contents, msg), noteLoaded);
  windows.set(id, { win, link });
  win.once("ready-to-show", () => win.show());
  win.on("closed", () => {
    link.close();
    windows.delete(id);
  });
  contents.on("render-process-gone", (_e, details) => {
    problem(`the window's renderer ended (${details.reason}); View → Reload brings it back`);
  });
  void win.loadURL(url);
  return win;
}

/**
 * The participant screen asked for by the page's "Participant window" button: its own window on
 * the same engine, full screen on a second display when there is one (participant-window.ts).
 */
function openParticipantWindow(url: string, opener: WebContents): void {
  const open = participants.get(url);
  if (open && !open.isDestroyed()) {
    open.focus();
    return;
  }
  const from = BrowserWindow.fromWebContents(opener) ?? focusedWindow();
  const here = from ? screen.getDisplayMatching(from.getBounds()) : screen.getPrimaryDisplay();
  const place = participantPlacement(screen.getAllDisplays(), here);
  const win = createWindow(url, {
    ...place.bounds,
    fullscreen: place.fullscreen,
    minWidth: 400,
    minHeight: 300,
    title: "MOSAIC — participant",
    autoHideMenuBar: true,
  });
  if (!win) return;
  participants.set(url, win);
  win.on("closed", () => participants.delete(url));
}

// Every web contents (the window, DevTools): no navigation away from the app, no new windows,
// no <webview>.
app.on("web-contents-created", (_event, contents) => {
  contents.on("will-navigate", (e, url) => {
    if (!isAllowedNavigation(url)) e.preventDefault();
  });
  contents.on("will-redirect", (e, url) => {
    if (!isAllowedNavigation(url)) e.preventDefault();
  });
  contents.on("will-attach-webview", (e) => e.preventDefault());
  // The participant window is opened here, on the same engine; nothing else opens.
  contents.setWindowOpenHandler(({ url }) => {
    if (isParticipantUrl(url)) openParticipantWindow(url, contents);
    return { action: "deny" };
  });
});

/** Pipeline files given as arguments (`MOSAIC file.yaml`, "Open with…" on Windows and Linux). */
function filesFromArgv(argv: readonly string[], cwd: string): string[] {
  return argv
    .slice(1)
    .filter((a) => !a.startsWith("-") && /\.ya?ml$/i.test(a))
    .map((a) => resolve(cwd, a))
    .filter((f) => existsSync(f));
}

async function ready(): Promise<void> {
  const ses = session.defaultSession;
  ses.setPermissionRequestHandler((_wc, permission, callback, details) =>
    callback(isAllowedPermission(permission, details.requestingUrl)),
  );
  ses.setPermissionCheckHandler((_wc, permission, origin) =>
    isAllowedPermission(permission, origin),
  );
  // Nothing remote, whatever the page asks for (the CSP says so too).
  ses.webRequest.onBeforeRequest(
    { urls: ["http://*/*", "https://*/*", "ws://*/*", "wss://*/*"] },
    (_d, cb) => cb({ cancel: true }),
  );
  ses.on("will-download", (_e, item) => {
    item.setSaveDialogOptions({ title: "Save", filters: PIPELINE_FILTERS });
  });
  protocol.handle(APP_SCHEME, async (request) => {
    const r = await serveAppRequest(layout.webRoot, request.url, request.method);
    return new Response(r.body, { status: r.status, headers: r.headers });
  });

  recent = new RecentFiles(join(app.getPath("userData"), RECENT_FILE), {
    caseInsensitive: process.platform === "win32" || process.platform === "darwin",
    onError: problem,
  });
  try {
    const dataDir =
      app.commandLine.getSwitchValue("data-dir") || join(app.getPath("documents"), "MOSAIC");
    hub = await SessionHub.start({
      pipelinesDir: layout.pipelinesBase,
      // What the window loads reads and writes only in the examples, the data folder
      // (`--data-dir=DIR`, by default Documents/MOSAIC) and the folders of files opened here.
      allowedDirs: defaultAllowedDirs(layout.pipelinesBase, dataDir),
      // Session recordings (the Record button) go to the data folder's recordings/.
      dataDir,
      workerPath: layout.sessionWorker,
      wasmPath: layout.wasm,
      // The hub also tells every window (an error event), so no dialog here.
      onProblem: (m) => {
        if (!quitting) problem(m);
      },
    });
  } catch (e) {
    dialog.showErrorBox(
      "MOSAIC cannot start its engine",
      `${(e as Error).message}\n\nExpected the engine at ${layout.sessionWorker} and the WASM core at ${layout.wasm}.`,
    );
    app.exit(1);
    return;
  }
  ipcMain.on(ENGINE_CHANNEL, onIpc);
  rebuildMenu();
  createWindow();
  for (const f of pendingFiles.splice(0)) void openPipeline(f);
}

if (!app.requestSingleInstanceLock()) {
  // One engine per machine user: a second start hands its files to the first and quits.
  app.quit();
} else {
  pendingFiles.push(...filesFromArgv(process.argv, process.cwd()));
  app.on("second-instance", (_e, argv, cwd) => {
    const win = focusedWindow();
    if (win) {
      if (win.isMinimized()) win.restore();
      win.focus();
    }
    for (const f of filesFromArgv(argv, cwd)) void openPipeline(f);
  });
  app.on("open-file", (e, file) => {
    e.preventDefault();
    void openPipeline(file);
  });
  app.on("activate", () => {
    if (windows.size === 0) createWindow();
  });
  app.on("window-all-closed", () => {
    if (process.platform !== "darwin") app.quit();
  });
  // Stop the pipeline and flush its logs before the process ends.
  app.on("will-quit", (e) => {
    const h = hub;
    if (!h) return;
    hub = undefined;
    quitting = true;
    e.preventDefault();
    void h.close().finally(() => app.quit());
  });
  app.whenReady().then(ready, (e: unknown) => {
    problem(`cannot start: ${(e as Error).message}`);
    app.exit(1);
  });
}
