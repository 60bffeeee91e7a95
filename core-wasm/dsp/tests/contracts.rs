//! Contract tests run over every kernel:
//! * processing N events in one call equals N calls of one event (bit-exact),
//!   and any other split too;
//! * after `reset()` the same input gives bit-identical output.

mod common;

use common::assert_bits_eq;
use mosaic_dsp::{
    design, AdaptiveFilter, AdaptiveFilterConfig, ArtifactConfig, ArtifactRejector,
    DerivativeOrder, EmgSynth, EmgSynthConfig, Feature, FeatureKernel, FeatureSpec, FilterBank,
    FunctionKernel, FunctionOp, SlidingWindow, WindowFunction, WindowedFeatures,
};

/// A uniform interface over the kernels for the contract checks.
trait Kernel {
    fn channels(&self) -> usize;
    fn run(&mut self, input: &[f64], output: &mut [f64]);
    fn reset(&mut self);
}

impl Kernel for FilterBank {
    fn channels(&self) -> usize {
        FilterBank::channels(self)
    }
    fn run(&mut self, input: &[f64], output: &mut [f64]) {
        self.process(input, output).unwrap();
    }
    fn reset(&mut self) {
        FilterBank::reset(self);
    }
}

impl Kernel for FunctionKernel {
    fn channels(&self) -> usize {
        FunctionKernel::channels(self)
    }
    fn run(&mut self, input: &[f64], output: &mut [f64]) {
        self.process(input, output).unwrap();
    }
    fn reset(&mut self) {
        FunctionKernel::reset(self);
    }
}

/// The generator ignores the input.
impl Kernel for EmgSynth {
    fn channels(&self) -> usize {
        EmgSynth::channels(self)
    }
    fn run(&mut self, _input: &[f64], output: &mut [f64]) {
        self.generate(output).unwrap();
    }
    fn reset(&mut self) {
        EmgSynth::reset(self);
    }
}

/// Deterministic test signal with a bit of everything (xorshift, no deps).
fn signal(len: usize, seed: u64) -> Vec<f64> {
    let mut s = seed | 1;
    (0..len)
        .map(|i| {
            s ^= s << 13;
            s ^= s >> 7;
            s ^= s << 17;
            let u = (s >> 11) as f64 / (1u64 << 53) as f64 - 0.5;
            match i % 97 {
                0 => 0.0,
                1 => -3.5,
                _ => u * 4.0,
            }
        })
        .collect()
}

fn check_contracts(name: &str, make: &dyn Fn() -> Box<dyn Kernel>) {
    const N: usize = 257;
    let mut k = make();
    let c = k.channels();
    let input = signal(N * c, 0x5EED ^ c as u64);

    let mut whole = vec![0.0; N * c];
    k.run(&input, &mut whole);

    // N calls of one event.
    let mut k1 = make();
    let mut single = vec![0.0; N * c];
    for (x, y) in input.chunks_exact(c).zip(single.chunks_exact_mut(c)) {
        k1.run(x, y);
    }
    assert_bits_eq(
        &whole,
        &single,
        &format!("{name}: 1 call vs {N} calls of 1 event"),
    );

    // Irregular splits, including empty calls.
    let mut k2 = make();
    let mut split = vec![0.0; N * c];
    let mut at = 0;
    for (i, n) in [0usize, 3, 1, 0, 64, 17, 100, 2].iter().cycle().enumerate() {
        if at == N {
            break;
        }
        let n = (*n + i % 2).min(N - at);
        k2.run(
            &input[at * c..(at + n) * c],
            &mut split[at * c..(at + n) * c],
        );
        at += n;
    }
    assert_bits_eq(&whole, &split, &format!("{name}: irregular split"));

    // reset() makes the output repeat, on the instance that was used.
    k.reset();
    let mut again = vec![0.0; N * c];
    k.run(&input, &mut again);
    assert_bits_eq(&whole, &again, &format!("{name}: after reset"));
}

#[test]
fn filter_banks_honour_the_contracts() {
    let lp = design::butterworth_lowpass2(2.0, 200.0).unwrap();
    let hp = design::butterworth_highpass2(20.0, 1000.0).unwrap();
    let cases: Vec<(&str, Vec<f64>, Vec<f64>, usize)> = vec![
        ("biquad low-pass, 1 ch", lp.b.to_vec(), lp.a.to_vec(), 1),
        ("biquad low-pass, 32 ch", lp.b.to_vec(), lp.a.to_vec(), 32),
        ("biquad high-pass, 3 ch", hp.b.to_vec(), hp.a.to_vec(), 3),
        ("FIR 10-tap, 8 ch", vec![0.1; 10], vec![1.0], 8),
        ("gain only, 5 ch", vec![2.0], vec![1.0], 5),
        (
            "den0 = 2, P > Q, 7 ch",
            vec![1.0, 0.5, 0.25, 0.125],
            vec![2.0, -0.9, 0.2],
            7,
        ),
        ("P < Q, 2 ch", vec![0.3], vec![1.0, -0.2, 0.1, -0.05], 2),
    ];
    for (name, b, a, c) in cases {
        check_contracts(name, &|| Box::new(FilterBank::new(&b, &a, c).unwrap()));
    }
}

#[test]
fn function_kernels_honour_the_contracts() {
    let ops = [
        FunctionOp::Add(vec![0.5]),
        FunctionOp::Add(vec![1.0, -1.0, 2.0]),
        FunctionOp::Multiply(vec![-2.0]),
        FunctionOp::Multiply(vec![0.0, 3.0, -0.5]),
        FunctionOp::Abs,
        FunctionOp::Power(2.0),
        FunctionOp::Power(-3.0),
        FunctionOp::Power(0.5),
        FunctionOp::Power(1.7),
        FunctionOp::Clip {
            min: -1.0,
            max: 0.5,
        },
    ];
    for op in ops {
        let name = format!("{op:?}");
        check_contracts(&name, &|| {
            Box::new(FunctionKernel::new(op.clone(), 3).unwrap())
        });
    }
}

#[test]
fn emg_synth_honours_the_contracts() {
    for (channels, fs) in [(1, 1000.0), (8, 2000.0), (3, 200.0)] {
        let make = || -> Box<dyn Kernel> {
            let mut s = EmgSynth::new(EmgSynthConfig::new(channels, fs, 1234)).unwrap();
            let targets: Vec<f64> = (0..channels)
                .map(|c| (c as f64 + 1.0) / channels as f64)
                .collect();
            s.set_targets(&targets).unwrap();
            Box::new(s)
        };
        check_contracts(&format!("EmgSynth {channels} ch @ {fs} Hz"), &make);
    }
}

/// Kernels whose output per call is not one event per input event (windows,
/// features, decisions): the concatenated outputs of any split of the input
/// must equal those of one call, and `reset()` must repeat them.
trait Streamer {
    /// Values per input event.
    fn event_size(&self) -> usize;
    /// Feeds whole events; returns everything produced (allocates: tests only).
    fn feed(&mut self, input: &[f64]) -> Vec<f64>;
    fn reset(&mut self);
}

impl Streamer for SlidingWindow {
    fn event_size(&self) -> usize {
        self.channels()
    }
    fn feed(&mut self, input: &[f64]) -> Vec<f64> {
        let k = self.windows_for(input.len() / self.channels());
        let mut out = vec![0.0; k * self.window_size()];
        let mut ends = vec![0; k];
        assert_eq!(self.process(input, &mut out, &mut ends).unwrap(), k);
        out
    }
    fn reset(&mut self) {
        SlidingWindow::reset(self);
    }
}

impl Streamer for WindowedFeatures {
    fn event_size(&self) -> usize {
        self.channels()
    }
    fn feed(&mut self, input: &[f64]) -> Vec<f64> {
        let k = self.windows_for(input.len() / self.channels());
        let mut out = vec![0.0; k * self.output_width()];
        let mut ends = vec![0; k];
        assert_eq!(self.process(input, &mut out, &mut ends).unwrap(), k);
        out
    }
    fn reset(&mut self) {
        WindowedFeatures::reset(self);
    }
}

impl Streamer for FeatureKernel {
    fn event_size(&self) -> usize {
        self.rows() * self.channels()
    }
    fn feed(&mut self, input: &[f64]) -> Vec<f64> {
        let n = input.len() / self.event_size();
        let mut out = vec![0.0; n * self.output_width()];
        self.process(input, &mut out).unwrap();
        out
    }
    fn reset(&mut self) {
        FeatureKernel::reset(self);
    }
}

/// Output per window: clean window, then mask, then flags.
impl Streamer for ArtifactRejector {
    fn event_size(&self) -> usize {
        self.window_size()
    }
    fn feed(&mut self, input: &[f64]) -> Vec<f64> {
        let (size, c) = (self.window_size(), self.channels());
        let mut out = Vec::new();
        for w in input.chunks_exact(size) {
            let (mut clean, mut mask, mut flags) = (vec![0.0; size], vec![0.0; c], vec![0.0; c]);
            self.process(w, &mut clean, &mut mask, &mut flags).unwrap();
            out.extend(clean.into_iter().chain(mask).chain(flags));
        }
        out
    }
    fn reset(&mut self) {
        ArtifactRejector::reset(self);
    }
}

/// An adaptive filter fed with timestamps `t0 + i / fs` plus jitter, derived
/// from the event index (so that any split sees the same times).
struct Timed {
    f: AdaptiveFilter,
    at: usize,
}

impl Streamer for Timed {
    fn event_size(&self) -> usize {
        self.f.channels()
    }
    fn feed(&mut self, input: &[f64]) -> Vec<f64> {
        let n = input.len() / self.f.channels();
        let times: Vec<f64> = (self.at..self.at + n)
            .map(|i| 50.0 + i as f64 / 500.0 + if i % 5 == 3 { 3e-4 } else { 0.0 })
            .collect();
        self.at += n;
        let mut out = vec![0.0; input.len()];
        self.f.process_timed(input, &times, &mut out).unwrap();
        out
    }
    fn reset(&mut self) {
        self.f.reset();
        self.at = 0;
    }
}

fn check_stream_contracts(name: &str, make: &dyn Fn() -> Box<dyn Streamer>) {
    const N: usize = 157;
    let mut k = make();
    let size = k.event_size();
    let input = signal(N * size, 0xC0FFEE ^ size as u64);
    let whole = k.feed(&input);

    let mut k1 = make();
    let single: Vec<f64> = input.chunks_exact(size).flat_map(|e| k1.feed(e)).collect();
    assert_bits_eq(
        &whole,
        &single,
        &format!("{name}: 1 call vs {N} calls of 1 event"),
    );

    let mut k2 = make();
    let mut split = Vec::new();
    let mut at = 0;
    for n in [0usize, 3, 1, 0, 64, 17, 100, 2].iter().cycle() {
        if at == N {
            break;
        }
        let n = (*n).min(N - at);
        split.extend(k2.feed(&input[at * size..(at + n) * size]));
        at += n;
    }
    assert_bits_eq(&whole, &split, &format!("{name}: irregular split"));

    k.reset();
    let again = k.feed(&input);
    assert_bits_eq(&whole, &again, &format!("{name}: after reset"));
}

#[test]
fn windowing_feature_adaptive_and_artifact_kernels_honour_the_contracts() {
    let specs: Vec<FeatureSpec> = Feature::ALL
        .iter()
        .map(|&f| FeatureSpec::with_threshold(f, 0.05))
        .collect();
    for (length, step, function) in [
        (8, 3, WindowFunction::None),
        (5, 5, WindowFunction::Hann),
        (4, 9, WindowFunction::Blackman),
        (1, 1, WindowFunction::Hamming),
    ] {
        check_stream_contracts(&format!("SlidingWindow L={length} S={step}"), &|| {
            Box::new(SlidingWindow::new(length, step, 3, function).unwrap())
        });
    }
    for (length, step) in [(8, 3), (2, 1), (6, 11)] {
        let specs = specs.clone();
        check_stream_contracts(
            &format!("WindowedFeatures L={length} S={step}"),
            &move || Box::new(WindowedFeatures::new(&specs, length, step, 4).unwrap()),
        );
    }
    check_stream_contracts("FeatureKernel 6 x 2", &|| {
        Box::new(FeatureKernel::new(&specs, 6, 2).unwrap())
    });
    for order in [DerivativeOrder::LowpassOfAbs, DerivativeOrder::AbsOfLowpass] {
        let mut cfg = AdaptiveFilterConfig::new(3, 500.0);
        (cfg.g1, cfg.g2, cfg.b1, cfg.b2, cfg.order) = (0.01, 0.5, 3.0, 1.0, order);
        check_contracts(&format!("AdaptiveFilter {order:?}"), &move || {
            Box::new(AdaptiveFilter::new(cfg).unwrap())
        });
        check_stream_contracts(&format!("AdaptiveFilter timed {order:?}"), &move || {
            Box::new(Timed {
                f: AdaptiveFilter::new(cfg).unwrap(),
                at: 0,
            })
        });
    }
    let mut auto = ArtifactConfig::new(10, 3);
    auto.drift_threshold = Some(1.0);
    let mut fixed = ArtifactConfig::new(12, 2);
    (fixed.rail_low, fixed.rail_high, fixed.hard) = (Some(-1.5), Some(1.5), false);
    for cfg in [auto, fixed] {
        check_stream_contracts(
            &format!("ArtifactRejector {}x{}", cfg.rows, cfg.channels),
            &move || Box::new(ArtifactRejector::new(cfg).unwrap()),
        );
    }
}

impl Kernel for AdaptiveFilter {
    fn channels(&self) -> usize {
        AdaptiveFilter::channels(self)
    }
    fn run(&mut self, input: &[f64], output: &mut [f64]) {
        self.process(input, output).unwrap();
    }
    fn reset(&mut self) {
        AdaptiveFilter::reset(self);
    }
}
