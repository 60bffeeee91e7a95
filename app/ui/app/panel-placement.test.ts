import { describe, expect, test } from "vitest";
import { MIN_PANEL, overlapArea, placeBeside, type Rect } from "./panel-placement";

const area = { width: 1000, height: 600 };
const size = { width: 480, height: 400 };
const box = (p: { x: number; y: number; width?: number; height?: number }): Rect => ({
  x: p.x,
  y: p.y,
  width: p.width ?? size.width,
  height: p.height ?? size.height,
});

describe("a floating panel beside the node that opened it", () => {
  test("stays where it is when it does not cover the node", () => {
    const node = { x: 700, y: 300, width: 184, height: 92 };
    expect(placeBeside(node, { x: 60, y: 40 }, size, area)).toEqual({ x: 60, y: 40 });
  });

  test("goes right of the node when it fits there, at the node's height", () => {
    const node = { x: 50, y: 100, width: 184, height: 92 };
    const p = placeBeside(node, { x: 60, y: 40 }, size, area);
    expect(p).toEqual({ x: 246, y: 100 });
    expect(overlapArea(node, box(p))).toBe(0);
  });

  test("goes left when the right is too narrow, kept inside the area", () => {
    const node = { x: 700, y: 500, width: 184, height: 92 };
    const p = placeBeside(node, { x: 650, y: 300 }, size, area);
    expect(p).toEqual({ x: 208, y: 200 });
    expect(overlapArea(node, box(p))).toBe(0);
  });

  test("is made narrower beside a node in the middle when it fits nowhere whole", () => {
    const small = { width: 820, height: 480 };
    const node = { x: 437, y: 185, width: 104, height: 50 };
    const p = placeBeside(node, { x: 60, y: 40 }, size, small);
    expect(p.width).toBeGreaterThanOrEqual(MIN_PANEL.width);
    expect(p.width).toBeLessThan(size.width);
    expect(overlapArea(node, box(p))).toBe(0);
    expect(p.x).toBeGreaterThanOrEqual(0);
    expect(p.x + p.width!).toBeLessThanOrEqual(small.width);
  });

  test("stays inside the area when there is no room beside the node at all", () => {
    const tiny = { width: 500, height: 420 };
    const node = { x: 150, y: 150, width: 184, height: 92 };
    const p = placeBeside(node, { x: 300, y: 100 }, size, tiny);
    expect(p.x).toBeGreaterThanOrEqual(0);
    expect(p.y).toBeGreaterThanOrEqual(0);
    expect(p.x + size.width).toBeLessThanOrEqual(tiny.width);
    expect(p.y + size.height).toBeLessThanOrEqual(tiny.height);
  });
});
