//! MOSAIC's Rust block ABI, version 1: plain `extern "C"` functions that the TypeScript wrapper
//! (`rustBlock` in MOSAIC's block SDK) calls. No wasm-bindgen: any Rust toolchain with the
//! `wasm32-unknown-unknown` target builds it. The full contract is in MOSAIC's
//! docs/rust-block-abi.md; in short:
//!
//! | export                                              | returns                                    |
//! | --------------------------------------------------- | ------------------------------------------ |
//! | `mosaic_abi_version()`                              | 1                                          |
//! | `mosaic_alloc(bytes)`                               | an 8-byte aligned pointer, 0 when out of memory |
//! | `mosaic_free(ptr, bytes)`                           | —                                          |
//! | `mosaic_create(params, n_params, channels)`         | a handle ≥ 1, 0 on error                   |
//! | `mosaic_output_channels(handle)`                    | values per output frame, 0 on error        |
//! | `mosaic_process(handle, input, frames, channels, output)` | 0, or -1 on error                    |
//! | `mosaic_reset(handle)`, `mosaic_destroy(handle)`    | 0, or -1 on error                          |
//! | `mosaic_error_ptr()`, `mosaic_error_len()`          | the last error message (UTF-8)             |
//!
//! Values are `f64`, frames row-major: frame `k`'s channel `c` is at `input[k * channels + c]`.
//! Every call runs to completion on one thread; nothing here is shared between threads.
//!
//! Leave this file as it is; write your kernel in its own module and name it `crate::Block`.

use std::alloc::{alloc_zeroed, dealloc, Layout};
use std::cell::RefCell;

use crate::Block;

/// The ABI version this module speaks; the wrapper refuses a module of another version.
pub const ABI_VERSION: u32 = 1;

/// What a block's kernel implements. One instance per block in a pipeline, per input shape.
pub trait Kernel: Sized {
    /// Builds the kernel from the block's numeric params (in the order the block's TypeScript
    /// definition lists them; booleans are 0 or 1) for `channels` values per input frame.
    /// An `Err` is shown to the user as the block's error: say which param is wrong and why.
    fn new(params: &[f64], channels: usize) -> Result<Self, String>;

    /// Values per output frame (for a per-channel kernel: its input channels).
    fn output_channels(&self) -> usize;

    /// Processes `input.len() / channels` frames (row-major) into `output` (the same number of
    /// frames, `output_channels()` values each). Keep any history the next call needs in `self`,
    /// so that splitting a signal into frames differently does not change the output.
    fn process(&mut self, input: &[f64], output: &mut [f64]);

    /// Forgets all history: afterwards the kernel behaves as if just created.
    fn reset(&mut self);
}

struct Slot {
    kernel: Block,
    channels: usize,
    output_channels: usize,
}

thread_local! {
    static SLOTS: RefCell<Vec<Option<Slot>>> = const { RefCell::new(Vec::new()) };
    static LAST_ERROR: RefCell<String> = const { RefCell::new(String::new()) };
}

const ALIGN: usize = 8;

fn set_error(message: impl Into<String>) {
    LAST_ERROR.with(|e| *e.borrow_mut() = message.into());
}

fn with_slot<R>(handle: u32, f: impl FnOnce(&mut Slot) -> Result<R, String>) -> Result<R, String> {
    SLOTS.with(|slots| {
        let mut slots = slots.borrow_mut();
        match (handle as usize)
            .checked_sub(1)
            .and_then(|i| slots.get_mut(i))
        {
            Some(Some(slot)) => f(slot),
            _ => Err(format!("no block with handle {handle}")),
        }
    })
}

fn status(result: Result<(), String>) -> i32 {
    match result {
        Ok(()) => 0,
        Err(message) => {
            set_error(message);
            -1
        }
    }
}

/// The ABI version of this module.
#[no_mangle]
pub extern "C" fn mosaic_abi_version() -> u32 {
    ABI_VERSION
}

/// Allocates `bytes` bytes (zeroed, 8-byte aligned) for the caller to fill; 0 when it cannot.
#[no_mangle]
pub extern "C" fn mosaic_alloc(bytes: usize) -> *mut u8 {
    match Layout::from_size_align(bytes.max(1), ALIGN) {
        // SAFETY: the layout has a non-zero size.
        Ok(layout) => unsafe { alloc_zeroed(layout) },
        Err(_) => std::ptr::null_mut(),
    }
}

/// Frees memory from `mosaic_alloc`.
///
/// # Safety
/// `ptr` must come from `mosaic_alloc(bytes)` with the same `bytes`, and be freed once.
#[no_mangle]
pub unsafe extern "C" fn mosaic_free(ptr: *mut u8, bytes: usize) {
    if ptr.is_null() {
        return;
    }
    if let Ok(layout) = Layout::from_size_align(bytes.max(1), ALIGN) {
        dealloc(ptr, layout);
    }
}

/// Creates a block from `n_params` params at `params` for `channels` values per input frame.
/// Returns its handle (≥ 1), or 0 with the reason in `mosaic_error_*`.
///
/// # Safety
/// `params` must point to `n_params` readable `f64`s (it may be null when `n_params` is 0).
#[no_mangle]
pub unsafe extern "C" fn mosaic_create(
    params: *const f64,
    n_params: usize,
    channels: usize,
) -> u32 {
    let params: &[f64] = if n_params == 0 {
        &[]
    } else if params.is_null() {
        set_error("params pointer is null");
        return 0;
    } else {
        std::slice::from_raw_parts(params, n_params)
    };
    if channels == 0 {
        set_error("the input has no values (0 channels)");
        return 0;
    }
    match Block::new(params, channels) {
        Ok(kernel) => {
            let output_channels = kernel.output_channels();
            let slot = Slot {
                kernel,
                channels,
                output_channels,
            };
            SLOTS.with(|slots| {
                let mut slots = slots.borrow_mut();
                let index = match slots.iter().position(Option::is_none) {
                    Some(free) => {
                        slots[free] = Some(slot);
                        free
                    }
                    None => {
                        slots.push(Some(slot));
                        slots.len() - 1
                    }
                };
                index as u32 + 1
            })
        }
        Err(message) => {
            set_error(message);
            0
        }
    }
}

/// Values per output frame of block `handle`; 0 when there is no such block.
#[no_mangle]
pub extern "C" fn mosaic_output_channels(handle: u32) -> usize {
    match with_slot(handle, |slot| Ok(slot.output_channels)) {
        Ok(n) => n,
        Err(message) => {
            set_error(message);
            0
        }
    }
}

/// Processes `frames` frames of `channels` values at `input` into `output`
/// (`frames * mosaic_output_channels(handle)` values). Returns 0, or -1 on error.
///
/// # Safety
/// `input` must point to `frames * channels` readable `f64`s and `output` to
/// `frames * mosaic_output_channels(handle)` writable ones, not overlapping.
#[no_mangle]
pub unsafe extern "C" fn mosaic_process(
    handle: u32,
    input: *const f64,
    frames: usize,
    channels: usize,
    output: *mut f64,
) -> i32 {
    status(with_slot(handle, |slot| {
        if channels != slot.channels {
            return Err(format!(
                "created for {} channels, called with {channels}",
                slot.channels
            ));
        }
        if frames == 0 {
            return Ok(());
        }
        if input.is_null() || output.is_null() {
            return Err("input or output pointer is null".into());
        }
        let n_in = frames.checked_mul(channels).ok_or("too many frames")?;
        let n_out = frames
            .checked_mul(slot.output_channels)
            .ok_or("too many frames")?;
        let input = std::slice::from_raw_parts(input, n_in);
        let output = std::slice::from_raw_parts_mut(output, n_out);
        slot.kernel.process(input, output);
        Ok(())
    }))
}

/// Forgets block `handle`'s history. Returns 0, or -1 when there is no such block.
#[no_mangle]
pub extern "C" fn mosaic_reset(handle: u32) -> i32 {
    status(with_slot(handle, |slot| {
        slot.kernel.reset();
        Ok(())
    }))
}

/// Frees block `handle`; its handle may be given to a later block. Returns 0, or -1 when there
/// is no such block (destroying twice is an error, and harmless).
#[no_mangle]
pub extern "C" fn mosaic_destroy(handle: u32) -> i32 {
    status(SLOTS.with(|slots| {
        let mut slots = slots.borrow_mut();
        match (handle as usize)
            .checked_sub(1)
            .and_then(|i| slots.get_mut(i))
        {
            Some(slot @ Some(_)) => {
                *slot = None;
                Ok(())
            }
            _ => Err(format!("no block with handle {handle}")),
        }
    }))
}

/// Where the last error message is (UTF-8, `mosaic_error_len()` bytes; valid until the next call).
#[no_mangle]
pub extern "C" fn mosaic_error_ptr() -> *const u8 {
    LAST_ERROR.with(|e| e.borrow().as_ptr())
}

/// Length in bytes of the last error message.
#[no_mangle]
pub extern "C" fn mosaic_error_len() -> usize {
    LAST_ERROR.with(|e| e.borrow().len())
}
