/**
 * Exports of the scope's visible window (DOM): the samples in view as CSV (time and the named
 * channels) and the picture as PNG with a legend strip under it, both downloaded.
 */
import { saveFile } from "../app/save-file";
import { channelColor } from "./channels";
import type { ScopeLive } from "./scope-draw";
import { visibleCsv } from "./scope-view";

/** "Emg.emg-2026-11-24T12-30-05" (no characters a file system refuses). */
export function exportName(block: string, port: string, ext: string, now = new Date()): string {
  const stamp = now.toISOString().slice(0, 19).replaceAll(":", "-");
  return `${block}.${port}-${stamp}.${ext}`.replace(/[^\w.\-]+/g, "_");
}

/** The CSV of the samples in view (the x range drawn last). */
export function scopeCsv(l: ScopeLive): string {
  const b = l.buffer;
  if (!b) return visibleCsv([], [], l.names, 0, 0);
  const data = b.view(l.x[0], l.x[1]);
  return visibleCsv(data[0]!, data.slice(1), l.names, l.x[0], l.x[1]);
}

export function downloadCsv(l: ScopeLive, block: string, port: string): void {
  saveFile(exportName(block, port, "csv"), "text/csv", new TextEncoder().encode(scopeCsv(l)));
}

/** The plot's canvas with a legend strip (colour and name of each channel) under it. */
function composePng(
  source: HTMLCanvasElement,
  names: string[],
  channels: number[],
): HTMLCanvasElement {
  const dpr = typeof devicePixelRatio === "number" ? devicePixelRatio : 1;
  const row = Math.round(18 * dpr);
  const out = document.createElement("canvas");
  const ctx0 = out.getContext("2d");
  const perRow = Math.max(1, Math.floor(source.width / (120 * dpr)));
  const rows = Math.ceil(names.length / perRow);
  out.width = source.width;
  out.height = source.height + rows * row + Math.round(6 * dpr);
  if (!ctx0) return source;
  const ctx = ctx0;
  ctx.fillStyle = "#ffffff";
  ctx.fillRect(0, 0, out.width, out.height);
  ctx.drawImage(source, 0, 0);
  ctx.font = `${Math.round(12 * dpr)}px system-ui, sans-serif`;
  ctx.textBaseline = "middle";
  names.forEach((name, k) => {
    const x = (k % perRow) * 120 * dpr + 8 * dpr;
    const y = source.height + Math.floor(k / perRow) * row + row / 2 + 3 * dpr;
    ctx.fillStyle = channelColor(channels[k] ?? k);
    ctx.fillRect(x, y - 5 * dpr, 10 * dpr, 10 * dpr);
    ctx.fillStyle = "#1f2328";
    ctx.fillText(name, x + 14 * dpr, y);
  });
  return out;
}

/** Downloads `canvas` (with the legend of `names`) as a PNG. */
export function downloadPng(
  canvas: HTMLCanvasElement,
  names: string[],
  channels: number[],
  block: string,
  port: string,
): void {
  composePng(canvas, names, channels).toBlob((blob) => {
    if (!blob) return;
    void blob
      .arrayBuffer()
      .then((buf) => saveFile(exportName(block, port, "png"), "image/png", new Uint8Array(buf)));
  }, "image/png");
}
