//! A MOSAIC block written in Rust, built to a WebAssembly module.
//!
//! - `src/tkeo.rs` is the kernel: replace it with yours (keep the [`abi::Kernel`] trait).
//! - `src/abi.rs` exports the kernel through MOSAIC's Rust block ABI (version
//!   [`abi::ABI_VERSION`]); leave it as it is.
//! - `Block` names the kernel type that the ABI exports.
//!
//! Build: `cargo build --release --target wasm32-unknown-unknown`; test: `cargo test`.

pub mod abi;
pub mod tkeo;

/// The kernel this module exports.
pub type Block = tkeo::Tkeo;
