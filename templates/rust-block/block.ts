// The block MOSAIC loads (name this file in a pipeline's `Pipeline: { Blocks: [...] }`): the Rust
// kernel of src/ built to WebAssembly, wrapped by rustBlock. Build the module first, and again
// after every change to src/ (`mosaic serve` then reloads the block):
//   cargo build --release --target wasm32-unknown-unknown
import { rustBlock, z } from "mosaic/sdk";
import wasm from "./target/wasm32-unknown-unknown/release/tkeo.wasm";

/** The name pipelines use for this block; never change it once others use it. */
const TYPE = "Tkeo";

export default rustBlock({
  type: TYPE,
  category: "Features",
  summary: "Teager–Kaiser energy of every channel, one sample late.",
  help:
    "The Teager–Kaiser energy operator ψ[n] = x[n]² − x[n−1]·x[n+1] (Kaiser 1990) of every " +
    "value of its input on its own, computed in Rust (src/tkeo.rs). ψ[n] needs the next sample, " +
    "so each output is the energy of the previous input sample, with zeros before the first " +
    "(the first output is 0, the second x[0]²). For a sine A·sin(ωn) it is A²·sin²(ω): it " +
    "follows amplitude and frequency together, which makes it a sharp detector of EMG onsets.",
  // The kernel gets these params in this order, as numbers (a boolean is 1 or 0).
  params: z.strictObject({
    Rectify: z
      .boolean()
      .default(false)
      .describe("Output |ψ| (ψ is negative where the signal's curvature exceeds its energy)"),
  }),
  views: ["scope"],
  panel: "The energy of every channel.",
  wasm,
  wasmName: "tkeo.wasm",
});
