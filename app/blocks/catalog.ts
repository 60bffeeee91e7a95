/**
 * The explicit catalog: every block type, in one place (CONVENTIONS.md: one file lists them all).
 * Adding a block = one file in its category folder + one line here.
 */
import { createCatalog, type AnyBlockDefinition } from "../engine";
import { Joiner } from "./flow/joiner";
import { Projector } from "./flow/projector";
import { Resampler } from "./flow/resampler";
import { Splitter } from "./flow/splitter";
import { Logger } from "./recording/logger";
import { Filter } from "./signal/filter";
import { FunctionBlock } from "./signal/function";
import { LinearMap } from "./signal/linear-map";
import { EmgSimulator } from "./sources/emg-simulator";
import { FilePlayer } from "./sources/file-player";
import { SinGenerator } from "./sources/sin-generator";
import { Busy } from "./testing/busy";
import { Sink } from "./testing/sink";
import { DecimatorTimer } from "./timing/decimator-timer";
import { ScheduledTimer } from "./timing/scheduled-timer";

export const BLOCKS: readonly AnyBlockDefinition[] = [
  // Timing
  ScheduledTimer,
  DecimatorTimer,
  // Sources
  SinGenerator,
  EmgSimulator,
  FilePlayer,
  // Signal processing
  FunctionBlock,
  Filter,
  LinearMap,
  // Flow control
  Resampler,
  Joiner,
  Splitter,
  Projector,
  // Recording
  Logger,
  // Testing
  Sink,
  Busy,
];

export const catalog = createCatalog(BLOCKS);
