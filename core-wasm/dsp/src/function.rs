use crate::{check_multiple, check_same_len, DspError};

/// An element-wise operation of the MOSAIC *Function* block (paper Table 1).
///
/// Operands (`Add`, `Multiply`) hold either one value, used for every
/// channel, or one value per channel.
///
/// ```
/// use mosaic_dsp::FunctionOp;
///
/// let gain = FunctionOp::Multiply(vec![2.0]);          // same gain on every channel
/// let offsets = FunctionOp::Add(vec![0.1, 0.2, 0.3]);  // one offset per channel (3 channels)
/// let square = FunctionOp::Power(2.0);
/// let limit = FunctionOp::Clip { min: -1.0, max: 1.0 };
/// assert_eq!(square.name(), "power");
/// # let _ = (gain, offsets, limit);
/// ```
#[derive(Debug, Clone, PartialEq)]
pub enum FunctionOp {
    /// `y = x + operand`.
    Add(Vec<f64>),
    /// `y = x · operand`.
    Multiply(Vec<f64>),
    /// `y = |x|`.
    Abs,
    /// `y = x^p`. Integer exponents with `|p| <= 64` are computed exactly as
    /// repeated multiplication (`x·x` for 2, `1/x` for −1, 1 for 0, like NumPy's
    /// fast paths), `p = 0.5` is `sqrt` (as in NumPy, so `(-inf)^0.5` is NaN);
    /// other exponents use `powf`. As in NumPy, a negative base with a
    /// non-integer exponent gives NaN, and `0^p` with `p < 0` gives infinity.
    Power(f64),
    /// `y = min(max(x, min), max)`; NaN stays NaN (as `numpy.clip`).
    /// Either bound may be infinite for a one-sided clip.
    Clip {
        /// Lower bound.
        min: f64,
        /// Upper bound.
        max: f64,
    },
}

impl FunctionOp {
    /// The operation's name as written in pipeline files:
    /// `add`, `multiply`, `abs`, `power` or `clip`.
    ///
    /// ```
    /// # use mosaic_dsp::FunctionOp;
    /// assert_eq!(FunctionOp::Abs.name(), "abs");
    /// ```
    pub fn name(&self) -> &'static str {
        match self {
            FunctionOp::Add(_) => "add",
            FunctionOp::Multiply(_) => "multiply",
            FunctionOp::Abs => "abs",
            FunctionOp::Power(_) => "power",
            FunctionOp::Clip { .. } => "clip",
        }
    }
}

#[derive(Debug, Clone, Copy, PartialEq)]
enum Kind {
    Add,
    Multiply,
    Abs,
    PowerInt(i32),
    Sqrt,
    PowerFloat(f64),
    Clip(f64, f64),
}

/// The MOSAIC *Function* block: an element-wise operation on events of
/// `channels` values (row-major interleaved buffers, see the crate docs).
///
/// ```
/// use mosaic_dsp::{FunctionKernel, FunctionOp};
///
/// let mut k = FunctionKernel::new(FunctionOp::Multiply(vec![10.0, -1.0]), 2)?;
/// let mut out = [0.0; 4];
/// k.process(&[1.0, 2.0, 3.0, 4.0], &mut out)?;
/// assert_eq!(out, [10.0, -2.0, 30.0, -4.0]);
/// # Ok::<(), mosaic_dsp::DspError>(())
/// ```
#[derive(Debug, Clone)]
pub struct FunctionKernel {
    op: FunctionOp,
    kind: Kind,
    channels: usize,
    /// The constant operand broadcast to `channels` values (empty when unused).
    operand: Vec<f64>,
}

impl FunctionKernel {
    /// Creates a kernel applying `op` to events of `channels` values.
    ///
    /// # Errors
    ///
    /// `channels == 0`; an operand whose length is neither 1 nor `channels`,
    /// or that contains NaN/infinity; a non-finite exponent; clip bounds with
    /// `min > max` or a NaN bound.
    ///
    /// ```
    /// use mosaic_dsp::{FunctionKernel, FunctionOp};
    ///
    /// let err = FunctionKernel::new(FunctionOp::Clip { min: 1.0, max: 0.0 }, 2).unwrap_err();
    /// assert!(err.to_string().contains("expected min <= max"));
    /// let err = FunctionKernel::new(FunctionOp::Add(vec![1.0, 2.0]), 3).unwrap_err();
    /// assert!(err.to_string().contains("expected 1 (the same value for every channel) or 3"));
    /// ```
    pub fn new(op: FunctionOp, channels: usize) -> Result<Self, DspError> {
        if channels == 0 {
            return Err(DspError::ZeroChannels);
        }
        let mut operand = Vec::new();
        let kind = match &op {
            FunctionOp::Add(v) | FunctionOp::Multiply(v) => {
                if v.len() != 1 && v.len() != channels {
                    return Err(DspError::OperandLength {
                        len: v.len(),
                        channels,
                        per_value: None,
                    });
                }
                if let Some(index) = v.iter().position(|x| !x.is_finite()) {
                    return Err(DspError::NonFinite {
                        name: "Operand",
                        index,
                        value: v[index],
                    });
                }
                operand = if v.len() == 1 {
                    vec![v[0]; channels]
                } else {
                    v.clone()
                };
                if matches!(op, FunctionOp::Add(_)) {
                    Kind::Add
                } else {
                    Kind::Multiply
                }
            }
            FunctionOp::Abs => Kind::Abs,
            &FunctionOp::Power(p) => {
                if !p.is_finite() {
                    return Err(DspError::InvalidParameter {
                        name: "Exponent",
                        value: p,
                        expected: "a finite number",
                    });
                }
                if p.fract() == 0.0 && p.abs() <= 64.0 {
                    Kind::PowerInt(p as i32)
                } else if p == 0.5 {
                    Kind::Sqrt
                } else {
                    Kind::PowerFloat(p)
                }
            }
            &FunctionOp::Clip { min, max } => {
                if min.is_nan() || max.is_nan() || min > max {
                    return Err(DspError::ClipRange { min, max });
                }
                Kind::Clip(min, max)
            }
        };
        Ok(FunctionKernel {
            op,
            kind,
            channels,
            operand,
        })
    }

    /// Number of channels.
    ///
    /// ```
    /// # use mosaic_dsp::{FunctionKernel, FunctionOp};
    /// assert_eq!(FunctionKernel::new(FunctionOp::Abs, 5)?.channels(), 5);
    /// # Ok::<(), mosaic_dsp::DspError>(())
    /// ```
    pub fn channels(&self) -> usize {
        self.channels
    }

    /// The operation this kernel applies.
    ///
    /// ```
    /// # use mosaic_dsp::{FunctionKernel, FunctionOp};
    /// let k = FunctionKernel::new(FunctionOp::Power(3.0), 1)?;
    /// assert_eq!(k.op(), &FunctionOp::Power(3.0));
    /// # Ok::<(), mosaic_dsp::DspError>(())
    /// ```
    pub fn op(&self) -> &FunctionOp {
        &self.op
    }

    /// Applies the operation (with its constant operand) to `input`, writing
    /// `output`; both hold `n` events × `channels` values. Never allocates.
    ///
    /// # Errors
    ///
    /// Lengths that differ or are not a multiple of `channels`.
    ///
    /// ```
    /// use mosaic_dsp::{FunctionKernel, FunctionOp};
    ///
    /// let mut k = FunctionKernel::new(FunctionOp::Power(2.0), 1)?;
    /// let mut out = [0.0; 3];
    /// k.process(&[-3.0, 0.5, 2.0], &mut out)?;
    /// assert_eq!(out, [9.0, 0.25, 4.0]);
    /// # Ok::<(), mosaic_dsp::DspError>(())
    /// ```
    pub fn process(&mut self, input: &[f64], output: &mut [f64]) -> Result<(), DspError> {
        check_same_len(input.len(), output.len())?;
        check_multiple("input", input.len(), self.channels)?;
        let c = self.channels;
        match self.kind {
            Kind::Add => {
                for (x, y) in input.chunks_exact(c).zip(output.chunks_exact_mut(c)) {
                    for ((y, &x), &k) in y.iter_mut().zip(x).zip(&self.operand) {
                        *y = x + k;
                    }
                }
            }
            Kind::Multiply => {
                for (x, y) in input.chunks_exact(c).zip(output.chunks_exact_mut(c)) {
                    for ((y, &x), &k) in y.iter_mut().zip(x).zip(&self.operand) {
                        *y = x * k;
                    }
                }
            }
            Kind::Abs => unary(input, output, f64::abs),
            Kind::PowerInt(p) => unary(input, output, |x| powi_exact(x, p)),
            Kind::Sqrt => unary(input, output, f64::sqrt),
            Kind::PowerFloat(p) => unary(input, output, |x| x.powf(p)),
            Kind::Clip(lo, hi) => unary(input, output, |x| x.clamp(lo, hi)),
        }
        Ok(())
    }

    /// Applies the operation in place. Same result as [`FunctionKernel::process`].
    ///
    /// # Errors
    ///
    /// A length that is not a multiple of `channels`.
    ///
    /// ```
    /// use mosaic_dsp::{FunctionKernel, FunctionOp};
    ///
    /// let mut k = FunctionKernel::new(FunctionOp::Clip { min: -1.0, max: 1.0 }, 1)?;
    /// let mut data = [-5.0, 0.5, 5.0];
    /// k.process_in_place(&mut data)?;
    /// assert_eq!(data, [-1.0, 0.5, 1.0]);
    /// # Ok::<(), mosaic_dsp::DspError>(())
    /// ```
    pub fn process_in_place(&mut self, data: &mut [f64]) -> Result<(), DspError> {
        check_multiple("data", data.len(), self.channels)?;
        let c = self.channels;
        match self.kind {
            Kind::Add => {
                for row in data.chunks_exact_mut(c) {
                    for (y, &k) in row.iter_mut().zip(&self.operand) {
                        *y += k;
                    }
                }
            }
            Kind::Multiply => {
                for row in data.chunks_exact_mut(c) {
                    for (y, &k) in row.iter_mut().zip(&self.operand) {
                        *y *= k;
                    }
                }
            }
            Kind::Abs => data.iter_mut().for_each(|y| *y = y.abs()),
            Kind::PowerInt(p) => data.iter_mut().for_each(|y| *y = powi_exact(*y, p)),
            Kind::Sqrt => data.iter_mut().for_each(|y| *y = y.sqrt()),
            Kind::PowerFloat(p) => data.iter_mut().for_each(|y| *y = y.powf(p)),
            Kind::Clip(lo, hi) => data.iter_mut().for_each(|y| *y = y.clamp(lo, hi)),
        }
        Ok(())
    }

    /// Applies `add` or `multiply` with an operand taken from another stream
    /// instead of the constant one. `operand` holds 1 value (used for every
    /// value), `channels` values (the same vector for every event of the
    /// call) or `input.len()` values (one per input value). Never allocates.
    ///
    /// # Errors
    ///
    /// [`DspError::OperandNotUsed`] for `abs`, `power` and `clip`; an operand of
    /// another length; input/output lengths that differ or are not a multiple
    /// of `channels`.
    ///
    /// ```
    /// use mosaic_dsp::{FunctionKernel, FunctionOp};
    ///
    /// let mut k = FunctionKernel::new(FunctionOp::Add(vec![0.0]), 2)?;
    /// let mut out = [0.0; 4];
    /// k.process_with_operand(&[1.0, 1.0, 2.0, 2.0], &[10.0, 20.0], &mut out)?;
    /// assert_eq!(out, [11.0, 21.0, 12.0, 22.0]);
    /// # Ok::<(), mosaic_dsp::DspError>(())
    /// ```
    pub fn process_with_operand(
        &mut self,
        input: &[f64],
        operand: &[f64],
        output: &mut [f64],
    ) -> Result<(), DspError> {
        check_same_len(input.len(), output.len())?;
        check_multiple("input", input.len(), self.channels)?;
        match self.kind {
            Kind::Add => binary(input, operand, output, self.channels, |x, k| x + k),
            Kind::Multiply => binary(input, operand, output, self.channels, |x, k| x * k),
            _ => Err(DspError::OperandNotUsed { op: self.op.name() }),
        }
    }

    /// Does nothing (the kernel has no state); present so that every kernel
    /// has the same interface.
    ///
    /// ```
    /// # use mosaic_dsp::{FunctionKernel, FunctionOp};
    /// let mut k = FunctionKernel::new(FunctionOp::Abs, 1)?;
    /// k.reset();
    /// # Ok::<(), mosaic_dsp::DspError>(())
    /// ```
    pub fn reset(&mut self) {}
}

#[inline(always)]
fn unary(input: &[f64], output: &mut [f64], f: impl Fn(f64) -> f64) {
    for (y, &x) in output.iter_mut().zip(input) {
        *y = f(x);
    }
}

#[inline(always)]
fn binary(
    input: &[f64],
    operand: &[f64],
    output: &mut [f64],
    channels: usize,
    f: impl Fn(f64, f64) -> f64,
) -> Result<(), DspError> {
    if operand.len() == 1 {
        let k = operand[0];
        for (y, &x) in output.iter_mut().zip(input) {
            *y = f(x, k);
        }
    } else if operand.len() == channels {
        for (x, y) in input
            .chunks_exact(channels)
            .zip(output.chunks_exact_mut(channels))
        {
            for ((y, &x), &k) in y.iter_mut().zip(x).zip(operand) {
                *y = f(x, k);
            }
        }
    } else if operand.len() == input.len() {
        for ((y, &x), &k) in output.iter_mut().zip(input).zip(operand) {
            *y = f(x, k);
        }
    } else {
        return Err(DspError::OperandLength {
            len: operand.len(),
            channels,
            per_value: Some(input.len()),
        });
    }
    Ok(())
}

/// `x^n` by binary exponentiation: bit-reproducible on every platform
/// (unlike `f64::powi`, whose precision is unspecified), exact `x·x` for
/// `n = 2` and `1/x` for `n = −1`.
#[inline]
fn powi_exact(x: f64, n: i32) -> f64 {
    let mut e = n.unsigned_abs();
    let mut base = x;
    let mut acc = 1.0;
    while e > 0 {
        if e & 1 == 1 {
            acc *= base;
        }
        e >>= 1;
        if e > 0 {
            base *= base;
        }
    }
    if n < 0 {
        1.0 / acc
    } else {
        acc
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn powi_exact_small_cases() {
        assert_eq!(powi_exact(3.0, 0), 1.0);
        assert_eq!(powi_exact(f64::NAN, 0), 1.0);
        assert_eq!(powi_exact(-3.0, 3), -27.0);
        assert_eq!(powi_exact(2.0, -2), 0.25);
        assert_eq!(powi_exact(0.0, -1), f64::INFINITY);
        assert_eq!(powi_exact(-0.0, -1), f64::NEG_INFINITY);
        let x = 1.1_f64;
        assert_eq!(powi_exact(x, 2), x * x);
    }

    #[test]
    fn operand_not_used() {
        let mut k = FunctionKernel::new(FunctionOp::Abs, 1).unwrap();
        let e = k
            .process_with_operand(&[1.0], &[1.0], &mut [0.0])
            .unwrap_err();
        assert_eq!(e, DspError::OperandNotUsed { op: "abs" });
    }

    #[test]
    fn process_with_operand_lengths() {
        let mut k = FunctionKernel::new(FunctionOp::Multiply(vec![1.0]), 2).unwrap();
        let x = [1.0, 2.0, 3.0, 4.0];
        let mut y = [0.0; 4];
        k.process_with_operand(&x, &[2.0], &mut y).unwrap();
        assert_eq!(y, [2.0, 4.0, 6.0, 8.0]);
        k.process_with_operand(&x, &[1.0, -1.0, 0.5, 0.0], &mut y)
            .unwrap();
        assert_eq!(y, [1.0, -2.0, 1.5, 0.0]);
        assert!(matches!(
            k.process_with_operand(&x, &[1.0, 2.0, 3.0], &mut y),
            Err(DspError::OperandLength {
                len: 3,
                channels: 2,
                per_value: Some(4)
            })
        ));
    }

    #[test]
    fn exponent_classification() {
        for (p, int) in [
            (2.0, true),
            (64.0, true),
            (-64.0, true),
            (65.0, false),
            (0.5, false),
        ] {
            let k = FunctionKernel::new(FunctionOp::Power(p), 1).unwrap();
            assert_eq!(matches!(k.kind, Kind::PowerInt(_)), int, "p = {p}");
        }
        assert!(FunctionKernel::new(FunctionOp::Power(f64::NAN), 1).is_err());
    }
}
