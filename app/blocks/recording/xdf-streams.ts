/**
 * What the XdfRecorder writes for each input: its stream description (the StreamHeader's name,
 * type, channels, rate and format, as an LSL outlet would describe it) and the file's name.
 */
import { z } from "zod";
import { BlockConfigError, type BlockContext, type InputInfo } from "../../engine";
import { signalInput } from "../shared/inputs";
import type { ChannelFormat, NumericFormat, StreamInfo } from "./xdf-writer";
import { MAX_CHANNELS } from "../shared/limits";

export const streamSettings = z.strictObject({
  Name: z.string().min(1).optional().describe("Stream name (default: the input as written)"),
  Type: z
    .string()
    .min(1)
    .optional()
    .describe(
      "Content type, e.g. EMG, EEG, Markers (default: Markers for events, else the source block's type)",
    ),
  Labels: z
    .array(z.string().max(200))
    .max(MAX_CHANNELS)
    .optional()
    .describe("One label per channel (default: the source's channel names, else ch1, ch2, …)"),
  Unit: z
    .string()
    .optional()
    .describe("Unit of every channel, e.g. microvolts (default: the source's, if it says)"),
  Format: z
    .enum(["float32", "double64", "string"])
    .optional()
    .describe(
      "Value format; string records each event as one marker text (its values joined by commas). Default: string for events (Stimulus trigger, Trigger, StimTrigger, TAC), else the block's Format",
    ),
});
export type StreamSettings = z.output<typeof streamSettings>;

/**
 * Outputs that carry events rather than a signal (the Buffer's trigger protocol, trials): recorded
 * as string marker streams (channel_format string, irregular rate) as LabRecorder records LSL
 * marker streams. Ports listed per source type; null: every port.
 */
const MARKER_OUTPUTS: Record<string, readonly string[] | null> = {
  Trigger: null,
  StimTrigger: null,
  TAC: null,
  Stimulus: ["trigger"],
};

export function isMarkerInput(info: InputInfo): boolean {
  if (info.type === undefined || !Object.hasOwn(MARKER_OUTPUTS, info.type)) return false;
  const ports = MARKER_OUTPUTS[info.type]!;
  return ports === null || ports.includes(info.port);
}

/** A stream's description, less the time it is created (set when a file is opened). */
export type PlannedStream = Omit<StreamInfo, "createdAt" | "uid"> & {
  /** Values per event in the input (rows × cols). */
  size: number;
};

/** The stream every input becomes. */
export function planStreams(
  ctx: BlockContext,
  format: NumericFormat,
  settings: Readonly<Record<string, StreamSettings>>,
): PlannedStream[] {
  const sources = new Set(ctx.inputs.map((i) => i.source));
  for (const key of Object.keys(settings)) {
    if (!sources.has(key)) {
      throw new BlockConfigError(
        `Streams names '${key}', which is not one of the inputs (${[...sources].join(", ")})`,
        "Streams",
      );
    }
  }
  const seen = new Set<string>();
  return ctx.inputs.map((info) => {
    if (seen.has(info.source)) {
      throw new BlockConfigError(
        `input '${info.source}' is listed twice; each input is one stream of the file, so list it once`,
      );
    }
    seen.add(info.source);
    const { size } = signalInput(ctx, info.index);
    return planStream(ctx, info, size, format, settings[info.source] ?? {});
  });
}

function planStream(
  ctx: BlockContext,
  info: InputInfo,
  size: number,
  format: NumericFormat,
  s: StreamSettings,
): PlannedStream {
  const fmt: ChannelFormat = s.Format ?? (isMarkerInput(info) ? "string" : format);
  const marker = fmt === "string";
  const channels = marker ? 1 : size;
  const name = s.Name ?? info.source;
  let labels: string[];
  if (s.Labels !== undefined) {
    if (s.Labels.length !== channels) {
      throw new BlockConfigError(
        `Streams.${info.source}.Labels has ${s.Labels.length} label${s.Labels.length === 1 ? "" : "s"}, ` +
          `but the stream has ${channels} channel${channels === 1 ? "" : "s"}` +
          (marker ? " (a marker stream has one)" : ""),
        "Streams",
      );
    }
    labels = [...s.Labels];
  } else if (marker) {
    labels = [name];
  } else {
    // The source's own channel names (PortMeta) when it gives them, else ch1, ch2, …
    const known = info.meta?.labels;
    labels =
      known?.length === channels
        ? [...known]
        : Array.from({ length: channels }, (_, k) => `ch${k + 1}`);
  }
  return {
    name,
    type: s.Type ?? (marker ? "Markers" : (info.type ?? "MOSAIC")),
    channelCount: channels,
    nominalRate: marker ? 0 : info.rate,
    format: fmt,
    sourceId: `MOSAIC/${ctx.name}/${info.source}`,
    labels,
    unit: s.Unit ?? (marker ? "" : (info.meta?.unit ?? "")),
    hostname: "",
    size,
  };
}

// ---------------------------------------------------------------------------------------------
// File names

const pad = (n: number, w = 2): string => String(n).padStart(w, "0");

/** `{date}` → 2026-11-24, `{time}` → 09-41-07 (local time of `t`, UNIX s), `{block}` → name. */
export function expandFileName(template: string, t: number, block: string): string {
  const d = new Date(t * 1000);
  const date = `${d.getFullYear()}-${pad(d.getMonth() + 1)}-${pad(d.getDate())}`;
  const time = `${pad(d.getHours())}-${pad(d.getMinutes())}-${pad(d.getSeconds())}`;
  return template
    .replaceAll("{date}", date)
    .replaceAll("{time}", time)
    .replaceAll("{block}", block);
}

/** The k-th alternative of a name that exists already: rec.xdf → rec_2.xdf, rec_3.xdf, … */
export function numberedName(name: string, k: number): string {
  if (k <= 1) return name;
  const slash = Math.max(name.lastIndexOf("/"), name.lastIndexOf("\\"));
  const dot = name.lastIndexOf(".");
  if (dot > slash + 1) return `${name.slice(0, dot)}_${k}${name.slice(dot)}`;
  return `${name}_${k}`;
}

/** A short size: 812 B, 3.4 kB, 12.0 MB, 1.25 GB. */
export function formatBytes(n: number): string {
  if (n < 1000) return `${n} B`;
  if (n < 1e6) return `${(n / 1e3).toFixed(1)} kB`;
  if (n < 1e9) return `${(n / 1e6).toFixed(1)} MB`;
  return `${(n / 1e9).toFixed(2)} GB`;
}
