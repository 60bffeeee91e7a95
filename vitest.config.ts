import { defineConfig } from "vitest/config";

export default defineConfig({
  test: {
    include: [
      "app/**/*.test.ts",
      // React component tests (type-checked with the DOM and JSX by tsconfig.web.json).
      "app/ui/**/*.test.tsx",
      "native-bridges/**/*.test.ts",
      "tests/**/*.test.ts",
      "tools/**/*.test.ts",
    ],
    exclude: ["**/node_modules/**", "dist/**", "core-wasm/**"],
    testTimeout: 30_000,
    hookTimeout: 60_000,
    pool: "forks",
    // Two cores: keep the run predictable.
    maxWorkers: 2,
  },
});
