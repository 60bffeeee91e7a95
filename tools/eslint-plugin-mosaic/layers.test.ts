// Tests for `mosaic/layers` (DESIGN.md §4): RuleTester cases with exact messages, plus the whole
// layer × layer matrix checked against the import column written out independently below.
import { Linter, RuleTester } from "eslint";
import path from "node:path";
import { fileURLToPath } from "node:url";
import tseslint from "typescript-eslint";
import { describe, expect, it, test } from "vitest";
import mosaic from "./index.js";

RuleTester.describe = describe;
RuleTester.it = it;
RuleTester.itOnly = it.only;

const ROOT = path.resolve(path.dirname(fileURLToPath(import.meta.url)), "..", "..");
const at = (rel: string): string => path.join(ROOT, rel);
const SEE = " See DESIGN.md §4.";

const rule = mosaic.rules.layers;
const tester = new RuleTester({
  languageOptions: { parser: tseslint.parser, ecmaVersion: "latest", sourceType: "module" },
});

/** A valid case: `code` in file `rel`. */
const ok = (rel: string, code: string, options?: object) => ({
  filename: at(rel),
  code,
  ...(options ? { options: [options] } : {}),
});
/** An invalid case with one error whose message is exactly `message` (or matches it). */
const bad = (rel: string, code: string, message: string | RegExp, options?: object) => ({
  filename: at(rel),
  code,
  errors: [{ message }],
  ...(options ? { options: [options] } : {}),
});

const ENGINE_BLOCKS =
  "app/engine must not import app/blocks (blocks → engine, never the other way: the engine is the bottom layer; pass the catalog in as a parameter)." +
  SEE;
const ENGINE_FS =
  "app/engine must not import 'node:fs' (the engine runs in browser Web Workers too; take file access through the Resources interface)." +
  SEE;

tester.run("mosaic/layers", rule, {
  valid: [
    // engine: itself, core-wasm bindings, plain packages, type-only imports
    ok("app/engine/graph.ts", `import { Frame } from "./frame";`),
    ok("app/engine/runtime/dsp.ts", `import init from "../../../core-wasm/pkg/mosaic_core.js";`),
    ok(
      "app/engine/pipeline/loader.ts",
      `import { parseDocument } from "yaml"; import type { z } from "zod";`,
    ),
    ok("app/engine/block.ts", `import type { SerialPort } from "serialport";`),
    // engine tests: node built-ins, vitest and tests/ helpers are fine
    ok(
      "app/engine/frame.test.ts",
      `import { readFileSync } from "node:fs"; import { test } from "vitest"; import { feed } from "../../tests/helpers/feed";`,
    ),
    // blocks: engine, zod, other blocks
    ok(
      "app/blocks/timing/scheduled-timer.ts",
      `import { z } from "zod"; import { defineBlock } from "../../engine";`,
    ),
    ok("app/blocks/catalog.ts", `import { Filter } from "./signal/filter";`),
    ok(
      "app/blocks/signal/filter.test.ts",
      `import { BlockHarness } from "../../engine/testing"; import fs from "fs";`,
    ),
    // bridges: Node, engine interfaces
    ok(
      "native-bridges/udp/socket.ts",
      `import dgram from "node:dgram"; import type { Resources } from "../../app/engine";`,
    ),
    ok(
      "native-bridges/serial/port.ts",
      `import { SerialPort } from "serialport"; import { Frame } from "../../app/engine/frame";`,
    ),
    // host: engine, blocks, bridges, Node
    ok(
      "app/host/server.ts",
      `import { Worker } from "node:worker_threads"; import { WebSocketServer } from "ws";
       import { catalog } from "../blocks/catalog"; import { Runtime } from "../engine";
       import { UdpBridge } from "../../native-bridges/udp/socket";`,
    ),
    // ui: itself, React, engine protocol modules, type-only engine imports
    ok(
      "app/ui/App.tsx",
      `import React from "react"; import { ReactFlow } from "@xyflow/react"; import uPlot from "uplot";`,
    ),
    ok(
      "app/ui/panel.ts",
      `import type { Telemetry } from "../engine"; import { Scope } from "./scope";`,
    ),
    ok("app/ui/client.ts", `import { encode, decode } from "../engine/protocol";`),
    ok(
      "app/ui/client2.ts",
      `import { Hello } from "../engine/protocol/messages"; export type { Frame } from "../engine/frame";`,
    ),
    ok("app/ui/graph/view.ts", `const p = await import("../../engine/protocol-codec");`),
    ok(
      "app/ui/graph/view.test.ts",
      `import { Runtime } from "../../engine"; import { test } from "vitest";`,
    ),
    // web: ui, engine, blocks
    ok(
      "app/web/main.ts",
      `import { createRoot } from "react-dom/client"; import { App } from "../ui/App";
       import { catalog } from "../blocks/catalog"; import { Runtime } from "../engine";`,
    ),
    ok(
      "app/web/engine-client.ts",
      `const w = new Worker(new URL("../engine/engine.worker.ts", import.meta.url), { type: "module" });`,
    ),
    ok(
      "app/engine/dsp/load.ts",
      `const wasm = new URL("../../../core-wasm/pkg/mosaic_core_bg.wasm", import.meta.url);`,
    ),
    ok(
      "app/blocks/x.ts",
      `const u = new URL("./data.csv", base); const v = new URL("https://example.org", import.meta.url);`,
    ),
    // electron: host, electron, Node
    ok(
      "app/electron/main.ts",
      `import { app } from "electron"; import path from "node:path"; import { startHost } from "../host/server";`,
    ),
    // cli: host, engine, Node
    ok(
      "app/cli/main.ts",
      `import { readFile } from "node:fs/promises"; import { startHost } from "../host/server"; import { loadPipeline } from "../engine";`,
    ),
    // tests and tooling: anything
    ok(
      "tests/integration/smoke.test.ts",
      `import { catalog } from "../../app/blocks/catalog"; import { startHost } from "../../app/host/server";
       import { App } from "../../app/ui/App"; import fs from "node:fs"; import { SerialPort } from "serialport";`,
    ),
    ok(
      "tools/gen-docs.ts",
      `import { BLOCKS } from "../app/blocks/catalog"; import { writeFile } from "node:fs/promises";`,
    ),
    ok(
      "scripts/build-ts.mjs",
      `import { build } from "esbuild"; import { entries } from "../tools/x.js";`,
    ),
    // files in no layer, files outside the repository, non-literal specifiers
    ok("vitest.config.ts", `import { catalog } from "./app/blocks/catalog";`),
    ok("app/shared/x.ts", `import { catalog } from "../blocks/catalog";`),
    {
      filename: "/elsewhere/app/engine/x.ts",
      code: `import { catalog } from "../blocks/catalog";`,
    },
    ok("app/engine/plugins.ts", `const name = "x"; await import(name); require(name);`),
    // the package lists are options
    ok("app/engine/x.ts", `import "ws";`, { nodeOnlyPackages: ["serialport"] }),
  ],

  invalid: [
    // --- engine
    bad("app/engine/graph.ts", `import { catalog } from "../blocks/catalog";`, ENGINE_BLOCKS),
    bad("app/engine/graph.ts", `import type { Catalog } from "../blocks/types";`, ENGINE_BLOCKS),
    bad("app/engine/graph.ts", `export * from "../blocks/catalog";`, ENGINE_BLOCKS),
    bad("app/engine/graph.ts", `import { catalog } from "../blocks";`, ENGINE_BLOCKS),
    bad("app/engine/graph.ts", `export { catalog } from "../blocks/catalog";`, ENGINE_BLOCKS),
    bad("app/engine/graph.ts", `const c = await import("../blocks/catalog");`, ENGINE_BLOCKS),
    bad("app/engine/graph.ts", "const c = await import(`../blocks/catalog`);", ENGINE_BLOCKS),
    bad("app/engine/graph.ts", `const c = require("../blocks/catalog");`, ENGINE_BLOCKS),
    bad("app/engine/graph.ts", `import c = require("../blocks/catalog");`, ENGINE_BLOCKS),
    bad("app/engine/io.ts", `import { readFile } from "node:fs";`, ENGINE_FS),
    bad(
      "app/engine/io.ts",
      `import { readFile } from "fs/promises";`,
      "app/engine must not import 'fs/promises' (the engine runs in browser Web Workers too; take file access through the Resources interface)." +
        SEE,
    ),
    bad(
      "app/engine/runtime/scheduler.ts",
      `const { Worker } = await import("node:worker_threads");`,
      "app/engine must not import 'node:worker_threads' (the engine runs in browser Web Workers too; workers and processes are created by the host (worker_threads) or app/web (Web Workers))." +
        SEE,
    ),
    bad(
      "app/engine/runtime/clock.ts",
      `const { performance } = require("perf_hooks");`,
      "app/engine must not import 'perf_hooks' (the engine runs in browser Web Workers too; use performance.now())." +
        SEE,
    ),
    bad(
      "app/engine/runtime/udp.ts",
      `import dgram from "dgram";`,
      "app/engine must not import 'dgram' (the engine runs in browser Web Workers too; network I/O lives in native-bridges, wired by the host)." +
        SEE,
    ),
    bad(
      "app/engine/serial.ts",
      `import { SerialPort } from "serialport";`,
      "app/engine must not import 'serialport' (it only works in Node and the engine runs in browser Web Workers too; device and network I/O belong in native-bridges, wired by the host)." +
        SEE,
    ),
    bad(
      "app/engine/serial.ts",
      `import b from "@serialport/bindings-cpp";`,
      /^app\/engine must not import '@serialport\/bindings-cpp' \(it only works in Node/,
    ),
    bad(
      "app/engine/ble.ts",
      `import noble from "@abandonware/noble";`,
      /'@abandonware\/noble' \(it only works in Node/,
    ),
    bad("app/engine/x.ts", `import "mqtt";`, /'mqtt' \(it only works in Node/, {
      nodeOnlyPackages: ["mqtt"],
    }),
    bad(
      "app/engine/view.ts",
      `import React from "react";`,
      "app/engine must not import 'react' (it needs a DOM and the engine runs in workers without one; drawing belongs in app/ui, which gets its data through the protocol)." +
        SEE,
    ),
    bad(
      "app/engine/view.ts",
      `import uPlot from "uplot";`,
      /^app\/engine must not import 'uplot' \(it needs a DOM/,
    ),
    bad(
      "app/engine/testing.ts",
      `import { expect } from "vitest";`,
      "app/engine must not import 'vitest' outside a *.test.ts file (test frameworks are not shipped; move this code into a test file or tests/)." +
        SEE,
    ),
    bad(
      "app/engine/testing.ts",
      `import { feed } from "../../tests/helpers/feed";`,
      "app/engine must not import tests (production code must not depend on tests; move the shared helper into the layer, e.g. app/engine/testing.ts, or keep it in a *.test.ts file)." +
        SEE,
    ),
    bad(
      "app/engine/x.ts",
      `import { entries } from "../../scripts/build-ts.mjs";`,
      "app/engine must not import scripts (tools/ and scripts/ are build-time only and are not shipped with the app)." +
        SEE,
    ),
    bad(
      "app/engine/graph.test.ts",
      `import { catalog } from "../blocks/catalog";`,
      "app/engine tests must not import app/blocks (blocks → engine, never the other way: the engine is the bottom layer; pass the catalog in as a parameter; a test that needs app/blocks belongs in tests/integration, which may import every layer)." +
        SEE,
    ),
    bad(
      "app/engine/serial.test.ts",
      `import { SerialPort } from "serialport";`,
      /'serialport' \(it only works in Node/,
    ),
    bad(
      "app/engine/host-bits.ts",
      `import { x } from "../host/server";`,
      "app/engine must not import app/host (the host runs the engine in worker_threads, not the other way; move what both need into the engine)." +
        SEE,
    ),
    // --- blocks
    bad(
      "app/blocks/signal/filter.ts",
      `import { Biquad } from "../../../core-wasm/pkg/mosaic_core.js";`,
      "app/blocks must not import core-wasm (blocks reach the WASM kernels through the engine's core-wasm bindings (ctx.dsp), so one module instance is loaded and shared)." +
        SEE,
    ),
    bad(
      "app/blocks/io/file-player.ts",
      `import { readFile } from "node:fs/promises";`,
      "app/blocks must not import 'node:fs/promises' (blocks run in browser Web Workers too; take file access through the Resources interface)." +
        SEE,
    ),
    bad(
      "app/blocks/io/udp-out.ts",
      `import { UdpBridge } from "../../../native-bridges/udp/socket";`,
      /^app\/blocks must not import native-bridges \(blocks run in browser Web Workers too; a device block takes its transport/,
    ),
    bad(
      "app/blocks/io/x.ts",
      `import { startHost } from "../../host/server";`,
      /^app\/blocks must not import app\/host \(the host loads blocks/,
    ),
    bad(
      "app/blocks/io/x.ts",
      `import "@xyflow/react";`,
      /^app\/blocks must not import '@xyflow\/react' \(it needs a DOM and blocks run in workers without one/,
    ),
    bad(
      "app/blocks/io/x.test.ts",
      `import { startHost } from "../../host/server";`,
      /^app\/blocks tests must not import app\/host \(.*; a test that needs app\/host belongs in tests\/integration, which may import every layer\)\. See DESIGN\.md §4\.$/,
    ),
    // --- bridges
    bad(
      "native-bridges/udp/socket.ts",
      `import { Filter } from "../../app/blocks/signal/filter";`,
      /^native-bridges must not import app\/blocks \(bridges implement engine interfaces/,
    ),
    bad(
      "native-bridges/udp/socket.ts",
      `import { startHost } from "../../app/host/server";`,
      /^native-bridges must not import app\/host \(the host wires bridges, not the other way/,
    ),
    bad(
      "native-bridges/udp/socket.ts",
      `import { App } from "../../app/ui/App";`,
      /^native-bridges must not import app\/ui \(/,
    ),
    // --- host
    bad(
      "app/host/server.ts",
      `import { App } from "../ui/App";`,
      "app/host must not import app/ui (the host serves the built UI over HTTP and talks to it over WebSocket with the engine protocol; it never imports browser code)." +
        SEE,
    ),
    bad(
      "app/host/server.ts",
      `import { run } from "../cli/main";`,
      /^app\/host must not import app\/cli \(the CLI is built on the host/,
    ),
    bad(
      "app/host/server.ts",
      `import { app } from "../electron/main";`,
      /^app\/host must not import app\/electron \(Electron starts the host/,
    ),
    // --- ui
    bad(
      "app/ui/graph/view.ts",
      `import { Runtime } from "../../engine/runtime/runtime";`,
      "app/ui must not import app/engine/runtime/runtime (the UI talks to any engine (in-page worker, host over WebSocket, Electron IPC) only through the message protocol; import app/engine/protocol* or use `import type` for engine types, since a value import would run engine code on the UI thread)." +
        SEE,
    ),
    // inline `type` specifiers still leave `import "…"` behind under verbatimModuleSyntax
    bad(
      "app/ui/graph/view.ts",
      `import { type Telemetry } from "../../engine";`,
      /^app\/ui must not import app\/engine \(the UI talks to any engine/,
    ),
    bad(
      "app/ui/graph/view.ts",
      `import { catalog } from "../../blocks/catalog";`,
      /^app\/ui must not import app\/blocks \(block code never runs on the UI thread/,
    ),
    bad(
      "app/ui/file.ts",
      `import fs from "node:fs";`,
      "app/ui must not import 'node:fs' (the UI runs in the browser; ask the engine for files through the protocol)." +
        SEE,
    ),
    bad(
      "app/ui/ws.ts",
      `import WebSocket from "ws";`,
      /^app\/ui must not import 'ws' \(it only works in Node and the UI runs in the browser/,
    ),
    bad(
      "app/ui/x.ts",
      `import { startHost } from "../host/server";`,
      /^app\/ui must not import app\/host \(the host is Node-only/,
    ),
    bad(
      "app/ui/x.ts",
      `import { boot } from "../web/main";`,
      /^app\/ui must not import app\/web \(/,
    ),
    // --- web
    bad(
      "app/web/main.ts",
      `import { startHost } from "../host/server";`,
      /^app\/web must not import app\/host \(the host is Node-only; app\/web runs the engine in a Web Worker/,
    ),
    bad(
      "app/web/main.ts",
      `import { SerialBridge } from "../../native-bridges/serial/port";`,
      /^app\/web must not import native-bridges \(app\/web is the no-install browser build/,
    ),
    bad(
      "app/web/main.ts",
      `import { join } from "path";`,
      "app/web must not import 'path' (app/web is the browser build; ask the engine for files through the protocol)." +
        SEE,
    ),
    bad(
      "app/web/engine-client.ts",
      `const w = new Worker(new URL("../host/engine.worker.ts", import.meta.url));`,
      /^app\/web must not import app\/host \(the host is Node-only/,
    ),
    // --- electron
    bad(
      "app/electron/main.ts",
      `import { Runtime } from "../engine";`,
      /^app\/electron must not import app\/engine \(Electron main and preload stay thin/,
    ),
    bad(
      "app/electron/preload.ts",
      `import { App } from "../ui/App";`,
      /^app\/electron must not import app\/ui \(main and preload never import UI code/,
    ),
    // --- cli
    bad(
      "app/cli/main.ts",
      `import { catalog } from "../blocks/catalog";`,
      "app/cli must not import app/blocks (the CLI gets the block catalog through the host, so `mosaic run` and the served app always register the same blocks; re-export what it needs from app/host)." +
        SEE,
    ),
    bad(
      "app/cli/serve.ts",
      `import { App } from "../ui/App";`,
      /^app\/cli must not import app\/ui \(the CLI is headless Node/,
    ),
    // --- several problems in one file are all reported
    {
      filename: at("app/engine/bad.ts"),
      code: `import fs from "node:fs";\nimport { catalog } from "../blocks/catalog";\nimport { x } from "../cli/main";`,
      errors: [
        { message: /'node:fs'/, line: 1 },
        { message: /app\/blocks/, line: 2 },
        {
          message:
            /^app\/engine must not import app\/cli \(the CLI is an entry point built on the engine/,
          line: 3,
        },
      ],
    },
  ],
});

// ---------------------------------------------------------------------------------------------
// The whole matrix. The import column of DESIGN.md §4, written out here independently of the rule.

type L =
  | "engine"
  | "blocks"
  | "bridges"
  | "host"
  | "ui"
  | "web"
  | "electron"
  | "cli"
  | "core-wasm"
  | "tests"
  | "tooling";
const ALL: L[] = [
  "engine",
  "blocks",
  "bridges",
  "host",
  "ui",
  "web",
  "electron",
  "cli",
  "core-wasm",
  "tests",
  "tooling",
];
const MAY_IMPORT: Record<L, L[]> = {
  engine: ["engine", "core-wasm"],
  blocks: ["blocks", "engine"],
  bridges: ["bridges", "engine"],
  host: ["host", "engine", "blocks", "bridges"],
  ui: ["ui"], // + app/engine/protocol* and `import type` (cases above)
  web: ["web", "ui", "engine", "blocks"],
  electron: ["electron", "host"],
  cli: ["cli", "host", "engine"],
  "core-wasm": ["core-wasm"],
  tests: ALL,
  tooling: ALL,
};
/** A source file and an import target in each layer, and the folder name messages use. */
const FILE: Record<L, { src: string; target: string; folder: string }> = {
  engine: {
    src: "app/engine/graph.ts",
    target: "app/engine/runtime/runtime.ts",
    folder: "app/engine",
  },
  blocks: {
    src: "app/blocks/signal/filter.ts",
    target: "app/blocks/catalog.ts",
    folder: "app/blocks",
  },
  bridges: {
    src: "native-bridges/udp/socket.ts",
    target: "native-bridges/serial/port.ts",
    folder: "native-bridges",
  },
  host: { src: "app/host/server.ts", target: "app/host/resources.ts", folder: "app/host" },
  ui: { src: "app/ui/graph/view.ts", target: "app/ui/App.tsx", folder: "app/ui" },
  web: { src: "app/web/main.ts", target: "app/web/sim.ts", folder: "app/web" },
  electron: {
    src: "app/electron/main.ts",
    target: "app/electron/preload.ts",
    folder: "app/electron",
  },
  cli: { src: "app/cli/main.ts", target: "app/cli/validate.ts", folder: "app/cli" },
  "core-wasm": {
    src: "core-wasm/pkg/glue.js",
    target: "core-wasm/pkg/mosaic_core.js",
    folder: "core-wasm",
  },
  tests: { src: "tests/integration/x.test.ts", target: "tests/helpers/feed.ts", folder: "tests" },
  tooling: {
    src: "tools/gen-docs.ts",
    target: "tools/eslint-plugin-mosaic/index.js",
    folder: "tools",
  },
};

function lint(rel: string, code: string): Linter.LintMessage[] {
  const linter = new Linter({ cwd: ROOT });
  return linter.verify(
    code,
    [
      {
        files: ["**/*.ts", "**/*.tsx", "**/*.js"],
        languageOptions: { parser: tseslint.parser, ecmaVersion: "latest", sourceType: "module" },
        plugins: { mosaic },
        rules: { "mosaic/layers": "error" },
      },
    ],
    { filename: at(rel) },
  );
}

function specifier(fromRel: string, toRel: string): string {
  const s = path.posix.relative(path.posix.dirname(fromRel), toRel).replace(/\.tsx?$/, "");
  return s.startsWith(".") ? s : `./${s}`;
}

describe("layer matrix (DESIGN.md §4)", () => {
  const whys = new Map<string, string>();
  for (const from of ALL) {
    for (const to of ALL) {
      const allowed = MAY_IMPORT[from].includes(to);
      test(`${from} → ${to}: ${allowed ? "allowed" : "rejected"}`, () => {
        const spec = specifier(FILE[from].src, FILE[to].target);
        const messages = lint(FILE[from].src, `import { x } from "${spec}";\nexport { x };\n`);
        expect(messages.filter((m) => m.fatal)).toEqual([]);
        if (allowed) {
          expect(messages).toEqual([]);
          return;
        }
        expect(messages).toHaveLength(1);
        const m = messages[0]!;
        expect(m.ruleId).toBe("mosaic/layers");
        const toName =
          from === "ui" && to === "engine" ? "app/engine/runtime/runtime" : FILE[to].folder;
        const head = `${FILE[from].folder} must not import ${toName} (`;
        expect(m.message.startsWith(head), m.message).toBe(true);
        expect(m.message.endsWith(")." + SEE), m.message).toBe(true);
        const why = m.message.slice(head.length, -(")." + SEE).length);
        expect(why.length).toBeGreaterThan(30);
        expect(why).not.toContain("not in this layer's import column");
        whys.set(`${from}→${to}`, why);
      });
    }
  }

  test("every forbidden pair into an app layer has its own reason", () => {
    const byWhy = new Map<string, string[]>();
    for (const [pair, why] of whys) {
      if (pair.endsWith("→tests") || pair.endsWith("→tooling") || pair.startsWith("core-wasm→"))
        continue;
      byWhy.set(why, [...(byWhy.get(why) ?? []), pair]);
    }
    const shared = [...byWhy.values()].filter((pairs) => pairs.length > 1);
    expect(shared).toEqual([]);
  });

  test("test files inside a layer may import tests/ but not a layer above", () => {
    for (const from of ALL) {
      if (from === "tests" || from === "tooling" || from === "core-wasm") continue;
      const src = FILE[from].src.replace(/\.ts$/, ".test.ts");
      expect(
        lint(src, `import { feed } from "${specifier(src, "tests/helpers/feed.ts")}";`),
      ).toEqual([]);
      for (const to of ALL) {
        if (MAY_IMPORT[from].includes(to) || to === "tests" || (from === "ui" && to === "engine"))
          continue;
        const messages = lint(src, `import { x } from "${specifier(src, FILE[to].target)}";`);
        expect(messages, `${from} test → ${to}`).toHaveLength(1);
        expect(messages[0]!.message).toContain(
          `${FILE[from].folder} tests must not import ${FILE[to].folder} (`,
        );
        expect(messages[0]!.message).toContain("belongs in tests/integration");
      }
    }
  });

  test("node built-ins are rejected in engine, blocks, ui and web, allowed elsewhere", () => {
    for (const from of ALL) {
      for (const spec of [
        "node:fs",
        "fs",
        "path",
        "worker_threads",
        "node:worker_threads",
        "fs/promises",
      ]) {
        const messages = lint(FILE[from].src, `import "${spec}";`);
        const pure = ["engine", "blocks", "ui", "web"].includes(from);
        expect(messages.length, `${from} ← ${spec}`).toBe(pure ? 1 : 0);
        if (pure) expect(messages[0]!.message).toContain(`must not import '${spec}' (`);
        // test files inside a pure layer may use them
        expect(lint(FILE[from].src.replace(/\.(ts|js)$/, ".test.$1"), `import "${spec}";`)).toEqual(
          [],
        );
      }
    }
  });
});
