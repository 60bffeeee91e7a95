/**
 * A small seeded PRNG for blocks that need reproducible random numbers (not for cryptography):
 * mulberry32 (Tommy Ettinger's 32-bit generator) for uniforms and the Box–Muller transform for
 * standard normals. The same seed gives the same sequence on every platform.
 */
export class SeededRandom {
  private s: number;
  private spare = NaN;

  constructor(seed: number) {
    this.s = seed >>> 0;
  }

  /** The next 32-bit unsigned integer (mulberry32). */
  nextUint32(): number {
    this.s = (this.s + 0x6d2b79f5) >>> 0;
    let z = this.s;
    z = Math.imul(z ^ (z >>> 15), z | 1);
    z ^= z + Math.imul(z ^ (z >>> 7), z | 61);
    return (z ^ (z >>> 14)) >>> 0;
  }

  /** Uniform in the open interval (0, 1): (u32 + 0.5) / 2³². */
  uniform(): number {
    return (this.nextUint32() + 0.5) / 4294967296;
  }

  /**
   * Standard normal by Box–Muller: from two uniforms u1, u2 it returns √(−2 ln u1)·cos(2πu2)
   * and, on the next call, √(−2 ln u1)·sin(2πu2).
   */
  normal(): number {
    if (!Number.isNaN(this.spare)) {
      const z = this.spare;
      this.spare = NaN;
      return z;
    }
    const r = Math.sqrt(-2 * Math.log(this.uniform()));
    const a = 2 * Math.PI * this.uniform();
    this.spare = r * Math.sin(a);
    return r * Math.cos(a);
  }
}
