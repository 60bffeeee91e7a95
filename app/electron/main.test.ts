/**
 * The bundled main process (dist/electron/main.cjs, built here with scripts/build-electron.mjs)
 * against a stand-in for the `electron` module: the Electron binary cannot run on the build
 * machines, so this checks the wiring around it with the real session worker, the real built UI
 * files and real files: the app:// protocol answers with the security headers, IPC from the
 * window's main frame reaches the hub and the engine's answers come back, IPC from another frame
 * is ignored, File → Open loads and starts a pipeline and records it in Open Recent, Save As
 * writes it, navigation away and window.open are refused (except the participant window, opened
 * on the second display and linked to the same engine), and quitting closes the engine.
 */
import { execFileSync } from "node:child_process";
import { existsSync, mkdtempSync, readFileSync, rmSync } from "node:fs";
import Module, { createRequire } from "node:module";
import { tmpdir } from "node:os";
import { join } from "node:path";
import { afterAll, beforeAll, describe, expect, test } from "vitest";
import { requireBuild, ROOT } from "../../tests/integration/helpers";
import { ENGINE_CHANNEL } from "./channel";
import { findMenuItem } from "./menu";
import { RECENT_FILE } from "./recent";
import { APP_ENTRY, CONTENT_SECURITY_POLICY } from "./security";

type Fn = (...args: never[]) => unknown;
type Handler = (...args: unknown[]) => unknown;
type MenuItem = { id?: string; click?: Fn; submenu?: MenuItem[]; enabled?: boolean };

/** A minimal event emitter. */
class Emitter {
  readonly handlers = new Map<string, Handler[]>();
  on(name: string, h: Handler): this {
    this.handlers.set(name, [...(this.handlers.get(name) ?? []), h]);
    return this;
  }
  once(name: string, h: Handler): this {
    return this.on(name, h);
  }
  emit(name: string, ...args: unknown[]): void {
    for (const h of this.handlers.get(name) ?? []) h(...args);
  }
}

function fakeElectron(userData: string, dialogs: { open?: string; save?: string }) {
  const sent: { channel: string; msg: Record<string, unknown>; to: number }[] = [];
  let protocolHandler: ((req: Request) => Promise<Response>) | undefined;
  let ipcHandler: Handler | undefined;
  let menu: MenuItem[] = [];
  const windows: FakeWindow[] = [];
  const errors: string[] = [];
  const app = new (class extends Emitter {
    isPackaged = false;
    quitCalls = 0;
    requestSingleInstanceLock = () => true;
    whenReady = () => Promise.resolve();
    getPath = (name: string) => (name === "userData" ? userData : tmpdir());
    commandLine = { getSwitchValue: (_name: string) => "" };
    getVersion = () => "0.1.0";
    quit = () => {
      this.quitCalls++;
      const e = { defaultPrevented: false, preventDefault: () => (e.defaultPrevented = true) };
      this.emit("will-quit", e);
    };
    exit = (code: number) => errors.push(`exit ${code}`);
  })();

  class FakeWebContents extends Emitter {
    static next = 1;
    id = FakeWebContents.next++;
    url = "";
    mainFrame = { url: "", parent: null };
    openHandler: Handler | undefined;
    isDestroyed = () => false;
    getURL = () => this.url;
    send = (channel: string, msg: Record<string, unknown>) =>
      void sent.push({ channel, msg, to: this.id });
    setWindowOpenHandler = (h: Handler) => void (this.openHandler = h);
    reload = () => {};
    toggleDevTools = () => {};
  }
  class FakeWindow extends Emitter {
    webContents = new FakeWebContents();
    constructor(readonly options: Record<string, unknown>) {
      super();
      windows.push(this);
      app.emit("web-contents-created", {}, this.webContents);
    }
    static getFocusedWindow = () => windows[0];
    static fromWebContents = (c: unknown) => windows.find((w) => w.webContents === c);
    focused = 0;
    focus = () => void this.focused++;
    getBounds = () => ({ x: 0, y: 0, width: 1400, height: 900 });
    loadURL = async (url: string) => {
      this.webContents.url = url;
      this.webContents.mainFrame.url = url;
    };
    isDestroyed = () => false;
    isMinimized = () => false;
    show = () => {};
  }
  // A laptop and, to its right, the participant's monitor.
  const displays = [
    {
      id: 1,
      bounds: { x: 0, y: 0, width: 1920, height: 1200 },
      workArea: { x: 0, y: 0, width: 1920, height: 1160 },
    },
    {
      id: 2,
      bounds: { x: 1920, y: 0, width: 1920, height: 1080 },
      workArea: { x: 1920, y: 0, width: 1920, height: 1080 },
    },
  ];
  const electron = {
    app,
    BrowserWindow: FakeWindow,
    screen: {
      getAllDisplays: () => displays,
      getDisplayMatching: () => displays[0],
      getPrimaryDisplay: () => displays[0],
    },
    protocol: {
      registerSchemesAsPrivileged: () => {},
      handle: (_scheme: string, h: (req: Request) => Promise<Response>) => (protocolHandler = h),
    },
    session: {
      defaultSession: Object.assign(new Emitter(), {
        setPermissionRequestHandler: () => {},
        setPermissionCheckHandler: () => {},
        webRequest: { onBeforeRequest: () => {} },
      }),
    },
    ipcMain: {
      on: (channel: string, h: Handler) => channel === ENGINE_CHANNEL && (ipcHandler = h),
    },
    Menu: {
      buildFromTemplate: (t: MenuItem[]) => t,
      setApplicationMenu: (t: MenuItem[]) => void (menu = t),
    },
    dialog: {
      showOpenDialog: async () => ({ canceled: !dialogs.open, filePaths: [dialogs.open] }),
      showSaveDialog: async () => ({ canceled: !dialogs.save, filePath: dialogs.save }),
      showMessageBox: async (...args: unknown[]) => {
        errors.push(JSON.stringify(args.at(-1)));
        return { response: 0 };
      },
      showErrorBox: (title: string, text: string) => errors.push(`${title}: ${text}`),
    },
  };
  return {
    electron,
    app,
    sent,
    windows,
    errors,
    protocol: () => protocolHandler!,
    ipc: () => ipcHandler!,
    menu: () => menu,
  };
}

async function until(cond: () => boolean, ms = 8000): Promise<void> {
  const end = Date.now() + ms;
  while (!cond()) {
    if (Date.now() > end) throw new Error("timed out");
    await new Promise((r) => setTimeout(r, 20));
  }
}

describe("main process (bundled, with a stand-in electron module)", () => {
  let dir: string;
  let fake: ReturnType<typeof fakeElectron>;
  const dialogs: { open?: string; save?: string } = {};

  beforeAll(async () => {
    requireBuild();
    if (!existsSync(join(ROOT, "dist", "web", "index.html"))) {
      throw new Error("dist/web is missing: run node scripts/build-web.mjs");
    }
    execFileSync(process.execPath, [join(ROOT, "scripts", "build-electron.mjs")], {
      cwd: ROOT,
      stdio: "pipe",
    });
    dir = mkdtempSync(join(tmpdir(), "mosaic-electron-"));
    fake = fakeElectron(join(dir, "userData"), dialogs);
    const mod = Module as unknown as { _load: (req: string, ...rest: unknown[]) => unknown };
    const load = mod._load;
    mod._load = function (req: string, ...rest: unknown[]) {
      return req === "electron" ? fake.electron : load.call(this, req, ...rest);
    };
    try {
      createRequire(import.meta.url)(join(ROOT, "dist", "electron", "main.cjs"));
    } finally {
      mod._load = load;
    }
    await until(() => fake.windows.length === 1);
  });

  afterAll(async () => {
    if (fake && fake.app.quitCalls === 0) fake.app.quit();
    await new Promise((r) => setTimeout(r, 300));
    if (dir) rmSync(dir, { recursive: true, force: true });
  });

  test("opens one sandboxed window on app://mosaic/ with the preload", () => {
    const win = fake.windows[0]!;
    expect(win.webContents.getURL()).toBe(APP_ENTRY);
    expect(win.options.webPreferences).toMatchObject({
      contextIsolation: true,
      nodeIntegration: false,
      sandbox: true,
      webSecurity: true,
      preload: join(ROOT, "dist", "electron", "preload.cjs"),
    });
  });

  test("app:// serves the built UI with the policy and isolation headers", async () => {
    const handle = fake.protocol();
    const page = await handle(new Request("app://mosaic/index.html"));
    expect(page.status).toBe(200);
    expect(page.headers.get("content-security-policy")).toBe(CONTENT_SECURITY_POLICY);
    expect(page.headers.get("cross-origin-embedder-policy")).toBe("require-corp");
    expect(await page.text()).toContain('src="app.js"');
    const wasm = await handle(new Request("app://mosaic/mosaic_core_bg.wasm"));
    expect(wasm.headers.get("content-type")).toBe("application/wasm");
    const out = await handle(new Request("app://mosaic/..%2f..%2fpackage.json"));
    expect(out.status).toBe(403);
  });

  test("navigation away and new windows are refused", () => {
    const contents = fake.windows[0]!.webContents;
    let prevented = 0;
    const e = { preventDefault: () => prevented++ };
    for (const h of contents.handlers.get("will-navigate") ?? []) h(e, "https://example.com/");
    for (const h of contents.handlers.get("will-navigate") ?? []) h(e, "app://mosaic/index.html");
    expect(prevented).toBe(1);
    expect(contents.openHandler?.({ url: "https://example.com/" })).toEqual({ action: "deny" });
  });

  test("IPC from the main frame reaches the engine and its answers come back", async () => {
    const win = fake.windows[0]!;
    const contents = win.webContents;
    const from = { sender: contents, senderFrame: contents.mainFrame };
    fake.ipc()(from, { type: "hello", version: 1 });
    await until(() => fake.sent.some((s) => s.msg.type === "hello"));
    expect(fake.sent[0]).toMatchObject({ channel: ENGINE_CHANNEL, msg: { type: "hello" } });

    // Another frame (an iframe, another page) is ignored.
    const n = fake.sent.length;
    fake.ipc()(
      { sender: contents, senderFrame: { url: APP_ENTRY, parent: contents.mainFrame } },
      { type: "start", id: 99 },
    );
    // Invalid messages get the hub's answer, naming the problem.
    fake.ipc()(from, { type: "load", id: 5 });
    await until(() => fake.sent.some((s) => s.msg.type === "reply" && s.msg.id === 5));
    expect(fake.sent.slice(n).some((s) => s.msg.id === 99)).toBe(false);
    expect(fake.sent.find((s) => s.msg.id === 5)!.msg).toMatchObject({ ok: false });
  });

  test("the page's participant window opens full screen on the second display, on the same engine", async () => {
    const main = fake.windows[0]!;
    const url = `${APP_ENTRY}?view=participant&block=Cues`;
    expect(main.webContents.openHandler?.({ url })).toEqual({ action: "deny" });
    expect(fake.windows).toHaveLength(2);
    const p = fake.windows[1]!;
    expect(p.webContents.getURL()).toBe(url);
    expect(p.options).toMatchObject({
      x: 1920,
      y: 0,
      width: 1920,
      height: 1080,
      fullscreen: true,
      webPreferences: { sandbox: true, contextIsolation: true, nodeIntegration: false },
    });
    // Its page speaks to the same engine: hello comes back to it.
    const contents = p.webContents;
    fake.ipc()(
      { sender: contents, senderFrame: contents.mainFrame },
      { type: "hello", version: 1 },
    );
    await until(() => fake.sent.some((s) => s.to === contents.id && s.msg.type === "hello"));
    // Asked again, it comes forward; nothing else opens.
    main.webContents.openHandler?.({ url });
    main.webContents.openHandler?.({ url: "app://mosaic/index.html?pipeline=demo.yaml" });
    expect(fake.windows).toHaveLength(2);
    expect(p.focused).toBe(1);
  });

  test("File → Open loads and starts the pipeline; Open Recent and Save As follow", async () => {
    dialogs.open = join(ROOT, "pipelines", "demo.yaml");
    const open = findMenuItem(fake.menu() as never, "open") as MenuItem;
    expect(findMenuItem(fake.menu() as never, "save-as")).toMatchObject({ enabled: false });
    (open.click as () => void)();
    await until(() => fake.sent.some((s) => s.msg.type === "graph"));
    await until(() => fake.sent.some((s) => s.msg.type === "state" && s.msg.state === "running"));
    const graph = fake.sent.find((s) => s.msg.type === "graph")!.msg.graph as { blocks: unknown[] };
    expect(graph.blocks.length).toBeGreaterThan(0);
    const stored = JSON.parse(readFileSync(join(dir, "userData", RECENT_FILE), "utf8"));
    expect(stored.files).toEqual([dialogs.open]);
    expect(findMenuItem(fake.menu() as never, "recent-0")).toBeDefined();
    expect(findMenuItem(fake.menu() as never, "save-as")).toMatchObject({ enabled: true });

    dialogs.save = join(dir, "copy");
    (findMenuItem(fake.menu() as never, "save-as")!.click as () => void)();
    // The file exists as soon as writeFile opens it: wait for its whole text.
    const copy = join(dir, "copy.yaml");
    const text = readFileSync(dialogs.open, "utf8");
    await until(() => existsSync(copy) && readFileSync(copy, "utf8") === text);
    expect(readFileSync(copy, "utf8")).toBe(text);
    expect(fake.errors).toEqual([]);
  });

  test("quitting stops the engine before the process ends", async () => {
    fake.app.quit();
    // will-quit is held until the hub closed, then quit is called again.
    await until(() => fake.app.quitCalls >= 2);
  });
});
