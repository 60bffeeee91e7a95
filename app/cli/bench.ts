/** `mosaic bench`: the standard performance suite (filled in below). */
export async function runBench(_args: string[]): Promise<number> {
  process.stderr.write("mosaic bench: not built yet\n");
  return 1;
}
