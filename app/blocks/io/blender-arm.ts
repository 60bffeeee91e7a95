import { z } from "zod";
import {
  BlockConfigError,
  defineBlock,
  LegacyParamsError,
  legacyInteger,
  vectorShape,
  type BlockContext,
  type Frame,
  type OutputPort,
} from "../../engine";
import {
  ACTUATION_SIZE,
  controlInput,
  describeControl,
  toActuation,
  type ControlKind,
} from "../control/actuation";
import { inputName, vectorInput } from "../shared/inputs";
import { plural } from "../shared/text";
import { asciiBytes, BLENDER_SIZE, blenderCommand, blenderText } from "./blender-format";
import { hostParam, portParam, NO_UDP } from "./udp-common";
import { UdpOutputRun } from "./udp-output-run";

const params = z.strictObject({
  Host: hostParam("The computer running the Blender scene: an IP address or host name"),
  Port: portParam(
    "Its UDP port (the original's examples: 3333 for the white target arm, 3334 for the skin arm)",
  ),
  Input: z
    .enum(["auto", "actuation", "prediction", "command"])
    .default("auto")
    .describe(
      "What the input carries: actuation (a ControlAlgorithm's MOSAIC output, 11 values 0–100), " +
        "prediction (MOSAIC's 12–15 predictions 0–1, mapped as DirectControl), command (the nine " +
        "values to send as they are); auto: 11 values actuation, 12–15 prediction, 9 command",
    ),
});

/** What the input carries (kind undefined: the nine command values as they are) and its width. */
interface Control {
  kind: ControlKind | undefined;
  size: number;
}

/** Checks input 0 against the Input param: a command has the nine values, else a control input. */
function checkControl(ctx: BlockContext, input: z.infer<typeof params>["Input"]): Control {
  if (input === "command") {
    const s = vectorInput(ctx, 0, "Input");
    if (s.size !== BLENDER_SIZE) {
      throw new BlockConfigError(
        `Input is command, but input ${inputName(s.info)} has ${s.size} values; a command has ${BLENDER_SIZE}`,
        "Input",
      );
    }
    return { kind: undefined, size: s.size };
  }
  return controlInput(ctx, 0, input, "Input", {
    width: BLENDER_SIZE,
    what: `the ${BLENDER_SIZE} command values`,
  });
}

export const BlenderArm = defineBlock({
  type: "BlenderArm",
  category: "Devices",
  summary:
    "Drives the virtual Blender arm of MOSAIC's studies: one ASCII UDP datagram [a,…,i] per control event.",
  help:
    "The virtual arm the paper's studies drive (a Blender scene listening on UDP; MOSAIC's " +
    "BlenderArm). Every input event becomes one datagram, the ASCII text `[a,b,c,d,e,f,g,h,i]`: " +
    "thumb flexion, thumb rotation, index, middle, ring and little finger (0–1), then wrist " +
    "flexion/extension, ulnar/radial deviation and supination/pronation (−1–1); see " +
    "docs/protocols.md. The input is normally a ControlAlgorithm's output in MOSAIC's mapping " +
    "(11 degrees of actuation, 0–100): fingers are divided by 100, the wrist axes mapped from " +
    "0–100 to −1–1 (pronation/supination with the sign the original's code applied; its formula " +
    "left the range, see the protocol notes). Several of the original's examples wired a plain " +
    "prediction vector (12–15 values 0–1, MOSAIC's order: 6 fingers, wrist flexion, extension, " +
    "pronation, supination, ulnar, radial, open, elbow flexion, extension) straight into the arm, " +
    "which the original could not read; here it is mapped as MOSAIC's DirectControl would (fingers " +
    "as they are, each wrist axis the difference of its two predictions), with missing predictions " +
    "at rest. A 9-value input is sent as it is. Output `command` [1, 9] carries the values sent " +
    "(for a scope or a log). Nothing is sent in the browser build (no sockets; the status says " +
    "so); send errors are counted and shown. MOSAIC's positional form is `[host, port]`.",
  params,
  legacyParams(args) {
    if (args.length !== 2) {
      throw new LegacyParamsError(
        `expected [host, port] (MOSAIC's BlenderArm took exactly 2), got ${args.length} argument${args.length === 1 ? "" : "s"}`,
      );
    }
    const host = args[0]!.trim();
    if (host === "") throw new LegacyParamsError("the host (first argument) is empty", "Host");
    return { Host: host, Port: legacyInteger(args[1]!, "port", "Port") };
  },
  legacyForm: "[host, port], e.g. [localhost, 3334]",
  inputs: { min: 1, max: 1, labels: ["control"] },
  outputs: ["command"],
  eventLoop: true,
  views: ["spider", "label"],
  panel: "The nine values sent (spider), the destination and the datagrams sent.",
  create(ctx, p) {
    const control = checkControl(ctx, p.Input);
    // Aperiodic (MOSAIC set its rate to 0); it sends what arrives.
    if (ctx.declaredRate === undefined) ctx.setDesiredRate(0);
    const out = ctx.output(vectorShape(BLENDER_SIZE), "command");
    return new BlenderArmRun(ctx, p.Host, p.Port, control, out).instance();
  },
});

/** One BlenderArm at run time: one datagram per event, the count and the status. */
class BlenderArmRun extends UdpOutputRun {
  private sent = 0;
  private readonly act = new Float64Array(ACTUATION_SIZE);
  private readonly cmd = new Float64Array(BLENDER_SIZE);
  private readonly reads: string;

  constructor(
    ctx: BlockContext,
    host: string,
    port: number,
    private readonly control: Control,
    private readonly out: OutputPort,
  ) {
    super(ctx, host, port, "the Blender arm");
    this.reads = describeControl(control);
    if (this.bridge) this.describe();
  }

  /** Emits each event's command on `command` and sends it; the status at the throttle's pace. */
  protected process(f: Frame): void {
    const n = f.n;
    if (n === 0) return;
    const o = this.out.frame(n);
    for (let e = 0; e < n; e++) {
      o.t[e] = f.t[e]!;
      this.commandAt(f.v, e);
      o.v.set(this.cmd, e * BLENDER_SIZE);
      this.send();
    }
    this.out.emit(o);
    if (this.throttle.due(f.t[n - 1]!)) this.describe();
  }

  /** Fills `cmd` with event e's nine values: as they are, or mapped from actuation/predictions. */
  private commandAt(v: Float64Array, e: number): void {
    if (this.control.kind === undefined) {
      for (let k = 0; k < BLENDER_SIZE; k++) this.cmd[k] = v[e * BLENDER_SIZE + k]!;
    } else {
      toActuation(this.control, v, e, this.act);
      blenderCommand(this.act, this.cmd);
    }
  }

  /** Sends `cmd` as one ASCII datagram, or counts it as not sent when there is no socket. */
  private send(): void {
    const s = this.socket;
    if (s) {
      s.send(asciiBytes(blenderText(this.cmd)));
      this.sent++;
    } else this.notSent++;
  }

  protected clearCounts(): void {
    this.sent = 0;
  }

  /** The status: the destination, what the input carries, datagrams sent and failed. */
  protected describe(): void {
    if (!this.bridge) {
      this.ctx.setText(`${NO_UDP}: ${plural(this.notSent, "command")} not sent`);
      return;
    }
    const err = this.failed > 0 ? `, ${this.failed} failed (${this.lastError})` : "";
    this.ctx.setText(`→ ${this.dest}, ${this.reads}: ${plural(this.sent, "datagram")} sent${err}`);
  }
}
