//! Contract tests run over every kernel:
//! * processing N events in one call equals N calls of one event (bit-exact),
//!   and any other split too;
//! * after `reset()` the same input gives bit-identical output.

mod common;

use common::assert_bits_eq;
use mosaic_dsp::{design, EmgSynth, EmgSynthConfig, FilterBank, FunctionKernel, FunctionOp};

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
