/**
 * Multi-line flow collections as the original MOSAIC's parser read them (YamlDotNet, lenient like
 * LibYAML and PyYAML about the layout of flow collections) made readable by the `yaml` package
 * (eemeli/yaml 2.x), without moving a single character.
 *
 * What `yaml` rejects, and why. Its lexer requires every line of a flow collection that sits in a
 * block mapping to be indented further than that mapping's keys (YAML 1.2 §7.4 and §8.2; the
 * column the keys start in, + 1). It excuses only the closing `]`/`}` of the outermost
 * collection in the keys' own column. It also counts only spaces as indentation. No option
 * changes that: `strict: false`, `uniqueKeys`, `version: "1.1"`, etc. all give the same
 * "Flow sequence in block collection must be sufficiently indented" error (BAD_INDENT, then
 * TAB_AS_INDENT for tabs). The original's files write both:
 *
 *     ground_truth: { Type: Trigger, Params: [          PythonNetTestWGUI: {
 *         rest:   0;0;0,                                <TAB>Type: PythonNetFiltUC,
 *         power:  1;1;1                                 <TAB>Inputs: [ sinusoidSignal ],
 *     ]}                                                }
 *
 * The pre-pass, for the lines inside a flow collection only:
 * - a tab in the indentation of a line is replaced by a space (in flow context a tab and a
 *   space are the same separation, YAML 1.2 §6.2);
 * - a line that starts with a closing `]` or `}` at a column the lexer would reject is joined to
 *   the line above: its line break becomes spaces (`\n` → one, `\r\n` → two), and a comment at the
 *   end of the line above is blanked with spaces (a comment would otherwise run on to the end
 *   of the joined line). Inside a flow collection a line break is only separation, so the
 *   values read are the same.
 * Every character stays at its offset, so node ranges and error positions index the file as
 * written; the file itself (what the editor and `mosaic format` keep) is never changed. Lines
 * that start with anything else at too small an indentation (usually a missing `]` or `}`
 * followed by the next block) are left alone: `yaml` reports them where they are.
 *
 * The scanner knows enough YAML to tell flow from block context: quoted scalars (which may span
 * lines), comments, block scalars (`|`, `>`), and the node starts where `[`/`{` open a flow
 * collection (a `[` inside a plain scalar such as `a[1]` does not).
 */

/** One change the pre-pass made. */
export interface LayoutFix {
  kind: "tab" | "join";
  /** The first tab replaced, or the line break replaced by spaces. */
  offset: number;
}

export interface RelaxedText {
  /** Same length as the source, every character at its offset. */
  text: string;
  fixes: LayoutFix[];
}

const isBlank = (c: string | undefined) => c === " " || c === "\t";

/** The source with the layout of its multi-line flow collections made acceptable to `yaml`. */
export function relaxFlowLayout(src: string): RelaxedText {
  const out = src.split("");
  const fixes: LayoutFix[] = [];
  const n = src.length;

  let depth = 0; // flow nesting depth
  let required = 0; // indentation a line of the current flow collection needs (opening line's + 1)
  let quote: "'" | '"' | undefined; // inside a quoted scalar
  let blockScalarIndent = -1; // >= 0: skipping the lines of a block scalar more indented than this
  let lastSig = ""; // in flow context: the last significant character seen
  let prevComment = -1; // offset of a comment ('#') on the previous line, or -1

  let ls = 0; // start of the current line
  while (ls <= n) {
    const nl = src.indexOf("\n", ls);
    const le = nl < 0 ? n : nl; // end of the line (before its '\n')
    const end = le > ls && src[le - 1] === "\r" ? le - 1 : le; // before a '\r\n'
    let comment = -1;
    let j = ls;
    // Leading whitespace.
    let k = ls;
    while (k < end && isBlank(src[k])) k++;

    if (quote === undefined && blockScalarIndent >= 0) {
      const spaces = countSpaces(src, ls, end);
      if (k === end || spaces > blockScalarIndent) {
        ls = le + 1;
        prevComment = -1;
        continue;
      }
      blockScalarIndent = -1;
    }

    let lineIndent = 0;
    if (quote === undefined) {
      if (depth > 0 && k < end) {
        // A tab in the indentation of a line inside a flow collection: a space.
        let first = -1;
        for (let t = ls; t < k; t++) {
          if (src[t] === "\t") {
            out[t] = " ";
            if (first < 0) first = t;
          }
        }
        if (first >= 0) fixes.push({ kind: "tab", offset: first });
        const indent = k - ls;
        const c = src[k];
        const tolerated = depth === 1 && indent === required - 1;
        if ((c === "]" || c === "}") && indent < required && !tolerated && ls > 0) {
          // Join the closing bracket's line to the line above.
          const br = ls >= 2 && src[ls - 2] === "\r" ? ls - 2 : ls - 1;
          for (let t = br; t < ls; t++) out[t] = " ";
          if (prevComment >= 0) for (let t = prevComment; t < br; t++) out[t] = " ";
          fixes.push({ kind: "join", offset: br });
        }
      }
      lineIndent = countSpaces(src, ls, end);
      j = k;
    }

    // Block context: may the next character start a node (a flow collection, a quoted scalar)?
    let nodeStart = true;
    while (j < end) {
      const c = src[j]!;
      if (quote !== undefined) {
        if (quote === '"' && c === "\\") {
          j += 2;
          continue;
        }
        if (c === quote) {
          if (quote === "'" && src[j + 1] === "'") {
            j += 2;
            continue;
          }
          quote = undefined;
          lastSig = c;
          nodeStart = false;
        }
        j++;
        continue;
      }
      if (c === "#" && (j === ls || isBlank(src[j - 1]))) {
        comment = j;
        break;
      }
      if (isBlank(c)) {
        j++;
        continue;
      }
      if (depth > 0) {
        if (c === "[" || c === "{") depth++;
        else if (c === "]" || c === "}") depth--;
        else if ((c === "'" || c === '"') && (lastSig === "" || "[{,:?".includes(lastSig)))
          quote = c;
        lastSig = c;
        if (depth === 0) nodeStart = false;
        j++;
        continue;
      }
      // Block context.
      const next = src[j + 1];
      const indicator = j + 1 >= end || isBlank(next);
      if (nodeStart) {
        if (c === "[" || c === "{") {
          depth = 1;
          required = lineIndent + 1;
          lastSig = c;
          nodeStart = false;
        } else if (c === "'" || c === '"') {
          quote = c;
          nodeStart = false;
        } else if (c === "|" || c === ">") {
          blockScalarIndent = lineIndent;
          // The rest of the line is the header (and maybe a comment).
          const h = src.indexOf(" #", j);
          if (h >= 0 && h < end) comment = h + 1;
          break;
        } else if ((c === "-" || c === "?" || c === ":") && indicator) {
          // An indicator: a node may follow.
        } else if (c === "&" || c === "!") {
          while (j + 1 < end && !isBlank(src[j + 1])) j++;
        } else {
          nodeStart = false;
        }
      } else if (c === ":" && indicator) {
        nodeStart = true;
      }
      j++;
    }
    prevComment = comment;
    if (nl < 0) break;
    ls = le + 1;
  }
  return { text: fixes.length > 0 ? out.join("") : src, fixes };
}

function countSpaces(src: string, from: number, end: number): number {
  let i = from;
  while (i < end && src[i] === " ") i++;
  return i - from;
}
