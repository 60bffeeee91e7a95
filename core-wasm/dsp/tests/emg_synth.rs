//! Statistical and determinism checks of EmgSynth.

mod common;

use common::assert_bits_eq;
use mosaic_dsp::{EmgSynth, EmgSynthConfig};

fn run(cfg: EmgSynthConfig, targets: &[f64], events: usize) -> Vec<f64> {
    let c = cfg.channels;
    let mut s = EmgSynth::new(cfg).unwrap();
    s.set_targets(targets).unwrap();
    let mut out = vec![0.0; events * c];
    s.generate(&mut out).unwrap();
    out
}

fn channel(out: &[f64], channels: usize, c: usize) -> Vec<f64> {
    out.iter().skip(c).step_by(channels).copied().collect()
}

fn rms(x: &[f64]) -> f64 {
    (x.iter().map(|v| v * v).sum::<f64>() / x.len() as f64).sqrt()
}

/// |X(f)|² of a plain DFT at frequency `f` (Hz), normalised so that a sine
/// of amplitude A gives about (A/2)² when f is on a bin.
fn power_at(x: &[f64], fs: f64, f: f64) -> f64 {
    let n = x.len() as f64;
    let w = std::f64::consts::TAU * f / fs;
    let (mut re, mut im) = (0.0, 0.0);
    for (k, &v) in x.iter().enumerate() {
        re += v * (w * k as f64).cos();
        im -= v * (w * k as f64).sin();
    }
    (re * re + im * im) / (n * n)
}

#[test]
fn same_seed_same_signal_different_seed_different_signal() {
    let t = [1.0, 0.3, 0.0, 0.7];
    let a = run(EmgSynthConfig::new(4, 1000.0, 99), &t, 500);
    let b = run(EmgSynthConfig::new(4, 1000.0, 99), &t, 500);
    assert_bits_eq(&a, &b, "same seed");
    let c = run(EmgSynthConfig::new(4, 1000.0, 100), &t, 500);
    let differing = a.iter().zip(&c).filter(|(x, y)| x != y).count();
    assert_eq!(
        differing,
        a.len(),
        "every sample should differ for another seed"
    );
    // Channels are independent streams too.
    let ch0 = channel(&a, 4, 0);
    let ch3 = channel(&a, 4, 3);
    assert!(ch0.iter().zip(&ch3).all(|(x, y)| x != y));
}

#[test]
fn hundred_events_equal_hundred_single_calls() {
    let cfg = EmgSynthConfig::new(6, 1926.0, 7);
    let t = [1.0, 0.5, 0.25, 0.0, 0.8, 1.0];
    let whole = run(cfg.clone(), &t, 100);
    let mut s = EmgSynth::new(cfg).unwrap();
    s.set_targets(&t).unwrap();
    let mut single = vec![0.0; 600];
    for row in single.chunks_exact_mut(6) {
        s.generate(row).unwrap();
    }
    assert_bits_eq(&whole, &single, "split invariance");
}

#[test]
fn reset_repeats_and_matches_a_fresh_instance() {
    let cfg = EmgSynthConfig::new(2, 1000.0, 3);
    let mut s = EmgSynth::new(cfg.clone()).unwrap();
    s.set_targets(&[0.6, 1.0]).unwrap();
    let mut a = vec![0.0; 2000];
    s.generate(&mut a).unwrap();
    s.reset();
    assert_eq!(s.sample_index(), 0);
    let mut b = vec![0.0; 2000];
    s.generate(&mut b).unwrap();
    assert_bits_eq(&a, &b, "after reset");
    assert_bits_eq(&a, &run(cfg, &[0.6, 1.0], 1000), "fresh instance");
}

#[test]
fn rms_at_full_activation_is_close_to_the_amplitude() {
    let fs = 2000.0;
    for seed in [1, 2, 3] {
        let cfg = EmgSynthConfig::new(4, fs, seed);
        let amp = cfg.amplitude_mv;
        // 0.5 s attack (≈ 8 time constants of 60 ms), then 2 s measured.
        let out = run(cfg, &[1.0; 4], (2.5 * fs) as usize);
        for c in 0..4 {
            let x = channel(&out, 4, c);
            let r = rms(&x[(0.5 * fs) as usize..]);
            assert!(
                (r - amp).abs() <= 0.1 * amp,
                "seed {seed} ch {c}: rms {r} vs {amp}"
            );
        }
    }
}

#[test]
fn envelope_follows_attack_and_release() {
    let mut cfg = EmgSynthConfig::new(1, 1000.0, 11);
    cfg.noise_floor_mv = 0.0;
    cfg.hum_mv = 0.0;
    cfg.modulation = 0.0;
    let mut s = EmgSynth::new(cfg).unwrap();
    let mut rest = vec![0.0; 500];
    s.generate(&mut rest).unwrap();
    assert!(
        rest.iter().all(|&x| x == 0.0),
        "no EMG at rest without noise"
    );
    s.set_targets(&[1.0]).unwrap();
    let mut on = vec![0.0; 1500];
    s.generate(&mut on).unwrap();
    // The first 20 ms (a third of the attack time constant) stay well below full scale.
    assert!(rms(&on[..20]) < 0.5 * rms(&on[500..]));
    s.set_targets(&[0.0]).unwrap();
    let mut off = vec![0.0; 2000];
    s.generate(&mut off).unwrap();
    // 150 ms release: after 1.5 s (10 time constants) the EMG is gone.
    assert!(rms(&off[1500..]) < 1e-3 * rms(&on[500..]));
    // ...and it decays more slowly than it rose (release > attack).
    assert!(rms(&off[100..150]) > 0.3 * rms(&on[500..]));
}

#[test]
fn most_power_lies_in_the_emg_band() {
    let fs = 2000.0;
    let mut cfg = EmgSynthConfig::new(1, fs, 5);
    cfg.noise_floor_mv = 0.0;
    cfg.hum_mv = 0.0;
    let (lo, hi) = (cfg.band_low_hz, cfg.band_high_hz);
    let n = 4000; // 2 s, 0.5 Hz bins
    let out = run(cfg, &[1.0], n + 1000);
    let x = &out[1000..];
    let (mut inside, mut total) = (0.0, 0.0);
    for bin in 1..n / 2 {
        let f = bin as f64 * fs / n as f64;
        let p = power_at(x, fs, f);
        total += p;
        if f >= lo && f <= hi {
            inside += p;
        }
    }
    let share = inside / total;
    // Two 2nd-order Butterworth skirts (−3 dB at the edges, 12 dB/octave):
    // analytically about 87 % of the power falls inside 20–450 Hz at 2 kHz.
    assert!(share > 0.8, "share of power in {lo}–{hi} Hz: {share}");
    // Well above the band the spectrum is strongly attenuated.
    let band_mean = inside / ((hi - lo) * n as f64 / fs);
    let top: f64 = (1800..2000)
        .map(|b| power_at(x, fs, b as f64 * 0.5))
        .sum::<f64>()
        / 200.0;
    assert!(
        top < 0.05 * band_mean,
        "900–1000 Hz: {top:e} vs band {band_mean:e}"
    );
}

#[test]
fn band_is_clamped_at_low_sample_rates() {
    let cfg = EmgSynthConfig::new(1, 200.0, 1);
    let s = EmgSynth::new(cfg.clone()).unwrap();
    assert_eq!(s.band_high_hz(), 90.0);
    assert!(s.has_highpass());
    let out = run(cfg, &[1.0], 2000);
    let r = rms(&out[400..]);
    assert!((r - 0.5).abs() < 0.1, "rms {r}");
}

#[test]
fn hum_is_present_at_its_frequency() {
    let fs = 1000.0;
    for hum_hz in [50.0, 60.0] {
        let mut cfg = EmgSynthConfig::new(3, fs, 8);
        cfg.hum_hz = hum_hz;
        let amp = cfg.hum_mv;
        let out = run(cfg, &[0.0; 3], 2000); // rest: noise floor + hum only
        for c in 0..3 {
            let x = channel(&out, 3, c);
            let p = power_at(&x, fs, hum_hz);
            let measured = 2.0 * p.sqrt();
            assert!(
                (measured - amp).abs() < 0.1 * amp,
                "ch {c}: hum {measured} mV vs {amp}"
            );
            let off = 2.0 * power_at(&x, fs, hum_hz + 7.0).sqrt();
            assert!(off < 0.2 * amp, "ch {c}: {off} mV at {} Hz", hum_hz + 7.0);
        }
    }
}

#[test]
fn non_finite_targets_and_bad_lengths_are_rejected() {
    let mut s = EmgSynth::new(EmgSynthConfig::new(2, 1000.0, 0)).unwrap();
    let e = s.set_targets(&[0.5]).unwrap_err();
    assert_eq!(
        e.to_string(),
        "targets has 1 values; expected 2 (one per channel)"
    );
    assert!(s.generate(&mut [0.0; 5]).is_err());
}
