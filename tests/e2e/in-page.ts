/**
 * The page as functions evaluated in it (page.evaluate, $eval, waitForFunction) see it, typed
 * for test files compiled without the DOM library (tsconfig.node.json): only what they use.
 */
export interface InPageRect {
  x: number;
  y: number;
  left: number;
  top: number;
  right: number;
  bottom: number;
  width: number;
  height: number;
}

export interface InPageElement {
  style: Record<string, string>;
  dataset: Record<string, string | undefined>;
  offsetLeft: number;
  offsetTop: number;
  offsetWidth: number;
  offsetHeight: number;
  textContent: string | null;
  value: string;
  classList: { contains(name: string): boolean };
  getBoundingClientRect(): InPageRect;
  getAttribute(name: string): string | null;
  matches(selector: string): boolean;
  closest(selector: string): InPageElement | null;
  querySelector(selector: string): InPageElement | null;
  querySelectorAll(selector: string): Iterable<InPageElement> & { length: number };
}

export interface InPageWindow {
  document: {
    activeElement: InPageElement | null;
    querySelector(selector: string): InPageElement | null;
    querySelectorAll(selector: string): Iterable<InPageElement> & { length: number };
  };
  getComputedStyle(el: InPageElement): Record<string, string>;
  localStorage: { getItem(key: string): string | null };
}
