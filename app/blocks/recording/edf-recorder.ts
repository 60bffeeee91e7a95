import { defineBlock } from "../../engine";
import { edfParams, resolveEdfSetup } from "./edf-setup";
import { EdfRecording } from "./edf-recorder-run";

export { changed, lagRecords, markerText } from "./edf-recorder-run";

export const EdfRecorder = defineBlock({
  type: "EdfRecorder",
  category: "Recording",
  summary:
    "Records its inputs into one continuous EDF+ (16-bit) or BDF+ (24-bit) file, markers as annotations; crash-safe.",
  help:
    "Writes the clinical standard read by EDFbrowser, MNE, EEGLAB and pyedflib: EDF+ " +
    "(https://www.edfplus.info/specs/edf.html, /edfplus.html) with 16-bit samples or BDF+ " +
    "(BioSemi's https://www.biosemi.com/faq/file_format.htm with the EDF+ header) with 24-bit " +
    "samples, continuous (EDF+C/BDF+C). Every channel of every periodic input is a signal of the " +
    "file (a matrix input's rows are consecutive samples, as a device's packets); inputs of " +
    "different rates share the file. The data-record duration is chosen so every rate gives a " +
    "whole number of samples: each rate is read as the simplest fraction within half its third " +
    "decimal (1925.926 Hz = 52000/27), the shortest common duration is made a decimal of at most " +
    "6 decimals (0.027 s holds 52 Trigno samples, 0.0005 s one at 2000 Hz), and the longest " +
    "multiple of it up to 0.5 s that keeps a record within 61 440 bytes is taken (an error names " +
    "the inputs when no duration up to 60 s fits). Samples are written as " +
    "digital = round((x − min)·(dmax − dmin)/(max − min) + dmin) with the physical range as the " +
    "header holds it (PhysicalRange, or per input ±10× the largest value of its first record) and " +
    "the format's digital range; values outside are clipped and NaN written as dmin, both " +
    "counted. The 'EDF Annotations' signal carries each record's time-keeping TAL (the first " +
    "record's onset is the fraction of a second at which the recording starts: the header keeps " +
    "whole seconds, UTC) and markers: aperiodic inputs (a Trigger's), the event outputs of " +
    "Stimulus, StimTrigger and TAC, or the inputs named in Markers give an annotation " +
    "`Input=v1,v2` at the event's time — on every event of an aperiodic input, when the value " +
    "changes for a periodic one. Crash-safe: each data record is written as soon as every input " +
    "has filled it and the header's record count is rewritten after it, so a killed recording " +
    "loses at most the record being filled (< 0.5 s by default) and opens in any reader; " +
    "`mosaic repair FILE` fixes files from older or interrupted recorders. The header is written " +
    "with the first record (its start time is the earliest first sample). An input that falls " +
    "about 2 s behind another has its last value held to keep the file going, and as many of its " +
    "late samples are dropped: both counted. `stop` (or Recording: false) finishes the file " +
    "(samples of an incomplete last record are not written); `start` begins a new one. In the " +
    "browser build the file is kept in memory and downloaded when it is finished; where a " +
    "runtime has no file access at all it records nothing and says so.",
  params: edfParams,
  inputs: { min: 1, max: Infinity },
  outputs: [],
  live: ["Recording"],
  views: ["label"],
  panel: "The file, its duration, size, records and clipped samples, with start/stop buttons.",
  create(ctx, p) {
    const run = new EdfRecording(ctx, p, resolveEdfSetup(ctx, p));
    return {
      start() {
        run.start();
      },
      process(f, port) {
        run.process(f, port);
      },
      stop() {
        run.stop();
      },
      dispose() {
        run.end();
      },
      setParam(name, value) {
        if (name === "Recording") run.setRecording(value as boolean);
      },
      actions: {
        start: {
          label: "Start recording",
          description: "Begin a new file (the File pattern's next free name)",
          run: () => run.setRecording(true),
        },
        stop: {
          label: "Stop recording",
          description: "Finish the file (its header is complete after every record already)",
          run: () => run.setRecording(false),
        },
      },
    };
  },
});
