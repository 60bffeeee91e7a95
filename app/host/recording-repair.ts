/**
 * Repairs of interrupted recordings, for `mosaic repair` (app/cli/repair.ts): the CLI reaches
 * the recorders' format code through the host, as the layers allow (cli → host → blocks).
 */
export { planXdfRepair, type RepairPlan } from "../blocks/recording/xdf-repair";
export { planEdfFileRepair } from "../blocks/recording/edf-repair";
