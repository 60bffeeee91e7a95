//! The kernel against the NumPy reference (tests/fixtures/tkeo.json, written by gen_tkeo.py),
//! and the ABI's functions called the way MOSAIC calls them (natively here; the wasm build is
//! the same code).

use tkeo::abi::{
    mosaic_abi_version, mosaic_alloc, mosaic_create, mosaic_destroy, mosaic_error_len,
    mosaic_error_ptr, mosaic_free, mosaic_output_channels, mosaic_process, mosaic_reset, Kernel,
    ABI_VERSION,
};
use tkeo::Block;

struct Fixture {
    channels: usize,
    input: Vec<f64>,
    expected: Vec<f64>,
    expected_rectified: Vec<f64>,
}

/// The text after `"key": ` up to the end of its line (gen_tkeo.py writes one key a line).
fn value<'a>(text: &'a str, key: &str) -> &'a str {
    let pattern = format!("\"{key}\": ");
    let start = text
        .find(&pattern)
        .unwrap_or_else(|| panic!("fixture has no {key}"))
        + pattern.len();
    let line = text[start..].lines().next().unwrap_or("");
    line.trim_end_matches(',')
}

fn numbers(text: &str, key: &str) -> Vec<f64> {
    let list = value(text, key);
    list.trim_start_matches('[')
        .trim_end_matches(']')
        .split(',')
        .map(|s| s.trim().parse::<f64>().expect("a number"))
        .collect()
}

fn fixture() -> Fixture {
    let path = concat!(env!("CARGO_MANIFEST_DIR"), "/tests/fixtures/tkeo.json");
    let text = std::fs::read_to_string(path).expect("tests/fixtures/tkeo.json");
    let f = Fixture {
        channels: value(&text, "channels").parse().expect("channels"),
        input: numbers(&text, "input"),
        expected: numbers(&text, "expected"),
        expected_rectified: numbers(&text, "expected_rectified"),
    };
    let frames: usize = value(&text, "frames").parse().expect("frames");
    assert_eq!(f.input.len(), frames * f.channels);
    assert_eq!(f.expected.len(), f.input.len());
    f
}

/// Runs `kernel` over `input`, `frames_per_call` frames at a time.
fn run_split(
    kernel: &mut Block,
    input: &[f64],
    channels: usize,
    frames_per_call: usize,
) -> Vec<f64> {
    let mut out = vec![f64::NAN; input.len()];
    for (x, y) in input
        .chunks(frames_per_call * channels)
        .zip(out.chunks_mut(frames_per_call * channels))
    {
        kernel.process(x, y);
    }
    out
}

fn assert_bits_equal(actual: &[f64], expected: &[f64], what: &str) {
    assert_eq!(actual.len(), expected.len(), "{what}: length");
    for (i, (a, e)) in actual.iter().zip(expected).enumerate() {
        assert_eq!(
            a.to_bits(),
            e.to_bits(),
            "{what}: value {i} is {a}, NumPy says {e}"
        );
    }
}

#[test]
fn equals_numpy_exactly() {
    let f = fixture();
    let mut plain = Block::new(&[0.0], f.channels).unwrap();
    assert_bits_equal(
        &run_split(&mut plain, &f.input, f.channels, 600),
        &f.expected,
        "TKEO",
    );
    let mut rect = Block::new(&[1.0], f.channels).unwrap();
    let rectified = run_split(&mut rect, &f.input, f.channels, 600);
    assert_bits_equal(&rectified, &f.expected_rectified, "rectified TKEO");
    assert!(
        f.expected.iter().any(|&v| v < 0.0),
        "the fixture has negative energy to rectify"
    );
}

#[test]
fn frame_splitting_does_not_change_the_output() {
    let f = fixture();
    for frames_per_call in [1, 2, 3, 7, 64, 599] {
        let mut k = Block::new(&[0.0], f.channels).unwrap();
        let out = run_split(&mut k, &f.input, f.channels, frames_per_call);
        assert_bits_equal(
            &out,
            &f.expected,
            &format!("{frames_per_call} frames per call"),
        );
    }
}

#[test]
fn reset_repeats_the_output() {
    let f = fixture();
    let mut k = Block::new(&[0.0], f.channels).unwrap();
    let first = run_split(&mut k, &f.input, f.channels, 50);
    k.reset();
    let again = run_split(&mut k, &f.input, f.channels, 50);
    assert_bits_equal(&again, &first, "after reset");
}

fn last_error() -> String {
    let bytes = unsafe { std::slice::from_raw_parts(mosaic_error_ptr(), mosaic_error_len()) };
    String::from_utf8(bytes.to_vec()).unwrap()
}

#[test]
fn the_abi_processes_what_the_kernel_does() {
    let f = fixture();
    assert_eq!(mosaic_abi_version(), ABI_VERSION);
    assert_eq!(ABI_VERSION, 1);
    let bytes = f.input.len() * 8;
    let params = [1.0];
    unsafe {
        let handle = mosaic_create(params.as_ptr(), 1, f.channels);
        assert!(handle >= 1, "{}", last_error());
        assert_eq!(mosaic_output_channels(handle), f.channels);
        let input = mosaic_alloc(bytes) as *mut f64;
        let output = mosaic_alloc(bytes) as *mut f64;
        assert_eq!(input as usize % 8, 0, "8-byte aligned");
        std::ptr::copy_nonoverlapping(f.input.as_ptr(), input, f.input.len());
        let frames = f.input.len() / f.channels;
        assert_eq!(mosaic_process(handle, input, frames, f.channels, output), 0);
        let out = std::slice::from_raw_parts(output, f.input.len());
        assert_bits_equal(out, &f.expected_rectified, "through the ABI");
        assert_eq!(mosaic_reset(handle), 0);
        assert_eq!(mosaic_destroy(handle), 0);
        mosaic_free(input as *mut u8, bytes);
        mosaic_free(output as *mut u8, bytes);
    }
}

#[test]
fn the_abi_reports_errors_in_words() {
    unsafe {
        let bad = [0.5];
        assert_eq!(mosaic_create(bad.as_ptr(), 1, 2), 0);
        assert_eq!(last_error(), "Rectify must be 0 or 1, got 0.5");
        assert_eq!(mosaic_create(std::ptr::null(), 0, 0), 0);
        assert_eq!(last_error(), "the input has no values (0 channels)");

        let handle = mosaic_create(std::ptr::null(), 0, 2);
        assert!(handle >= 1);
        let x = [1.0; 6];
        let mut y = [0.0; 6];
        assert_eq!(mosaic_process(handle, x.as_ptr(), 2, 3, y.as_mut_ptr()), -1);
        assert_eq!(last_error(), "created for 2 channels, called with 3");
        assert_eq!(mosaic_destroy(handle), 0);
        assert_eq!(mosaic_destroy(handle), -1, "destroying twice is an error");
        assert_eq!(last_error(), format!("no block with handle {handle}"));
        assert_eq!(mosaic_reset(handle), -1);
        assert_eq!(mosaic_output_channels(0), 0);
        assert_eq!(last_error(), "no block with handle 0");
    }
}
