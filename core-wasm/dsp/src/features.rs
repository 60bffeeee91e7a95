use crate::{check_multiple, DspError};

/// A time-domain EMG feature of one channel over a window of `N` samples
/// `x_1 … x_N` (Hudgins et al. 1993; Phinyomark, Phukpattaranont &
/// Limsakul 2012, *Expert Systems with Applications* 39(8); the names are
/// LibEMG's abbreviations).
///
/// | feature | definition |
/// |---|---|
/// | `Mav`   | MAV = 1/N Σ \|x_i\| |
/// | `Rms`   | RMS = √(1/N Σ x_i²) |
/// | `Wl`    | WL = Σ_{i=1..N−1} \|x_{i+1} − x_i\| |
/// | `Zc`    | ZC = #{i : x_i·x_{i+1} < 0 and \|x_i − x_{i+1}\| ≥ T} |
/// | `Ssc`   | SSC = #{i = 2..N−1 : (x_i − x_{i−1})(x_i − x_{i+1}) ≥ T} |
/// | `SscMosaic` | #{i = 2..N−1 : (x_i − x_{i−1})(x_{i+1} − x_i) < 0, both \|differences\| ≥ T} (MOSAIC 1's rule) |
/// | `Var`   | VAR = 1/(N−1) Σ x_i² (no mean removal, as in the EMG literature) |
/// | `Iav`   | IAV = Σ \|x_i\| |
/// | `Dasdv` | DASDV = √(1/(N−1) Σ_{i=1..N−1} (x_{i+1} − x_i)²) |
/// | `Wamp`  | WAMP = #{i : \|x_i − x_{i+1}\| ≥ T} |
///
/// `T` is the feature's threshold ([`FeatureSpec::threshold`]); counts are
/// returned as `f64`. NaN: sums and the features built on them become NaN;
/// a comparison with NaN is false, so a NaN sample never adds to a count.
///
/// ```
/// use mosaic_dsp::Feature;
///
/// assert_eq!(Feature::parse("wamp"), Some(Feature::Wamp));
/// assert_eq!(Feature::Wamp.name(), "WAMP");
/// assert!(Feature::Zc.uses_threshold() && !Feature::Mav.uses_threshold());
/// ```
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum Feature {
    /// Mean absolute value.
    Mav,
    /// Root mean square.
    Rms,
    /// Waveform length.
    Wl,
    /// Zero crossings.
    Zc,
    /// Slope sign changes (Phinyomark 2012 / LibEMG product rule).
    Ssc,
    /// Slope sign changes with MOSAIC 1's rule (strict sign change of the
    /// slope and both differences at least `T` in magnitude).
    SscMosaic,
    /// Variance as used for EMG: 1/(N−1) Σ x².
    Var,
    /// Integrated absolute value.
    Iav,
    /// Difference absolute standard deviation value.
    Dasdv,
    /// Willison amplitude.
    Wamp,
}

impl Feature {
    /// Every feature, in the order of the table above.
    pub const ALL: [Feature; 10] = [
        Feature::Mav,
        Feature::Rms,
        Feature::Wl,
        Feature::Zc,
        Feature::Ssc,
        Feature::SscMosaic,
        Feature::Var,
        Feature::Iav,
        Feature::Dasdv,
        Feature::Wamp,
    ];

    /// The feature's abbreviation: `MAV`, `RMS`, `WL`, `ZC`, `SSC`,
    /// `SSC_MOSAIC`, `VAR`, `IAV`, `DASDV`, `WAMP`.
    pub fn name(self) -> &'static str {
        match self {
            Feature::Mav => "MAV",
            Feature::Rms => "RMS",
            Feature::Wl => "WL",
            Feature::Zc => "ZC",
            Feature::Ssc => "SSC",
            Feature::SscMosaic => "SSC_MOSAIC",
            Feature::Var => "VAR",
            Feature::Iav => "IAV",
            Feature::Dasdv => "DASDV",
            Feature::Wamp => "WAMP",
        }
    }

    /// The feature named `name` (case-insensitive abbreviation), if any.
    pub fn parse(name: &str) -> Option<Feature> {
        Feature::ALL
            .into_iter()
            .find(|f| f.name().eq_ignore_ascii_case(name))
    }

    /// `true` for the counts that take a threshold (ZC, SSC, WAMP).
    pub fn uses_threshold(self) -> bool {
        matches!(
            self,
            Feature::Zc | Feature::Ssc | Feature::SscMosaic | Feature::Wamp
        )
    }
}

/// One feature to compute, with its threshold (used by ZC, SSC and WAMP,
/// ignored by the others).
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct FeatureSpec {
    /// The feature.
    pub feature: Feature,
    /// Its threshold `T`.
    pub threshold: f64,
}

impl FeatureSpec {
    /// A feature with threshold 0.
    pub fn new(feature: Feature) -> Self {
        FeatureSpec {
            feature,
            threshold: 0.0,
        }
    }

    /// A feature with threshold `threshold`.
    pub fn with_threshold(feature: Feature, threshold: f64) -> Self {
        FeatureSpec { feature, threshold }
    }
}

/// Computes a list of features over windows of `rows` samples × `channels`
/// channels, stored row-major (row = sample, oldest first; the layout of a
/// SlidingWindow event).
///
/// For every window the output is `features.len() × channels` values,
/// feature-major: all channels of the first feature, then all channels of
/// the second, … (LibEMG's concatenation order). The window is read in
/// strips of 8 adjacent channels (a cache line per row) whose accumulators
/// stay in registers; every channel sums its samples in order. Nothing is
/// allocated in `process`. With SIMD128 (the wasm build) a strip is four
/// vectors of two channels, and Hudgins' set (exactly MAV, WL, ZC and SSC
/// with the product rule, in any order: FeatureSet's default) is computed in
/// one pass over pairs of channels; both give the same bits as the scalar
/// code ([`crate::set_simd_enabled`]).
///
/// ```
/// use mosaic_dsp::{Feature, FeatureKernel, FeatureSpec};
///
/// // MAV and WL of a 4-sample window of 2 channels.
/// let specs = [FeatureSpec::new(Feature::Mav), FeatureSpec::new(Feature::Wl)];
/// let mut k = FeatureKernel::new(&specs, 4, 2)?;
/// let window = [1.0, 0.0, -1.0, 0.0, 1.0, 0.0, -1.0, 2.0];
/// let mut out = [0.0; 4];
/// k.process(&window, &mut out)?;
/// assert_eq!(out, [1.0, 0.5, 6.0, 2.0]); // [MAV ch0, MAV ch1, WL ch0, WL ch1]
/// # Ok::<(), mosaic_dsp::DspError>(())
/// ```
#[derive(Debug, Clone)]
pub struct FeatureKernel {
    rows: usize,
    channels: usize,
    specs: Vec<FeatureSpec>,
    /// One accumulator row of `channels` values per spec.
    acc: Vec<f64>,
}

impl FeatureKernel {
    /// Creates a kernel for windows of `rows` × `channels`.
    ///
    /// # Errors
    ///
    /// No feature, `rows < 2` (VAR and DASDV divide by N − 1),
    /// `channels == 0`, or a NaN threshold.
    ///
    /// ```
    /// use mosaic_dsp::{Feature, FeatureKernel, FeatureSpec};
    ///
    /// assert!(FeatureKernel::new(&[], 10, 1).is_err());
    /// assert!(FeatureKernel::new(&[FeatureSpec::new(Feature::Var)], 1, 1).is_err());
    /// let nan = FeatureSpec::with_threshold(Feature::Zc, f64::NAN);
    /// assert!(FeatureKernel::new(&[nan], 10, 1).is_err());
    /// ```
    pub fn new(specs: &[FeatureSpec], rows: usize, channels: usize) -> Result<Self, DspError> {
        if specs.is_empty() {
            return Err(DspError::WrongLength {
                name: "Features",
                len: 0,
                expected: 1,
            });
        }
        if rows < 2 {
            return Err(DspError::InvalidParameter {
                name: "window length",
                value: rows as f64,
                expected: "at least 2 samples",
            });
        }
        if channels == 0 {
            return Err(DspError::ZeroChannels);
        }
        if let Some(s) = specs.iter().find(|s| s.threshold.is_nan()) {
            return Err(DspError::InvalidParameter {
                name: "Threshold",
                value: s.threshold,
                expected: "a number (not NaN)",
            });
        }
        Ok(FeatureKernel {
            rows,
            channels,
            specs: specs.to_vec(),
            acc: vec![0.0; specs.len() * channels],
        })
    }

    /// Samples per window.
    pub fn rows(&self) -> usize {
        self.rows
    }

    /// Number of channels.
    pub fn channels(&self) -> usize {
        self.channels
    }

    /// The features computed, in output order.
    pub fn specs(&self) -> &[FeatureSpec] {
        &self.specs
    }

    /// Replaces the thresholds, one per feature in [`FeatureKernel::specs`]
    /// order (ignored by the features that take none).
    ///
    /// # Errors
    ///
    /// Not one value per feature, or a NaN; nothing changes then.
    ///
    /// ```
    /// use mosaic_dsp::{Feature, FeatureKernel, FeatureSpec};
    /// let mut k = FeatureKernel::new(&[FeatureSpec::new(Feature::Wamp)], 3, 1)?;
    /// k.set_thresholds(&[1.5])?;
    /// let mut o = [0.0];
    /// k.process(&[0.0, 1.0, 3.0], &mut o)?;
    /// assert_eq!(o, [1.0]);
    /// assert!(k.set_thresholds(&[1.0, 2.0]).is_err());
    /// # Ok::<(), mosaic_dsp::DspError>(())
    /// ```
    pub fn set_thresholds(&mut self, thresholds: &[f64]) -> Result<(), DspError> {
        if thresholds.len() != self.specs.len() {
            return Err(DspError::WrongLength {
                name: "thresholds",
                len: thresholds.len(),
                expected: self.specs.len(),
            });
        }
        if let Some(&t) = thresholds.iter().find(|t| t.is_nan()) {
            return Err(DspError::InvalidParameter {
                name: "Threshold",
                value: t,
                expected: "a number (not NaN)",
            });
        }
        for (s, &t) in self.specs.iter_mut().zip(thresholds) {
            s.threshold = t;
        }
        Ok(())
    }

    /// Values per window in the output: `specs().len() × channels`.
    pub fn output_width(&self) -> usize {
        self.specs.len() * self.channels
    }

    /// Computes the features of `n` windows: `windows` holds `n × rows ×
    /// channels` values, `output` `n × output_width()`.
    ///
    /// # Errors
    ///
    /// The lengths are not whole numbers of windows, or do not agree. Nothing
    /// is written in that case.
    pub fn process(&mut self, windows: &[f64], output: &mut [f64]) -> Result<(), DspError> {
        let size = self.rows * self.channels;
        let n = check_multiple("input", windows.len(), size)?;
        let width = self.output_width();
        if output.len() != n * width {
            return Err(DspError::OutputLength {
                len: output.len(),
                expected: n * width,
            });
        }
        for (w, o) in windows
            .chunks_exact(size)
            .zip(output.chunks_exact_mut(width))
        {
            self.window(w, o);
        }
        Ok(())
    }

    /// The features of one window (`rows × channels` values) into `out`
    /// (`output_width()` values). Lengths are the caller's responsibility
    /// (checked by `process`; [`crate::SlidingWindow`] users pass slices of
    /// the right size).
    pub(crate) fn window(&mut self, w: &[f64], out: &mut [f64]) {
        let c = self.channels;
        let rows = self.rows;
        // Strips of BLOCK adjacent channels (one cache line per row): a strip
        // is read from memory once and stays in L1 while every feature runs
        // over it with its accumulators in registers; every channel still sums
        // its samples in order (same bits as a plain loop over the channel).
        // With SIMD128 a strip is BLOCK / 2 vectors of two channels (or one
        // vector for the last pairs), with the same operations per channel.
        let acc = &mut self.acc;
        let simd = crate::simd::simd_enabled();
        let mut c0 = 0;
        #[cfg(all(target_arch = "wasm32", target_feature = "simd128"))]
        if let (true, Some(at)) = (simd, hudgins(&self.specs)) {
            // Hudgins' set in one pass per strip (the usual request).
            let (tz, ts) = (self.specs[at[2]].threshold, self.specs[at[3]].threshold);
            while c0 + FUSED <= c {
                let mut out = [[0.0; FUSED]; 4];
                strip_hudgins::<{ FUSED / 2 }>(w, c, c0, rows, tz, ts, &mut out);
                for (&i, o) in at.iter().zip(&out) {
                    acc[i * c + c0..][..FUSED].copy_from_slice(o);
                }
                c0 += FUSED;
            }
        }
        while c0 < c {
            let left = c - c0;
            let width = if left >= BLOCK {
                BLOCK
            } else if simd && left >= 2 {
                2
            } else {
                1
            };
            for (spec, a) in self.specs.iter().zip(acc.chunks_exact_mut(c)) {
                let (f, t) = (spec.feature, spec.threshold);
                let a = &mut a[c0..c0 + width];
                #[cfg(all(target_arch = "wasm32", target_feature = "simd128"))]
                if simd {
                    if width == BLOCK {
                        strip_simd::<{ BLOCK / 2 }>(w, c, c0, rows, f, t, a);
                        continue;
                    }
                    if width == 2 {
                        strip_simd::<1>(w, c, c0, rows, f, t, a);
                        continue;
                    }
                }
                if width == BLOCK {
                    a.copy_from_slice(&strip::<BLOCK>(w, c, c0, rows, f, t));
                } else {
                    a[0] = strip::<1>(w, c, c0, rows, f, t)[0];
                }
            }
            c0 += width;
        }
        let n = rows as f64;
        let n1 = (rows - 1) as f64;
        for ((spec, a), o) in self
            .specs
            .iter()
            .zip(acc.chunks_exact(c))
            .zip(out.chunks_exact_mut(c))
        {
            match spec.feature {
                Feature::Mav => {
                    for (o, &s) in o.iter_mut().zip(a) {
                        *o = s / n;
                    }
                }
                Feature::Rms => {
                    for (o, &s) in o.iter_mut().zip(a) {
                        *o = (s / n).sqrt();
                    }
                }
                Feature::Var => {
                    for (o, &s) in o.iter_mut().zip(a) {
                        *o = s / n1;
                    }
                }
                Feature::Dasdv => {
                    for (o, &s) in o.iter_mut().zip(a) {
                        *o = (s / n1).sqrt();
                    }
                }
                _ => o.copy_from_slice(a),
            }
        }
    }

    /// Does nothing (a window's features depend on that window only);
    /// present for a uniform kernel interface.
    pub fn reset(&mut self) {}
}

/// Channels per strip in [`FeatureKernel`] (a cache line of f64).
const BLOCK: usize = 8;

/// The raw accumulation (sum or count) of `feature` for channels
/// `c0 .. c0 + B` of a row-major window of `rows` rows × `c` channels.
#[inline(always)]
fn strip<const B: usize>(
    w: &[f64],
    c: usize,
    c0: usize,
    rows: usize,
    feature: Feature,
    t: f64,
) -> [f64; B] {
    let at = |r: usize| -> &[f64; B] {
        let i = r * c + c0;
        w[i..i + B].try_into().expect("a strip of B channels")
    };
    let count = |hit: bool| if hit { 1.0 } else { 0.0 };
    let mut acc = [0.0; B];
    match feature {
        Feature::Mav | Feature::Iav => {
            for r in 0..rows {
                let x = at(r);
                for k in 0..B {
                    acc[k] += x[k].abs();
                }
            }
        }
        Feature::Rms | Feature::Var => {
            for r in 0..rows {
                let x = at(r);
                for k in 0..B {
                    acc[k] += x[k] * x[k];
                }
            }
        }
        Feature::Wl => {
            for r in 1..rows {
                let (p, x) = (at(r - 1), at(r));
                for k in 0..B {
                    acc[k] += (x[k] - p[k]).abs();
                }
            }
        }
        Feature::Dasdv => {
            for r in 1..rows {
                let (p, x) = (at(r - 1), at(r));
                for k in 0..B {
                    let d = x[k] - p[k];
                    acc[k] += d * d;
                }
            }
        }
        Feature::Zc => {
            for r in 1..rows {
                let (p, x) = (at(r - 1), at(r));
                for k in 0..B {
                    acc[k] += count((p[k] * x[k] < 0.0) & ((p[k] - x[k]).abs() >= t));
                }
            }
        }
        Feature::Wamp => {
            for r in 1..rows {
                let (p, x) = (at(r - 1), at(r));
                for k in 0..B {
                    acc[k] += count((p[k] - x[k]).abs() >= t);
                }
            }
        }
        Feature::Ssc => {
            // Middle sample m = x_i, neighbours b = x_{i−1} and x = x_{i+1}.
            for r in 2..rows {
                let (b, m, x) = (at(r - 2), at(r - 1), at(r));
                for k in 0..B {
                    acc[k] += count((m[k] - b[k]) * (m[k] - x[k]) >= t);
                }
            }
        }
        Feature::SscMosaic => {
            for r in 2..rows {
                let (b, m, x) = (at(r - 2), at(r - 1), at(r));
                for k in 0..B {
                    let d1 = m[k] - b[k];
                    let d2 = x[k] - m[k];
                    acc[k] += count((d1 * d2 < 0.0) & (d1.abs() >= t) & (d2.abs() >= t));
                }
            }
        }
    }
    acc
}

/// Channels per strip of [`strip_hudgins`].
#[cfg(all(target_arch = "wasm32", target_feature = "simd128"))]
const FUSED: usize = 2;

/// Where MAV, WL, ZC and SSC (product rule) are in `specs` when `specs` is
/// exactly those four, in any order.
#[cfg(all(target_arch = "wasm32", target_feature = "simd128"))]
fn hudgins(specs: &[FeatureSpec]) -> Option<[usize; 4]> {
    if specs.len() != 4 {
        return None;
    }
    let find = |f: Feature| specs.iter().position(|s| s.feature == f);
    let at = [
        find(Feature::Mav)?,
        find(Feature::Wl)?,
        find(Feature::Zc)?,
        find(Feature::Ssc)?,
    ];
    Some(at)
}

/// MAV (raw sum), WL, ZC and SSC of channels `c0 .. c0 + 2·V` in one pass
/// over the rows (SIMD128), into `out` in that order. Each feature sums or
/// counts in sample order with the same values as [`strip`]: with
/// `d_r = x_r − x_{r−1}`, `|x_{r−1} − x_r| = |d_r|` and SSC's
/// `(x_{r−1} − x_{r−2})·(x_{r−1} − x_r) = −(d_{r−1}·d_r)` exactly (IEEE
/// subtraction and multiplication are symmetric in sign), so
/// `≥ T` ⇔ `d_{r−1}·d_r ≤ −T`: bit-identical results.
#[cfg(all(target_arch = "wasm32", target_feature = "simd128"))]
#[inline(always)]
fn strip_hudgins<const V: usize>(
    w: &[f64],
    c: usize,
    c0: usize,
    rows: usize,
    tz: f64,
    ts: f64,
    out: &mut [[f64; FUSED]; 4],
) {
    use crate::simd::v::*;
    let at = |r: usize| -> [v128; V] {
        let i = r * c + c0;
        let x = &w[i..i + 2 * V];
        core::array::from_fn(|k| ld(x, 2 * k))
    };
    let zero = f64x2_splat(0.0);
    let (tz, nts) = (f64x2_splat(tz), f64x2_splat(-ts));
    let mut mav = [zero; V];
    let mut wl = [zero; V];
    let mut zc = [i64x2_splat(0); V];
    let mut ssc = [i64x2_splat(0); V];
    let mut p = at(0);
    let mut dp = [zero; V];
    for k in 0..V {
        mav[k] = f64x2_add(mav[k], f64x2_abs(p[k]));
    }
    for r in 1..rows {
        let x = at(r);
        for k in 0..V {
            let d = f64x2_sub(x[k], p[k]);
            let ad = f64x2_abs(d);
            mav[k] = f64x2_add(mav[k], f64x2_abs(x[k]));
            wl[k] = f64x2_add(wl[k], ad);
            let sign = f64x2_lt(f64x2_mul(p[k], x[k]), zero);
            zc[k] = i64x2_add(zc[k], v128_and(sign, f64x2_ge(ad, tz)));
            if r >= 2 {
                ssc[k] = i64x2_add(ssc[k], f64x2_le(f64x2_mul(dp[k], d), nts));
            }
            dp[k] = d;
        }
        p = x;
    }
    for k in 0..V {
        st(&mut out[0], 2 * k, mav[k]);
        st(&mut out[1], 2 * k, wl[k]);
        for (o, hits) in [(2, zc[k]), (3, ssc[k])] {
            out[o][2 * k] = -i64x2_extract_lane::<0>(hits) as f64;
            out[o][2 * k + 1] = -i64x2_extract_lane::<1>(hits) as f64;
        }
    }
}

/// [`strip`] for channels `c0 .. c0 + 2·V` with SIMD128 (`V` vectors of two
/// channels), written into `out`. Every channel goes through the same
/// operations in the same order as in [`strip`] (sums in sample order), so the
/// results are bit-identical; counts are kept as integers (exact either way).
#[cfg(all(target_arch = "wasm32", target_feature = "simd128"))]
#[inline(always)]
fn strip_simd<const V: usize>(
    w: &[f64],
    c: usize,
    c0: usize,
    rows: usize,
    feature: Feature,
    t: f64,
    out: &mut [f64],
) {
    use crate::simd::v::*;
    let at = |r: usize| -> [v128; V] {
        let i = r * c + c0;
        let x = &w[i..i + 2 * V];
        core::array::from_fn(|k| ld(x, 2 * k))
    };
    let zero = f64x2_splat(0.0);
    let tv = f64x2_splat(t);
    let mut acc = [zero; V];
    // Counts: the sum of the comparison masks (−1 per hit).
    let mut hits = [i64x2_splat(0); V];
    let mut counts = false;
    match feature {
        Feature::Mav | Feature::Iav => {
            for r in 0..rows {
                let x = at(r);
                for k in 0..V {
                    acc[k] = f64x2_add(acc[k], f64x2_abs(x[k]));
                }
            }
        }
        Feature::Rms | Feature::Var => {
            for r in 0..rows {
                let x = at(r);
                for k in 0..V {
                    acc[k] = f64x2_add(acc[k], f64x2_mul(x[k], x[k]));
                }
            }
        }
        Feature::Wl => {
            let mut p = at(0);
            for r in 1..rows {
                let x = at(r);
                for k in 0..V {
                    acc[k] = f64x2_add(acc[k], f64x2_abs(f64x2_sub(x[k], p[k])));
                }
                p = x;
            }
        }
        Feature::Dasdv => {
            let mut p = at(0);
            for r in 1..rows {
                let x = at(r);
                for k in 0..V {
                    let d = f64x2_sub(x[k], p[k]);
                    acc[k] = f64x2_add(acc[k], f64x2_mul(d, d));
                }
                p = x;
            }
        }
        Feature::Zc => {
            counts = true;
            let mut p = at(0);
            for r in 1..rows {
                let x = at(r);
                for k in 0..V {
                    let sign = f64x2_lt(f64x2_mul(p[k], x[k]), zero);
                    let big = f64x2_ge(f64x2_abs(f64x2_sub(p[k], x[k])), tv);
                    hits[k] = i64x2_add(hits[k], v128_and(sign, big));
                }
                p = x;
            }
        }
        Feature::Wamp => {
            counts = true;
            let mut p = at(0);
            for r in 1..rows {
                let x = at(r);
                for k in 0..V {
                    let big = f64x2_ge(f64x2_abs(f64x2_sub(p[k], x[k])), tv);
                    hits[k] = i64x2_add(hits[k], big);
                }
                p = x;
            }
        }
        Feature::Ssc => {
            counts = true;
            let (mut b, mut m) = (at(0), at(1));
            for r in 2..rows {
                let x = at(r);
                for k in 0..V {
                    let prod = f64x2_mul(f64x2_sub(m[k], b[k]), f64x2_sub(m[k], x[k]));
                    hits[k] = i64x2_add(hits[k], f64x2_ge(prod, tv));
                }
                b = m;
                m = x;
            }
        }
        Feature::SscMosaic => {
            counts = true;
            let (mut b, mut m) = (at(0), at(1));
            for r in 2..rows {
                let x = at(r);
                for k in 0..V {
                    let d1 = f64x2_sub(m[k], b[k]);
                    let d2 = f64x2_sub(x[k], m[k]);
                    let turn = f64x2_lt(f64x2_mul(d1, d2), zero);
                    let big = v128_and(f64x2_ge(f64x2_abs(d1), tv), f64x2_ge(f64x2_abs(d2), tv));
                    hits[k] = i64x2_add(hits[k], v128_and(turn, big));
                }
                b = m;
                m = x;
            }
        }
    }
    for k in 0..V {
        if counts {
            out[2 * k] = -i64x2_extract_lane::<0>(hits[k]) as f64;
            out[2 * k + 1] = -i64x2_extract_lane::<1>(hits[k]) as f64;
        } else {
            st(out, 2 * k, acc[k]);
        }
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    fn run(f: Feature, t: f64, x: &[f64]) -> f64 {
        let mut k = FeatureKernel::new(&[FeatureSpec::with_threshold(f, t)], x.len(), 1).unwrap();
        let mut o = [0.0];
        k.process(x, &mut o).unwrap();
        o[0]
    }

    #[test]
    fn counts_follow_the_published_rules() {
        let x = [1.0, -1.0, 2.0, 2.0, -0.5, 0.0, 3.0];
        // ZC: (1,-1), (-1,2), (2,-0.5); a zero sample never crosses.
        assert_eq!(run(Feature::Zc, 0.0, &x), 3.0);
        assert_eq!(run(Feature::Zc, 2.6, &x), 1.0);
        // SSC product rule: i=1: (-2)(-3)=6; i=2: (3)(0)=0; i=3: (0)(2.5)=0;
        // i=4: (-2.5)(-0.5)=1.25; i=5: (0.5)(-3)=-1.5 -> 4 with T = 0, 2 with T = 1.
        assert_eq!(run(Feature::Ssc, 0.0, &x), 4.0);
        assert_eq!(run(Feature::Ssc, 1.0, &x), 2.0);
        // MOSAIC rule: strict sign change: i=1 and i=4 only.
        assert_eq!(run(Feature::SscMosaic, 0.0, &x), 2.0);
        assert_eq!(run(Feature::SscMosaic, 1.0, &x), 1.0);
        // WAMP: |diffs| = 2, 3, 0, 2.5, 0.5, 3.
        assert_eq!(run(Feature::Wamp, 0.0, &x), 6.0);
        assert_eq!(run(Feature::Wamp, 2.5, &x), 3.0);
    }

    #[test]
    fn nan_never_counts_and_poisons_sums() {
        let x = [1.0, f64::NAN, -1.0, 1.0];
        assert_eq!(run(Feature::Zc, 0.0, &x), 1.0);
        assert_eq!(run(Feature::Wamp, 0.0, &x), 1.0);
        assert!(run(Feature::Mav, 0.0, &x).is_nan());
        assert!(run(Feature::Wl, 0.0, &x).is_nan());
    }

    #[test]
    fn parse_and_names_round_trip() {
        for f in Feature::ALL {
            assert_eq!(Feature::parse(f.name()), Some(f));
        }
        assert_eq!(Feature::parse("nope"), None);
    }
}
