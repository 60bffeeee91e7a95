/**
 * The explicit catalog: every block type, in one place (CONVENTIONS.md: one file lists them all).
 * Adding a block = one file in its category folder + one line here.
 */
import { createCatalog, type AnyBlockDefinition } from "../engine";
import { Dasdv } from "./features/dasdv";
import { BrainFlow } from "./devices/brainflow";
import { Delsys } from "./devices/delsys";
import { DLR_ADCBT } from "./devices/dlr-adcbt";
import { ImuSimulator } from "./devices/imu-simulator";
import { Muovi } from "./devices/muovi";
import { MuoviSingleProbe } from "./devices/muovi-single-probe";
import { NilsPod } from "./devices/nilspod";
import { Quattrocento } from "./devices/quattrocento";
import { Sessantaquattro } from "./devices/sessantaquattro";
import { SimulatedOutput } from "./devices/simulated-output";
import { FeatureSet } from "./features/feature-set";
import { IntegratedAbsoluteValue } from "./features/integrated-absolute-value";
import { MeanAbsoluteValue } from "./features/mean-absolute-value";
import { Rms } from "./features/rms";
import { SlopeSignChanges } from "./features/slope-sign-changes";
import { Variance } from "./features/variance";
import { WaveformLength } from "./features/waveform-length";
import { WillisonAmplitude } from "./features/willison-amplitude";
import { ZeroCrossings } from "./features/zero-crossings";
import { ArtifactRejection } from "./flow/artifact-rejection";
import { BodyRig } from "./kinematics/body-rig";
import { BufferBlock } from "./flow/buffer";
import { ChannelSelector } from "./flow/channel-selector";
import { Joiner } from "./flow/joiner";
import { Projector } from "./flow/projector";
import { Resampler } from "./flow/resampler";
import { Selector } from "./flow/selector";
import { SlidingWindow } from "./flow/sliding-window";
import { Splitter } from "./flow/splitter";
import { Switch } from "./flow/switch";
import { VectorialFunction } from "./flow/vectorial-function";
import { Ros } from "./io/ros";
import { Myo } from "./io/myo";
import { BlenderArm } from "./io/blender-arm";
import { HannesGUI } from "./io/hannes-gui";
import { HannesHand } from "./io/hannes-hand";
import { HannesReceiver } from "./io/hannes-receiver";
import { Python } from "./io/python";
import { INmf } from "./learning/inmf";
import { PythonNetLearning } from "./learning/python-net-learning";
import { SimplePyTorch } from "./learning/simple-pytorch";
import { SerialPort } from "./io/serial-port";
import { UdpReceiver } from "./io/udp-receiver";
import { UdpSender } from "./io/udp-sender";
import { BatchPredictor } from "./learning/batch-predictor";
import { IncrementalPredictor } from "./learning/incremental-predictor";
import { Stimulus } from "./learning/stimulus";
import { StimTrigger } from "./learning/stim-trigger";
import { TAC } from "./learning/tac";
import { Trigger } from "./learning/trigger";
import { LslInlet } from "./lsl/lsl-inlet";
import { LslMarkerInlet } from "./lsl/lsl-marker-inlet";
import { LslMarkers } from "./lsl/lsl-markers";
import { LslOutlet } from "./lsl/lsl-outlet";
import { EdfRecorder } from "./recording/edf-recorder";
import { Logger } from "./recording/logger";
import { XdfRecorder } from "./recording/xdf-recorder";
import { AdaptiveFilter } from "./signal/adaptive-filter";
import { DoubleDifferential } from "./signal/dds";
import { PythonNetFiltUC } from "./signal/python-net-filt-uc";
import { ControlAlgorithm } from "./control/control-algorithm";
import { Filter } from "./signal/filter";
import { FunctionBlock } from "./signal/function";
import { LinearMap } from "./signal/linear-map";
import { Amplification, Rectification } from "./signal/presets";
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
  Amplification,
  Rectification,
  Filter,
  LinearMap,
  AdaptiveFilter,
  DoubleDifferential,
  PythonNetFiltUC,
  VectorialFunction,
  // Features
  MeanAbsoluteValue,
  Rms,
  WaveformLength,
  ZeroCrossings,
  SlopeSignChanges,
  Variance,
  IntegratedAbsoluteValue,
  Dasdv,
  WillisonAmplitude,
  FeatureSet,
  // Kinematics
  BodyRig,
  // Flow control
  SlidingWindow,
  ArtifactRejection,
  Resampler,
  Joiner,
  Splitter,
  Projector,
  BufferBlock,
  ChannelSelector,
  Selector,
  Switch,
  // Learning
  Trigger,
  Stimulus,
  StimTrigger,
  TAC,
  BatchPredictor,
  IncrementalPredictor,
  Python,
  PythonNetLearning,
  SimplePyTorch,
  INmf,
  // Control
  ControlAlgorithm,
  // Communication
  UdpSender,
  UdpReceiver,
  SerialPort,
  Myo,
  Ros,
  BlenderArm,
  HannesHand,
  HannesGUI,
  HannesReceiver,
  LslOutlet,
  LslInlet,
  LslMarkers,
  LslMarkerInlet,
  // Devices (app/blocks/devices/)
  Muovi,
  MuoviSingleProbe,
  Quattrocento,
  Sessantaquattro,
  Delsys,
  DLR_ADCBT,
  NilsPod,
  BrainFlow,
  ImuSimulator,
  SimulatedOutput,
  // Recording
  Logger,
  EdfRecorder,
  XdfRecorder,
  // Testing
  Sink,
  Busy,
];

export const catalog = createCatalog(BLOCKS);
