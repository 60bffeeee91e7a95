// ESLint flat config. Fast on purpose (2 cores): typescript-eslint `recommended` without type
// information; the type checker runs separately (`npm run typecheck`).
// `mosaic/layers` enforces the layer import column of DESIGN.md §4.
import js from "@eslint/js";
import { defineConfig, globalIgnores } from "eslint/config";
import globals from "globals";
import tseslint from "typescript-eslint";
import mosaic from "./tools/eslint-plugin-mosaic/index.js";

const TS = ["**/*.ts", "**/*.tsx", "**/*.mts", "**/*.cts"];
const JS = ["**/*.js", "**/*.mjs", "**/*.cjs"];

export default defineConfig([
  globalIgnores([
    "**/node_modules/",
    "dist/",
    "core-wasm/target/",
    "core-wasm/pkg/",
    "bench/results/",
    "**/fixtures/**",
    "**/.venv/",
  ]),

  // Plain JavaScript: build scripts, this config, the local plugin (Node ESM).
  {
    files: JS,
    extends: [js.configs.recommended],
    languageOptions: {
      ecmaVersion: "latest",
      sourceType: "module",
      globals: { ...globals.node },
    },
  },

  // TypeScript, without type information (lint stays fast; `tsc -b` checks types).
  {
    files: TS,
    extends: [tseslint.configs.recommended],
    rules: {
      "@typescript-eslint/no-unused-vars": [
        "error",
        { argsIgnorePattern: "^_", varsIgnorePattern: "^_", caughtErrorsIgnorePattern: "^_" },
      ],
      // `const rt = this` before returning an object literal with getters (a BlockContext) is
      // deliberate: getters cannot be arrow functions, so they need the outer `this` by name.
      "@typescript-eslint/no-this-alias": "off",
    },
  },

  // Layering (DESIGN.md §4), for every source file.
  {
    files: [...TS, ...JS],
    plugins: { mosaic },
    rules: { "mosaic/layers": "error" },
  },

  // The engine and blocks report through ctx.warn / ctx.setText and diagnostics, never the console.
  {
    files: ["app/engine/**", "app/blocks/**"],
    rules: { "no-console": "error" },
  },
  {
    files: ["app/cli/**", "app/host/**", "scripts/**", "tools/**", "tests/**"],
    rules: { "no-console": "off" },
  },
]);
