/**
 * The pipeline document model (app/engine/pipeline/document.ts) for the UI's editor: a pure
 * module (text in, text out; no runtime, no blocks), re-exported under the protocol's name so
 * that the layering rule lets app/ui import it (see tools/eslint-plugin-mosaic).
 */
export {
  DocumentHistory,
  PipelineDocument,
  referencedBlock,
  type AddBlockOptions,
} from "./pipeline/document";
export {
  pipelineLayoutValue,
  type LayoutComment,
  type LayoutGroup,
  type PipelineLayout,
} from "./pipeline/pipeline-layout";
