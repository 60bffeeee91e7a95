import { z } from "zod";
import {
  BlockConfigError,
  defineBlock,
  LegacyParamsError,
  legacyInteger,
  type BlockContext,
  type Frame,
  type UdpSocketHandle,
} from "../../engine";
import { ACTUATION_SIZE, controlInput, describeControl, toActuation } from "../control/actuation";
import { inputName, vectorInput, type SignalInput } from "../shared/inputs";
import { plural } from "../shared/text";
import { guiActivations, guiArv, guiRawEmg } from "./hannes-protocol";
import { hostParam, portParam, NO_UDP } from "./udp-common";
import { UdpOutputRun } from "./udp-output-run";

const params = z.strictObject({
  Host: hostParam("The computer running IIT's Hannes GUI (the virtual arm)"),
  Port: portParam("Its UDP port (8889 in the original's examples)"),
  RawEmgBytes: z
    .number()
    .int()
    .min(1)
    .max(60_000)
    .optional()
    .describe(
      "Data bytes of a raw-EMG datagram (the original's nRawEMGBytes; one byte per channel); " +
        "default: one per value of the raw-EMG input",
    ),
  ArvBytes: z
    .number()
    .int()
    .min(8)
    .max(60_000)
    .optional()
    .describe(
      "Data bytes of an ARV datagram (the original's nARVBytes; 8 per value, float64); " +
        "default: 8 per value of the ARV input",
    ),
  Input: z
    .enum(["auto", "actuation", "prediction"])
    .default("auto")
    .describe(
      "What the control input carries: actuation (a ControlAlgorithm's MOSAIC output, 11 values " +
        "0–100) or prediction (MOSAIC's 12–15 predictions 0–1, mapped as DirectControl); auto: by " +
        "its width",
    ),
});

/** The raw-EMG or ARV input, with its datagram size in bytes. */
interface StreamInput {
  input: SignalInput;
  bytes: number;
}

/** What the control input carries, as controlInput found it. */
type Control = ReturnType<typeof controlInput>;

/** The optional raw-EMG or ARV input, with its datagram size in bytes. */
function streamInput(
  ctx: BlockContext,
  index: number,
  given: number | undefined,
  perValue: number,
  param: string,
): StreamInput | null {
  if (ctx.inputs.length <= index) {
    if (given !== undefined) {
      throw new BlockConfigError(
        `${param} is given but there is no input at position ${index + 1} (Inputs: [control, rawEmg, arv])`,
        param,
      );
    }
    return null;
  }
  const input = vectorInput(ctx, index);
  const need = input.size * perValue;
  const bytes = given ?? need;
  if (bytes < need) {
    throw new BlockConfigError(
      `input ${inputName(input.info)} has ${input.size} values, ${need} bytes, more than ${param} ${bytes} ` +
        "(the original failed on every event here)",
      param,
    );
  }
  return { input, bytes };
}

export const HannesGUI = defineBlock({
  type: "HannesGUI",
  category: "Devices",
  summary:
    "Drives IIT's virtual Hannes arm (HannesGUI) over UDP: hand and wrist activations, and optionally raw EMG and ARVs for its display.",
  help:
    "MOSAIC's HannesGUI (older files: HannesArm) sends to IIT's Hannes GUI, a virtual Hannes arm, " +
    "over UDP (docs/protocols.md, Hannes). Inputs `[control, rawEmg?, arv?]`. Every control event " +
    "sends three 7-byte datagrams `%`, 15, joint, value, `&`, CR, LF: joint 0 (hand) with the " +
    "thumb flexion, 1 (wrist pronation/supination) and 2 (wrist flexion/extension), each the " +
    "actuation value 0–100 as a byte. The control input is a ControlAlgorithm's MOSAIC output " +
    "(11 degrees of actuation) or a plain prediction vector (12–15 values, mapped as DirectControl: " +
    "the original's older examples wired a predictor straight in). A raw-EMG event sends `%`, 16, " +
    "one signed byte per value (128·x), `&`, CR, LF; an ARV event `%`, 32, one little-endian " +
    "float64 per value, `&`, CR, LF; `RawEmgBytes` and `ArvBytes` fix their sizes (zero padded), " +
    "as the original's nRawEMGBytes and nARVBytes. MOSAIC's positional form is `[host, port, " +
    "nRawEMGBytes, nARVBytes]`; the older `HannesArm` files give `[host, port]` and one input, " +
    "which loads too (the original's HannesGUI refused it). Nothing is sent in the browser build " +
    "(no sockets; the status says so); send errors are counted and shown.",
  params,
  legacyParams(args) {
    if (args.length !== 2 && args.length !== 4) {
      throw new LegacyParamsError(
        `expected [host, port, nRawEMGBytes, nARVBytes] or [host, port], got ${args.length} argument${args.length === 1 ? "" : "s"}`,
      );
    }
    const host = args[0]!.trim();
    if (host === "") throw new LegacyParamsError("the host (first argument) is empty", "Host");
    const out: Record<string, unknown> = {
      Host: host,
      Port: legacyInteger(args[1]!, "port", "Port"),
    };
    if (args.length === 4) {
      out.RawEmgBytes = legacyInteger(args[2]!, "nRawEMGBytes", "RawEmgBytes");
      out.ArvBytes = legacyInteger(args[3]!, "nARVBytes", "ArvBytes");
    }
    return out;
  },
  legacyForm:
    "[host, port, nRawEMGBytes, nARVBytes] with Inputs [control, rawEmg, arv], or the older " +
    "HannesArm's [host, port] with Inputs [control]",
  inputs: { min: 1, max: 3, labels: ["control", "rawEmg", "arv"] },
  outputs: [],
  eventLoop: true,
  views: ["label"],
  panel: "Destination and datagrams sent per kind.",
  create(ctx, p) {
    const control = controlInput(ctx, 0, p.Input, "Input");
    // MOSAIC's 4-value form sized both streams; with two inputs or fewer the sizes only check.
    const raw = streamInput(ctx, 1, p.RawEmgBytes, 1, "RawEmgBytes");
    const arv = streamInput(ctx, 2, p.ArvBytes, 8, "ArvBytes");
    if (ctx.declaredRate === undefined) ctx.setDesiredRate(0);
    return new HannesGuiRun(ctx, p.Host, p.Port, control, raw, arv).instance();
  },
});

/** One HannesGUI at run time: the datagrams per event, their counts and the status. */
class HannesGuiRun extends UdpOutputRun {
  private readonly act = new Float64Array(ACTUATION_SIZE);
  private readonly reads: string;
  /** Datagrams sent: activations, raw EMG, ARV. */
  private readonly counts = [0, 0, 0];

  constructor(
    ctx: BlockContext,
    host: string,
    port: number,
    private readonly control: Control,
    private readonly raw: StreamInput | null,
    private readonly arv: StreamInput | null,
  ) {
    super(ctx, host, port, "the Hannes GUI");
    this.reads = describeControl(control);
    if (this.bridge) this.describe();
  }

  /** Sends each event (none without a socket: counted as not sent); the status at its pace. */
  protected process(f: Frame, port: number): void {
    const n = f.n;
    if (n === 0) return;
    const s = this.socket;
    if (!s) {
      this.notSent += n;
      if (this.throttle.due(f.t[n - 1]!)) this.describe();
      return;
    }
    const v = f.v;
    for (let e = 0; e < n; e++) this.sendEvent(s, port, v, e);
    if (this.throttle.due(f.t[n - 1]!)) this.describe();
  }

  /** Event e of input `port`: three activation datagrams, a raw-EMG or an ARV datagram. */
  private sendEvent(s: UdpSocketHandle, port: number, v: Float64Array, e: number): void {
    const counts = this.counts;
    const raw = this.raw;
    const arv = this.arv;
    if (port === 0) {
      toActuation(this.control, v, e, this.act);
      for (const d of guiActivations(this.act)) s.send(d);
      counts[0] = counts[0]! + 3;
    } else if (port === 1 && raw) {
      s.send(guiRawEmg(v, e * raw.input.size, raw.input.size, raw.bytes));
      counts[1] = counts[1]! + 1;
    } else if (port === 2 && arv) {
      s.send(guiArv(v, e * arv.input.size, arv.input.size, arv.bytes));
      counts[2] = counts[2]! + 1;
    }
  }

  protected clearCounts(): void {
    this.counts.fill(0);
  }

  /** The status: the destination, what the input carries, datagrams per kind and failures. */
  protected describe(): void {
    if (!this.bridge) {
      this.ctx.setText(`${NO_UDP}: ${plural(this.notSent, "event")} not sent`);
      return;
    }
    const counts = this.counts;
    let s = `→ ${this.dest}, ${this.reads}: ${plural(counts[0]!, "activation")}`;
    if (this.raw) s += `, ${plural(counts[1]!, "raw EMG datagram")}`;
    if (this.arv) s += `, ${plural(counts[2]!, "ARV datagram")}`;
    if (this.failed > 0) s += `; ${this.failed} failed (${this.lastError})`;
    this.ctx.setText(s);
  }
}
