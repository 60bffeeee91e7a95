/** `mosaic test-block FILE...`: the block contract on a user's block modules, PASS/FAIL per check. */
import { testBlockFile } from "../host/test-block";

export function testBlockHelp(): string {
  return `  mosaic test-block FILE...
      Runs the contract every built-in block passes on each block a user's module defines
      (docs/writing-blocks.md): docs, defaults validate, frame splitting, reset repeats,
      dispose twice, garbage params. Prints PASS or FAIL per check; exit 0 when all pass, 1 when
      a check fails, 2 when a module cannot be loaded. The module's \`contract\` export gives
      each block's params and inputs (default: its defaults, 2 channels at 100 Hz).`;
}

export async function cmdTestBlock(
  files: string[],
  out: (s: string) => void,
  err: (s: string) => void,
): Promise<number> {
  if (files.length === 0) {
    err("mosaic test-block: name a block module, e.g. mosaic test-block blocks/smoother.ts");
    return 2;
  }
  let code = 0;
  for (const file of files) {
    const r = await testBlockFile(file);
    if (!r.ok) {
      for (const p of r.problems) err(p);
      code = 2;
      continue;
    }
    for (const b of r.blocks) {
      out(`${file}: ${b.type}`);
      for (const c of b.checks) out(`  ${c.ok ? "PASS" : "FAIL"} ${c.name}: ${c.detail}`);
      const failed = b.checks.filter((c) => !c.ok).length;
      out(
        failed === 0
          ? `  ${b.type}: all ${b.checks.length} checks pass`
          : `  ${b.type}: ${failed} of ${b.checks.length} checks fail`,
      );
      if (failed > 0 && code === 0) code = 1;
    }
  }
  return code;
}
