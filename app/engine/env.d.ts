// The few host facilities that exist in every runtime the engine targets (Node worker_threads,
// browser Web Workers) but are not part of the ECMAScript library. The engine declares exactly
// these and nothing more, so that a `process`, `require` or `document` in engine code is a type
// error (see tsconfig.pure.json).

declare const performance: {
  /** Milliseconds from an arbitrary, monotonic origin, with sub-millisecond resolution. */
  now(): number;
  readonly timeOrigin: number;
};

declare function queueMicrotask(callback: () => void): void;
