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
  return new FlowLayoutScanner(src).run();
}

/**
 * relaxFlowLayout's one pass over the lines: it follows quoted scalars, block scalars and flow
 * nesting, and in a flow collection turns tabs in the indentation into spaces and joins a closing
 * bracket indented less than the collection's lines need to the line above.
 */
class FlowLayoutScanner {
  private readonly out: string[];
  private readonly fixes: LayoutFix[] = [];
  private depth = 0; // flow nesting depth
  private required = 0; // indentation a line of the current flow collection needs (opening line's + 1)
  private quote: "'" | '"' | undefined; // inside a quoted scalar
  private blockScalarIndent = -1; // >= 0: skipping the lines of a block scalar more indented than this
  private lastSig = ""; // in flow context: the last significant character seen
  private prevComment = -1; // offset of a comment ('#') on the previous line, or -1
  // The current line:
  private lineIndent = 0;
  private comment = -1; // offset of its comment, or -1
  private nodeStart = true; // block context: may the next character start a node?

  constructor(private readonly src: string) {
    this.out = src.split("");
  }

  run(): RelaxedText {
    const { src } = this;
    const n = src.length;
    let ls = 0; // start of the current line
    while (ls <= n) {
      const nl = src.indexOf("\n", ls);
      const le = nl < 0 ? n : nl; // end of the line (before its '\n')
      const end = le > ls && src[le - 1] === "\r" ? le - 1 : le; // before a '\r\n'
      this.line(ls, end);
      if (nl < 0) break;
      ls = le + 1;
    }
    return { text: this.fixes.length > 0 ? this.out.join("") : src, fixes: this.fixes };
  }

  /** The line from `ls` to `end` (its line break excluded). */
  private line(ls: number, end: number): void {
    const { src } = this;
    // Leading whitespace.
    let k = ls;
    while (k < end && isBlank(src[k])) k++;

    if (this.quote === undefined && this.blockScalarIndent >= 0) {
      const spaces = countSpaces(src, ls, end);
      if (k === end || spaces > this.blockScalarIndent) {
        this.prevComment = -1;
        return;
      }
      this.blockScalarIndent = -1;
    }

    let j = ls;
    this.lineIndent = 0;
    if (this.quote === undefined) {
      if (this.depth > 0 && k < end) this.fixFlowIndent(ls, k);
      this.lineIndent = countSpaces(src, ls, end);
      j = k;
    }
    this.prevComment = this.scan(ls, j, end);
  }

  /**
   * A line inside a flow collection, indented up to `k`: tabs in the indentation become spaces;
   * a closing bracket indented less than required joins the line above.
   */
  private fixFlowIndent(ls: number, k: number): void {
    const { src, out } = this;
    let first = -1;
    for (let t = ls; t < k; t++) {
      if (src[t] === "\t") {
        out[t] = " ";
        if (first < 0) first = t;
      }
    }
    if (first >= 0) this.fixes.push({ kind: "tab", offset: first });
    const indent = k - ls;
    const c = src[k];
    const tolerated = this.depth === 1 && indent === this.required - 1;
    if ((c === "]" || c === "}") && indent < this.required && !tolerated && ls > 0) {
      // Join the closing bracket's line to the line above.
      const br = ls >= 2 && src[ls - 2] === "\r" ? ls - 2 : ls - 1;
      for (let t = br; t < ls; t++) out[t] = " ";
      if (this.prevComment >= 0) for (let t = this.prevComment; t < br; t++) out[t] = " ";
      this.fixes.push({ kind: "join", offset: br });
    }
  }

  /** The line's characters from `from` to `end`; returns where its comment starts, or -1. */
  private scan(ls: number, from: number, end: number): number {
    const { src } = this;
    this.comment = -1;
    this.nodeStart = true;
    let j = from;
    while (j < end) {
      const c = src[j]!;
      if (this.quote !== undefined) {
        j = this.quoted(j);
      } else if (c === "#" && (j === ls || isBlank(src[j - 1]))) {
        this.comment = j;
        break;
      } else if (isBlank(c)) {
        j++;
      } else if (this.depth > 0) {
        this.flowChar(c);
        j++;
      } else {
        j = this.blockChar(j, end);
      }
    }
    return this.comment;
  }

  /** Inside a quoted scalar: the character at `j`; returns the next offset to read. */
  private quoted(j: number): number {
    const { src } = this;
    const c = src[j]!;
    if (this.quote === '"' && c === "\\") return j + 2;
    if (c === this.quote) {
      if (this.quote === "'" && src[j + 1] === "'") return j + 2;
      this.quote = undefined;
      this.lastSig = c;
      this.nodeStart = false;
    }
    return j + 1;
  }

  /** In flow context: a significant character `c` (nesting, the start of a quoted scalar). */
  private flowChar(c: string): void {
    if (c === "[" || c === "{") this.depth++;
    else if (c === "]" || c === "}") this.depth--;
    else if ((c === "'" || c === '"') && (this.lastSig === "" || "[{,:?".includes(this.lastSig)))
      this.quote = c;
    this.lastSig = c;
    if (this.depth === 0) this.nodeStart = false;
  }

  /**
   * In block context: the significant character at `j`, which may start a flow collection, a
   * quoted scalar or a block scalar (the rest of the line is then its header); returns the next
   * offset to read.
   */
  private blockChar(j: number, end: number): number {
    const { src } = this;
    const c = src[j]!;
    const indicator = j + 1 >= end || isBlank(src[j + 1]);
    if (!this.nodeStart) {
      if (c === ":" && indicator) this.nodeStart = true;
      return j + 1;
    }
    if (c === "[" || c === "{") {
      this.depth = 1;
      this.required = this.lineIndent + 1;
      this.lastSig = c;
      this.nodeStart = false;
    } else if (c === "'" || c === '"') {
      this.quote = c;
      this.nodeStart = false;
    } else if (c === "|" || c === ">") {
      this.blockScalarIndent = this.lineIndent;
      // The rest of the line is the header (and maybe a comment).
      const h = src.indexOf(" #", j);
      if (h >= 0 && h < end) this.comment = h + 1;
      return end;
    } else if ((c === "-" || c === "?" || c === ":") && indicator) {
      // An indicator: a node may follow.
    } else if (c === "&" || c === "!") {
      while (j + 1 < end && !isBlank(src[j + 1])) j++;
    } else {
      this.nodeStart = false;
    }
    return j + 1;
  }
}

function countSpaces(src: string, from: number, end: number): number {
  let i = from;
  while (i < end && src[i] === " ") i++;
  return i - from;
}
