/**
 * The Myo decoders on notifications built by hand from myohw.h's layout: `myohw_emg_data_t`
 * (two samples of 8 int8) and `myohw_imu_data_t` (ten int16, little-endian on the wire), with
 * the expected values worked out from the documented scales.
 */
import { describe, expect, test } from "vitest";
import {
  decodeEmg,
  decodeImu,
  EmgTimestamps,
  MYO,
  myoUuid,
  normalizeUuid,
  sameAddress,
  setModeCommand,
  sleepModeCommand,
  vibrateCommand,
} from "./myo-protocol";

describe("Myo UUIDs and commands", () => {
  test("UUIDs are myohw.h's base with the short id in bytes 2–3", () => {
    expect(myoUuid(0x0001)).toBe("d5060001a904deb947482c7f4a124842");
    expect(MYO.commandCharacteristic).toBe(normalizeUuid("D5060401-A904-DEB9-4748-2C7F4A124842"));
    expect(MYO.imuCharacteristic).toBe("d5060402a904deb947482c7f4a124842");
    // The four EMG characteristics MOSAIC's Myo.cs subscribed to.
    expect(MYO.emgCharacteristics).toEqual(
      [
        "d5060105-a904-deb9-4748-2c7f4a124842",
        "d5060205-a904-deb9-4748-2c7f4a124842",
        "d5060305-a904-deb9-4748-2c7f4a124842",
        "d5060405-a904-deb9-4748-2c7f4a124842",
      ].map(normalizeUuid),
    );
  });

  test("command bytes: header (command, payload size) then the payload", () => {
    // set_mode 0x01, 3 bytes: EMG filtered 0x02, IMU data 0x01, classifier off 0x00.
    expect([...setModeCommand(2, 1, 0)]).toEqual([0x01, 0x03, 0x02, 0x01, 0x00]);
    // MOSAIC's "FiltEMG_NoIMU_NoClass" and its end command.
    expect([...setModeCommand(2, 0, 0)]).toEqual([0x01, 0x03, 0x02, 0x00, 0x00]);
    expect([...setModeCommand(0, 0, 0)]).toEqual([0x01, 0x03, 0x00, 0x00, 0x00]);
    // set_sleep_mode 0x09: never sleep 1, normal 0 (MOSAIC's NoSleep / NormalSleep).
    expect([...sleepModeCommand(1)]).toEqual([0x09, 0x01, 0x01]);
    expect([...sleepModeCommand(0)]).toEqual([0x09, 0x01, 0x00]);
    // vibrate 0x03: short 1, long 3.
    expect([...vibrateCommand(3)]).toEqual([0x03, 0x01, 0x03]);
  });

  test("addresses compare without case or separators", () => {
    expect(sameAddress("AA:BB:CC:00:11:22", "aa-bb-cc-00-11-22")).toBe(true);
    expect(sameAddress("aa:bb:cc:00:11:22", "aa:bb:cc:00:11:23")).toBe(false);
  });
});

describe("decodeEmg", () => {
  test("two samples of 8 signed bytes, each / 128 (MOSAIC's scale)", () => {
    const bytes = Uint8Array.of(
      // sample 1: 0, 1, 127, −128, −1, 64, −64, 2
      0x00,
      0x01,
      0x7f,
      0x80,
      0xff,
      0x40,
      0xc0,
      0x02,
      // sample 2: 10, −10, 100, −100, 0, 0, 3, −3
      0x0a,
      0xf6,
      0x64,
      0x9c,
      0x00,
      0x00,
      0x03,
      0xfd,
    );
    const out = new Float64Array(16);
    expect(decodeEmg(bytes, out)).toBeUndefined();
    expect([...out.subarray(0, 8)]).toEqual([
      0, 0.0078125, 0.9921875, -1, -0.0078125, 0.5, -0.5, 0.015625,
    ]);
    expect([...out.subarray(8)]).toEqual([
      0.078125, -0.078125, 0.78125, -0.78125, 0, 0, 0.0234375, -0.0234375,
    ]);
    // Scale 1: the raw int8 values.
    decodeEmg(bytes, out, 1);
    expect([...out.subarray(0, 8)]).toEqual([0, 1, 127, -128, -1, 64, -64, 2]);
  });

  test("a notification of another length is refused with the reason", () => {
    const out = new Float64Array(16);
    expect(decodeEmg(new Uint8Array(8), out)).toBe("8 bytes, an EMG notification has 16");
  });
});

describe("decodeImu", () => {
  test("quaternion / 16384, accelerometer / 2048 (g), gyroscope / 16 (deg/s), little-endian", () => {
    const bytes = Uint8Array.of(
      0x00,
      0x40, // w = 0x4000 = 16384 → 1
      0x00,
      0xe0, // x = 0xe000 = −8192 → −0.5
      0x00,
      0x00, // y = 0
      0x01,
      0x00, // z = 1 → 1/16384
      0x00,
      0x08, // ax = 2048 → 1 g
      0x00,
      0xfc, // ay = 0xfc00 = −1024 → −0.5 g
      0x00,
      0x10, // az = 4096 → 2 g
      0x10,
      0x00, // gx = 16 → 1 deg/s
      0x00,
      0x80, // gy = 0x8000 = −32768 → −2048 deg/s
      0x02,
      0x01, // gz = 0x0102 = 258 → 16.125 deg/s
    );
    const out = new Float64Array(10);
    expect(decodeImu(bytes, out)).toBeUndefined();
    expect([...out]).toEqual([1, -0.5, 0, 1 / 16384, 1, -0.5, 2, 1, -2048, 16.125]);
  });

  test("works on a view into a larger buffer at an odd offset", () => {
    const big = new Uint8Array(25);
    big.set([0x00, 0x40], 3);
    const out = new Float64Array(10);
    expect(decodeImu(big.subarray(3, 23), out)).toBeUndefined();
    expect(out[0]).toBe(1);
    expect(decodeImu(big.subarray(3, 22), out)).toBe("19 bytes, an IMU notification has 20");
  });
});

describe("EmgTimestamps", () => {
  test("5 ms apart, continued across notifications, pulled back, re-synchronised after a gap", () => {
    const c = new EmgTimestamps(0.005, 0.05);
    const t = [0, 0];
    c.stamp(10, t);
    expect(t[0]).toBeCloseTo(9.995, 12);
    expect(t[1]).toBe(10);
    // Arrives 12 ms later: continues the sample clock (10.005, 10.010), not the arrival time.
    c.stamp(10.012, t);
    expect(t[0]).toBeCloseTo(10.005, 12);
    expect(t[1]).toBeCloseTo(10.01, 12);
    // A burst: the next pair would end at 10.020, after its arrival at 10.012; pulled back by
    // half a period (10.0125) rather than to the arrival time (10.007).
    c.stamp(10.012, t);
    expect(t[0]).toBeCloseTo(10.0125, 12);
    expect(t[1]).toBeCloseTo(10.0175, 12);
    // 180 ms without a notification (more than maxLag behind): back to the arrival time.
    c.stamp(10.2, t);
    expect(t[0]).toBeCloseTo(10.195, 12);
    expect(t[1]).toBe(10.2);
    expect(c.resyncs).toBe(1);
    c.reset();
    c.stamp(11, t);
    expect(t[1]).toBe(11);
    expect(c.resyncs).toBe(1);
  });
});
