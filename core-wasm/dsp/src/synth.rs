use std::f64::consts::TAU;

use crate::design::{butterworth_highpass2, butterworth_lowpass2, Biquad};
use crate::rng::{polar_pair, Rng};
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

/// Per-channel state that `reset` restores, one value per channel in each
/// field (side by side, so that the SIMD path loads two channels at once).
#[derive(Debug, Clone)]
struct State {
    /// xoshiro256++ states: `rng[i][c]` is word `i` of channel `c`'s generator.
    rng: [Vec<u64>; 4],
    /// Transposed direct form II states of the high-pass and low-pass.
    hp: [Vec<f64>; 2],
    lp: [Vec<f64>; 2],
    env: Vec<f64>,
    /// sin/cos of the modulation phase at the current sample: advanced by the
    /// rotation every sample, recomputed exactly every `RESYNC` samples (so
    /// rounding never accumulates and the output does not depend on how the
    /// samples are split into calls).
    mod_sin: Vec<f64>,
    mod_cos: Vec<f64>,
}

/// Constant per-channel parameters drawn from the channel's generator: the
/// hum's phase as (sin ψ, cos ψ) so that the hum needs no `sin` per channel,
/// the modulation's phase and rate (cycles per sample), and sin/cos of one
/// sample's modulation phase step (a rotation).
#[derive(Debug, Clone)]
struct Constants {
    hum_sin: Vec<f64>,
    hum_cos: Vec<f64>,
    mod_phase: Vec<f64>,
    mod_rate: Vec<f64>,
    step_sin: Vec<f64>,
    step_cos: Vec<f64>,
}

/// Rows generated per block: the hum phasor of a block's rows is computed
/// once for all channels, then every channel (pair) runs through the block
/// with its state in registers.
const BLOCK_ROWS: usize = 32;

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
    consts: Constants,
    state: State,
    initial: State,
    /// Scratch of the SIMD path: the white noise of a block (6 values per
    /// channel pair and row).
    #[cfg_attr(
        not(all(target_arch = "wasm32", target_feature = "simd128")),
        allow(dead_code)
    )]
    noise: Vec<f64>,
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
        let c = config.channels;
        let mut initial = State {
            rng: std::array::from_fn(|_| Vec::with_capacity(c)),
            hp: [vec![0.0; c], vec![0.0; c]],
            lp: [vec![0.0; c], vec![0.0; c]],
            env: vec![0.0; c],
            mod_sin: Vec::with_capacity(c),
            mod_cos: Vec::with_capacity(c),
        };
        let mut consts = Constants {
            hum_sin: Vec::with_capacity(c),
            hum_cos: Vec::with_capacity(c),
            mod_phase: Vec::with_capacity(c),
            mod_rate: Vec::with_capacity(c),
            step_sin: Vec::with_capacity(c),
            step_cos: Vec::with_capacity(c),
        };
        for ch in 0..c {
            let mut rng = Rng::new(config.seed, ch as u64);
            let hum_phase = TAU * rng.uniform();
            let mod_phase = TAU * rng.uniform();
            let mod_hz = 1.0 + 2.0 * rng.uniform();
            let mod_rate = mod_hz / fs;
            for (word, value) in initial.rng.iter_mut().zip(rng.state()) {
                word.push(value);
            }
            initial.mod_sin.push(mod_phase.sin());
            initial.mod_cos.push(mod_phase.cos());
            consts.hum_sin.push(hum_phase.sin());
            consts.hum_cos.push(hum_phase.cos());
            consts.mod_phase.push(mod_phase);
            consts.mod_rate.push(mod_rate);
            consts.step_sin.push((TAU * mod_rate).sin());
            consts.step_cos.push((TAU * mod_rate).cos());
        }
        Ok(EmgSynth {
            alpha_attack: alpha(config.attack_ms),
            alpha_release: alpha(config.release_ms),
            hum_rate: config.hum_hz / fs,
            targets: vec![0.0; config.channels],
            consts,
            state: initial.clone(),
            initial,
            noise: if crate::simd::SIMD_COMPILED {
                vec![0.0; BLOCK_ROWS * c * 3]
            } else {
                Vec::new()
            },
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
        let simd = crate::simd::simd_enabled();
        for block in out.chunks_mut(BLOCK_ROWS * c) {
            let rows = block.len() / c;
            // sin(a + ψ) = sin a · cos ψ + cos a · sin ψ: one sin/cos per sample for all channels.
            let mut hum = [(0.0, 0.0); BLOCK_ROWS];
            for (r, h) in hum.iter_mut().take(rows).enumerate() {
                let t = (self.n + r as u64) as f64;
                *h = (TAU * fract(t * self.hum_rate)).sin_cos();
            }
            let hum = &hum[..rows];
            // The row (if any) at which the modulation phasors are recomputed.
            let resync = (0..rows).find(|&r| (self.n + r as u64) % RESYNC == 0);
            let mut ch = 0;
            #[cfg(all(target_arch = "wasm32", target_feature = "simd128"))]
            if simd && c >= 2 {
                // The white noise of every channel pair and row first: drawing
                // the points, then scaling them all in one long loop, keeps the
                // long chains of the logarithm, division and square root of many
                // rows in flight at once, even when a call has few rows.
                let pairs = c / 2;
                let mut noise = std::mem::take(&mut self.noise);
                let noise_rows = &mut noise[..pairs * rows * 6];
                for (p, out) in noise_rows.chunks_exact_mut(rows * 6).enumerate() {
                    polar_points_simd(&mut self.state.rng, 2 * p, out);
                }
                polar_scale_simd(noise_rows);
                for (p, w) in noise_rows.chunks_exact(rows * 6).enumerate() {
                    self.pair_simd(2 * p, block, hum, resync, w);
                }
                self.noise = noise;
                ch = 2 * pairs;
            }
            let _ = simd;
            while ch < c {
                self.channel_scalar(ch, block, hum, resync);
                ch += 1;
            }
            self.n += rows as u64;
        }
        Ok(())
    }

    /// The exact modulation phasor (sin, cos) of channel `ch` at sample `n`.
    fn modulation_at(&self, ch: usize, n: u64) -> (f64, f64) {
        let t = n as f64;
        (TAU * fract(t * self.consts.mod_rate[ch]) + self.consts.mod_phase[ch]).sin_cos()
    }

    /// Rows `0..hum.len()` of channel `ch` of a block of output rows
    /// (starting at sample `self.n`).
    fn channel_scalar(
        &mut self,
        ch: usize,
        block: &mut [f64],
        hum: &[(f64, f64)],
        resync: Option<usize>,
    ) {
        let c = self.config.channels;
        let noise = self.config.noise_floor_mv;
        let hum_mv = self.config.hum_mv;
        let depth = self.config.modulation;
        let gain = self.emg_gain;
        let target = self.targets[ch];
        let (hum_cos_ch, hum_sin_ch) = (self.consts.hum_cos[ch], self.consts.hum_sin[ch]);
        let (step_sin, step_cos) = (self.consts.step_sin[ch], self.consts.step_cos[ch]);
        let resync = resync.map(|r| (r, self.modulation_at(ch, self.n + r as u64)));
        let st = &mut self.state;
        let mut rng = [st.rng[0][ch], st.rng[1][ch], st.rng[2][ch], st.rng[3][ch]];
        let mut hp = [st.hp[0][ch], st.hp[1][ch]];
        let mut lp = [st.lp[0][ch], st.lp[1][ch]];
        let mut env = st.env[ch];
        let (mut mod_sin, mut mod_cos) = (st.mod_sin[ch], st.mod_cos[ch]);
        for (r, &(hum_sin, hum_cos)) in hum.iter().enumerate() {
            let (w1, w2) = polar_pair(&mut rng);
            let mut band = w1;
            if let Some(f) = &self.hp {
                band = biquad(f, &mut hp, band);
            }
            band = biquad(&self.lp, &mut lp, band);
            let alpha = if target > env {
                self.alpha_attack
            } else {
                self.alpha_release
            };
            env += alpha * (target - env);
            if let Some((at, (s, c))) = resync {
                if at == r {
                    mod_sin = s;
                    mod_cos = c;
                }
            }
            let modulation = 1.0 + depth * mod_sin;
            block[r * c + ch] = gain * band * env * modulation
                + noise * w2
                + hum_mv * (hum_sin * hum_cos_ch + hum_cos * hum_sin_ch);
            // Advance the modulation phasor by one sample.
            let (s, c) = (mod_sin, mod_cos);
            mod_sin = s * step_cos + c * step_sin;
            mod_cos = c * step_cos - s * step_sin;
        }
        for (word, value) in st.rng.iter_mut().zip(rng) {
            word[ch] = value;
        }
        (st.hp[0][ch], st.hp[1][ch]) = (hp[0], hp[1]);
        (st.lp[0][ch], st.lp[1][ch]) = (lp[0], lp[1]);
        st.env[ch] = env;
        (st.mod_sin[ch], st.mod_cos[ch]) = (mod_sin, mod_cos);
    }

    /// [`EmgSynth::channel_scalar`] for channels `ch` and `ch + 1` at once
    /// (SIMD128: the same operations in the same order, two lanes), given
    /// their white noise (`noise_rows`: per row w₁ of both, then w₂ of both).
    #[cfg(all(target_arch = "wasm32", target_feature = "simd128"))]
    fn pair_simd(
        &mut self,
        ch: usize,
        block: &mut [f64],
        hum: &[(f64, f64)],
        resync: Option<usize>,
        noise_rows: &[f64],
    ) {
        use crate::simd::v::*;
        let c = self.config.channels;
        let noise = f64x2_splat(self.config.noise_floor_mv);
        let hum_mv = f64x2_splat(self.config.hum_mv);
        let depth = f64x2_splat(self.config.modulation);
        let gain = f64x2_splat(self.emg_gain);
        let attack = f64x2_splat(self.alpha_attack);
        let release = f64x2_splat(self.alpha_release);
        let one = f64x2_splat(1.0);
        let target = ld(&self.targets, ch);
        let hum_cos_ch = ld(&self.consts.hum_cos, ch);
        let hum_sin_ch = ld(&self.consts.hum_sin, ch);
        let step_sin = ld(&self.consts.step_sin, ch);
        let step_cos = ld(&self.consts.step_cos, ch);
        let resync = resync.map(|r| {
            let n = self.n + r as u64;
            let (s0, c0) = self.modulation_at(ch, n);
            let (s1, c1) = self.modulation_at(ch + 1, n);
            (r, f64x2(s0, s1), f64x2(c0, c1))
        });
        let hp = self.hp.as_ref().map(BiquadX2::new);
        let lp = BiquadX2::new(&self.lp);
        let state = &mut self.state;
        let mut hp_z = [ld(&state.hp[0], ch), ld(&state.hp[1], ch)];
        let mut lp_z = [ld(&state.lp[0], ch), ld(&state.lp[1], ch)];
        let mut env = ld(&state.env, ch);
        let mut mod_sin = ld(&state.mod_sin, ch);
        let mut mod_cos = ld(&state.mod_cos, ch);
        for (r, (&(hum_sin, hum_cos), w)) in hum.iter().zip(noise_rows.chunks_exact(6)).enumerate()
        {
            let (w1, w2) = (ld(w, 0), ld(w, 2));
            let mut band = w1;
            if let Some(f) = &hp {
                band = f.step(&mut hp_z, band);
            }
            band = lp.step(&mut lp_z, band);
            let alpha = v128_bitselect(attack, release, f64x2_gt(target, env));
            env = f64x2_add(env, f64x2_mul(alpha, f64x2_sub(target, env)));
            if let Some((at, s, c)) = resync {
                if at == r {
                    mod_sin = s;
                    mod_cos = c;
                }
            }
            let modulation = f64x2_add(one, f64x2_mul(depth, mod_sin));
            let emg = f64x2_mul(f64x2_mul(f64x2_mul(gain, band), env), modulation);
            let h = f64x2_add(
                f64x2_mul(f64x2_splat(hum_sin), hum_cos_ch),
                f64x2_mul(f64x2_splat(hum_cos), hum_sin_ch),
            );
            let y = f64x2_add(f64x2_add(emg, f64x2_mul(noise, w2)), f64x2_mul(hum_mv, h));
            st(block, r * c + ch, y);
            let (s, c) = (mod_sin, mod_cos);
            mod_sin = f64x2_add(f64x2_mul(s, step_cos), f64x2_mul(c, step_sin));
            mod_cos = f64x2_sub(f64x2_mul(c, step_cos), f64x2_mul(s, step_sin));
        }
        st(&mut state.hp[0], ch, hp_z[0]);
        st(&mut state.hp[1], ch, hp_z[1]);
        st(&mut state.lp[0], ch, lp_z[0]);
        st(&mut state.lp[1], ch, lp_z[1]);
        st(&mut state.env, ch, env);
        st(&mut state.mod_sin, ch, mod_sin);
        st(&mut state.mod_cos, ch, mod_cos);
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
        self.state.clone_from(&self.initial);
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

/// The points of the polar method of channels `ch`, `ch + 1` for
/// `out.len() / 6` rows: per row u of both channels, v of both, s of both.
#[cfg(all(target_arch = "wasm32", target_feature = "simd128"))]
fn polar_points_simd(rng: &mut [Vec<u64>; 4], ch: usize, out: &mut [f64]) {
    use crate::simd::v::*;
    let mut state: [v128; 4] = std::array::from_fn(|i| ld_u64(&rng[i], ch));
    for row in out.chunks_exact_mut(6) {
        let (u, v, s) = crate::rng::polar_point_x2(&mut state);
        st(row, 0, u);
        st(row, 2, v);
        st(row, 4, s);
    }
    for (word, x) in rng.iter_mut().zip(state) {
        st_u64(word, ch, x);
    }
}

/// Turns the points of [`polar_points_simd`] into the deviates in place:
/// (u, v, s) → (w₁, w₂, s).
#[cfg(all(target_arch = "wasm32", target_feature = "simd128"))]
fn polar_scale_simd(rows: &mut [f64]) {
    use crate::simd::v::*;
    for row in rows.chunks_exact_mut(6) {
        let (w1, w2) = crate::rng::polar_scale_x2(ld(row, 0), ld(row, 2), ld(row, 4));
        st(row, 0, w1);
        st(row, 2, w2);
    }
}

/// [`biquad`] on two channels at once.
#[cfg(all(target_arch = "wasm32", target_feature = "simd128"))]
struct BiquadX2 {
    b: [core::arch::wasm32::v128; 3],
    a: [core::arch::wasm32::v128; 3],
}

#[cfg(all(target_arch = "wasm32", target_feature = "simd128"))]
impl BiquadX2 {
    fn new(s: &Biquad) -> Self {
        use core::arch::wasm32::f64x2_splat;
        BiquadX2 {
            b: s.b.map(|x| f64x2_splat(x)),
            a: s.a.map(|x| f64x2_splat(x)),
        }
    }

    #[inline(always)]
    fn step(
        &self,
        z: &mut [core::arch::wasm32::v128; 2],
        x: core::arch::wasm32::v128,
    ) -> core::arch::wasm32::v128 {
        use core::arch::wasm32::*;
        let y = f64x2_add(f64x2_mul(self.b[0], x), z[0]);
        z[0] = f64x2_add(
            f64x2_sub(f64x2_mul(self.b[1], x), f64x2_mul(self.a[1], y)),
            z[1],
        );
        z[1] = f64x2_sub(f64x2_mul(self.b[2], x), f64x2_mul(self.a[2], y));
        y
    }
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
            for ch in 0..3 {
                let exact = TAU * fract(t * s.consts.mod_rate[ch]) + s.consts.mod_phase[ch];
                worst = worst
                    .max((s.state.mod_sin[ch] - exact.sin()).abs())
                    .max((s.state.mod_cos[ch] - exact.cos()).abs());
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
