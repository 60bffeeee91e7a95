//! Filter design: second-order Butterworth sections by the bilinear transform
//! with frequency prewarping (the same designs as
//! `scipy.signal.butter(2, cutoff, btype, fs=sample_rate)`).
//!
//! ```
//! use mosaic_dsp::{design, FilterBank};
//!
//! let lp = design::butterworth_lowpass2(2.0, 200.0)?;
//! let mut bank = FilterBank::new(&lp.b, &lp.a, 1)?;
//! // Unit DC gain: a long step settles at 1.
//! let mut data = vec![1.0; 2000];
//! bank.process_in_place(&mut data)?;
//! assert!((data[1999] - 1.0).abs() < 1e-9);
//! # Ok::<(), mosaic_dsp::DspError>(())
//! ```

use crate::DspError;

/// Coefficients of one second-order section, normalised so that `a[0] == 1`:
/// `H(z) = (b0 + b1 z⁻¹ + b2 z⁻²) / (1 + a1 z⁻¹ + a2 z⁻²)`.
///
/// ```
/// let s = mosaic_dsp::design::Biquad { b: [1.0, 0.0, 0.0], a: [1.0, 0.0, 0.0] };
/// assert_eq!(s.b[0], 1.0);
/// ```
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct Biquad {
    /// Numerator `b0, b1, b2`.
    pub b: [f64; 3],
    /// Denominator `1, a1, a2`.
    pub a: [f64; 3],
}

/// Second-order Butterworth low-pass with its −3 dB point at `cutoff_hz`.
///
/// # Errors
///
/// `sample_rate` not finite and > 0, or `cutoff_hz` not in (0, sample_rate/2).
///
/// ```
/// let s = mosaic_dsp::design::butterworth_lowpass2(100.0, 1000.0)?;
/// // DC gain (b0+b1+b2)/(1+a1+a2) is 1.
/// let dc = s.b.iter().sum::<f64>() / s.a.iter().sum::<f64>();
/// assert!((dc - 1.0).abs() < 1e-12);
/// # Ok::<(), mosaic_dsp::DspError>(())
/// ```
pub fn butterworth_lowpass2(cutoff_hz: f64, sample_rate: f64) -> Result<Biquad, DspError> {
    let (k, norm, a) = prewarped(cutoff_hz, sample_rate)?;
    let b0 = k * k * norm;
    Ok(Biquad {
        b: [b0, 2.0 * b0, b0],
        a,
    })
}

/// Second-order Butterworth high-pass with its −3 dB point at `cutoff_hz`.
///
/// # Errors
///
/// `sample_rate` not finite and > 0, or `cutoff_hz` not in (0, sample_rate/2).
///
/// ```
/// let s = mosaic_dsp::design::butterworth_highpass2(20.0, 1000.0)?;
/// // No DC gain: b0 + b1 + b2 = 0.
/// assert!(s.b.iter().sum::<f64>().abs() < 1e-15);
/// # Ok::<(), mosaic_dsp::DspError>(())
/// ```
pub fn butterworth_highpass2(cutoff_hz: f64, sample_rate: f64) -> Result<Biquad, DspError> {
    let (_, norm, a) = prewarped(cutoff_hz, sample_rate)?;
    Ok(Biquad {
        b: [norm, -2.0 * norm, norm],
        a,
    })
}

/// Prewarped analogue frequency `K = tan(π fc / fs)`, the normalisation
/// `1 / (1 + √2 K + K²)` and the shared denominator.
fn prewarped(cutoff_hz: f64, sample_rate: f64) -> Result<(f64, f64, [f64; 3]), DspError> {
    if !(sample_rate.is_finite() && sample_rate > 0.0) {
        return Err(DspError::InvalidParameter {
            name: "sample_rate",
            value: sample_rate,
            expected: "a finite number of hertz > 0",
        });
    }
    if !(cutoff_hz > 0.0 && cutoff_hz < sample_rate / 2.0) {
        return Err(DspError::InvalidParameter {
            name: "cutoff_hz",
            value: cutoff_hz,
            expected: "a frequency above 0 and below half the sample rate",
        });
    }
    let k = (std::f64::consts::PI * cutoff_hz / sample_rate).tan();
    let s2 = std::f64::consts::SQRT_2;
    let norm = 1.0 / (1.0 + s2 * k + k * k);
    let a = [
        1.0,
        2.0 * (k * k - 1.0) * norm,
        (1.0 - s2 * k + k * k) * norm,
    ];
    Ok((k, norm, a))
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn rejects_bad_frequencies() {
        assert!(butterworth_lowpass2(0.0, 1000.0).is_err());
        assert!(butterworth_lowpass2(500.0, 1000.0).is_err());
        assert!(butterworth_highpass2(10.0, f64::NAN).is_err());
        assert!(butterworth_highpass2(f64::NAN, 1000.0).is_err());
    }
}
