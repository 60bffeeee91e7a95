import { createElement, type FC } from "react";
import { renderToStaticMarkup } from "react-dom/server";
import { describe, expect, it } from "vitest";
import type { CatalogInfo } from "../../engine/protocol";
import type { EditIssue } from "./model";

// Imported by a computed name: test files are type-checked by tsconfig.node.json, which has no
// JSX, so a static import of the .tsx file does not type-check there (vitest itself compiles it).
const source = "./text-view.tsx";
const { TextView } = (await import(source)) as {
  TextView: FC<{
    text: string;
    issues: readonly EditIssue[];
    catalog: CatalogInfo | undefined;
    onChange(text: string): void;
  }>;
};

/** The server markup (no DOM here: the CodeMirror view itself is made in an effect, which does not run). */
function markup(issues: EditIssue[]): string {
  return renderToStaticMarkup(
    createElement(TextView, {
      text: "T: { Type: Tick }\n",
      issues,
      catalog: undefined,
      onChange: () => {},
    }),
  );
}

describe("TextView", () => {
  it("is the code host alone when there are no problems", () => {
    expect(markup([])).toBe(
      '<section class="text-view" aria-label="Pipeline text (YAML)"><div class="text-view__code"></div></section>',
    );
  });

  it("lists the problems, a positioned one as a button to its line", () => {
    const html = markup([
      { line: 3, col: 5, severity: "error", message: "unknown type 'Tik'" },
      { line: 0, col: 0, severity: "warning", message: "no timer" },
    ]);
    expect(html).toBe(
      '<section class="text-view" aria-label="Pipeline text (YAML)"><div class="text-view__code"></div>' +
        '<ul class="text-view__issues" aria-label="Problems in the text">' +
        '<li class="level-error"><button type="button" aria-label="Go to line 3">3:5</button> unknown type &#x27;Tik&#x27;</li>' +
        '<li class="level-warning"><button type="button" aria-label="Position unknown">–</button> no timer</li>' +
        "</ul></section>",
    );
  });
});
