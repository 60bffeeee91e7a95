use std::f64::consts::TAU;

use crate::design::{butterworth_highpass2, butterworth_lowpass2, Biquad};
use crate::rng::Rng;
use crate::{check_multiple, DspError};

/// Configuration of an [`EmgSynth`]. Build it with [`EmgSynthConfig::new`]
/// and change the fields you need.
///
/// ```
/// use mosaic_dsp::EmgSynthConfig;
///
/// let mut cfg = EmgSynthConfig::new(8, 2000.0, 42);
/// cfg.hum_hz = 60.0; // North America
/// assert_eq!(cfg.amplitude_mv, 0.5);
/// ```
#[derive(Debug, Clone, PartialEq)]
pub struct EmgSynthConfig {
    /// Number of channels (>= 1).
    pub channels: usize,
    /// Sample rate in Hz (> 0).
    pub sample_rate: f64,
    /// Seed; the same seed gives the same signal on every platform run by
    /// the same binary.
    pub seed: u64,
    /// RMS of the EMG component at full activation, in mV (default 0.5).
    /// The slow modulation raises the long-term RMS by `sqrt(1 + modulation²/2)`.
    pub amplitude_mv: f64,
    /// RMS of the white background noise, in mV (default 0.01).
    pub noise_floor_mv: f64,
    /// Amplitude (peak) of the powerline interference, in mV (default 0.02).
    pub hum_mv: f64,
    /// Powerline frequency in Hz (default 50).
    pub hum_hz: f64,
    /// High-pass corner of the EMG band in Hz (default 20; 0 for none).
    pub band_low_hz: f64,
    /// Low-pass corner of the EMG band in Hz (default 450). Clamped to
    /// 0.45 × `sample_rate`; when that puts it at or below `band_low_hz`, the
    /// high-pass is dropped.
    pub band_high_hz: f64,
    /// Time constant of the envelope when the activation rises, in ms (default 60).
    pub attack_ms: f64,
    /// Time constant of the envelope when the activation falls, in ms (default 150).
    pub release_ms: f64,
    /// Relative depth of the slow (1–3 Hz, per-channel phase and rate)
    /// amplitude fluctuation, 0..=1 (default 0.1).
    pub modulation: f64,
}

impl EmgSynthConfig {
    /// Default amplitude at full activation (mV RMS).
    pub const DEFAULT_AMPLITUDE_MV: f64 = 0.5;
    /// Default noise floor (mV RMS).
    pub const DEFAULT_NOISE_FLOOR_MV: f64 = 0.01;
    /// Default hum amplitude (mV).
    pub const DEFAULT_HUM_MV: f64 = 0.02;
    /// Default hum frequency (Hz).
    pub const DEFAULT_HUM_HZ: f64 = 50.0;
    /// Default lower band edge (Hz).
    pub const DEFAULT_BAND_LOW_HZ: f64 = 20.0;
    /// Default upper band edge (Hz).
    pub const DEFAULT_BAND_HIGH_HZ: f64 = 450.0;
    /// Default attack time constant (ms).
    pub const DEFAULT_ATTACK_MS: f64 = 60.0;
    /// Default release time constant (ms).
    pub const DEFAULT_RELEASE_MS: f64 = 150.0;
    /// Default modulation depth.
    pub const DEFAULT_MODULATION: f64 = 0.1;

    /// A configuration with the defaults for everything but the channel
    /// count, the sample rate and the seed.
    ///
    /// ```
    /// let cfg = mosaic_dsp::EmgSynthConfig::new(2, 1000.0, 1);
    /// assert_eq!((cfg.band_low_hz, cfg.band_high_hz), (20.0, 450.0));
    /// ```
    pub fn new(channels: usize, sample_rate: f64, seed: u64) -> Self {
        EmgSynthConfig {
            channels,
            sample_rate,
            seed,
            amplitude_mv: Self::DEFAULT_AMPLITUDE_MV,
            noise_floor_mv: Self::DEFAULT_NOISE_FLOOR_MV,
            hum_mv: Self::DEFAULT_HUM_MV,
            hum_hz: Self::DEFAULT_HUM_HZ,
            band_low_hz: Self::DEFAULT_BAND_LOW_HZ,
            band_high_hz: Self::DEFAULT_BAND_HIGH_HZ,
            attack_ms: Self::DEFAULT_ATTACK_MS,
            release_ms: Self::DEFAULT_RELEASE_MS,
            modulation: Self::DEFAULT_MODULATION,
        }
    }
}

/// Per-channel state that `reset` restores.
#[derive(Debug, Clone)]
struct Channel {
    rng: Rng,
    /// Transposed direct form II states of the high-pass and low-pass.
    hp: [f64; 2],
    lp: [f64; 2],
    env: f64,
    /// Constant per-channel parameters drawn from the channel's generator:
    /// the hum's phase as (sin ψ, cos ψ) so that the hum needs no `sin` per
    /// channel, the modulation's phase and rate (cycles per sample).
    hum_sin: f64,
    hum_cos: f64,
    mod_phase: f64,
    mod_rate: f64,
    /// sin/cos of one sample's modulation phase step (a rotation).
    step_sin: f64,
    step_cos: f64,
    /// sin/cos of the modulation phase at the current sample: advanced by the
    /// rotation every sample, recomputed exactly every `RESYNC` samples (so
    /// rounding never accumulates and the output does not depend on how the
    /// samples are split into calls).
    mod_sin: f64,
    mod_cos: f64,
}

/// Samples between exact recomputations of the modulation phasor.
const RESYNC: u64 = 1024;

/// A seeded, multi-channel surface-EMG generator (the *EmgSimulator* block).
///
/// Every channel is, sample by sample (t = n / sample_rate):
///
/// ```text
/// emg   = amplitude_mv · g · BP(w₁)[n] · env[n] · (1 + modulation · sin(2π f_m t + ψ))
/// out   = emg + noise_floor_mv · w₂[n] + hum_mv · sin(2π hum_hz t + φ)
/// ```
///
/// * `w₁`, `w₂`: standard Gaussian white noise from the channel's own
///   xoshiro256++ generator (seeded by splitmix64 from `seed` and the channel
///   index; Marsaglia polar method).
/// * `BP`: 2nd-order Butterworth high-pass at `band_low_hz` followed by a
///   2nd-order Butterworth low-pass at `band_high_hz` (bilinear transform with
///   prewarping, see [`crate::design`]); `g` scales it to unit RMS. `g` is
///   calibrated once, in `new`, as `1 / sqrt(Σ h[k]²)` where `h` is the impulse
///   response of the cascade, summed until the last 1024 terms add less than
///   1e-16 of the total: for white noise of unit variance the output variance
///   is exactly `Σ h[k]²`.
/// * `env`: follows the channel's target activation (0..=1, [`EmgSynth::set_targets`])
///   with a first-order smoother whose time constant is `attack_ms` when
///   rising and `release_ms` when falling.
/// * `f_m` (uniform in 1–3 Hz), `ψ` and the hum phase `φ` (uniform in
///   0–2π) are drawn per channel from the channel's generator.
///
/// Output for `n` events is the same whether generated in one call or in
/// `n` calls of one event.
///
/// ```
/// use mosaic_dsp::{EmgSynth, EmgSynthConfig};
///
/// let mut synth = EmgSynth::new(EmgSynthConfig::new(2, 1000.0, 42))?;
/// synth.set_targets(&[1.0, 0.0])?;  // channel 0 fully active, channel 1 at rest
/// let mut out = vec![0.0; 2 * 1000]; // 1 s
/// synth.generate(&mut out)?;
/// let rms = |c: usize| {
///     let tail = &out[2 * 500..]; // after the attack
///     (tail.iter().skip(c).step_by(2).map(|x| x * x).sum::<f64>() / 500.0).sqrt()
/// };
/// assert!(rms(0) > 0.4 && rms(0) < 0.6);
/// assert!(rms(1) < 0.05);
/// # Ok::<(), mosaic_dsp::DspError>(())
/// ```
#[derive(Debug, Clone)]
pub struct EmgSynth {
    config: EmgSynthConfig,
    hp: Option<Biquad>,
    lp: Biquad,
    /// amplitude_mv × unit-RMS gain of the band-pass.
    emg_gain: f64,
    alpha_attack: f64,
    alpha_release: f64,
    /// Hum frequency in cycles per sample.
    hum_rate: f64,
    targets: Vec<f64>,
    channels: Vec<Channel>,
    initial: Vec<Channel>,
    /// Index of the next sample.
    n: u64,
}

impl EmgSynth {
    /// Creates a generator. Targets start at 0 (rest).
    ///
    /// # Errors
    ///
    /// `channels == 0`; a sample rate that is not a finite number > 0; a
    /// negative or non-finite amplitude, noise floor, hum amplitude, hum
    /// frequency, band edge or time constant; `band_low_hz >= band_high_hz`;
    /// a modulation outside 0..=1.
    ///
    /// ```
    /// use mosaic_dsp::{EmgSynth, EmgSynthConfig};
    ///
    /// let mut cfg = EmgSynthConfig::new(4, 1000.0, 0);
    /// cfg.modulation = 2.0;
    /// let err = EmgSynth::new(cfg).unwrap_err();
    /// assert_eq!(err.to_string(), "modulation is 2; expected a number from 0 to 1");
    /// ```
    pub fn new(config: EmgSynthConfig) -> Result<Self, DspError> {
        validate(&config)?;
        let fs = config.sample_rate;
        let high = config.band_high_hz.min(0.45 * fs);
        let lp = butterworth_lowpass2(high, fs)?;
        let hp = if config.band_low_hz > 0.0 && config.band_low_hz < high {
            Some(butterworth_highpass2(config.band_low_hz, fs)?)
        } else {
            None
        };
        let emg_gain = config.amplitude_mv / impulse_energy(hp.as_ref(), &lp).sqrt();
        let alpha = |ms: f64| {
            let samples = ms * 1e-3 * fs;
            if samples > 0.0 {
                1.0 - (-1.0 / samples).exp()
            } else {
                1.0
            }
        };
        let initial: Vec<Channel> = (0..config.channels)
            .map(|c| {
                let mut rng = Rng::new(config.seed, c as u64);
                let hum_phase = TAU * rng.uniform();
                let mod_phase = TAU * rng.uniform();
                let mod_hz = 1.0 + 2.0 * rng.uniform();
                let mod_rate = mod_hz / fs;
                Channel {
                    rng,
                    hp: [0.0; 2],
                    lp: [0.0; 2],
                    env: 0.0,
                    hum_sin: hum_phase.sin(),
                    hum_cos: hum_phase.cos(),
                    mod_phase,
                    mod_rate,
                    step_sin: (TAU * mod_rate).sin(),
                    step_cos: (TAU * mod_rate).cos(),
                    mod_sin: mod_phase.sin(),
                    mod_cos: mod_phase.cos(),
                }
            })
            .collect();
        Ok(EmgSynth {
            alpha_attack: alpha(config.attack_ms),
            alpha_release: alpha(config.release_ms),
            hum_rate: config.hum_hz / fs,
            targets: vec![0.0; config.channels],
            channels: initial.clone(),
            initial,
            hp,
            lp,
            emg_gain,
            config,
            n: 0,
        })
    }

    /// The configuration this generator was made with.
    ///
    /// ```
    /// # use mosaic_dsp::{EmgSynth, EmgSynthConfig};
    /// let s = EmgSynth::new(EmgSynthConfig::new(3, 500.0, 9))?;
    /// assert_eq!(s.config().channels, 3);
    /// # Ok::<(), mosaic_dsp::DspError>(())
    /// ```
    pub fn config(&self) -> &EmgSynthConfig {
        &self.config
    }

    /// Number of channels.
    ///
    /// ```
    /// # use mosaic_dsp::{EmgSynth, EmgSynthConfig};
    /// assert_eq!(EmgSynth::new(EmgSynthConfig::new(3, 500.0, 9))?.channels(), 3);
    /// # Ok::<(), mosaic_dsp::DspError>(())
    /// ```
    pub fn channels(&self) -> usize {
        self.config.channels
    }

    /// The upper band edge actually used (after clamping to 0.45 × sample rate).
    ///
    /// ```
    /// # use mosaic_dsp::{EmgSynth, EmgSynthConfig};
    /// let s = EmgSynth::new(EmgSynthConfig::new(1, 200.0, 0))?;
    /// assert_eq!(s.band_high_hz(), 90.0);
    /// # Ok::<(), mosaic_dsp::DspError>(())
    /// ```
    pub fn band_high_hz(&self) -> f64 {
        self.config.band_high_hz.min(0.45 * self.config.sample_rate)
    }

    /// `true` when the high-pass is in use (see [`EmgSynthConfig::band_high_hz`]).
    ///
    /// ```
    /// # use mosaic_dsp::{EmgSynth, EmgSynthConfig};
    /// let mut cfg = EmgSynthConfig::new(1, 40.0, 0); // band_high clamps to 18 Hz < 20 Hz
    /// assert!(!EmgSynth::new(cfg.clone())?.has_highpass());
    /// cfg.sample_rate = 1000.0;
    /// assert!(EmgSynth::new(cfg)?.has_highpass());
    /// # Ok::<(), mosaic_dsp::DspError>(())
    /// ```
    pub fn has_highpass(&self) -> bool {
        self.hp.is_some()
    }

    /// Index of the next sample to be generated (0 after `new`/`reset`).
    ///
    /// ```
    /// # use mosaic_dsp::{EmgSynth, EmgSynthConfig};
    /// let mut s = EmgSynth::new(EmgSynthConfig::new(2, 1000.0, 0))?;
    /// s.generate(&mut [0.0; 6])?;
    /// assert_eq!(s.sample_index(), 3);
    /// # Ok::<(), mosaic_dsp::DspError>(())
    /// ```
    pub fn sample_index(&self) -> u64 {
        self.n
    }

    /// The current target activations.
    ///
    /// ```
    /// # use mosaic_dsp::{EmgSynth, EmgSynthConfig};
    /// let mut s = EmgSynth::new(EmgSynthConfig::new(2, 1000.0, 0))?;
    /// s.set_targets(&[0.5, 7.0])?;
    /// assert_eq!(s.targets(), &[0.5, 1.0]);
    /// # Ok::<(), mosaic_dsp::DspError>(())
    /// ```
    pub fn targets(&self) -> &[f64] {
        &self.targets
    }

    /// Sets the target activation of every channel (one value per channel).
    /// Values are clamped to 0..=1. Takes effect from the next sample.
    ///
    /// # Errors
    ///
    /// A length other than `channels`, or a NaN value (nothing is changed then).
    ///
    /// ```
    /// # use mosaic_dsp::{EmgSynth, EmgSynthConfig};
    /// let mut s = EmgSynth::new(EmgSynthConfig::new(2, 1000.0, 0))?;
    /// assert!(s.set_targets(&[1.0]).is_err());
    /// assert!(s.set_targets(&[1.0, f64::NAN]).is_err());
    /// s.set_targets(&[-1.0, 0.25])?;
    /// assert_eq!(s.targets(), &[0.0, 0.25]);
    /// # Ok::<(), mosaic_dsp::DspError>(())
    /// ```
    pub fn set_targets(&mut self, targets: &[f64]) -> Result<(), DspError> {
        if targets.len() != self.config.channels {
            return Err(DspError::WrongLength {
                name: "targets",
                len: targets.len(),
                expected: self.config.channels,
            });
        }
        if let Some(index) = targets.iter().position(|t| t.is_nan()) {
            return Err(DspError::NonFinite {
                name: "targets",
                index,
                value: targets[index],
            });
        }
        for (dst, &t) in self.targets.iter_mut().zip(targets) {
            *dst = t.clamp(0.0, 1.0);
        }
        Ok(())
    }

    /// Fills `out` with `n` events × `channels` samples (row-major
    /// interleaved). Never allocates.
    ///
    /// # Errors
    ///
    /// A length that is not a multiple of `channels` (nothing is generated then).
    ///
    /// ```
    /// # use mosaic_dsp::{EmgSynth, EmgSynthConfig};
    /// let mut s = EmgSynth::new(EmgSynthConfig::new(2, 1000.0, 0))?;
    /// let mut out = [0.0; 20];
    /// s.generate(&mut out)?;
    /// assert!(out.iter().all(|x| x.is_finite()));
    /// assert!(s.generate(&mut [0.0; 3]).is_err());
    /// # Ok::<(), mosaic_dsp::DspError>(())
    /// ```
    pub fn generate(&mut self, out: &mut [f64]) -> Result<(), DspError> {
        let c = self.config.channels;
        check_multiple("output", out.len(), c)?;
        let noise = self.config.noise_floor_mv;
        let hum = self.config.hum_mv;
        let depth = self.config.modulation;
        for row in out.chunks_exact_mut(c) {
            let t = self.n as f64;
            let resync = self.n % RESYNC == 0;
            // sin(a + ψ) = sin a · cos ψ + cos a · sin ψ: one sin/cos per sample for all channels.
            let (hum_sin, hum_cos) = (TAU * fract(t * self.hum_rate)).sin_cos();
            for ((y, ch), &target) in row.iter_mut().zip(&mut self.channels).zip(&self.targets) {
                let w1 = ch.rng.gaussian();
                let w2 = ch.rng.gaussian();
                let mut band = w1;
                if let Some(hp) = &self.hp {
                    band = biquad(hp, &mut ch.hp, band);
                }
                band = biquad(&self.lp, &mut ch.lp, band);
                let alpha = if target > ch.env {
                    self.alpha_attack
                } else {
                    self.alpha_release
                };
                ch.env += alpha * (target - ch.env);
                if resync {
                    let (s, c) = (TAU * fract(t * ch.mod_rate) + ch.mod_phase).sin_cos();
                    ch.mod_sin = s;
                    ch.mod_cos = c;
                }
                let modulation = 1.0 + depth * ch.mod_sin;
                *y = self.emg_gain * band * ch.env * modulation
                    + noise * w2
                    + hum * (hum_sin * ch.hum_cos + hum_cos * ch.hum_sin);
                // Advance the modulation phasor by one sample.
                let (s, c) = (ch.mod_sin, ch.mod_cos);
                ch.mod_sin = s * ch.step_cos + c * ch.step_sin;
                ch.mod_cos = c * ch.step_cos - s * ch.step_sin;
            }
            self.n += 1;
        }
        Ok(())
    }

    /// Returns to the state right after `new`: same generator states, filter
    /// states, envelopes and time, so the same targets give bit-identical
    /// output again. The targets themselves are kept (they are an input,
    /// not state).
    ///
    /// ```
    /// # use mosaic_dsp::{EmgSynth, EmgSynthConfig};
    /// let mut s = EmgSynth::new(EmgSynthConfig::new(2, 1000.0, 5))?;
    /// s.set_targets(&[1.0, 0.5])?;
    /// let (mut a, mut b) = ([0.0; 64], [0.0; 64]);
    /// s.generate(&mut a)?;
    /// s.reset();
    /// s.generate(&mut b)?;
    /// assert_eq!(a, b);
    /// # Ok::<(), mosaic_dsp::DspError>(())
    /// ```
    pub fn reset(&mut self) {
        self.channels.clone_from_slice(&self.initial);
        self.n = 0;
    }
}

#[inline(always)]
fn fract(x: f64) -> f64 {
    x - x.floor()
}

/// One sample through a biquad in transposed direct form II.
#[inline(always)]
fn biquad(s: &Biquad, z: &mut [f64; 2], x: f64) -> f64 {
    let y = s.b[0] * x + z[0];
    z[0] = s.b[1] * x - s.a[1] * y + z[1];
    z[1] = s.b[2] * x - s.a[2] * y;
    y
}

/// Σ h[k]² of the impulse response of the cascade (the noise power gain).
fn impulse_energy(hp: Option<&Biquad>, lp: &Biquad) -> f64 {
    const WINDOW: usize = 1024;
    const MAX_SAMPLES: usize = 1 << 24;
    let (mut zh, mut zl) = ([0.0; 2], [0.0; 2]);
    let mut total = 0.0;
    let mut window = 0.0;
    for k in 0..MAX_SAMPLES {
        let x = if k == 0 { 1.0 } else { 0.0 };
        let v = match hp {
            Some(hp) => biquad(hp, &mut zh, x),
            None => x,
        };
        let h = biquad(lp, &mut zl, v);
        total += h * h;
        window += h * h;
        if (k + 1) % WINDOW == 0 {
            if window <= 1e-16 * total {
                break;
            }
            window = 0.0;
        }
    }
    total
}

fn validate(c: &EmgSynthConfig) -> Result<(), DspError> {
    if c.channels == 0 {
        return Err(DspError::ZeroChannels);
    }
    let check = |name, value: f64, ok: bool, expected| {
        if ok {
            Ok(())
        } else {
            Err(DspError::InvalidParameter {
                name,
                value,
                expected,
            })
        }
    };
    let non_negative = |v: f64| v.is_finite() && v >= 0.0;
    let fs = c.sample_rate;
    check(
        "sample_rate",
        fs,
        fs.is_finite() && fs > 0.0,
        "a finite number of hertz > 0",
    )?;
    for (name, value) in [
        ("amplitude_mv", c.amplitude_mv),
        ("noise_floor_mv", c.noise_floor_mv),
        ("hum_mv", c.hum_mv),
        ("hum_hz", c.hum_hz),
        ("band_low_hz", c.band_low_hz),
        ("attack_ms", c.attack_ms),
        ("release_ms", c.release_ms),
    ] {
        check(name, value, non_negative(value), "a finite number >= 0")?;
    }
    check(
        "band_high_hz",
        c.band_high_hz,
        c.band_high_hz.is_finite() && c.band_high_hz > c.band_low_hz,
        "a finite frequency above band_low_hz",
    )?;
    check(
        "modulation",
        c.modulation,
        (0.0..=1.0).contains(&c.modulation),
        "a number from 0 to 1",
    )?;
    Ok(())
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn modulation_phasor_tracks_the_exact_phase() {
        let mut s = EmgSynth::new(EmgSynthConfig::new(3, 2048.0, 4)).unwrap();
        let mut out = vec![0.0; 3 * 1023];
        let mut worst: f64 = 0.0;
        for _ in 0..20 {
            s.generate(&mut out).unwrap();
            let t = s.n as f64;
            for ch in &s.channels {
                let exact = TAU * fract(t * ch.mod_rate) + ch.mod_phase;
                worst = worst
                    .max((ch.mod_sin - exact.sin()).abs())
                    .max((ch.mod_cos - exact.cos()).abs());
            }
        }
        assert!(worst < 1e-12, "phasor error {worst}");
    }

    #[test]
    fn impulse_energy_of_identity_lowpass_is_positive() {
        let lp = butterworth_lowpass2(100.0, 1000.0).unwrap();
        let e = impulse_energy(None, &lp);
        // Noise bandwidth of a 2nd-order Butterworth ≈ 1.11 × fc; energy ≈ 2·1.11·fc/fs.
        assert!((e - 0.222).abs() < 0.02, "{e}");
    }

    #[test]
    fn validation_messages() {
        let mut c = EmgSynthConfig::new(1, 1000.0, 0);
        c.band_low_hz = 500.0;
        c.band_high_hz = 400.0;
        let e = EmgSynth::new(c).unwrap_err();
        assert_eq!(
            e.to_string(),
            "band_high_hz is 400; expected a finite frequency above band_low_hz"
        );
        let mut c = EmgSynthConfig::new(1, 1000.0, 0);
        c.attack_ms = -1.0;
        assert!(EmgSynth::new(c).is_err());
        assert!(EmgSynth::new(EmgSynthConfig::new(0, 1000.0, 0)).is_err());
        assert!(EmgSynth::new(EmgSynthConfig::new(1, 0.0, 0)).is_err());
    }
}
