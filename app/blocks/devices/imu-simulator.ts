import { z } from "zod";
import { defineBlock, vectorShape } from "../../engine";
import { timerInput } from "../shared/inputs";
import { SeededRandom } from "../shared/random";

const G = 9.80665;
const DEG = 180 / Math.PI;

/** Values per layout. */
export const IMU_LAYOUT_VALUES = { "acc-gyro": 6, myo: 10 } as const;

export const ImuSimulator = defineBlock({
  type: "ImuSimulator",
  category: "Sources",
  summary:
    "A simulated inertial sensor on a forearm that turns slowly: accelerometer, gyroscope and (Myo) orientation.",
  help:
    "Stands in for an IMU (a NilsPod, a Myo's IMU) when devices are simulated, one sample per " +
    "tick of its timer. The simulated forearm rolls about the sensor's x axis (pronation and " +
    "supination) by θ(t) = Amplitude · sin(2π (t − t0) / PeriodS); the accelerometer sees " +
    "gravity turning with it, (0, g·sin θ, g·cos θ), the gyroscope the roll rate (dθ/dt, 0, 0), " +
    "both with seeded Gaussian noise (NoiseStd of full scale: 1 % of g, 1 % of 100 deg/s by " +
    "default). `Layout` acc-gyro gives [1, 6]: acceleration x, y, z in m/s², angular rate x, y, " +
    "z in deg/s (NilsPod's order and units); myo gives [1, 10]: orientation quaternion w, x, y, z, " +
    "acceleration in g, angular rate in deg/s (the Myo block's imu output). The same Seed gives " +
    "the same signal.",
  params: z.strictObject({
    Layout: z
      .enum(["acc-gyro", "myo"])
      .default("acc-gyro")
      .describe(
        "acc-gyro: [acc x y z (m/s²), gyro x y z (deg/s)]; myo: [quaternion w x y z, acc (g), gyro (deg/s)]",
      ),
    Amplitude: z
      .number()
      .min(0)
      .max(180)
      .default(60)
      .describe("Largest roll angle of the simulated forearm, in degrees"),
    PeriodS: z.number().positive().default(4).describe("Seconds per roll back and forth"),
    NoiseStd: z
      .number()
      .min(0)
      .default(0.01)
      .describe(
        "Noise standard deviation, as a fraction of g (accelerometer) and of 100 deg/s (gyroscope)",
      ),
    Seed: z.number().int().min(0).max(4294967295).default(7).describe("Seed of the noise"),
  }),
  inputs: { min: 1, max: 1, labels: ["timer"] },
  outputs: ["imu"],
  views: ["scope"],
  panel: "Scope of the simulated axes.",
  create(ctx, p) {
    timerInput(ctx, 0);
    const myo = p.Layout === "myo";
    const size = IMU_LAYOUT_VALUES[p.Layout];
    const out = ctx.output(vectorShape(size), "imu");
    const amp = p.Amplitude / DEG;
    const w = (2 * Math.PI) / p.PeriodS;
    let rng = new SeededRandom(p.Seed);
    const accNoise = p.NoiseStd * G;
    const gyroNoise = p.NoiseStd * 100;
    ctx.setText(`simulated IMU (${p.Layout}), rolling ±${p.Amplitude}° every ${p.PeriodS} s`);
    return {
      process(f) {
        const n = f.n;
        if (n === 0) return;
        const o = out.frame(n);
        const v = o.v;
        for (let e = 0; e < n; e++) {
          const t = f.t[e]!;
          o.t[e] = t;
          const s = t - ctx.startTime;
          const theta = amp * Math.sin(w * s);
          const rate = amp * w * Math.cos(w * s) * DEG;
          const ay = G * Math.sin(theta) + accNoise * rng.normal();
          const az = G * Math.cos(theta) + accNoise * rng.normal();
          const ax = accNoise * rng.normal();
          const gx = rate + gyroNoise * rng.normal();
          const gy = gyroNoise * rng.normal();
          const gz = gyroNoise * rng.normal();
          const at = e * size;
          if (myo) {
            v[at] = Math.cos(theta / 2);
            v[at + 1] = Math.sin(theta / 2);
            v[at + 2] = 0;
            v[at + 3] = 0;
            v[at + 4] = ax / G;
            v[at + 5] = ay / G;
            v[at + 6] = az / G;
            v[at + 7] = gx;
            v[at + 8] = gy;
            v[at + 9] = gz;
          } else {
            v[at] = ax;
            v[at + 1] = ay;
            v[at + 2] = az;
            v[at + 3] = gx;
            v[at + 4] = gy;
            v[at + 5] = gz;
          }
        }
        out.emit(o);
      },
      reset() {
        rng = new SeededRandom(p.Seed);
      },
    };
  },
});
