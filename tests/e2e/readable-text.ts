/**
 * Measures the text a person sees on the page: every visible text node's font size on screen
 * (its computed size times the scale of every transform above it, the BlockTable's zoom
 * included, and any CSS zoom), and every string drawn into a visible canvas (the font it was
 * drawn with times the canvas's transform and its CSS size / backing size). Used by
 * readable-text.test.ts (issue 17, acceptance: no label under 11 px on screen).
 */
import type { Page } from "playwright-core";

export interface SeenText {
  text: string;
  /** Font size on screen, CSS px. */
  px: number;
  /** "dom" (a text node, with its element's classes) or "canvas" (the canvas's view). */
  where: string;
}

/**
 * Installed before the page's own scripts: remembers what every canvas draws (text, font size
 * on screen) so the test can read what the last frames of each visible canvas said.
 */
export const CANVAS_TEXT_RECORDER = `(() => {
  window.__canvasText = new WeakMap();
  const proto = CanvasRenderingContext2D.prototype;
  for (const name of ["fillText", "strokeText"]) {
    const orig = proto[name];
    proto[name] = function (text, ...rest) {
      try {
        const m = /([\\d.]+)px/.exec(this.font);
        const t = this.getTransform();
        const c = this.canvas;
        const css = c.getBoundingClientRect().width / (c.width || 1);
        if (m && String(text).trim() !== "") {
          const seen = window.__canvasText;
          const list = seen.get(c) ?? [];
          list.push({ text: String(text), px: Number(m[1]) * Math.hypot(t.a, t.b) * css });
          if (list.length > 400) list.splice(0, list.length - 400);
          seen.set(c, list);
        }
      } catch {}
      return orig.call(this, text, ...rest);
    };
  }
})();`;

/** Forgets what canvases drew so far (the next measure reads only newer frames). */
export async function resetCanvasText(page: Page): Promise<void> {
  await page.evaluate("window.__canvasText = new WeakMap()");
}

/** Every text the page shows now, with its size on screen. */
export function seenText(page: Page): Promise<SeenText[]> {
  return page.evaluate(MEASURE) as Promise<SeenText[]>;
}

/** Runs in the page (a string: this file is type-checked without the DOM library). */
const MEASURE = `(() => {
  const vw = window.innerWidth, vh = window.innerHeight;
  const clipOf = (el) => {
    let r = { left: 0, top: 0, right: vw, bottom: vh };
    for (let a = el; a && a !== document.documentElement; a = a.parentElement) {
      const cs = getComputedStyle(a);
      if (cs.overflowX !== "visible" || cs.overflowY !== "visible" || cs.clip !== "auto") {
        const b = a.getBoundingClientRect();
        r = { left: Math.max(r.left, b.left), top: Math.max(r.top, b.top),
              right: Math.min(r.right, b.right), bottom: Math.min(r.bottom, b.bottom) };
      }
    }
    return r;
  };
  const shows = (rect, clip) =>
    Math.min(rect.right, clip.right) - Math.max(rect.left, clip.left) > 1 &&
    Math.min(rect.bottom, clip.bottom) - Math.max(rect.top, clip.top) > 1;
  const scaleOf = (el) => {
    let s = 1;
    for (let a = el; a; a = a.parentElement) {
      const cs = getComputedStyle(a);
      if (cs.transform && cs.transform !== "none") {
        const m = new DOMMatrixReadOnly(cs.transform);
        s *= Math.hypot(m.a, m.b);
      }
      const z = Number(cs.zoom);
      if (z > 0 && z !== 1) s *= z;
    }
    return s;
  };
  const label = (el) =>
    el.tagName.toLowerCase() + (typeof el.className === "string" && el.className
      ? "." + el.className.trim().split(/\\s+/).join(".") : "");
  const out = [];
  const walker = document.createTreeWalker(document.body, NodeFilter.SHOW_TEXT);
  for (let n = walker.nextNode(); n; n = walker.nextNode()) {
    const text = n.textContent.trim();
    const el = n.parentElement;
    if (!text || !el || el.closest("title, script, style, option, noscript, [hidden]")) continue;
    if (!el.checkVisibility({ opacityProperty: true, visibilityProperty: true })) continue;
    const range = document.createRange();
    range.selectNodeContents(n);
    const clip = clipOf(el);
    if (![...range.getClientRects()].some((r) => shows(r, clip))) continue;
    const px = parseFloat(getComputedStyle(el).fontSize) * scaleOf(el);
    out.push({ text: text.slice(0, 60), px, where: "dom " + label(el) });
  }
  for (const c of document.querySelectorAll("canvas")) {
    if (!c.checkVisibility({ opacityProperty: true, visibilityProperty: true })) continue;
    if (!shows(c.getBoundingClientRect(), clipOf(c))) continue;
    for (const t of window.__canvasText?.get(c) ?? []) {
      out.push({ text: t.text.slice(0, 60), px: t.px, where: "canvas " + label(c.closest("[data-view]") ?? c) });
    }
  }
  return out;
})()`;

/** The texts under `min` px, one line each (for the failure message). */
export function tooSmall(seen: readonly SeenText[], min: number): string[] {
  const lines = new Set<string>();
  for (const s of seen) {
    if (s.px < min) lines.add(`${s.px.toFixed(1)} px  "${s.text}"  (${s.where})`);
  }
  return [...lines];
}
