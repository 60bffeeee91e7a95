import { connect } from "node:net";
import { afterEach, describe, expect, test } from "vitest";
import { pairedSensors, TrignoSimulator, trignoEmgValue } from "./trigno-simulator";

const open: TrignoSimulator[] = [];
afterEach(async () => {
  for (const s of open.splice(0)) await s.close();
});

async function sim(sensors: number | number[] = 4): Promise<TrignoSimulator> {
  const s = await TrignoSimulator.start({ commandPort: 0, emgPort: 0, auxPort: 0, sensors });
  open.push(s);
  return s;
}

describe("Trigno simulator", () => {
  test("answers the SDK's commands as the public clients expect", async () => {
    const s = await sim([1, 3]);
    expect(s.answer("SENSOR 3 PAIRED?")).toBe("YES");
    expect(s.answer("sensor 2 paired?")).toBe("NO");
    expect(s.answer("SENSOR 1 TYPE?")).toBe("O");
    expect(s.answer("SENSOR 2 TYPE?")).toBe("INVALID SENSOR");
    expect(s.answer("SENSOR 17 PAIRED?")).toBe("INVALID SENSOR NUMBER");
    expect(s.answer("SENSOR 1 EMGCHANNELCOUNT?")).toBe("1");
    expect(s.answer("SENSOR 1 AUXCHANNELCOUNT?")).toBe("9");
    expect(s.answer("FRAME INTERVAL?")).toBe("0.0135");
    expect(s.answer("MAX SAMPLES EMG?")).toBe("26");
    expect(s.answer("RATE?")).toBe("1925.926");
    expect(s.answer("BACKWARDS COMPATIBILITY ON")).toBe("OK");
    expect(s.answer("MAX SAMPLES EMG")).toBe("27");
    expect(s.answer("BACKWARDS COMPATIBILITY?")).toBe("ON");
    expect(s.answer("RATE?")).toBe("2000.000");
    expect(s.answer("UPSAMPLE OFF")).toBe("OK");
    expect(s.answer("UPSAMPLING?")).toBe("OFF");
    expect(s.answer("MASTER")).toBe("NEW MASTER");
    expect(s.answer("HELLO")).toBe("INVALID COMMAND");
  });

  test("banner on connect, replies ended by \\r\\n\\r\\n, EMG frames of 26 × 16 float32 after START", async () => {
    const s = await sim(2);
    const text: string[] = [];
    const cmd = connect(s.ports.command, "127.0.0.1");
    cmd.setEncoding("latin1");
    cmd.on("data", (d: string) => text.push(d));
    const emg: Buffer[] = [];
    const data = connect(s.ports.emg, "127.0.0.1");
    data.on("data", (b: Buffer) => emg.push(b));
    await new Promise((r) => data.once("connect", r));
    cmd.write("START\r\n\r\n");
    await new Promise((r) => setTimeout(r, 120));
    cmd.write("STOP\r\n\r\n");
    await new Promise((r) => setTimeout(r, 30));
    cmd.destroy();
    data.destroy();
    expect(text.join("")).toMatch(
      /^Delsys Trigno System Digital Protocol Version [\d.]+ \(MOSAIC simulator\)\r\n\r\nOK\r\n\r\nOK\r\n\r\n$/,
    );
    const all = Buffer.concat(emg);
    expect(all.length % (26 * 64)).toBe(0);
    expect(all.length / 64).toBeGreaterThanOrEqual(26 * 5);
    for (let k = 0; k < all.length / 64; k++) {
      expect(all.readFloatLE(k * 64)).toBe(trignoEmgValue(1, 1, k));
      expect(all.readFloatLE(k * 64 + 4)).toBe(trignoEmgValue(1, 2, k));
      expect(all.readFloatLE(k * 64 + 8)).toBe(0); // sensor 3: not paired
    }
  });

  test("values are float32, seeded, EMG-sized; bad sensor lists and taken ports are refused", async () => {
    expect(trignoEmgValue(1, 5, 100)).toBe(Math.fround(trignoEmgValue(1, 5, 100)));
    expect(trignoEmgValue(1, 5, 100)).not.toBe(trignoEmgValue(2, 5, 100));
    for (let k = 0; k < 5000; k++) expect(Math.abs(trignoEmgValue(9, 16, k))).toBeLessThan(5e-4);
    expect(() => pairedSensors([0])).toThrow(/sensor 0 is not a Trigno sensor number \(1…16\)/);
    expect(() => pairedSensors(17)).toThrow(/pairs 0…16 sensors, not 17/);
    const s = await sim();
    await expect(TrignoSimulator.start({ commandPort: s.ports.command })).rejects.toThrow(
      new RegExp(`port ${s.ports.command} on 127\\.0\\.0\\.1 is already in use \\(EADDRINUSE\\)`),
    );
  });
});
