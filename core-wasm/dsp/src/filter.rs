use crate::{check_multiple, check_same_len, DspError};

/// The MOSAIC *Filter* block: a bank of identical IIR/FIR filters, one per
/// channel, realised in direct form I (paper eq. 1):
///
/// `y[n] = Σ_{i=0..P} m_i·x[n−i] − Σ_{j=1..Q} d_j·y[n−j]`
///
/// * The coefficients are divided by `Denominator[0]` first, exactly as
///   `scipy.signal.lfilter` does, so `[2, -1]` and `[1, -0.5]` are the same filter.
/// * `Denominator = [1]` (Q = 0) gives an FIR filter.
/// * The initial state is zero (like `lfilter` with `zi=None`).
/// * The input and output histories are circular buffers laid out
///   `[tap][channel]`, so the inner loops run over contiguous channels (the
///   compiler vectorises them, e.g. with WebAssembly `simd128`).
///
/// Buffers are row-major interleaved: event `e`, channel `c` is at index
/// `e * channels + c`.
///
/// ```
/// use mosaic_dsp::FilterBank;
///
/// // y[n] = x[n] + 0.5·y[n−1] on two channels.
/// let mut bank = FilterBank::new(&[1.0], &[1.0, -0.5], 2)?;
/// let input = [1.0, 2.0, 0.0, 0.0, 0.0, 0.0]; // 3 events × 2 channels
/// let mut output = [0.0; 6];
/// bank.process(&input, &mut output)?;
/// assert_eq!(output, [1.0, 2.0, 0.5, 1.0, 0.25, 0.5]);
/// # Ok::<(), mosaic_dsp::DspError>(())
/// ```
#[derive(Debug, Clone)]
pub struct FilterBank {
    channels: usize,
    /// Normalised numerator m_0 … m_P.
    num: Vec<f64>,
    /// Normalised denominator 1, d_1 … d_Q.
    den: Vec<f64>,
    /// Last P+1 inputs, `(P+1)` rows × `channels`, circular.
    x_hist: Vec<f64>,
    /// Last Q outputs, `Q` rows × `channels`, circular.
    y_hist: Vec<f64>,
    /// Row of `x_hist` holding the newest input.
    x_head: usize,
    /// Row of `y_hist` holding the newest output.
    y_head: usize,
    /// P = Q = 2: use the fused single-pass biquad loop (same arithmetic,
    /// same order of operations, so bit-identical to the general loop).
    biquad: bool,
}

impl FilterBank {
    /// Creates a filter bank for `channels` channels.
    ///
    /// `numerator` is `[m_0, …, m_P]`, `denominator` is `[d_0, d_1, …, d_Q]`;
    /// both are divided by `d_0`.
    ///
    /// # Errors
    ///
    /// An empty list, `d_0 == 0`, a NaN or infinite coefficient (also after
    /// the division by `d_0`), or `channels == 0`.
    ///
    /// ```
    /// use mosaic_dsp::FilterBank;
    ///
    /// let err = FilterBank::new(&[1.0, f64::NAN], &[1.0], 4).unwrap_err();
    /// assert_eq!(
    ///     err.to_string(),
    ///     "Numerator[1] is NaN; every value of Numerator must be a finite number"
    /// );
    /// assert!(FilterBank::new(&[], &[1.0], 4).is_err());
    /// assert!(FilterBank::new(&[1.0], &[1.0], 0).is_err());
    /// ```
    pub fn new(numerator: &[f64], denominator: &[f64], channels: usize) -> Result<Self, DspError> {
        if numerator.is_empty() {
            return Err(DspError::EmptyNumerator);
        }
        if denominator.is_empty() {
            return Err(DspError::EmptyDenominator);
        }
        check_finite("Numerator", numerator)?;
        check_finite("Denominator", denominator)?;
        let d0 = denominator[0];
        if d0 == 0.0 {
            return Err(DspError::ZeroLeadingDenominator);
        }
        if channels == 0 {
            return Err(DspError::ZeroChannels);
        }
        let num = normalise("Numerator", numerator, d0)?;
        let mut den = normalise("Denominator", denominator, d0)?;
        den[0] = 1.0;
        let taps_x = num.len();
        let taps_y = den.len() - 1;
        Ok(FilterBank {
            channels,
            num,
            den,
            x_hist: vec![0.0; taps_x * channels],
            y_hist: vec![0.0; taps_y * channels],
            x_head: 0,
            y_head: 0,
            biquad: taps_x == 3 && taps_y == 2,
        })
    }

    /// Number of channels.
    ///
    /// ```
    /// # use mosaic_dsp::FilterBank;
    /// assert_eq!(FilterBank::new(&[1.0], &[1.0], 3)?.channels(), 3);
    /// # Ok::<(), mosaic_dsp::DspError>(())
    /// ```
    pub fn channels(&self) -> usize {
        self.channels
    }

    /// The numerator after division by `Denominator[0]`.
    ///
    /// ```
    /// # use mosaic_dsp::FilterBank;
    /// let bank = FilterBank::new(&[1.0, 3.0], &[2.0, -1.0], 1)?;
    /// assert_eq!(bank.numerator(), &[0.5, 1.5]);
    /// # Ok::<(), mosaic_dsp::DspError>(())
    /// ```
    pub fn numerator(&self) -> &[f64] {
        &self.num
    }

    /// The denominator after division by `Denominator[0]` (so it starts with 1).
    ///
    /// ```
    /// # use mosaic_dsp::FilterBank;
    /// let bank = FilterBank::new(&[1.0, 3.0], &[2.0, -1.0], 1)?;
    /// assert_eq!(bank.denominator(), &[1.0, -0.5]);
    /// # Ok::<(), mosaic_dsp::DspError>(())
    /// ```
    pub fn denominator(&self) -> &[f64] {
        &self.den
    }

    /// `true` when the filter has no feedback (Q = 0).
    ///
    /// ```
    /// # use mosaic_dsp::FilterBank;
    /// assert!(FilterBank::new(&[0.5, 0.5], &[1.0], 1)?.is_fir());
    /// assert!(!FilterBank::new(&[1.0], &[1.0, -0.9], 1)?.is_fir());
    /// # Ok::<(), mosaic_dsp::DspError>(())
    /// ```
    pub fn is_fir(&self) -> bool {
        self.den.len() == 1
    }

    /// Filters `input` into `output`, both `n` events × `channels` values,
    /// row-major interleaved. Never allocates.
    ///
    /// # Errors
    ///
    /// [`DspError::NotWholeEvents`] when the length is not a multiple of
    /// `channels`, [`DspError::LengthMismatch`] when the lengths differ. Nothing
    /// is processed and the state is unchanged in that case.
    ///
    /// ```
    /// use mosaic_dsp::FilterBank;
    ///
    /// let mut ma = FilterBank::new(&[0.5, 0.5], &[1.0], 1)?; // 2-tap moving average
    /// let mut out = [0.0; 3];
    /// ma.process(&[2.0, 4.0, 6.0], &mut out)?;
    /// assert_eq!(out, [1.0, 3.0, 5.0]);
    /// assert!(ma.process(&[1.0], &mut [0.0; 2]).is_err());
    /// # Ok::<(), mosaic_dsp::DspError>(())
    /// ```
    pub fn process(&mut self, input: &[f64], output: &mut [f64]) -> Result<(), DspError> {
        check_same_len(input.len(), output.len())?;
        check_multiple("input", input.len(), self.channels)?;
        let c = self.channels;
        if self.biquad {
            for (x, y) in input.chunks_exact(c).zip(output.chunks_exact_mut(c)) {
                self.biquad_step(Some(x), y);
            }
        } else {
            for (x, y) in input.chunks_exact(c).zip(output.chunks_exact_mut(c)) {
                self.push_input(x);
                self.step(y);
            }
        }
        Ok(())
    }

    /// Filters `data` in place (`n` events × `channels` values). Gives the
    /// same result as [`FilterBank::process`].
    ///
    /// # Errors
    ///
    /// [`DspError::NotWholeEvents`] when the length is not a multiple of `channels`.
    ///
    /// ```
    /// use mosaic_dsp::FilterBank;
    ///
    /// let mut bank = FilterBank::new(&[1.0], &[1.0, -0.5], 1)?;
    /// let mut data = [1.0, 0.0, 0.0];
    /// bank.process_in_place(&mut data)?;
    /// assert_eq!(data, [1.0, 0.5, 0.25]);
    /// # Ok::<(), mosaic_dsp::DspError>(())
    /// ```
    pub fn process_in_place(&mut self, data: &mut [f64]) -> Result<(), DspError> {
        check_multiple("data", data.len(), self.channels)?;
        let c = self.channels;
        if self.biquad {
            for row in data.chunks_exact_mut(c) {
                self.biquad_step(None, row);
            }
        } else {
            for row in data.chunks_exact_mut(c) {
                self.push_input(row);
                self.step(row);
            }
        }
        Ok(())
    }

    /// Clears the history: the next output is as if the bank was just created.
    ///
    /// ```
    /// use mosaic_dsp::FilterBank;
    ///
    /// let mut bank = FilterBank::new(&[1.0], &[1.0, -0.5], 1)?;
    /// let mut a = [1.0, 0.0];
    /// bank.process_in_place(&mut a)?;
    /// bank.reset();
    /// let mut b = [1.0, 0.0];
    /// bank.process_in_place(&mut b)?;
    /// assert_eq!(a, b);
    /// # Ok::<(), mosaic_dsp::DspError>(())
    /// ```
    pub fn reset(&mut self) {
        self.x_hist.fill(0.0);
        self.y_hist.fill(0.0);
        self.x_head = 0;
        self.y_head = 0;
    }

    /// One event of a biquad (P = Q = 2) in a single pass over the channels:
    /// reads x[n−1], x[n−2], y[n−1], y[n−2], writes x[n] over the row of
    /// x[n−3] and y[n] over the row of y[n−2]. The rows are split into
    /// disjoint slices so that the compiler can vectorise across channels.
    /// `input == None` means in place: the input is read from `out`.
    #[inline(always)]
    fn biquad_step(&mut self, input: Option<&[f64]>, out: &mut [f64]) {
        let c = self.channels;
        let (m0, m1, m2) = (self.num[0], self.num[1], self.num[2]);
        let (d1, d2) = (self.den[1], self.den[2]);
        let (r0, rest) = self.x_hist.split_at_mut(c);
        let (r1, r2) = rest.split_at_mut(c);
        // (row receiving x[n], row of x[n−1], row of x[n−2]) for each head.
        let (xw, x1, x2, x_head) = match self.x_head {
            0 => (r1, &*r0, &*r2, 1),
            1 => (r2, &*r1, &*r0, 2),
            _ => (r0, &*r2, &*r1, 0),
        };
        let (s0, s1) = self.y_hist.split_at_mut(c);
        // (row of y[n−1], row of y[n−2] that receives y[n]).
        let (y1, yw, y_head) = match self.y_head {
            0 => (&*s0, s1, 1),
            _ => (&*s1, s0, 0),
        };
        match input {
            Some(x) => {
                for (((((o, &x0), xw), (&x1, &x2)), &y1), yw) in out
                    .iter_mut()
                    .zip(x)
                    .zip(xw.iter_mut())
                    .zip(x1.iter().zip(x2))
                    .zip(y1)
                    .zip(yw.iter_mut())
                {
                    let y = m0 * x0 + m1 * x1 + m2 * x2 - d1 * y1 - d2 * *yw;
                    *xw = x0;
                    *yw = y;
                    *o = y;
                }
            }
            None => {
                for ((((o, xw), (&x1, &x2)), &y1), yw) in out
                    .iter_mut()
                    .zip(xw.iter_mut())
                    .zip(x1.iter().zip(x2))
                    .zip(y1)
                    .zip(yw.iter_mut())
                {
                    let x0 = *o;
                    let y = m0 * x0 + m1 * x1 + m2 * x2 - d1 * y1 - d2 * *yw;
                    *xw = x0;
                    *yw = y;
                    *o = y;
                }
            }
        }
        self.x_head = x_head;
        self.y_head = y_head;
    }

    /// Stores one event of input as the newest row of the input history.
    #[inline(always)]
    fn push_input(&mut self, x: &[f64]) {
        let c = self.channels;
        let rows = self.num.len();
        self.x_head = if self.x_head + 1 == rows {
            0
        } else {
            self.x_head + 1
        };
        let h = self.x_head * c;
        self.x_hist[h..h + c].copy_from_slice(x);
    }

    /// Computes one event of output from the histories (the newest input is
    /// already stored) and stores it as the newest row of the output history.
    #[inline(always)]
    fn step(&mut self, out: &mut [f64]) {
        let c = self.channels;
        let rows_x = self.num.len();
        // i = 0: newest input.
        {
            let r = self.x_head * c;
            let m0 = self.num[0];
            for (o, &x) in out.iter_mut().zip(&self.x_hist[r..r + c]) {
                *o = m0 * x;
            }
        }
        // i = 1..=P: x[n-i] lives i rows before the head (circularly).
        for (i, &m) in self.num.iter().enumerate().skip(1) {
            let row = if self.x_head >= i {
                self.x_head - i
            } else {
                self.x_head + rows_x - i
            };
            let r = row * c;
            for (o, &x) in out.iter_mut().zip(&self.x_hist[r..r + c]) {
                *o += m * x;
            }
        }
        let rows_y = self.den.len() - 1;
        if rows_y == 0 {
            return;
        }
        // j = 1..=Q: y[n-j] lives j-1 rows before the head.
        for (j, &d) in self.den.iter().enumerate().skip(1) {
            let back = j - 1;
            let row = if self.y_head >= back {
                self.y_head - back
            } else {
                self.y_head + rows_y - back
            };
            let r = row * c;
            for (o, &y) in out.iter_mut().zip(&self.y_hist[r..r + c]) {
                *o -= d * y;
            }
        }
        self.y_head = if self.y_head + 1 == rows_y {
            0
        } else {
            self.y_head + 1
        };
        let h = self.y_head * c;
        self.y_hist[h..h + c].copy_from_slice(out);
    }
}

fn check_finite(name: &'static str, values: &[f64]) -> Result<(), DspError> {
    match values.iter().position(|v| !v.is_finite()) {
        Some(index) => Err(DspError::NonFinite {
            name,
            index,
            value: values[index],
        }),
        None => Ok(()),
    }
}

fn normalise(name: &'static str, values: &[f64], d0: f64) -> Result<Vec<f64>, DspError> {
    let out: Vec<f64> = values.iter().map(|v| v / d0).collect();
    match out.iter().position(|v| !v.is_finite()) {
        Some(index) => Err(DspError::NormalisationOverflow {
            name,
            index,
            den0: d0,
        }),
        None => Ok(out),
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn normalisation_overflow_is_reported() {
        let err = FilterBank::new(&[1e300], &[1e-300], 1).unwrap_err();
        assert!(matches!(
            err,
            DspError::NormalisationOverflow {
                name: "Numerator",
                index: 0,
                ..
            }
        ));
    }

    #[test]
    fn num_longer_and_shorter_than_den() {
        // y[n] = x[n] + x[n-1] + x[n-2] - 0.5 y[n-1]
        let mut f = FilterBank::new(&[1.0, 1.0, 1.0], &[1.0, 0.5], 1).unwrap();
        let mut d = [1.0, 0.0, 0.0, 0.0];
        f.process_in_place(&mut d).unwrap();
        assert_eq!(d, [1.0, 0.5, 0.75, -0.375]);
        // y[n] = x[n] - 0.25 y[n-2]
        let mut f = FilterBank::new(&[1.0], &[1.0, 0.0, 0.25], 1).unwrap();
        let mut d = [1.0, 0.0, 0.0, 0.0, 0.0];
        f.process_in_place(&mut d).unwrap();
        assert_eq!(d, [1.0, 0.0, -0.25, 0.0, 0.0625]);
    }

    #[test]
    fn fused_biquad_is_bit_identical_to_the_general_loop() {
        let (b, a) = ([0.2, -0.3, 0.15], [1.0, -1.2, 0.5]);
        let c = 5;
        let x: Vec<f64> = (0..c * 300)
            .map(|i| ((i * 37 % 101) as f64 - 50.0) / 7.0)
            .collect();
        let mut fast = FilterBank::new(&b, &a, c).unwrap();
        let mut general = fast.clone();
        general.biquad = false;
        assert!(fast.biquad);
        let (mut y1, mut y2) = (vec![0.0; x.len()], vec![0.0; x.len()]);
        fast.process(&x, &mut y1).unwrap();
        general.process(&x, &mut y2).unwrap();
        for (u, v) in y1.iter().zip(&y2) {
            assert_eq!(u.to_bits(), v.to_bits());
        }
        let mut z = x.clone();
        fast.reset();
        fast.process_in_place(&mut z).unwrap();
        assert_eq!(z, y1);
    }

    #[test]
    fn bad_lengths_leave_state_untouched() {
        let mut f = FilterBank::new(&[1.0], &[1.0, -0.5], 2).unwrap();
        assert!(matches!(
            f.process(&[1.0, 2.0, 3.0], &mut [0.0; 3]),
            Err(DspError::NotWholeEvents { .. })
        ));
        assert!(matches!(
            f.process_in_place(&mut [1.0]),
            Err(DspError::NotWholeEvents { .. })
        ));
        let mut out = [0.0; 2];
        f.process(&[1.0, 1.0], &mut out).unwrap();
        assert_eq!(out, [1.0, 1.0]);
    }
}
