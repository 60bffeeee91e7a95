// Local ESLint plugin for MOSAIC (plain ESM so ESLint loads it without a build step).
//
// Rule `mosaic/layers` enforces the import column of DESIGN.md §4 ("data flows one way"), in the
// style of VS Code's layering rule: an import across the wrong boundary is rejected with a message
// that says why and what to do instead. Layers are found from repo-relative paths; relative
// specifiers are resolved against the importing file. Checked: static `import` / `export … from`,
// `import("…")`, `require("…")`, `import x = require("…")` and `new URL("…", import.meta.url)`.
import { builtinModules } from "node:module";
import path from "node:path";
import { fileURLToPath } from "node:url";

/** The repository root: this file lives in <root>/tools/eslint-plugin-mosaic/. */
const DEFAULT_ROOT = path.resolve(path.dirname(fileURLToPath(import.meta.url)), "..", "..");

/** Folder prefix (repo-relative, '/'-separated) → layer. More specific prefixes first. */
export const LAYER_FOLDERS = [
  ["app/engine/", "engine"],
  ["app/blocks/", "blocks"],
  ["native-bridges/", "bridges"],
  ["app/host/", "host"],
  ["app/ui/", "ui"],
  ["app/web/", "web"],
  ["app/electron/", "electron"],
  ["app/cli/", "cli"],
  ["app/devices/", "devices"],
  ["core-wasm/", "core-wasm"],
  ["tests/", "tests"],
  ["tools/", "tooling"],
  ["scripts/", "tooling"],
];

/** Source layer → the layers it may import (itself included). `*` = anything. */
export const ALLOWED = {
  engine: ["engine", "core-wasm"],
  blocks: ["blocks", "engine"],
  bridges: ["bridges", "engine"],
  host: ["host", "engine", "blocks", "bridges"],
  // ui → engine is further limited to app/engine/protocol* modules or `import type`.
  ui: ["ui", "engine"],
  web: ["web", "ui", "engine", "blocks"],
  electron: ["electron", "host"],
  cli: ["cli", "host", "engine", "devices"],
  // Device simulators (Node programs speaking a device's protocol): the engine's types at most.
  devices: ["devices", "engine"],
  "core-wasm": ["core-wasm"],
  tests: ["*"],
  tooling: ["*"],
};

/** Layers that also run in a browser or Web Worker: no Node built-ins, no Node-only packages. */
const PURE_LAYERS = new Set(["engine", "blocks", "ui", "web"]);
/** Layers that run in workers without a DOM. */
const NO_DOM_LAYERS = new Set(["engine", "blocks"]);

const DEFAULT_NODE_ONLY = [
  "serialport",
  "@serialport/*",
  "@abandonware/noble",
  "ws",
  "electron",
  "roslib",
];
const DEFAULT_DOM_ONLY = ["react", "react-dom", "@xyflow/react", "uplot"];
const DEFAULT_TEST_ONLY = ["vitest", "@vitest/*"];

const BUILTINS = new Set(builtinModules.filter((m) => !m.startsWith("_")));

/** How a layer is named in messages: its folder. */
function layerFolder(layer, rel) {
  if (layer === "tooling") return rel.startsWith("scripts/") ? "scripts" : "tools";
  const hit = LAYER_FOLDERS.find(([, l]) => l === layer);
  return hit ? hit[0].replace(/\/$/, "") : layer;
}

/** Why the source layer may not import the target layer (one specific reason per pair). */
const WHY = {
  engine: {
    blocks:
      "blocks → engine, never the other way: the engine is the bottom layer; pass the catalog in as a parameter",
    bridges:
      "bridges are Node-only and the engine runs in browser Web Workers too; declare an interface in the engine and let the host inject the bridge",
    host: "the host runs the engine in worker_threads, not the other way; move what both need into the engine",
    ui: "the engine never knows who draws it; the UI talks to it only through the message protocol in app/engine/protocol*",
    web: "app/web is a browser entry that starts the engine; the engine must not depend on one of its hosts",
    electron:
      "Electron is the outermost shell; the engine also runs without it, in the CLI and the browser build",
    cli: "the CLI is an entry point built on the engine; shared code belongs in the engine",
  },
  blocks: {
    "core-wasm":
      "blocks reach the WASM kernels through the engine's core-wasm bindings (ctx.dsp), so one module instance is loaded and shared",
    bridges:
      "blocks run in browser Web Workers too; a device block takes its transport through an engine interface that the host wires to a bridge",
    host: "the host loads blocks, not the other way; blocks also run in the browser build, where there is no host",
    ui: "blocks describe their panel with `views` and `panel`, and the UI draws it; blocks run in workers without a DOM",
    web: "app/web is a browser entry that registers blocks; blocks must not depend on one of their hosts",
    electron: "Electron is the outermost shell; blocks also run in the CLI and the browser build",
    cli: "the CLI runs pipelines of blocks; code shared with the CLI belongs in the engine",
  },
  bridges: {
    blocks:
      "bridges implement engine interfaces and never depend on a particular block; the host wires a bridge to the blocks that use it",
    "core-wasm":
      "bridges move bytes between devices and the engine; signal processing belongs in the engine and blocks",
    host: "the host wires bridges, not the other way; a bridge must work under any Node host: CLI, Electron, tests",
    ui: "bridges run in Node and the UI in the browser; the UI reaches devices only through the engine protocol",
    web: "app/web is the no-install browser build with simulated devices; bridges are Node-only",
    electron:
      "Electron only starts the host, which wires the bridges; bridges must also work headless",
    cli: "the CLI reaches bridges through the host; shared code belongs in native-bridges or the engine",
  },
  host: {
    "core-wasm":
      "the engine loads the WASM module inside each engine worker; the host reaches kernels only through the engine",
    ui: "the host serves the built UI over HTTP and talks to it over WebSocket with the engine protocol; it never imports browser code",
    web: "app/web is the browser counterpart of the host, with the engine in a Web Worker; share code through the engine",
    electron:
      "Electron starts the host, not the other way; the host also runs headless under the CLI",
    cli: "the CLI is built on the host; move what both need into app/host",
  },
  ui: {
    engine:
      "the UI talks to any engine (in-page worker, host over WebSocket, Electron IPC) only through the message protocol; import app/engine/protocol* or use `import type` for engine types, since a value import would run engine code on the UI thread",
    blocks:
      "block code never runs on the UI thread; block metadata reaches the UI through the protocol, in the catalog message",
    "core-wasm": "kernels run in the engine worker, never on the UI thread",
    bridges: "bridges are Node-only; the UI reaches devices through the engine protocol",
    host: "the host is Node-only; the UI talks to it over WebSocket with the engine protocol",
    web: "app/web is the browser entry that mounts the UI; the UI is shared with Electron and must not depend on one entry",
    electron:
      "the UI is shared by the browser build and Electron; Electron glue belongs in app/electron's preload, reached through the protocol",
    cli: "the CLI is a Node entry point and the UI runs in the browser",
  },
  web: {
    "core-wasm": "the engine loads the WASM module in its worker; app/web goes through the engine",
    bridges:
      "app/web is the no-install browser build: real devices need Node bridges, so it uses simulated devices",
    host: "the host is Node-only; app/web runs the engine in a Web Worker in the page instead",
    electron: "Electron is a separate shell; the browser build must not depend on it",
    cli: "the CLI is a Node entry point; app/web is the browser entry",
  },
  electron: {
    engine:
      "Electron main and preload stay thin: they start the host and open the window; engine work belongs in the host",
    blocks: "Electron stays thin; the host loads the blocks",
    bridges: "Electron stays thin; the host wires the bridges",
    ui: "main and preload never import UI code: the window loads the UI bundle in its own renderer process",
    web: "app/web is the browser-build entry; the Electron window loads the UI with the host as its engine",
    cli: "the CLI and Electron are sibling entry points over the host; share code through the host",
    "core-wasm": "Electron stays thin; kernels run in the engine workers the host starts",
  },
  cli: {
    blocks:
      "the CLI gets the block catalog through the host, so `mosaic run` and the served app always register the same blocks; re-export what it needs from app/host",
    bridges: "the host wires bridges to the engine; the CLI asks the host",
    ui: "the CLI is headless Node and the UI is browser code; `mosaic serve` serves it through the host",
    web: "the CLI is headless Node and app/web is the browser build; `mosaic serve` goes through the host",
    electron: "the CLI and Electron are sibling entry points over the host",
    "core-wasm":
      "kernels are loaded by the engine inside its workers; the CLI goes through the engine",
  },
  "core-wasm": {
    "*": "core-wasm is the pure Rust/WASM core at the bottom; its generated bindings depend on no TypeScript layer",
  },
};

const WHY_TESTS =
  "production code must not depend on tests; move the shared helper into the layer, e.g. app/engine/testing.ts, or keep it in a *.test.ts file";
const WHY_TOOLING = "tools/ and scripts/ are build-time only and are not shipped with the app";

function whyLayer(from, to) {
  if (to === "tests") return WHY_TESTS;
  if (to === "tooling") return WHY_TOOLING;
  const table = WHY[from] ?? {};
  return table[to] ?? table["*"] ?? "it is not in this layer's import column";
}

const LAYER_RUNS_IN = {
  engine: "the engine runs in browser Web Workers too",
  blocks: "blocks run in browser Web Workers too",
  ui: "the UI runs in the browser",
  web: "app/web is the browser build",
};

/** What to use instead of a Node built-in, by module family and layer. */
function builtinHint(layer, mod) {
  const base = mod.replace(/^node:/, "").split("/")[0];
  const inWorker = layer === "engine" || layer === "blocks";
  switch (base) {
    case "fs":
    case "path":
    case "url":
    case "readline":
    case "stream":
      return inWorker
        ? "take file access through the Resources interface"
        : "ask the engine for files through the protocol";
    case "worker_threads":
    case "child_process":
    case "cluster":
      return inWorker
        ? "workers and processes are created by the host (worker_threads) or app/web (Web Workers)"
        : "use Web Workers; the host owns worker_threads";
    case "net":
    case "dgram":
    case "http":
    case "https":
    case "http2":
    case "tls":
    case "dns":
      return "network I/O lives in native-bridges, wired by the host";
    case "crypto":
      return "use the Web Crypto API (globalThis.crypto)";
    case "events":
      return "use EventTarget or a small callback list";
    case "perf_hooks":
      return "use performance.now()";
    case "buffer":
    case "string_decoder":
      return "use Uint8Array, TextEncoder and TextDecoder";
    case "timers":
      return inWorker ? "use ctx.every / ctx.at from the scheduler" : "use the global timers";
    case "os":
    case "process":
      return "the host passes what it knows about the platform in as data";
    default:
      return inWorker
        ? "use only the ECMAScript library and what app/engine/env.d.ts declares"
        : "use browser APIs";
  }
}

function isTestFile(rel) {
  return /\.(test|spec)\.[cm]?[jt]sx?$/.test(rel);
}

function toPosix(p) {
  return p.split(path.sep).join("/");
}

/** Layer of a repo-relative path, or undefined when the path is in no layer. */
export function layerOf(rel) {
  // "app/engine" itself (a folder import of its index) is in the layer too.
  const hit = LAYER_FOLDERS.find(([prefix]) => `${rel}/`.startsWith(prefix));
  return hit ? hit[1] : undefined;
}

/** Package name of a bare specifier: "@scope/name/sub" → "@scope/name", "name/sub" → "name". */
function packageName(spec) {
  const parts = spec.split("/");
  return spec.startsWith("@") ? parts.slice(0, 2).join("/") : parts[0];
}

function matchesPackage(name, patterns) {
  return patterns.some((p) => (p.endsWith("/*") ? name.startsWith(p.slice(0, -1)) : name === p));
}

function isBuiltin(spec) {
  if (spec.startsWith("node:")) return true;
  return BUILTINS.has(spec) || BUILTINS.has(spec.split("/")[0]);
}

const SEE = " See DESIGN.md §4.";

/** @type {import("eslint").Rule.RuleModule} */
const layers = {
  meta: {
    type: "problem",
    docs: {
      description:
        "Enforce the layer import column of DESIGN.md §4: data flows one way, and every layer runs where it says",
    },
    schema: [
      {
        type: "object",
        properties: {
          root: { type: "string" },
          nodeOnlyPackages: { type: "array", items: { type: "string" } },
          domOnlyPackages: { type: "array", items: { type: "string" } },
          testOnlyPackages: { type: "array", items: { type: "string" } },
        },
        additionalProperties: false,
      },
    ],
    messages: {
      layer: "{{from}} must not import {{to}} ({{why}})." + SEE,
      testLayer:
        "{{from}} tests must not import {{to}} ({{why}}; a test that needs {{to}} belongs in tests/integration, which may import every layer)." +
        SEE,
      uiEngine: "{{from}} must not import {{to}} ({{why}})." + SEE,
      builtin: "{{from}} must not import '{{spec}}' ({{runsIn}}; {{hint}})." + SEE,
      nodeOnly:
        "{{from}} must not import '{{spec}}' (it only works in Node and {{runsIn}}; device and network I/O belong in native-bridges, wired by the host)." +
        SEE,
      domOnly:
        "{{from}} must not import '{{spec}}' (it needs a DOM and {{runsIn}} without one; drawing belongs in app/ui, which gets its data through the protocol)." +
        SEE,
      testOnly:
        "{{from}} must not import '{{spec}}' outside a *.test.ts file (test frameworks are not shipped; move this code into a test file or tests/)." +
        SEE,
    },
  },

  create(context) {
    const opts = context.options[0] ?? {};
    const root = path.resolve(opts.root ?? DEFAULT_ROOT);
    const nodeOnly = opts.nodeOnlyPackages ?? DEFAULT_NODE_ONLY;
    const domOnly = opts.domOnlyPackages ?? DEFAULT_DOM_ONLY;
    const testOnly = opts.testOnlyPackages ?? DEFAULT_TEST_ONLY;

    const filename = context.filename;
    if (!filename || !path.isAbsolute(filename)) return {};
    const rel = toPosix(path.relative(root, filename));
    if (rel.startsWith("../")) return {};
    const from = layerOf(rel);
    if (from === undefined || from === "tests" || from === "tooling") return {};
    const fromName = layerFolder(from, rel);
    const isTest = isTestFile(rel);
    const dir = path.dirname(filename);

    /**
     * @param {import("estree").Node} node where to report
     * @param {string} spec the module specifier
     * @param {boolean} typeOnly `import type` / `export type`: erased at compile time
     */
    function check(node, spec, typeOnly) {
      if (typeof spec !== "string" || spec === "") return;

      // Paths: relative, or absolute.
      if (spec.startsWith(".") || spec.startsWith("/")) {
        const target = toPosix(path.relative(root, path.resolve(dir, spec)));
        if (target.startsWith("../")) return;
        const to = layerOf(target);
        if (to === undefined) return;
        const allowed = ALLOWED[from];
        if (allowed.includes("*") || allowed.includes(to)) {
          const protocol = /^app\/engine\/protocol/.test(target);
          if (from === "ui" && to === "engine" && !typeOnly && !protocol && !isTest) {
            context.report({
              node,
              messageId: "uiEngine",
              data: {
                from: fromName,
                to: target.replace(/\.[cm]?[jt]sx?$/, ""),
                why: WHY.ui.engine,
              },
            });
          }
          return;
        }
        if (isTest && to === "tests") return;
        const toName = layerFolder(to, target);
        context.report({
          node,
          messageId: isTest ? "testLayer" : "layer",
          data: { from: fromName, to: toName, why: whyLayer(from, to) },
        });
        return;
      }

      // Node built-ins.
      if (isBuiltin(spec)) {
        if (PURE_LAYERS.has(from) && !isTest) {
          context.report({
            node,
            messageId: "builtin",
            data: {
              from: fromName,
              spec,
              runsIn: LAYER_RUNS_IN[from],
              hint: builtinHint(from, spec),
            },
          });
        }
        return;
      }

      // Bare package specifiers (typeOnly imports are erased, so only values count).
      if (typeOnly) return;
      const name = packageName(spec);
      if (PURE_LAYERS.has(from) && matchesPackage(name, nodeOnly)) {
        context.report({
          node,
          messageId: "nodeOnly",
          data: { from: fromName, spec, runsIn: LAYER_RUNS_IN[from] },
        });
        return;
      }
      if (NO_DOM_LAYERS.has(from) && matchesPackage(name, domOnly)) {
        const runsIn = from === "engine" ? "the engine runs in workers" : "blocks run in workers";
        context.report({ node, messageId: "domOnly", data: { from: fromName, spec, runsIn } });
        return;
      }
      if (!isTest && matchesPackage(name, testOnly)) {
        context.report({ node, messageId: "testOnly", data: { from: fromName, spec } });
      }
    }

    /** A string literal, or a template literal without expressions. */
    function literalValue(node) {
      if (!node) return undefined;
      if (node.type === "Literal" && typeof node.value === "string") return node.value;
      if (node.type === "TemplateLiteral" && node.expressions.length === 0) {
        return node.quasis[0]?.value.cooked ?? undefined;
      }
      return undefined;
    }

    return {
      ImportDeclaration(node) {
        check(node.source, node.source.value, node.importKind === "type");
      },
      ExportNamedDeclaration(node) {
        if (node.source) check(node.source, node.source.value, node.exportKind === "type");
      },
      ExportAllDeclaration(node) {
        check(node.source, node.source.value, node.exportKind === "type");
      },
      ImportExpression(node) {
        const v = literalValue(node.source);
        if (v !== undefined) check(node.source, v, false);
      },
      CallExpression(node) {
        if (node.callee.type === "Identifier" && node.callee.name === "require") {
          const v = literalValue(node.arguments[0]);
          if (v !== undefined) check(node.arguments[0], v, false);
        }
      },
      // `new URL("../x/y.worker.ts", import.meta.url)`: how workers and WASM files are referenced.
      NewExpression(node) {
        const [first, second] = node.arguments;
        if (
          node.callee.type === "Identifier" &&
          node.callee.name === "URL" &&
          second?.type === "MemberExpression" &&
          second.object.type === "MetaProperty" &&
          second.property.type === "Identifier" &&
          second.property.name === "url"
        ) {
          const v = literalValue(first);
          if (v !== undefined && v.startsWith(".")) check(first, v, false);
        }
      },
      TSImportEqualsDeclaration(node) {
        const ref = node.moduleReference;
        if (ref && ref.type === "TSExternalModuleReference") {
          const v = literalValue(ref.expression);
          if (v !== undefined) check(ref.expression, v, node.importKind === "type");
        }
      },
    };
  },
};

const plugin = {
  meta: { name: "eslint-plugin-mosaic", version: "0.1.0" },
  rules: { layers },
};

export default plugin;
