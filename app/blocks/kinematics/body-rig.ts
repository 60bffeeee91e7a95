import { z } from "zod";
import { defineBlock, matrixShape, vectorShape, type BlockContext } from "../../engine";
import { MAX_CHANNELS } from "../shared/limits";
import { TextThrottle, plural } from "../shared/text";
import { chainIssues } from "./chain";
import { compileRig, describeRefusal, RigState, type RefusalListener, type RigPlan } from "./rig";
import { validEulerSequence } from "./quaternion";

/** Most links of one chain (a full body has about 20). */
export const MAX_LINKS = 256;

const AXES = ["x", "-x", "y", "-y", "z", "-z"] as const;

const vector3 = (description: string) => z.array(z.number()).length(3).describe(description);

const link = z.strictObject({
  Name: z
    .string()
    .regex(
      /^[A-Za-z_][A-Za-z0-9_-]*$/,
      "a link name is a letter or _, then letters, digits, _ or -",
    )
    .max(64)
    .describe("The link's name (unique; its output channels are Name.x, Name.y, Name.z)"),
  Parent: z
    .string()
    .min(1)
    .optional()
    .describe(
      "The link this one hangs from (its distal end is this one's start); none: a root at Origin",
    ),
  Length: z
    .number()
    .min(0)
    .optional()
    .describe("Length of the segment in m, along Axis of the segment's frame"),
  Axis: z
    .enum(AXES)
    .optional()
    .describe(
      "The segment-frame axis Length runs along, proximal to distal; default the block's Axis",
    ),
  Offset: vector3(
    "Instead of Length: the distal end relative to the proximal one, [x, y, z] in m in the segment's frame",
  ).optional(),
  SensorToSegment: z
    .array(z.number())
    .length(4)
    .optional()
    .describe(
      "Rotation from the sensor's frame to the segment's frame, quaternion [w, x, y, z] (normalised); default identity",
    ),
  SensorToSegmentEuler: vector3(
    "Instead of SensorToSegment: the same rotation as Euler angles in degrees, in the block's EulerSequence",
  ).optional(),
  Input: z
    .string()
    .min(1)
    .optional()
    .describe(
      "The input (block name as written in Inputs) carrying this link's IMU orientation; default the first",
    ),
  Channel: z
    .number()
    .int()
    .min(0)
    .max(MAX_CHANNELS)
    .optional()
    .describe(
      "First channel of the orientation in that input (4 values w, x, y, z, or 3 Euler angles); default: " +
        "right after the previous link read from the same input (0, 4, 8, … for quaternions)",
    ),
});

export type LinkParams = z.output<typeof link>;

/** The default chain: a right arm, one quaternion per segment in one input (12 channels). */
const ARM: LinkParams[] = [
  { Name: "UpperArm", Length: 0.3 },
  { Name: "Forearm", Parent: "UpperArm", Length: 0.25 },
  { Name: "Hand", Parent: "Forearm", Length: 0.08 },
];

const params = z
  .strictObject({
    Links: z
      .array(link)
      .min(1)
      .max(MAX_LINKS)
      .default(ARM)
      .describe(
        "The chain, one mapping per link: Name; Parent (none: a root at Origin); Length (m, along Axis) " +
          "or Offset [x, y, z]; Axis; SensorToSegment [w, x, y, z] or SensorToSegmentEuler (deg); " +
          "Input and Channel of its orientation",
      ),
    Axis: z
      .enum(AXES)
      .default("x")
      .describe(
        "The segment-frame axis along which every Length runs (unless the link sets its own)",
      ),
    Origin: vector3("World position of the root links' proximal ends, in m").default([0, 0, 0]),
    Orientation: z
      .enum(["quaternion", "euler"])
      .default("quaternion")
      .describe(
        "What the inputs carry per link: quaternion [w, x, y, z] (any norm; normalised) or Euler angles in degrees (EulerSequence)",
      ),
    EulerSequence: z
      .string()
      .refine(validEulerSequence, {
        message:
          "expected 3 axes, all uppercase (intrinsic, e.g. ZYX) or all lowercase (extrinsic, e.g. xyz), no axis twice in a row",
      })
      .default("ZYX")
      .describe(
        "Axes of Euler angles (SciPy's convention): uppercase intrinsic, lowercase extrinsic; angles in the letters' order",
      ),
    Trigger: z
      .string()
      .min(1)
      .optional()
      .describe(
        "The input (block name as written in Inputs) whose events make the block emit; default the first input",
      ),
    Output: z
      .enum(["vector", "matrix"])
      .default("vector")
      .describe(
        "vector: positions [1, 3·(links+1)], orientations [1, 4·links]; matrix: [links+1, 3] and [links, 4]",
      ),
  })
  .superRefine((p, ctx) => {
    for (const issue of chainIssues(p.Links)) {
      ctx.addIssue({
        code: "custom",
        path: ["Links", issue.index, issue.key],
        message: issue.message,
      });
    }
  });

export type BodyRigParams = z.output<typeof params>;

export const BodyRig = defineBlock({
  type: "BodyRig",
  category: "Kinematics",
  summary:
    "Forward kinematics of a chain of body segments from their IMUs' orientations: joint positions in the world frame.",
  help:
    "The paper's BodyRig kinematics (§ III.E.4, Inertial measurement unit; Table 3): a chain of " +
    "links, each a body segment with an IMU strapped on it, defined by its length, the sensor's " +
    "orientation relative to the segment and its parent. The orientations come from any source " +
    "on the inputs — a UdpReceiver, a device's IMU (NilsPod, Muovi, Myo), an ImuSimulator — as " +
    "quaternions [w, x, y, z] (any norm; normalised) or Euler angles in degrees. " +
    "**Conventions**: quaternions are scalar first with the Hamilton product; an orientation q " +
    "maps a vector from the rotated frame to the reference frame, v_ref = q ⊗ v ⊗ q*. An IMU's " +
    "orientation q_imu maps sensor to world (what an AHRS filter reports). SensorToSegment q_ss " +
    "maps sensor to segment coordinates (the sensor's mounting as seen from the segment). The " +
    "segment's world orientation is q_seg = q_imu ⊗ q_ss⁻¹ (world←sensor · sensor←segment), and " +
    "a link's distal end is p = p_parent + q_seg ⊗ d ⊗ q_seg*, where d = Length · Axis (or " +
    "Offset) in the segment's frame and a root link (no Parent) starts at Origin. Euler angles " +
    "follow SciPy's `Rotation.from_euler`: uppercase letters are intrinsic rotations (about the " +
    "moving axes), lowercase extrinsic (about the fixed ones), angles in the letters' order; the " +
    "default ZYX is yaw, pitch, roll. **Outputs**: `positions` is the base (Origin) then every " +
    "link's distal end in the order of Links — channels `base.x`, `base.y`, `base.z`, then " +
    "`Name.x`, `Name.y`, `Name.z` per link (or rows of a [links+1, 3] matrix) — in m; " +
    "`orientations` is every segment's q_seg [w, x, y, z] with w ≥ 0 (channels `Name.w` … " +
    "`Name.z`). The block emits one " +
    "pose per event of its Trigger input (a timer there gives poses at its rate); the other " +
    "inputs give their latest orientation (join streams first for exact pairing). A quaternion " +
    "of zero norm or with a NaN is refused: the link keeps its last good orientation, the " +
    "refusals are counted in the status and warned about; until a link has had a good one its " +
    "orientation and every point that depends on it are NaN. Verified against SciPy's Rotation " +
    "(app/blocks/kinematics/fixtures/gen_body_rig.py). In the paper the block also reads the " +
    "BodyRig sensors over Bluetooth serial; the original MOSAIC's public source has no such " +
    "block, hence no positional form.",
  params,
  inputs: { min: 1, max: 64, labels: ["orientations"] },
  outputs: ["positions", "orientations"],
  views: ["scope"],
  panel: "Scope of the joint positions (x, y, z of the base and of every link's end).",
  create(ctx, p) {
    const plan = compileRig(ctx, p);
    const nLinks = plan.names.length;
    const matrix = p.Output === "matrix";
    const positions = ctx.output(
      matrix ? matrixShape(nLinks + 1, 3) : vectorShape(3 * (nLinks + 1)),
      "positions",
    );
    const orientations = ctx.output(
      matrix ? matrixShape(nLinks, 4) : vectorShape(4 * nLinks),
      "orientations",
    );
    if (ctx.declaredRate === undefined) ctx.setDesiredRate(ctx.inputs[plan.trigger]!.rate);
    const state = new RigState(plan);
    const status = new RefusalStatus(ctx, plan);
    return {
      process(f, port) {
        const n = f.n;
        if (n === 0) return;
        // Nothing listens: keep the orientations up to date, skip the pose.
        const emit = port === plan.trigger && !(positions.idle && orientations.idle);
        const po = emit ? positions.frame(n) : null;
        const oo = emit ? orientations.frame(n) : null;
        const stride = f.stride;
        for (let e = 0; e < n; e++) {
          state.update(port, f.v, e * stride, f.t[e]!, status);
          if (po && oo) {
            po.t[e] = f.t[e]!;
            oo.t[e] = f.t[e]!;
            state.pose(po.v, e * 3 * (nLinks + 1), oo.v, e * 4 * nLinks);
          }
        }
        if (po && oo) {
          positions.emit(po);
          orientations.emit(oo);
        }
      },
      reset() {
        state.reset();
        status.reset();
      },
    };
  },
});

/** The status line and the warnings about refused orientations. */
class RefusalStatus implements RefusalListener {
  private count = 0;
  private readonly throttle = new TextThrottle(1);

  constructor(
    private readonly ctx: BlockContext,
    private readonly plan: RigPlan,
  ) {
    this.reset();
  }

  refused(link: number, v: ArrayLike<number>, at: number, t: number): void {
    this.count++;
    this.ctx.setText(`${this.summary()}; ${plural(this.count, "orientation")} refused`);
    if (!this.throttle.due(t)) return; // the first one always goes out
    const plan = this.plan;
    const port = plan.input[link]!;
    const values = Array.from({ length: plan.valuesPer }, (_, k) => v[at + k]);
    this.ctx.warn(
      `link '${plan.names[link]}': orientation [${values.join(", ")}] from input ` +
        `'${plan.inputNames[port]}' refused (${describeRefusal(plan, v, at)}); it keeps its last ` +
        `good orientation (${plural(this.count, "refusal")} so far)`,
    );
  }

  reset(): void {
    this.count = 0;
    this.throttle.reset();
    this.ctx.setText(this.summary());
  }

  private summary(): string {
    return `${plural(this.plan.names.length, "link")} from ${plural(this.plan.inputNames.length, "input")}`;
  }
}
