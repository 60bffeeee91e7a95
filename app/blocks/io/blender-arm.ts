import { z } from "zod";
import {
  BlockConfigError,
  defineBlock,
  LegacyParamsError,
  legacyInteger,
  vectorShape,
  type UdpSocketHandle,
} from "../../engine";
import {
  ACTUATION_SIZE,
  controlInput,
  describeControl,
  toActuation,
  type ControlKind,
} from "../control/actuation";
import { inputName, vectorInput } from "../shared/inputs";
import { plural, TextThrottle } from "../shared/text";
import { asciiBytes, BLENDER_SIZE, blenderCommand, blenderText } from "./blender-format";
import { endpointText, hostParam, portParam, udpBridge, WarnLimiter, NO_UDP } from "./udp-common";

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
    let control: { kind: ControlKind | undefined; size: number };
    if (p.Input === "command") {
      const s = vectorInput(ctx, 0, "Input");
      if (s.size !== BLENDER_SIZE) {
        throw new BlockConfigError(
          `Input is command, but input ${inputName(s.info)} has ${s.size} values; a command has ${BLENDER_SIZE}`,
          "Input",
        );
      }
      control = { kind: undefined, size: s.size };
    } else {
      control = controlInput(ctx, 0, p.Input, "Input", {
        width: BLENDER_SIZE,
        what: `the ${BLENDER_SIZE} command values`,
      });
    }
    // Aperiodic (MOSAIC set its rate to 0); it sends what arrives.
    if (ctx.declaredRate === undefined) ctx.setDesiredRate(0);
    const out = ctx.output(vectorShape(BLENDER_SIZE), "command");
    const dest = endpointText(p.Host, p.Port);
    const act = new Float64Array(ACTUATION_SIZE);
    const cmd = new Float64Array(BLENDER_SIZE);
    const warns = new WarnLimiter(ctx);
    const throttle = new TextThrottle();
    const reads = describeControl(control);

    let socket: UdpSocketHandle | undefined;
    let sent = 0;
    let failed = 0;
    let notSent = 0;
    let lastError = "";
    const bridge = udpBridge(ctx);
    const describe = (): void => {
      if (!bridge) {
        ctx.setText(`${NO_UDP}: ${plural(notSent, "command")} not sent`);
        return;
      }
      const err = failed > 0 ? `, ${failed} failed (${lastError})` : "";
      ctx.setText(`→ ${dest}, ${reads}: ${plural(sent, "datagram")} sent${err}`);
    };
    if (bridge) describe();
    const onError = (message: string): void => {
      failed++;
      lastError = message;
      warns.warn(`UDP to ${dest}: ${message}`);
      describe();
    };
    const close = (): void => {
      const s = socket;
      socket = undefined;
      s?.close();
    };

    return {
      start() {
        if (!bridge) {
          ctx.warn(`${NO_UDP}: the Blender arm gets nothing`);
          return;
        }
        if (socket) return;
        try {
          socket = bridge.open({ remote: { host: p.Host, port: p.Port }, onError });
        } catch (e) {
          onError(e instanceof Error ? e.message : String(e));
        }
      },
      process(f) {
        const n = f.n;
        if (n === 0) return;
        const o = out.frame(n);
        const v = f.v;
        for (let e = 0; e < n; e++) {
          o.t[e] = f.t[e]!;
          if (control.kind === undefined) {
            for (let k = 0; k < BLENDER_SIZE; k++) cmd[k] = v[e * BLENDER_SIZE + k]!;
          } else {
            toActuation(control, v, e, act);
            blenderCommand(act, cmd);
          }
          o.v.set(cmd, e * BLENDER_SIZE);
          const s = socket;
          if (s) {
            s.send(asciiBytes(blenderText(cmd)));
            sent++;
          } else notSent++;
        }
        out.emit(o);
        if (throttle.due(f.t[n - 1]!)) describe();
      },
      stop() {
        close();
        describe();
      },
      reset() {
        sent = 0;
        failed = 0;
        notSent = 0;
        lastError = "";
        throttle.reset();
        warns.reset();
        describe();
      },
      dispose() {
        close();
      },
    };
  },
});
