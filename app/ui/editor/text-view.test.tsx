import { createElement } from "react";
import { renderToStaticMarkup } from "react-dom/server";
import { describe, expect, it } from "vitest";
import type { EditIssue } from "./model";
import { TextView } from "./text-view";

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
