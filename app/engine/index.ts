// Public surface of the engine (used by blocks, host, CLI and UI types).
export * from "./block";
export * from "./catalog";
export * from "./clock";
export * from "./diagnostics";
export * from "./frame";
export * from "./io";
export * from "./suggest";
export * from "./pipeline/legacy";
export * from "./pipeline/loader";
export * from "./runtime/logsink";
export * from "./runtime/runtime";
export * from "./runtime/scheduler";
export * from "./runtime/status";
export * from "./runtime/virtual";
