use crate::{check_multiple, DspError};

/// Why a channel of a window was rejected (bit `1 << (reason as u32)` of
/// the per-channel flags).
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum ArtifactReason {
    /// Samples on the rails (saturation / ADC clipping).
    Clipping = 0,
    /// Standard deviation below the flat-line threshold.
    Flat = 1,
    /// An impulsive jump between two consecutive samples.
    Jump = 2,
    /// Window mean beyond the drift threshold.
    Drift = 3,
    /// A NaN or infinite sample.
    NonFinite = 4,
}

impl ArtifactReason {
    /// Every reason, in flag-bit order.
    pub const ALL: [ArtifactReason; 5] = [
        ArtifactReason::Clipping,
        ArtifactReason::Flat,
        ArtifactReason::Jump,
        ArtifactReason::Drift,
        ArtifactReason::NonFinite,
    ];

    /// Short name: `clipping`, `flat`, `jump`, `drift`, `nonfinite`.
    pub fn name(self) -> &'static str {
        match self {
            ArtifactReason::Clipping => "clipping",
            ArtifactReason::Flat => "flat",
            ArtifactReason::Jump => "jump",
            ArtifactReason::Drift => "drift",
            ArtifactReason::NonFinite => "nonfinite",
        }
    }

    /// The flag bit of this reason.
    pub fn bit(self) -> u32 {
        1 << (self as u32)
    }
}

/// Number of counters per channel: one per reason, then the rejected total.
pub const ARTIFACT_COUNTERS: usize = 6;

/// Parameters of an [`ArtifactRejector`].
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct ArtifactConfig {
    /// Samples per window (L).
    pub rows: usize,
    /// Channels (C).
    pub channels: usize,
    /// Lower rail; `None`: the running minimum of the channel (auto).
    pub rail_low: Option<f64>,
    /// Upper rail; `None`: the running maximum of the channel (auto).
    pub rail_high: Option<f64>,
    /// A sample is on a rail when within this distance of it (signal units).
    pub clip_tolerance: f64,
    /// A side is clipped when at least this fraction of the window's samples
    /// is on its rail (and at least 1 sample for a fixed rail, 2 for an
    /// auto rail).
    pub clip_fraction: f64,
    /// Flat line: population standard deviation below this.
    pub flat_threshold: f64,
    /// Jump: `max |Δ − med(Δ)| > jump_factor · s` over the first
    /// differences Δ of the window, `s` a robust scale of Δ (see
    /// [`ArtifactRejector`]). `f64::INFINITY` disables it.
    pub jump_factor: f64,
    /// Drift: `|mean| > drift_threshold`; `None` disables it.
    pub drift_threshold: Option<f64>,
    /// Hard mode: rejected channels are zeroed in the clean output; soft
    /// mode passes the window unchanged.
    pub hard: bool,
}

impl ArtifactConfig {
    /// Defaults: auto rails, tolerance 1e-6, fraction 0, flat below 1e-6,
    /// jump factor 50, no drift test, hard mode.
    ///
    /// ```
    /// use mosaic_dsp::ArtifactConfig;
    /// let c = ArtifactConfig::new(200, 8);
    /// assert_eq!((c.rail_low, c.jump_factor, c.drift_threshold), (None, 50.0, None));
    /// ```
    pub fn new(rows: usize, channels: usize) -> Self {
        ArtifactConfig {
            rows,
            channels,
            rail_low: None,
            rail_high: None,
            clip_tolerance: 1e-6,
            clip_fraction: 0.0,
            flat_threshold: 1e-6,
            jump_factor: 50.0,
            drift_threshold: None,
            hard: true,
        }
    }
}

/// Rule-based artifact detection on windows `[L, C]` (row = sample, oldest
/// first), per channel (the MOSAIC *ArtifactRejection* block, paper
/// Table 3). A channel of a window is rejected when any rule fires:
///
/// * **non-finite** — a NaN or infinite sample (the other rules are skipped);
/// * **clipping** — on either side, the samples within `clip_tolerance` of
///   the rail (or beyond it) number at least `max(m, ⌈clip_fraction·L⌉)`,
///   with `m = 1` for a fixed rail. An auto rail is the running extreme of
///   all samples seen so far (this window included); the window that sets
///   an extreme always has one sample on it, so an auto rail needs `m = 2`
///   samples, is judged from the second window on, and only while the
///   running range is wider than `2·clip_tolerance`;
/// * **flat** — population standard deviation `< flat_threshold`;
/// * **jump** — `max_i |Δ_i − med(Δ)| > jump_factor · s`, where
///   `Δ_i = x_{i+1} − x_i`, `s = 1.4826 · MAD(Δ)` and `MAD(Δ) =
///   med(|Δ − med(Δ)|)`: the robust (modified) z-score of the largest step
///   (Iglewicz & Hoaglin 1993). When MAD is 0 (up to rounding: below 1e-9
///   times the mean absolute deviation, e.g. a quantised, nearly flat
///   channel whose steps are mostly equal), `s = 1.253314 · mean|Δ −
///   med(Δ)|`, their fallback. Medians of an even count average the two
///   middle values, as NumPy;
/// * **drift** — `|mean| > drift_threshold` (when set).
///
/// Outputs per window: the clean window (rejected channels zeroed in hard
/// mode), a mask (1 good, 0 rejected) and the reason flags per channel.
/// Counters per channel (one per reason, plus the rejected total) add up
/// over calls until [`ArtifactRejector::reset_counters`].
///
/// ```
/// use mosaic_dsp::{ArtifactConfig, ArtifactRejector};
///
/// // 4 samples × 2 channels: channel 1 is flat.
/// let mut cfg = ArtifactConfig::new(4, 2);
/// (cfg.rail_low, cfg.rail_high) = (Some(-1.0), Some(1.0));
/// let mut ar = ArtifactRejector::new(cfg)?;
/// let w = [0.1, 0.5, -0.2, 0.5, 0.3, 0.5, 0.0, 0.5];
/// let (mut clean, mut mask, mut flags) = ([9.0; 8], [9.0; 2], [9.0; 2]);
/// ar.process(&w, &mut clean, &mut mask, &mut flags)?;
/// assert_eq!(mask, [1.0, 0.0]);
/// assert_eq!(flags, [0.0, 2.0]); // bit 1: flat
/// assert_eq!(clean, [0.1, 0.0, -0.2, 0.0, 0.3, 0.0, 0.0, 0.0]);
/// # Ok::<(), mosaic_dsp::DspError>(())
/// ```
#[derive(Debug, Clone)]
pub struct ArtifactRejector {
    cfg: ArtifactConfig,
    /// Samples needed on a fixed / auto rail.
    need_fixed: usize,
    need_auto: usize,
    lo: Vec<f64>,
    hi: Vec<f64>,
    windows: u64,
    /// `channels × ARTIFACT_COUNTERS`, reason-major per channel.
    counters: Vec<f64>,
    /// Per-channel accumulators of one window.
    stats: Stats,
    /// Scratch: the differences of one channel, and a copy for selection.
    diffs: Vec<f64>,
    work: Vec<f64>,
}

/// One value per channel for each statistic of a window.
#[derive(Debug, Clone)]
struct Stats {
    lo: Vec<f64>,
    hi: Vec<f64>,
    sum: Vec<f64>,
    bad: Vec<f64>,
    mean: Vec<f64>,
    low: Vec<f64>,
    high: Vec<f64>,
    ss: Vec<f64>,
    n_lo: Vec<f64>,
    n_hi: Vec<f64>,
}

impl Stats {
    fn new(c: usize) -> Self {
        let v = || vec![0.0; c];
        Stats {
            lo: v(),
            hi: v(),
            sum: v(),
            bad: v(),
            mean: v(),
            low: v(),
            high: v(),
            ss: v(),
            n_lo: v(),
            n_hi: v(),
        }
    }
}

impl ArtifactRejector {
    /// Creates the detector.
    ///
    /// # Errors
    ///
    /// `rows < 3`, `channels == 0`, rails that are not finite or not
    /// `low < high`, a negative or NaN tolerance/threshold, a fraction
    /// outside `[0, 1]`, a jump factor that is not positive.
    ///
    /// ```
    /// use mosaic_dsp::{ArtifactConfig, ArtifactRejector};
    /// assert!(ArtifactRejector::new(ArtifactConfig::new(2, 1)).is_err());
    /// let mut c = ArtifactConfig::new(10, 1);
    /// (c.rail_low, c.rail_high) = (Some(1.0), Some(-1.0));
    /// assert!(ArtifactRejector::new(c).is_err());
    /// ```
    pub fn new(cfg: ArtifactConfig) -> Result<Self, DspError> {
        if cfg.rows < 3 {
            return Err(DspError::InvalidParameter {
                name: "window length",
                value: cfg.rows as f64,
                expected: "at least 3 samples (windows [L, C] from SlidingWindow)",
            });
        }
        if cfg.channels == 0 {
            return Err(DspError::ZeroChannels);
        }
        for (name, v) in [("RailLow", cfg.rail_low), ("RailHigh", cfg.rail_high)] {
            if let Some(v) = v {
                if !v.is_finite() {
                    return Err(DspError::InvalidParameter {
                        name,
                        value: v,
                        expected: "a finite number",
                    });
                }
            }
        }
        if let (Some(l), Some(h)) = (cfg.rail_low, cfg.rail_high) {
            if l >= h {
                return Err(DspError::InvalidParameter {
                    name: "RailLow",
                    value: l,
                    expected: "a value below RailHigh",
                });
            }
        }
        let non_negative = [
            ("ClipTolerance", cfg.clip_tolerance),
            ("FlatThreshold", cfg.flat_threshold),
        ];
        for (name, v) in non_negative {
            if !(v >= 0.0 && v.is_finite()) {
                return Err(DspError::InvalidParameter {
                    name,
                    value: v,
                    expected: "a finite number, 0 or more",
                });
            }
        }
        if !(0.0..=1.0).contains(&cfg.clip_fraction) {
            return Err(DspError::InvalidParameter {
                name: "ClipFraction",
                value: cfg.clip_fraction,
                expected: "a fraction from 0 to 1",
            });
        }
        if cfg.jump_factor.is_nan() || cfg.jump_factor <= 0.0 {
            return Err(DspError::InvalidParameter {
                name: "JumpFactor",
                value: cfg.jump_factor,
                expected: "a positive number (.inf disables the jump test)",
            });
        }
        if let Some(d) = cfg.drift_threshold {
            if d.is_nan() || d < 0.0 {
                return Err(DspError::InvalidParameter {
                    name: "DriftThreshold",
                    value: d,
                    expected: "a number, 0 or more",
                });
            }
        }
        let by_fraction = (cfg.clip_fraction * cfg.rows as f64).ceil() as usize;
        let c = cfg.channels;
        Ok(ArtifactRejector {
            need_fixed: by_fraction.max(1),
            need_auto: by_fraction.max(2),
            lo: vec![f64::INFINITY; c],
            hi: vec![f64::NEG_INFINITY; c],
            windows: 0,
            counters: vec![0.0; c * ARTIFACT_COUNTERS],
            stats: Stats::new(c),
            diffs: vec![0.0; cfg.rows - 1],
            work: vec![0.0; cfg.rows - 1],
            cfg,
        })
    }

    /// The configuration.
    pub fn config(&self) -> &ArtifactConfig {
        &self.cfg
    }

    /// Number of channels.
    pub fn channels(&self) -> usize {
        self.cfg.channels
    }

    /// Values per window (`rows × channels`).
    pub fn window_size(&self) -> usize {
        self.cfg.rows * self.cfg.channels
    }

    /// Windows judged since creation or the last [`ArtifactRejector::reset_counters`].
    pub fn windows(&self) -> u64 {
        self.windows
    }

    /// Counters, `ARTIFACT_COUNTERS` per channel: the windows in which each
    /// reason fired ([`ArtifactReason`] order), then the windows rejected.
    pub fn counters(&self) -> &[f64] {
        &self.counters
    }

    /// The rails in use for channel `c`: `(low, high)` (running extremes for
    /// auto rails; ±∞ before any sample).
    pub fn rails(&self, c: usize) -> (f64, f64) {
        (
            self.cfg.rail_low.unwrap_or(self.lo[c]),
            self.cfg.rail_high.unwrap_or(self.hi[c]),
        )
    }

    /// Judges `n` windows: `windows` and `clean` hold `n × rows × channels`
    /// values, `mask` and `flags` `n × channels`.
    ///
    /// # Errors
    ///
    /// Lengths that are not whole windows or do not agree; nothing is
    /// judged then.
    pub fn process(
        &mut self,
        windows: &[f64],
        clean: &mut [f64],
        mask: &mut [f64],
        flags: &mut [f64],
    ) -> Result<(), DspError> {
        let size = self.window_size();
        let c = self.cfg.channels;
        let n = check_multiple("input", windows.len(), size)?;
        if clean.len() != windows.len() {
            return Err(DspError::OutputLength {
                len: clean.len(),
                expected: windows.len(),
            });
        }
        for out in [&*mask, &*flags] {
            if out.len() != n * c {
                return Err(DspError::OutputLength {
                    len: out.len(),
                    expected: n * c,
                });
            }
        }
        for (((w, o), m), f) in windows
            .chunks_exact(size)
            .zip(clean.chunks_exact_mut(size))
            .zip(mask.chunks_exact_mut(c))
            .zip(flags.chunks_exact_mut(c))
        {
            self.window(w, o, m, f);
        }
        Ok(())
    }

    /// Judges one window. The per-channel statistics run row by row with one
    /// accumulator per channel (contiguous, independent: the compiler
    /// vectorises them), in the same order per channel as a column loop, so
    /// the sums are those of a sequential loop over the channel's samples.
    fn window(&mut self, w: &[f64], clean: &mut [f64], mask: &mut [f64], flags: &mut [f64]) {
        let c = self.cfg.channels;
        let rows = self.cfg.rows;
        let cfg = self.cfg;
        let judge_auto = self.windows >= 1;
        self.windows += 1;
        let n = rows as f64;
        let tol = cfg.clip_tolerance;
        let s = &mut self.stats;

        // Pass 1: non-finite samples, extremes, sums.
        s.lo.fill(f64::INFINITY);
        s.hi.fill(f64::NEG_INFINITY);
        s.sum.fill(0.0);
        s.bad.fill(0.0);
        for row in w.chunks_exact(c) {
            for ((&x, sum), bad) in row.iter().zip(s.sum.iter_mut()).zip(s.bad.iter_mut()) {
                *bad += if x.is_finite() { 0.0 } else { 1.0 };
                *sum += x;
            }
            for ((&x, lo), hi) in row.iter().zip(s.lo.iter_mut()).zip(s.hi.iter_mut()) {
                *lo = lo.min(x);
                *hi = hi.max(x);
            }
        }

        // Rails and thresholds per channel.
        for ch in 0..c {
            if s.bad[ch] == 0.0 {
                self.lo[ch] = self.lo[ch].min(s.lo[ch]);
                self.hi[ch] = self.hi[ch].max(s.hi[ch]);
            }
            let rl = cfg.rail_low.unwrap_or(self.lo[ch]);
            let rh = cfg.rail_high.unwrap_or(self.hi[ch]);
            s.low[ch] = rl + tol;
            s.high[ch] = rh - tol;
            s.mean[ch] = s.sum[ch] / n;
        }

        // Pass 2: squared deviations and samples on the rails.
        s.ss.fill(0.0);
        s.n_lo.fill(0.0);
        s.n_hi.fill(0.0);
        for row in w.chunks_exact(c) {
            for ((&x, ss), &mean) in row.iter().zip(s.ss.iter_mut()).zip(&s.mean) {
                let d = x - mean;
                *ss += d * d;
            }
            for ((&x, n_lo), &low) in row.iter().zip(s.n_lo.iter_mut()).zip(&s.low) {
                *n_lo += if x <= low { 1.0 } else { 0.0 };
            }
            for ((&x, n_hi), &high) in row.iter().zip(s.n_hi.iter_mut()).zip(&s.high) {
                *n_hi += if x >= high { 1.0 } else { 0.0 };
            }
        }

        for ch in 0..c {
            let bits = if s.bad[ch] != 0.0 {
                ArtifactReason::NonFinite.bit()
            } else {
                let mut bits = 0;
                let auto_ok = judge_auto && self.hi[ch] - self.lo[ch] > 2.0 * tol;
                let check_low = cfg.rail_low.is_some() || auto_ok;
                let check_high = cfg.rail_high.is_some() || auto_ok;
                let need_lo = if cfg.rail_low.is_some() {
                    self.need_fixed
                } else {
                    self.need_auto
                };
                let need_hi = if cfg.rail_high.is_some() {
                    self.need_fixed
                } else {
                    self.need_auto
                };
                if (check_low && s.n_lo[ch] >= need_lo as f64)
                    || (check_high && s.n_hi[ch] >= need_hi as f64)
                {
                    bits |= ArtifactReason::Clipping.bit();
                }
                if (s.ss[ch] / n).sqrt() < cfg.flat_threshold {
                    bits |= ArtifactReason::Flat.bit();
                }
                if let Some(d) = cfg.drift_threshold {
                    if s.mean[ch].abs() > d {
                        bits |= ArtifactReason::Drift.bit();
                    }
                }
                if cfg.jump_factor.is_finite()
                    && jump(w, ch, c, &mut self.diffs, &mut self.work, cfg.jump_factor)
                {
                    bits |= ArtifactReason::Jump.bit();
                }
                bits
            };
            flags[ch] = f64::from(bits);
            let counters = &mut self.counters[ch * ARTIFACT_COUNTERS..(ch + 1) * ARTIFACT_COUNTERS];
            for r in ArtifactReason::ALL {
                if bits & r.bit() != 0 {
                    counters[r as usize] += 1.0;
                }
            }
            if bits != 0 {
                counters[ARTIFACT_COUNTERS - 1] += 1.0;
            }
            mask[ch] = if bits == 0 { 1.0 } else { 0.0 };
        }
        if cfg.hard {
            for (o, x) in clean.chunks_exact_mut(c).zip(w.chunks_exact(c)) {
                for ((o, &x), &m) in o.iter_mut().zip(x).zip(mask.iter()) {
                    *o = if m == 1.0 { x } else { 0.0 };
                }
            }
        } else {
            clean.copy_from_slice(w);
        }
    }

    /// Zeroes the counters (the rails learned so far are kept).
    pub fn reset_counters(&mut self) {
        self.counters.fill(0.0);
        self.windows = 0;
    }

    /// Back to the initial state: counters and auto rails forgotten.
    pub fn reset(&mut self) {
        self.reset_counters();
        self.lo.fill(f64::INFINITY);
        self.hi.fill(f64::NEG_INFINITY);
    }
}

/// The jump rule on channel `ch` of the row-major window `w` (`c` channels):
/// `max |Δ − med(Δ)| > factor · s`, `s` the robust scale of the steps.
fn jump(w: &[f64], ch: usize, c: usize, diffs: &mut [f64], work: &mut [f64], factor: f64) -> bool {
    let mut prev = w[ch];
    for (d, x) in diffs.iter_mut().zip(w[ch + c..].iter().step_by(c)) {
        *d = x - prev;
        prev = *x;
    }
    work.copy_from_slice(diffs);
    let med = median(work);
    let (mut dev_max, mut dev_sum) = (0.0f64, 0.0);
    for (wk, &d) in work.iter_mut().zip(diffs.iter()) {
        let dev = (d - med).abs();
        *wk = dev;
        dev_max = dev_max.max(dev);
        dev_sum += dev;
    }
    let mad = median(work);
    let mean_ad = dev_sum / diffs.len() as f64;
    let scale = if mad > 1e-9 * mean_ad {
        1.4826 * mad
    } else {
        1.253314 * mean_ad
    };
    dev_max > factor * scale
}

/// Median of finite values (reorders `v`); the mean of the two middle
/// values for an even count, as `numpy.median`.
fn median(v: &mut [f64]) -> f64 {
    let n = v.len();
    let k = n / 2;
    let (left, m, _) = v.select_nth_unstable_by(k, |a, b| {
        a.partial_cmp(b).unwrap_or(std::cmp::Ordering::Equal)
    });
    let m = *m;
    if n % 2 == 1 {
        m
    } else {
        let below = left.iter().copied().fold(f64::NEG_INFINITY, f64::max);
        (below + m) / 2.0
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn median_matches_numpy_convention() {
        assert_eq!(median(&mut [3.0, 1.0, 2.0]), 2.0);
        assert_eq!(median(&mut [4.0, 1.0, 3.0, 2.0]), 2.5);
        assert_eq!(median(&mut [5.0]), 5.0);
    }

    fn run(cfg: ArtifactConfig, w: &[f64]) -> (Vec<f64>, Vec<f64>) {
        let mut ar = ArtifactRejector::new(cfg).unwrap();
        let mut clean = vec![0.0; w.len()];
        let n = w.len() / ar.window_size();
        let mut mask = vec![0.0; n * cfg.channels];
        let mut flags = vec![0.0; n * cfg.channels];
        ar.process(w, &mut clean, &mut mask, &mut flags).unwrap();
        (mask, flags)
    }

    #[test]
    fn fixed_rails_catch_a_single_sample() {
        let mut cfg = ArtifactConfig::new(5, 1);
        (cfg.rail_low, cfg.rail_high) = (Some(-1.5), Some(1.499267578125));
        let (m, f) = run(cfg, &[0.1, -0.2, 1.499268, 0.0, 0.3]);
        assert_eq!((m[0], f[0]), (0.0, 1.0));
        cfg.clip_fraction = 0.4; // two samples needed now
        assert_eq!(run(cfg, &[0.1, -0.2, 1.499268, 0.0, 0.3]).0[0], 1.0);
    }

    #[test]
    fn auto_rails_need_two_samples_and_a_second_window() {
        let cfg = ArtifactConfig::new(4, 1);
        // Window 1 has two samples at its own maximum: not judged (learning).
        // Window 2 re-hits that maximum twice: clipped. Window 3 once: fine.
        let w = [
            0.0, 1.0, 1.0, -0.5, //
            1.0, 0.2, 1.0, -0.4, //
            1.0, 0.2, 0.1, -0.3,
        ];
        let (m, _) = run(cfg, &w);
        assert_eq!(m, [1.0, 0.0, 1.0]);
    }

    #[test]
    fn jump_and_drift() {
        let mut cfg = ArtifactConfig::new(40, 1);
        cfg.jump_factor = 10.0;
        cfg.drift_threshold = Some(0.8);
        let base: Vec<f64> = (0..40)
            .map(|i| if i % 2 == 0 { 0.1 } else { -0.1 } + 0.01 * f64::from(i % 7))
            .collect();
        let (m, f) = run(cfg, &base);
        assert_eq!((m[0], f[0]), (1.0, 0.0));
        let mut spike = base.clone();
        spike[20] = 5.0;
        assert_eq!(run(cfg, &spike).1[0], f64::from(ArtifactReason::Jump.bit()));
        let shifted: Vec<f64> = base.iter().map(|x| x + 1.0).collect();
        assert_eq!(
            run(cfg, &shifted).1[0],
            f64::from(ArtifactReason::Drift.bit())
        );
        let mut nan = base.clone();
        nan[2] = f64::NAN;
        assert_eq!(
            run(cfg, &nan).1[0],
            f64::from(ArtifactReason::NonFinite.bit())
        );
    }
}
