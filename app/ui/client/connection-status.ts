/**
 * Which engine runs the page's pipeline, and why a connection to `mosaic serve` ended, in words
 * the toolbar and the page show (issue 17): "engine: mosaic serve at 127.0.0.1:8321" or "engine:
 * in this page (browser build)"; a refused socket names its cause (wrong token, foreign page)
 * instead of leaving the page at "engine starting…".
 */
import { CLOSE_BAD_TOKEN, CLOSE_FOREIGN_ORIGIN } from "../../engine/protocol-wire";

/** Where the engine the page talks to runs. */
export type EngineWhere =
  { kind: "host"; address: string } | { kind: "page" } | { kind: "desktop" };

/** The toolbar's words for an engine. */
export function engineLabel(where: EngineWhere): string {
  switch (where.kind) {
    case "host":
      return `engine: mosaic serve at ${where.address}`;
    case "page":
      return "engine: in this page (browser build)";
    case "desktop":
      return "engine: MOSAIC desktop app";
  }
}

/** The longer explanation (tooltip) for an engine: what runs where, and how to get the other. */
export function engineDetail(where: EngineWhere, helloName: string): string {
  const named = helloName ? ` (${helloName})` : "";
  switch (where.kind) {
    case "host":
      return `The pipeline runs in the \`mosaic serve\` process at ${where.address}${named}, with its devices; other tabs on that address share it.`;
    case "page":
      return `The pipeline runs in this page's own engine${named}, with simulated devices. This URL has no ?token=: to use a \`mosaic serve\` engine, open the URL it printed.`;
    case "desktop":
      return `The pipeline runs in the MOSAIC desktop app's engine${named}, shared by its windows.`;
  }
}

/** Why the socket to `mosaic serve` closed; `opened` tells whether it ever opened. */
export interface ConnectionLoss {
  /** True when the host refused this page (it never got an engine). */
  refused: boolean;
  message: string;
}

/** A close event (code and reason) in words. */
export function explainClose(code: number, reason: string, opened: boolean): ConnectionLoss {
  const why = reason.trim();
  if (code === CLOSE_BAD_TOKEN || code === CLOSE_FOREIGN_ORIGIN) {
    const what = why || (code === CLOSE_BAD_TOKEN ? "wrong or missing token" : "foreign page");
    return {
      refused: true,
      message: `mosaic serve refused this page: ${what} — open the URL mosaic serve printed`,
    };
  }
  if (!opened) {
    return {
      refused: true,
      message:
        "could not connect to mosaic serve" +
        (why ? `: ${why}` : " (is `mosaic serve` still running at this address?)"),
    };
  }
  if (why) return { refused: false, message: `mosaic serve closed the connection: ${why}` };
  return {
    refused: false,
    message: "the connection to mosaic serve closed (is `mosaic serve` still running?)",
  };
}
