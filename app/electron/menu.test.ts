import type { MenuItemConstructorOptions } from "electron";
import { describe, expect, test } from "vitest";
import { buildMenuTemplate, findMenuItem, recentLabel, type MenuActions } from "./menu";

function actions() {
  const calls: string[] = [];
  const a: MenuActions = {
    openPipeline: () => calls.push("open"),
    openRecent: (f) => calls.push(`recent:${f}`),
    clearRecent: () => calls.push("clear"),
    savePipelineAs: () => calls.push("save"),
    reload: () => calls.push("reload"),
    toggleDevTools: () => calls.push("devtools"),
    about: () => calls.push("about"),
    quit: () => calls.push("quit"),
  };
  return { a, calls };
}

function click(items: MenuItemConstructorOptions[], id: string): void {
  const item = findMenuItem(items, id);
  if (!item?.click) throw new Error(`no clickable item ${id}`);
  (item.click as () => void)();
}

const labels = (items: MenuItemConstructorOptions[]) => items.map((i) => i.label);

describe("menu template", () => {
  test("File, Edit, View, Help on Windows and Linux; the items call their actions", () => {
    const { a, calls } = actions();
    const t = buildMenuTemplate(
      { recent: ["/p/a.yaml", "/q/b.yaml"], canSave: true, dev: false, platform: "linux" },
      a,
    );
    expect(labels(t)).toEqual(["&File", "&Edit", "&View", "&Help"]);
    click(t, "open");
    click(t, "recent-1");
    click(t, "recent-clear");
    click(t, "save-as");
    click(t, "reload");
    click(t, "about");
    click(t, "quit");
    expect(calls).toEqual(["open", "recent:/q/b.yaml", "clear", "save", "reload", "about", "quit"]);
    expect(findMenuItem(t, "open")?.accelerator).toBe("CmdOrCtrl+O");
    expect(findMenuItem(t, "quit")?.accelerator).toBe("CmdOrCtrl+Q");
  });

  test("Open Recent lists the files newest first, or says there are none", () => {
    const { a } = actions();
    const t = buildMenuTemplate(
      { recent: ["/p/a.yaml", "/q/b.yaml"], canSave: false, dev: false, platform: "win32" },
      a,
    );
    const recent = findMenuItem(t, "recent")!.submenu as MenuItemConstructorOptions[];
    expect(recent.map((i) => i.label ?? i.type)).toEqual([
      "a.yaml — /p",
      "b.yaml — /q",
      "separator",
      "Clear Recently Opened",
    ]);
    expect(findMenuItem(t, "recent-0")?.toolTip).toBe("/p/a.yaml");

    const empty = buildMenuTemplate(
      { recent: [], canSave: false, dev: false, platform: "win32" },
      a,
    );
    expect(findMenuItem(empty, "recent-none")).toMatchObject({ enabled: false });
    expect(findMenuItem(empty, "recent-clear")).toMatchObject({ enabled: false });
  });

  test("Save Pipeline As… is enabled only with a loaded pipeline", () => {
    const { a } = actions();
    const base = { recent: [], dev: false, platform: "linux" };
    expect(
      findMenuItem(buildMenuTemplate({ ...base, canSave: false }, a), "save-as")?.enabled,
    ).toBe(false);
    expect(findMenuItem(buildMenuTemplate({ ...base, canSave: true }, a), "save-as")?.enabled).toBe(
      true,
    );
  });

  test("Toggle Developer Tools only in development", () => {
    const { a, calls } = actions();
    const base = { recent: [], canSave: false, platform: "linux" };
    expect(findMenuItem(buildMenuTemplate({ ...base, dev: false }, a), "devtools")).toBeUndefined();
    const dev = buildMenuTemplate({ ...base, dev: true }, a);
    click(dev, "devtools");
    expect(calls).toEqual(["devtools"]);
  });

  test("macOS: the application menu first, with About and Quit", () => {
    const { a, calls } = actions();
    const t = buildMenuTemplate({ recent: [], canSave: false, dev: false, platform: "darwin" }, a);
    expect(labels(t)).toEqual(["MOSAIC", "&File", "&Edit", "&View", "&Help"]);
    const app = t[0]!.submenu as MenuItemConstructorOptions[];
    expect(app.map((i) => i.label ?? i.role ?? i.type)).toContain("Quit MOSAIC");
    expect(app[0]!.label).toBe("About MOSAIC");
    (app.find((i) => i.id === "quit")!.click as () => void)();
    expect(calls).toEqual(["quit"]);
    // File ends with Close Window, not Quit, on macOS.
    const file = t[1]!.submenu as MenuItemConstructorOptions[];
    expect(file.at(-1)).toEqual({ role: "close" });
  });

  test("every item is a plain object (no functions other than click)", () => {
    const { a } = actions();
    const t = buildMenuTemplate(
      { recent: ["/a.yaml"], canSave: true, dev: true, platform: "linux" },
      a,
    );
    const walk = (items: MenuItemConstructorOptions[]): void => {
      for (const i of items) {
        for (const [k, v] of Object.entries(i)) {
          if (typeof v === "function") expect(k).toBe("click");
        }
        if (Array.isArray(i.submenu)) walk(i.submenu);
      }
    };
    walk(t);
  });

  test("the whole template, item by item: order, ids, labels, accelerators, roles, clicks", () => {
    const { a, calls } = actions();
    /** One line per item, its keys in order; `click` shows the action it calls. */
    const outline = (items: MenuItemConstructorOptions[], indent = ""): string[] =>
      items.flatMap((item) => {
        const fields = Object.entries(item).flatMap(([k, v]) => {
          if (k === "submenu") return [];
          if (k !== "click") return [`${k}=${String(v)}`];
          calls.length = 0;
          (v as () => void)();
          return [`click->${calls.join(",")}`];
        });
        const sub = Array.isArray(item.submenu) ? outline(item.submenu, `${indent}  `) : [];
        return [indent + fields.join(" "), ...sub];
      });

    const linux = buildMenuTemplate(
      { recent: ["/p/a.yaml", "/q/R&D/b.yaml"], canSave: true, dev: true, platform: "linux" },
      a,
    );
    expect(outline(linux)).toEqual([
      "id=file label=&File",
      "  id=open label=&Open Pipeline… accelerator=CmdOrCtrl+O click->open",
      "  id=recent label=Open &Recent",
      "    id=recent-0 label=a.yaml — /p toolTip=/p/a.yaml click->recent:/p/a.yaml",
      "    id=recent-1 label=b.yaml — /q/R&&D toolTip=/q/R&D/b.yaml click->recent:/q/R&D/b.yaml",
      "    type=separator",
      "    id=recent-clear label=Clear Recently Opened enabled=true click->clear",
      "  type=separator",
      "  id=save-as label=&Save Pipeline As… accelerator=CmdOrCtrl+Shift+S enabled=true click->save",
      "  type=separator",
      "  id=quit label=Quit accelerator=CmdOrCtrl+Q click->quit",
      "id=edit label=&Edit",
      "  role=undo",
      "  role=redo",
      "  type=separator",
      "  role=cut",
      "  role=copy",
      "  role=paste",
      "  role=selectAll",
      "id=view label=&View",
      "  id=reload label=&Reload accelerator=CmdOrCtrl+R click->reload",
      "  id=devtools label=Toggle &Developer Tools accelerator=Ctrl+Shift+I click->devtools",
      "  type=separator",
      "  role=resetZoom",
      "  role=zoomIn",
      "  role=zoomOut",
      "  type=separator",
      "  role=togglefullscreen",
      "id=help label=&Help role=help",
      "  id=about label=About MOSAIC click->about",
    ]);

    const mac = buildMenuTemplate(
      { recent: [], canSave: false, dev: true, platform: "darwin", appName: "Mosaic Dev" },
      a,
    );
    expect(outline(mac)).toEqual([
      "id=app label=Mosaic Dev",
      "  id=about label=About Mosaic Dev click->about",
      "  type=separator",
      "  role=services",
      "  type=separator",
      "  role=hide",
      "  role=hideOthers",
      "  role=unhide",
      "  type=separator",
      "  id=quit label=Quit Mosaic Dev accelerator=CmdOrCtrl+Q click->quit",
      "id=file label=&File",
      "  id=open label=&Open Pipeline… accelerator=CmdOrCtrl+O click->open",
      "  id=recent label=Open &Recent",
      "    id=recent-none label=No recent pipelines enabled=false",
      "    type=separator",
      "    id=recent-clear label=Clear Recently Opened enabled=false click->clear",
      "  type=separator",
      "  id=save-as label=&Save Pipeline As… accelerator=CmdOrCtrl+Shift+S enabled=false click->save",
      "  type=separator",
      "  role=close",
      "id=edit label=&Edit",
      "  role=undo",
      "  role=redo",
      "  type=separator",
      "  role=cut",
      "  role=copy",
      "  role=paste",
      "  role=selectAll",
      "id=view label=&View",
      "  id=reload label=&Reload accelerator=CmdOrCtrl+R click->reload",
      "  id=devtools label=Toggle &Developer Tools accelerator=Alt+Command+I click->devtools",
      "  type=separator",
      "  role=resetZoom",
      "  role=zoomIn",
      "  role=zoomOut",
      "  type=separator",
      "  role=togglefullscreen",
      "id=help label=&Help role=help",
      "  id=about label=About Mosaic Dev click->about",
    ]);
    // macOS shares one About item between the application menu and Help.
    expect(findMenuItem(mac.slice(-1), "about")).toBe(findMenuItem(mac, "about"));
  });

  test("recent labels escape mnemonics", () => {
    expect(recentLabel("/data/R&D/emg.yaml")).toBe("emg.yaml — /data/R&&D");
  });
});
