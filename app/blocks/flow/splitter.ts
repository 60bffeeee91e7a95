import { z } from "zod";
import {
  BlockConfigError,
  defineBlock,
  legacyVector,
  LegacyParamsError,
  vectorShape,
  type OutputPort,
} from "../../engine";
import { checkIndices, inputName, vectorInput } from "../shared/inputs";
import { MAX_CHANNELS, MAX_ITEMS } from "../shared/limits";
import { index } from "../shared/params";

const PORT_RE = /^[A-Za-z0-9_-]+$/;

const params = z
  .strictObject({
    Parts: z
      .record(
        z.string().regex(PORT_RE, "a port name uses only letters, digits, '_' and '-'"),
        z.array(index()).min(1).max(MAX_CHANNELS),
      )
      .refine((parts) => Object.keys(parts).length <= MAX_ITEMS, {
        message: `at most ${MAX_ITEMS} ports`,
      })
      .optional()
      .describe(
        "Output ports by name, each with the 0-based input indices it carries, e.g. " +
          "{ flexors: [0, 1, 2], extensors: [4, 5, 6] }; downstream blocks read `Split.flexors`",
      ),
    Sizes: z
      .array(z.number().int().min(1))
      .min(1)
      .max(MAX_ITEMS)
      .optional()
      .describe(
        "Consecutive part sizes, e.g. [4, 4] splits 8 channels into ports `0` (0–3) and `1` " +
          "(4–7); the sizes must add up to the input width",
      ),
  })
  .refine((p) => (p.Parts === undefined) !== (p.Sizes === undefined), {
    message: "give exactly one of Parts (named index lists) or Sizes (consecutive part sizes)",
  })
  .refine((p) => p.Parts === undefined || Object.keys(p.Parts).length > 0, {
    message: "Parts needs at least one port",
    path: ["Parts"],
  });

type Params = z.output<typeof params>;

const portNames = (p: Params): string[] =>
  p.Parts !== undefined ? Object.keys(p.Parts) : (p.Sizes ?? []).map((_, i) => String(i));

export const Splitter = defineBlock({
  type: "Splitter",
  category: "Flow control",
  summary: "Divides a vector stream into several output ports, by index lists or by part sizes.",
  help:
    "Divides a vector stream into multiple outputs (paper Table 3). With `Parts`, every named " +
    "port carries the listed input elements, in the listed order (an index may appear in several " +
    "parts, or be left out). With `Sizes`, the vector is cut into consecutive parts whose sizes " +
    "must add up to the input width; the ports are named `0`, `1`, …. Downstream blocks subscribe " +
    "to a port as `Split.flexors` or `Split.1`. Timestamps are copied.",
  params,
  legacyParams(args) {
    if (args.length !== 1) {
      throw new LegacyParamsError(
        `expected one argument (sizes a;b;c), got ${args.length}`,
        "Sizes",
      );
    }
    const sizes = legacyVector(args[0]!, "sizes", "Sizes");
    return { Sizes: sizes };
  },
  legacyForm: "[a;b;c]: consecutive part sizes, ports named 0, 1, 2",
  inputs: { min: 1, max: 1, labels: ["signal"] },
  outputs: portNames,
  views: ["scope"],
  panel: "Scope of each part.",
  create(ctx, p) {
    const sig = vectorInput(ctx, 0);
    const width = sig.size;
    const parts: number[][] = [];
    if (p.Parts !== undefined) {
      for (const [name, idx] of Object.entries(p.Parts)) {
        checkIndices(idx, width, `input ${inputName(sig.info)} (part '${name}')`, "Parts");
        parts.push(idx);
      }
    } else {
      const sizes = p.Sizes!;
      const total = sizes.reduce((a, b) => a + b, 0);
      if (total !== width) {
        throw new BlockConfigError(
          `Sizes [${sizes.join(", ")}] add up to ${total}, but input ${inputName(sig.info)} has ` +
            `${width} channels; the sizes must add up to the input width`,
          "Sizes",
        );
      }
      let start = 0;
      for (const s of sizes) {
        parts.push(Array.from({ length: s }, (_, i) => start + i));
        start += s;
      }
    }
    const names = portNames(p);
    const ports: OutputPort[] = parts.map((idx, i) =>
      ctx.output(vectorShape(idx.length), names[i]!),
    );
    const maps = parts.map((idx) => Int32Array.from(idx));
    return {
      process(f) {
        const n = f.n;
        if (n === 0) return;
        const v = f.v;
        const ft = f.t;
        for (let j = 0; j < ports.length; j++) {
          const port = ports[j]!;
          if (port.idle) continue;
          const map = maps[j]!;
          const k = map.length;
          const o = port.frame(n);
          const ov = o.v;
          for (let e = 0; e < n; e++) {
            o.t[e] = ft[e]!;
            const src = e * width;
            const dst = e * k;
            for (let c = 0; c < k; c++) ov[dst + c] = v[src + map[c]!]!;
          }
          port.emit(o);
        }
      },
    };
  },
});
