// For your editor's type checker: MOSAIC hands a `.wasm` import to the module as its bytes.
declare module "*.wasm" {
  const bytes: Uint8Array;
  export default bytes;
}
