use crate::{check_multiple, check_same_len, DspError};
use std::f64::consts::PI;

/// Where the absolute value of the derivative is taken in eq. 4.
///
/// The paper writes `LP(|ẋ[n]|, B1)` (rectify, then smooth); MOSAIC 1's C#
/// code smooths the signed derivative and rectifies the result,
/// `|LP(ẋ[n], B1)|`. The two differ whenever the derivative changes sign.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum DerivativeOrder {
    /// `LP(|ẋ|)`: the paper's eq. 4 (default).
    LowpassOfAbs,
    /// `|LP(ẋ)|`: what MOSAIC 1's `AdaptiveFilter.cs` computes.
    AbsOfLowpass,
}

/// Parameters of an [`AdaptiveFilter`] (paper III-F, eqs. 2–4).
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct AdaptiveFilterConfig {
    /// Number of channels (each filtered independently).
    pub channels: usize,
    /// Nominal sampling rate in Hz: ΔT = 1 / `sample_rate` unless the
    /// timestamps give it ([`AdaptiveFilter::process_timed`]).
    pub sample_rate: f64,
    /// G1: gain of the smoothed derivative magnitude in eq. 4.
    pub g1: f64,
    /// G2: gain of the signal magnitude in eq. 4.
    pub g2: f64,
    /// B1: cut-off frequency (Hz) of the first-order low-pass that smooths
    /// the derivative; its factor is `2πB1ΔT / (1 + 2πB1ΔT)` (eq. 3's form,
    /// as MOSAIC 1 converts its first positional parameter).
    pub b1: f64,
    /// B2: bias (offset) inside the exponential of eq. 4.
    pub b2: f64,
    /// Where the absolute value of the derivative is taken.
    pub order: DerivativeOrder,
}

impl AdaptiveFilterConfig {
    /// MOSAIC 1's documented example (`Params: ['0.7', '-1', '-7', '8']`):
    /// B1 = 0.7 Hz, B2 = −1, G2 = −7, G1 = 8, paper order.
    ///
    /// ```
    /// use mosaic_dsp::AdaptiveFilterConfig;
    /// let c = AdaptiveFilterConfig::new(4, 200.0);
    /// assert_eq!((c.g1, c.g2, c.b1, c.b2), (8.0, -7.0, 0.7, -1.0));
    /// ```
    pub fn new(channels: usize, sample_rate: f64) -> Self {
        AdaptiveFilterConfig {
            channels,
            sample_rate,
            g1: 8.0,
            g2: -7.0,
            b1: 0.7,
            b2: -1.0,
            order: DerivativeOrder::LowpassOfAbs,
        }
    }
}

/// The MOSAIC *AdaptiveFilter* block: a single-pole low-pass whose cut-off
/// follows the signal (paper III-F, eqs. 2–4), per channel:
///
/// ```text
/// ẋ[n]   = (x[n] − x[n−1]) / ΔT
/// d[n]   = a·|ẋ[n]| + (1 − a)·d[n−1],   a = 2πB1ΔT / (1 + 2πB1ΔT)      (LP(|ẋ|, B1))
/// F_c[n] = exp(G2·|x[n]| + G1·d[n] + B2)                                  (4)
/// α[n]   = 2πF_c[n]ΔT / (1 + 2πF_c[n]ΔT)                                  (3)
/// y[n]   = α[n]·x[n] + (1 − α[n])·y[n−1]                                  (2)
/// ```
///
/// With [`DerivativeOrder::AbsOfLowpass`], `d[n] = a·ẋ[n] + (1 − a)·d[n−1]`
/// and eq. 4 uses `|d[n]|` (MOSAIC 1's code). The state starts at zero
/// (`x[−1] = y[−1] = d[−1] = 0`, as MOSAIC 1), so the first derivative is
/// `x[0] / ΔT`. When `F_c` overflows to infinity, α is 1 (the limit of eq. 3)
/// and the output follows the input.
///
/// ```
/// use mosaic_dsp::{AdaptiveFilter, AdaptiveFilterConfig};
///
/// // G1 = G2 = 0: a fixed cut-off of exp(B2) Hz, i.e. a plain one-pole low-pass.
/// let mut cfg = AdaptiveFilterConfig::new(1, 100.0);
/// (cfg.g1, cfg.g2, cfg.b2) = (0.0, 0.0, (5.0f64).ln());
/// let mut f = AdaptiveFilter::new(cfg)?;
/// let mut y = [0.0; 3];
/// f.process(&[1.0, 1.0, 1.0], &mut y)?;
/// let k = 2.0 * std::f64::consts::PI * 5.0 / 100.0;
/// let a = k / (1.0 + k);
/// assert!((y[0] - a).abs() < 1e-15);
/// assert!((y[2] - (1.0 - (1.0 - a).powi(3))).abs() < 1e-15);
/// # Ok::<(), mosaic_dsp::DspError>(())
/// ```
#[derive(Debug, Clone)]
pub struct AdaptiveFilter {
    cfg: AdaptiveFilterConfig,
    dt: f64,
    /// Derivative smoothing factor for the nominal ΔT.
    a_nominal: f64,
    x_prev: Vec<f64>,
    d: Vec<f64>,
    y_prev: Vec<f64>,
    cutoff: Vec<f64>,
    t_prev: f64,
}

/// `2πfΔT / (1 + 2πfΔT)`, with the limit 1 when `f` is infinite.
#[inline(always)]
fn smoothing(f: f64, dt: f64) -> f64 {
    let k = 2.0 * PI * f * dt;
    if k.is_finite() {
        k / (1.0 + k)
    } else if k > 0.0 {
        1.0
    } else {
        // NaN (NaN input) stays NaN.
        k
    }
}

impl AdaptiveFilter {
    /// Creates the filter with zero state.
    ///
    /// # Errors
    ///
    /// `channels == 0`, a sampling rate that is not a positive finite number,
    /// a non-finite gain or bias, or a negative `b1`.
    ///
    /// ```
    /// use mosaic_dsp::{AdaptiveFilter, AdaptiveFilterConfig};
    /// assert!(AdaptiveFilter::new(AdaptiveFilterConfig::new(1, 0.0)).is_err());
    /// let mut c = AdaptiveFilterConfig::new(1, 100.0);
    /// c.b1 = -1.0;
    /// assert!(AdaptiveFilter::new(c).is_err());
    /// ```
    pub fn new(cfg: AdaptiveFilterConfig) -> Result<Self, DspError> {
        if cfg.channels == 0 {
            return Err(DspError::ZeroChannels);
        }
        if !(cfg.sample_rate.is_finite() && cfg.sample_rate > 0.0) {
            return Err(DspError::InvalidParameter {
                name: "sampling rate",
                value: cfg.sample_rate,
                expected: "a positive number of Hz",
            });
        }
        for (name, v) in [("G1", cfg.g1), ("G2", cfg.g2), ("B2", cfg.b2)] {
            if !v.is_finite() {
                return Err(DspError::InvalidParameter {
                    name,
                    value: v,
                    expected: "a finite number",
                });
            }
        }
        if !(cfg.b1.is_finite() && cfg.b1 >= 0.0) {
            return Err(DspError::InvalidParameter {
                name: "B1",
                value: cfg.b1,
                expected: "a cut-off frequency in Hz, 0 or more",
            });
        }
        let dt = 1.0 / cfg.sample_rate;
        let c = cfg.channels;
        Ok(AdaptiveFilter {
            cfg,
            dt,
            a_nominal: smoothing(cfg.b1, dt),
            x_prev: vec![0.0; c],
            d: vec![0.0; c],
            y_prev: vec![0.0; c],
            cutoff: vec![0.0; c],
            t_prev: f64::NAN,
        })
    }

    /// Number of channels.
    pub fn channels(&self) -> usize {
        self.cfg.channels
    }

    /// Changes G1, G2, B1 and B2 while running (MOSAIC 1's control panel
    /// does); the state is kept.
    ///
    /// # Errors
    ///
    /// As [`AdaptiveFilter::new`]; nothing changes then.
    ///
    /// ```
    /// use mosaic_dsp::{AdaptiveFilter, AdaptiveFilterConfig};
    /// let mut f = AdaptiveFilter::new(AdaptiveFilterConfig::new(1, 100.0))?;
    /// f.set_gains(1.0, 2.0, 3.0, 4.0)?;
    /// assert_eq!(f.config().b1, 3.0);
    /// assert!(f.set_gains(1.0, 2.0, -3.0, 4.0).is_err());
    /// # Ok::<(), mosaic_dsp::DspError>(())
    /// ```
    pub fn set_gains(&mut self, g1: f64, g2: f64, b1: f64, b2: f64) -> Result<(), DspError> {
        let cfg = AdaptiveFilterConfig {
            g1,
            g2,
            b1,
            b2,
            ..self.cfg
        };
        let checked = AdaptiveFilter::new(cfg)?;
        self.cfg = cfg;
        self.a_nominal = checked.a_nominal;
        Ok(())
    }

    /// The configuration.
    pub fn config(&self) -> &AdaptiveFilterConfig {
        &self.cfg
    }

    /// The cut-off frequency `F_c` (Hz) of each channel at the last sample
    /// (0 before the first).
    pub fn cutoff(&self) -> &[f64] {
        &self.cutoff
    }

    /// Filters `input` into `output` (`n` events × `channels`) with the
    /// nominal ΔT = 1 / `sample_rate`.
    ///
    /// # Errors
    ///
    /// Lengths that differ or are not whole events.
    pub fn process(&mut self, input: &[f64], output: &mut [f64]) -> Result<(), DspError> {
        check_same_len(input.len(), output.len())?;
        check_multiple("input", input.len(), self.cfg.channels)?;
        let (dt, a) = (self.dt, self.a_nominal);
        let c = self.cfg.channels;
        for (x, y) in input.chunks_exact(c).zip(output.chunks_exact_mut(c)) {
            self.step(x, y, dt, a);
        }
        Ok(())
    }

    /// Like [`AdaptiveFilter::process`], with ΔT taken from the event
    /// timestamps `times` (seconds, one per event): ΔT = t[n] − t[n−1]. The
    /// first event ever, and any event whose ΔT is not a positive finite
    /// number (a repeated or decreasing timestamp), use the nominal ΔT.
    ///
    /// # Errors
    ///
    /// Lengths that differ or are not whole events, or `times` not one per
    /// event.
    ///
    /// ```
    /// use mosaic_dsp::{AdaptiveFilter, AdaptiveFilterConfig};
    ///
    /// // Evenly spaced timestamps at the nominal rate give the same output.
    /// let cfg = AdaptiveFilterConfig::new(1, 4.0);
    /// let (mut a, mut b) = (AdaptiveFilter::new(cfg)?, AdaptiveFilter::new(cfg)?);
    /// let x = [0.1, 0.5, 0.2, 0.4];
    /// let (mut ya, mut yb) = ([0.0; 4], [0.0; 4]);
    /// a.process(&x, &mut ya)?;
    /// b.process_timed(&x, &[10.0, 10.25, 10.5, 10.75], &mut yb)?;
    /// assert_eq!(ya, yb);
    /// # Ok::<(), mosaic_dsp::DspError>(())
    /// ```
    pub fn process_timed(
        &mut self,
        input: &[f64],
        times: &[f64],
        output: &mut [f64],
    ) -> Result<(), DspError> {
        check_same_len(input.len(), output.len())?;
        let n = check_multiple("input", input.len(), self.cfg.channels)?;
        if times.len() != n {
            return Err(DspError::WrongLength {
                name: "times",
                len: times.len(),
                expected: n,
            });
        }
        let c = self.cfg.channels;
        for ((x, y), &t) in input
            .chunks_exact(c)
            .zip(output.chunks_exact_mut(c))
            .zip(times)
        {
            let dt = t - self.t_prev;
            let (dt, a) = if dt.is_finite() && dt > 0.0 {
                (dt, smoothing(self.cfg.b1, dt))
            } else {
                (self.dt, self.a_nominal)
            };
            self.t_prev = t;
            self.step(x, y, dt, a);
        }
        Ok(())
    }

    #[inline(always)]
    fn step(&mut self, x: &[f64], y: &mut [f64], dt: f64, a: f64) {
        let cfg = &self.cfg;
        let (g1, g2, b2) = (cfg.g1, cfg.g2, cfg.b2);
        let abs_first = cfg.order == DerivativeOrder::LowpassOfAbs;
        for (((((&x, y), xp), d), yp), fc) in x
            .iter()
            .zip(y.iter_mut())
            .zip(self.x_prev.iter_mut())
            .zip(self.d.iter_mut())
            .zip(self.y_prev.iter_mut())
            .zip(self.cutoff.iter_mut())
        {
            let dx = (x - *xp) / dt;
            let term = if abs_first {
                *d = a * dx.abs() + (1.0 - a) * *d;
                *d
            } else {
                *d = a * dx + (1.0 - a) * *d;
                d.abs()
            };
            let f = (g2 * x.abs() + g1 * term + b2).exp();
            let alpha = smoothing(f, dt);
            let out = alpha * x + (1.0 - alpha) * *yp;
            *xp = x;
            *yp = out;
            *fc = f;
            *y = out;
        }
    }

    /// Back to the zero initial state.
    pub fn reset(&mut self) {
        self.x_prev.fill(0.0);
        self.d.fill(0.0);
        self.y_prev.fill(0.0);
        self.cutoff.fill(0.0);
        self.t_prev = f64::NAN;
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn overflowing_cutoff_passes_the_input() {
        let mut c = AdaptiveFilterConfig::new(1, 1000.0);
        (c.g1, c.g2, c.b2) = (0.0, 1000.0, 0.0);
        let mut f = AdaptiveFilter::new(c).unwrap();
        let mut y = [0.0; 2];
        f.process(&[5.0, -3.0], &mut y).unwrap();
        assert_eq!(y, [5.0, -3.0]);
        assert_eq!(f.cutoff()[0], f64::INFINITY);
    }

    #[test]
    fn orders_differ_when_the_derivative_changes_sign() {
        let x = [1.0, -1.0, 1.0, -1.0];
        let mut outs = vec![];
        for order in [DerivativeOrder::LowpassOfAbs, DerivativeOrder::AbsOfLowpass] {
            let mut c = AdaptiveFilterConfig::new(1, 10.0);
            c.order = order;
            let mut f = AdaptiveFilter::new(c).unwrap();
            let mut y = [0.0; 4];
            f.process(&x, &mut y).unwrap();
            outs.push(y);
        }
        assert_eq!(outs[0][0], outs[1][0]);
        assert_ne!(outs[0][3], outs[1][3]);
    }

    #[test]
    fn bad_timestamps_fall_back_to_the_nominal_step() {
        let cfg = AdaptiveFilterConfig::new(2, 100.0);
        let x = [0.3, -0.2, 0.5, 0.1, -0.4, 0.9];
        let mut a = AdaptiveFilter::new(cfg).unwrap();
        let mut b = AdaptiveFilter::new(cfg).unwrap();
        let (mut ya, mut yb) = ([0.0; 6], [0.0; 6]);
        a.process(&x, &mut ya).unwrap();
        b.process_timed(&x, &[5.0, 5.0, f64::NAN], &mut yb).unwrap();
        assert_eq!(ya, yb);
        assert!(b.process_timed(&x, &[1.0], &mut yb).is_err());
    }
}
