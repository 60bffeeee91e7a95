/**
 * `mosaic test-block FILE`: loads a user's block module as a pipeline would
 * (app/host/user-blocks.ts) and runs the block contract (app/engine/block-contract.ts) on every
 * block it defines, with the module's `contract` export as the setups (docs/writing-blocks.md).
 */
import { dirname, resolve } from "node:path";
import { catalog } from "../blocks/catalog";
import type { AnyBlockDefinition } from "../engine/block";
import { runBlockContract, type CheckResult, type ContractSetup } from "../engine/block-contract";
import { blockDefinitions, definitionProblem } from "../engine/user-blocks";
import { loadDspFromDisk } from "./validate";
import { nodeResources } from "./resources";
import { loadBlockModule } from "./user-blocks";

export interface BlockReport {
  type: string;
  checks: CheckResult[];
}

export type TestBlockOutcome =
  { ok: true; blocks: BlockReport[] } | { ok: false; problems: string[] };

/** What a test run reports as it goes (a check that never ends must not hide the others). */
export interface TestBlockProgress {
  block?(type: string): void;
  result?(r: CheckResult): void;
  /** Block types not to test (tested already, by a run that was stopped). */
  skip?: ReadonlySet<string>;
}

/** The module's blocks, each through the contract; or why the module gives none. */
export async function testBlockFile(
  file: string,
  progress: TestBlockProgress = {},
): Promise<TestBlockOutcome> {
  const full = resolve(file);
  const r = await loadBlockModule(full);
  if (!r.ok) {
    const where = r.line !== undefined ? `${file}:${r.line}:${r.col ?? 0}` : file;
    return { ok: false, problems: [`${where}: cannot load: ${r.message}`] };
  }
  const found = blockDefinitions(r.exports);
  const problems = [...found.problems];
  for (const d of found.defs) {
    const p = definitionProblem(d);
    if (p) problems.push(p);
    else if (catalog.has(d.type)) problems.push(`block type '${d.type}' is a built-in block type`);
  }
  if (found.defs.length === 0 && problems.length === 0) {
    problems.push("it exports no block definition (export default defineBlock({...}))");
  }
  if (problems.length > 0) return { ok: false, problems: problems.map((p) => `${file}: ${p}`) };
  loadDspFromDisk();
  const setups = (r.exports.contract ?? {}) as Record<string, ContractSetup | undefined>;
  const resources = nodeResources(dirname(full));
  const blocks: BlockReport[] = [];
  for (const def of found.defs as AnyBlockDefinition[]) {
    if (progress.skip?.has(def.type)) continue;
    progress.block?.(def.type);
    const setup = setups[def.type] ?? {};
    const checks = await runBlockContract(def, setup, resources, catalog, progress.result);
    blocks.push({ type: def.type, checks });
  }
  return { ok: true, blocks };
}
