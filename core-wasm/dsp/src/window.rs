use crate::features::{FeatureKernel, FeatureSpec};
use crate::{check_multiple, DspError};

/// A taper applied to the samples of a window (the `WindowFunction` of the
/// SlidingWindow block). Coefficients are those of
/// `scipy.signal.get_window(name, M, fftbins=False)`, i.e. the symmetric
/// windows (`sym=True`):
///
/// * Hann: `0.5 − 0.5·cos(2πn/(M−1))`
/// * Hamming: `0.54 − 0.46·cos(2πn/(M−1))`
/// * Blackman: `0.42 − 0.5·cos(2πn/(M−1)) + 0.08·cos(4πn/(M−1))`
///
/// for `n = 0 … M−1`, and `[1]` when `M = 1`. They are evaluated as SciPy's
/// `general_cosine` does (`Σ a_k·cos(k·φ_n)`, `φ_n` evenly spaced from −π
/// to π), so they agree with SciPy to the last bit or two.
///
/// ```
/// use mosaic_dsp::WindowFunction;
///
/// let w = WindowFunction::Hann.coefficients(5);
/// assert!((w[2] - 1.0).abs() < 1e-15 && w[0].abs() < 1e-15);
/// assert_eq!(WindowFunction::None.coefficients(3), vec![1.0; 3]);
/// assert_eq!(WindowFunction::parse("HAMMING"), Some(WindowFunction::Hamming));
/// ```
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum WindowFunction {
    /// No taper (rectangular window).
    None,
    /// Hann window.
    Hann,
    /// Hamming window.
    Hamming,
    /// Blackman window.
    Blackman,
}

impl WindowFunction {
    /// The name as written in pipelines: `none`, `hann`, `hamming`, `blackman`.
    pub fn name(self) -> &'static str {
        match self {
            WindowFunction::None => "none",
            WindowFunction::Hann => "hann",
            WindowFunction::Hamming => "hamming",
            WindowFunction::Blackman => "blackman",
        }
    }

    /// The window function named `name` (case-insensitive), if any.
    pub fn parse(name: &str) -> Option<WindowFunction> {
        [
            WindowFunction::None,
            WindowFunction::Hann,
            WindowFunction::Hamming,
            WindowFunction::Blackman,
        ]
        .into_iter()
        .find(|w| w.name().eq_ignore_ascii_case(name))
    }

    fn cosine_terms(self) -> &'static [f64] {
        match self {
            WindowFunction::None => &[1.0],
            WindowFunction::Hann => &[0.5, 0.5],
            WindowFunction::Hamming => &[0.54, 0.46],
            WindowFunction::Blackman => &[0.42, 0.5, 0.08],
        }
    }

    /// The `m` coefficients of the symmetric window (allocates).
    pub fn coefficients(self, m: usize) -> Vec<f64> {
        if m <= 1 || self == WindowFunction::None {
            return vec![1.0; m];
        }
        // φ_n as numpy.linspace(-π, π, m): start + n·step, last exactly π.
        let step = (2.0 * std::f64::consts::PI) / (m - 1) as f64;
        (0..m)
            .map(|n| {
                let phi = if n + 1 == m {
                    std::f64::consts::PI
                } else {
                    n as f64 * step + -std::f64::consts::PI
                };
                let mut w = 0.0;
                for (k, &a) in self.cosine_terms().iter().enumerate() {
                    w += a * (k as f64 * phi).cos();
                }
                w
            })
            .collect()
    }
}

/// Frames a stream of events of `channels` values into overlapping (or
/// gapped) windows of `length` events, one every `step` events once
/// `length` events have arrived (the MOSAIC *SlidingWindow* block).
///
/// A window is `length × channels` values, row-major, oldest event first,
/// multiplied by the window function when one is set. The history is a
/// "double-written" ring of `R ≥ length` rows (every event is stored twice,
/// `R` rows apart), so the latest `R` events are always one contiguous slice:
/// nothing is allocated or rotated per event. With `R = length + n − 1`
/// ([`SlidingWindow::reserve`]`(n)`), every window that a call of up to `n`
/// events completes is still whole in the ring when the call returns, and
/// [`SlidingWindow::process_in_ring`] hands out where each one lies instead of
/// copying it.
///
/// ```
/// use mosaic_dsp::{SlidingWindow, WindowFunction};
///
/// // Windows of 3 events every 2 events, one channel.
/// let mut sw = SlidingWindow::new(3, 2, 1, WindowFunction::None)?;
/// let mut out = [0.0; 6];
/// let mut ends = [0usize; 2];
/// let k = sw.process(&[1.0, 2.0, 3.0, 4.0, 5.0], &mut out, &mut ends)?;
/// assert_eq!(k, 2);
/// assert_eq!(out, [1.0, 2.0, 3.0, 3.0, 4.0, 5.0]);
/// assert_eq!(ends, [2, 4]); // index of the newest event of each window
/// # Ok::<(), mosaic_dsp::DspError>(())
/// ```
#[derive(Debug, Clone)]
pub struct SlidingWindow {
    length: usize,
    step: usize,
    channels: usize,
    taper: Option<Vec<f64>>,
    /// Rows per copy of the ring, `R ≥ length`.
    rows: usize,
    /// `2·R` rows × channels.
    ring: Vec<f64>,
    /// Next row to write (0..R); after a write the latest `R` events are
    /// rows `head .. head + R`, the window the last `length` of them.
    head: usize,
    /// Events still needed before the next window.
    until: usize,
}

impl SlidingWindow {
    /// Windows of `length` events every `step` events (`step > length`
    /// skips events between windows).
    ///
    /// # Errors
    ///
    /// `length == 0`, `step == 0` or `channels == 0`.
    ///
    /// ```
    /// use mosaic_dsp::{SlidingWindow, WindowFunction};
    /// assert!(SlidingWindow::new(0, 1, 1, WindowFunction::None).is_err());
    /// assert!(SlidingWindow::new(4, 0, 1, WindowFunction::None).is_err());
    /// ```
    pub fn new(
        length: usize,
        step: usize,
        channels: usize,
        function: WindowFunction,
    ) -> Result<Self, DspError> {
        if length == 0 {
            return Err(DspError::InvalidParameter {
                name: "Length",
                value: 0.0,
                expected: "at least 1 sample",
            });
        }
        if step == 0 {
            return Err(DspError::InvalidParameter {
                name: "Step",
                value: 0.0,
                expected: "at least 1 sample",
            });
        }
        if channels == 0 {
            return Err(DspError::ZeroChannels);
        }
        let taper = (function != WindowFunction::None).then(|| function.coefficients(length));
        Ok(SlidingWindow {
            length,
            step,
            channels,
            taper,
            rows: length,
            ring: vec![0.0; 2 * length * channels],
            head: 0,
            until: length,
        })
    }

    /// Events per window.
    pub fn length(&self) -> usize {
        self.length
    }

    /// Events between the starts of two windows.
    pub fn step(&self) -> usize {
        self.step
    }

    /// Number of channels.
    pub fn channels(&self) -> usize {
        self.channels
    }

    /// Values per window: `length × channels`.
    pub fn window_size(&self) -> usize {
        self.length * self.channels
    }

    /// The most windows that `n_events` events can complete in one call.
    ///
    /// ```
    /// use mosaic_dsp::{SlidingWindow, WindowFunction};
    /// let sw = SlidingWindow::new(200, 50, 8, WindowFunction::None)?;
    /// assert_eq!(sw.max_windows(0), 0);
    /// assert_eq!(sw.max_windows(1), 1);
    /// assert_eq!(sw.max_windows(100), 2);
    /// # Ok::<(), mosaic_dsp::DspError>(())
    /// ```
    pub fn max_windows(&self, n_events: usize) -> usize {
        if n_events == 0 {
            0
        } else {
            1 + (n_events - 1) / self.step
        }
    }

    /// The number of windows that the next `n_events` events will complete
    /// (exact, given what has been fed so far).
    ///
    /// ```
    /// use mosaic_dsp::{SlidingWindow, WindowFunction};
    /// let mut sw = SlidingWindow::new(4, 2, 1, WindowFunction::None)?;
    /// assert_eq!(sw.windows_for(3), 0);
    /// assert_eq!(sw.windows_for(6), 2);
    /// # Ok::<(), mosaic_dsp::DspError>(())
    /// ```
    pub fn windows_for(&self, n_events: usize) -> usize {
        if n_events < self.until {
            0
        } else {
            1 + (n_events - self.until) / self.step
        }
    }

    /// Stores one event; returns `true` when it completes a window (then
    /// [`SlidingWindow::current`] is that window, untapered).
    #[inline]
    pub(crate) fn push(&mut self, event: &[f64]) -> bool {
        let c = self.channels;
        let a = self.head * c;
        let b = (self.head + self.rows) * c;
        self.ring[a..a + c].copy_from_slice(event);
        self.ring[b..b + c].copy_from_slice(event);
        self.head += 1;
        if self.head == self.rows {
            self.head = 0;
        }
        self.until -= 1;
        if self.until == 0 {
            self.until = self.step;
            true
        } else {
            false
        }
    }

    /// The latest `length` events, oldest first, untapered.
    #[inline]
    pub(crate) fn current(&self) -> &[f64] {
        &self.ring[self.current_start()..][..self.window_size()]
    }

    /// Index in [`SlidingWindow::ring`] of the first value of the latest
    /// `length` events.
    #[inline]
    fn current_start(&self) -> usize {
        (self.head + self.rows - self.length) * self.channels
    }

    /// The history: `2·R` rows × channels, see [`SlidingWindow::process_in_ring`].
    pub fn ring(&self) -> &[f64] {
        &self.ring
    }

    /// The most events one call of [`SlidingWindow::process_in_ring`] may
    /// bring: `R − length + 1` (1 until [`SlidingWindow::reserve`]).
    pub fn reach(&self) -> usize {
        self.rows - self.length + 1
    }

    /// Grows the ring so that calls of up to `events` events can use
    /// [`SlidingWindow::process_in_ring`] (`R = length + events − 1`).
    /// Keeps the history; allocates, so call it outside the hot path (it
    /// does nothing when the ring is large enough already).
    ///
    /// ```
    /// use mosaic_dsp::{SlidingWindow, WindowFunction};
    /// let mut sw = SlidingWindow::new(4, 2, 1, WindowFunction::None)?;
    /// assert_eq!(sw.reach(), 1);
    /// sw.reserve(16);
    /// assert_eq!(sw.reach(), 16);
    /// # Ok::<(), mosaic_dsp::DspError>(())
    /// ```
    pub fn reserve(&mut self, events: usize) {
        let rows = self.length + events.max(1) - 1;
        if rows <= self.rows {
            return;
        }
        let c = self.channels;
        let size = self.window_size();
        let mut ring = vec![0.0; 2 * rows * c];
        // The latest `length` events become rows R − length .. R (and their
        // copies R rows later); the next event goes to row 0.
        let latest = self.current();
        ring[(rows - self.length) * c..][..size].copy_from_slice(latest);
        ring[(2 * rows - self.length) * c..][..size].copy_from_slice(latest);
        self.ring = ring;
        self.rows = rows;
        self.head = 0;
    }

    /// Feeds `input` (`n` events × `channels`) and writes every completed
    /// window into `output` (window `k` at `k × window_size()`), and the
    /// index of its newest event within this call into `ends[k]`. Returns the
    /// number of windows written.
    ///
    /// # Errors
    ///
    /// `input` is not whole events, or `output`/`ends` cannot hold
    /// [`SlidingWindow::windows_for`]`(n)` windows. Nothing is consumed then.
    pub fn process(
        &mut self,
        input: &[f64],
        output: &mut [f64],
        ends: &mut [usize],
    ) -> Result<usize, DspError> {
        let n = check_multiple("input", input.len(), self.channels)?;
        let most = self.windows_for(n);
        let size = self.window_size();
        check_room("output", output.len(), most * size)?;
        check_room("ends", ends.len(), most)?;
        let mut k = 0;
        for (e, event) in input.chunks_exact(self.channels).enumerate() {
            if self.push(event) {
                let out = &mut output[k * size..(k + 1) * size];
                self.copy_current(out);
                ends[k] = e;
                k += 1;
            }
        }
        Ok(k)
    }

    /// Feeds `input` (`n` events × `channels`, at most
    /// [`SlidingWindow::reach`] events) like [`SlidingWindow::process`] but
    /// copies nothing: for every completed window it writes where the window
    /// (**untapered**) starts in [`SlidingWindow::ring`] into `starts[k]`
    /// (`window_size()` values from there) and the index of its newest event
    /// into `ends[k]`. The windows stay there until the next call. Returns
    /// the number of windows.
    ///
    /// # Errors
    ///
    /// `input` is not whole events, brings more than `reach()` events, or
    /// `starts`/`ends` cannot hold [`SlidingWindow::windows_for`]`(n)`
    /// windows. Nothing is consumed then.
    ///
    /// ```
    /// use mosaic_dsp::{SlidingWindow, WindowFunction};
    ///
    /// let mut sw = SlidingWindow::new(3, 2, 1, WindowFunction::None)?;
    /// sw.reserve(5);
    /// let (mut starts, mut ends) = ([0usize; 2], [0usize; 2]);
    /// let k = sw.process_in_ring(&[1.0, 2.0, 3.0, 4.0, 5.0], &mut starts, &mut ends)?;
    /// assert_eq!((k, ends), (2, [2, 4]));
    /// assert_eq!(&sw.ring()[starts[0]..][..3], &[1.0, 2.0, 3.0]);
    /// assert_eq!(&sw.ring()[starts[1]..][..3], &[3.0, 4.0, 5.0]);
    /// # Ok::<(), mosaic_dsp::DspError>(())
    /// ```
    pub fn process_in_ring(
        &mut self,
        input: &[f64],
        starts: &mut [usize],
        ends: &mut [usize],
    ) -> Result<usize, DspError> {
        let n = check_multiple("input", input.len(), self.channels)?;
        if n > self.reach() {
            return Err(DspError::InvalidParameter {
                name: "events per call",
                value: n as f64,
                expected: "at most reach() events (see SlidingWindow::reserve)",
            });
        }
        let most = self.windows_for(n);
        check_room("starts", starts.len(), most)?;
        check_room("ends", ends.len(), most)?;
        let mut k = 0;
        for (e, event) in input.chunks_exact(self.channels).enumerate() {
            if self.push(event) {
                starts[k] = self.current_start();
                ends[k] = e;
                k += 1;
            }
        }
        Ok(k)
    }

    fn copy_current(&self, out: &mut [f64]) {
        let c = self.channels;
        let w = self.current();
        match &self.taper {
            None => out.copy_from_slice(w),
            Some(taper) => {
                for ((o, x), &g) in out.chunks_exact_mut(c).zip(w.chunks_exact(c)).zip(taper) {
                    for (o, &x) in o.iter_mut().zip(x) {
                        *o = x * g;
                    }
                }
            }
        }
    }

    /// Forgets every event: the next window needs `length` new events.
    pub fn reset(&mut self) {
        self.ring.fill(0.0);
        self.head = 0;
        self.until = self.length;
    }
}

/// A [`SlidingWindow`] (no taper) feeding a [`FeatureKernel`]: features of a
/// plain stream of events, computed every `step` events over the last
/// `length` events ("RMS over a sliding window with window and hop"). The
/// features read the window straight from the ring: nothing is copied.
///
/// ```
/// use mosaic_dsp::{Feature, FeatureSpec, WindowedFeatures};
///
/// // RMS over 4 events every 2 events, one channel.
/// let mut wf = WindowedFeatures::new(&[FeatureSpec::new(Feature::Rms)], 4, 2, 1)?;
/// let mut out = [0.0; 2];
/// let mut ends = [0usize; 2];
/// let k = wf.process(&[1.0, -1.0, 1.0, -1.0, 3.0, 3.0], &mut out, &mut ends)?;
/// assert_eq!((k, out, ends), (2, [1.0, 5f64.sqrt()], [3, 5]));
/// # Ok::<(), mosaic_dsp::DspError>(())
/// ```
#[derive(Debug, Clone)]
pub struct WindowedFeatures {
    window: SlidingWindow,
    features: FeatureKernel,
}

impl WindowedFeatures {
    /// Features `specs` over windows of `length` events every `step` events.
    ///
    /// # Errors
    ///
    /// As [`SlidingWindow::new`] and [`FeatureKernel::new`].
    pub fn new(
        specs: &[FeatureSpec],
        length: usize,
        step: usize,
        channels: usize,
    ) -> Result<Self, DspError> {
        let window = SlidingWindow::new(length, step, channels, WindowFunction::None)?;
        let features = FeatureKernel::new(specs, length, channels)?;
        Ok(WindowedFeatures { window, features })
    }

    /// Number of channels.
    pub fn channels(&self) -> usize {
        self.window.channels()
    }

    /// Values per output event: features × channels.
    pub fn output_width(&self) -> usize {
        self.features.output_width()
    }

    /// See [`SlidingWindow::max_windows`].
    pub fn max_windows(&self, n_events: usize) -> usize {
        self.window.max_windows(n_events)
    }

    /// See [`FeatureKernel::set_thresholds`]; the window history is kept.
    ///
    /// # Errors
    ///
    /// As [`FeatureKernel::set_thresholds`].
    pub fn set_thresholds(&mut self, thresholds: &[f64]) -> Result<(), DspError> {
        self.features.set_thresholds(thresholds)
    }

    /// See [`SlidingWindow::windows_for`].
    pub fn windows_for(&self, n_events: usize) -> usize {
        self.window.windows_for(n_events)
    }

    /// Feeds `input` (`n` events × `channels`); for every completed window
    /// writes its features into `output` (`output_width()` values per
    /// window) and the index of its newest event into `ends`. Returns the
    /// number of windows (room is needed for [`WindowedFeatures::windows_for`]`(n)`).
    ///
    /// # Errors
    ///
    /// As [`SlidingWindow::process`].
    pub fn process(
        &mut self,
        input: &[f64],
        output: &mut [f64],
        ends: &mut [usize],
    ) -> Result<usize, DspError> {
        let c = self.window.channels();
        let n = check_multiple("input", input.len(), c)?;
        let most = self.window.windows_for(n);
        let width = self.features.output_width();
        check_room("output", output.len(), most * width)?;
        check_room("ends", ends.len(), most)?;
        let mut k = 0;
        for (e, event) in input.chunks_exact(c).enumerate() {
            if self.window.push(event) {
                let out = &mut output[k * width..(k + 1) * width];
                self.features.window(self.window.current(), out);
                ends[k] = e;
                k += 1;
            }
        }
        Ok(k)
    }

    /// Forgets every event.
    pub fn reset(&mut self) {
        self.window.reset();
        self.features.reset();
    }
}

fn check_room(name: &'static str, len: usize, needed: usize) -> Result<(), DspError> {
    if len >= needed {
        Ok(())
    } else {
        Err(DspError::TooShort { name, len, needed })
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::Feature;

    #[test]
    fn step_longer_than_length_skips_events() {
        let mut sw = SlidingWindow::new(2, 3, 1, WindowFunction::None).unwrap();
        let x: Vec<f64> = (0..9).map(f64::from).collect();
        let mut out = [0.0; 6];
        let mut ends = [0; 3];
        let k = sw.process(&x, &mut out, &mut ends).unwrap();
        assert_eq!(k, 3);
        assert_eq!(out, [0.0, 1.0, 3.0, 4.0, 6.0, 7.0]);
        assert_eq!(ends, [1, 4, 7]);
    }

    #[test]
    fn taper_multiplies_each_row() {
        let mut sw = SlidingWindow::new(3, 1, 2, WindowFunction::Hann).unwrap();
        let mut out = [0.0; 6];
        let mut ends = [0; 3];
        let k = sw
            .process(&[1.0, 2.0, 1.0, 2.0, 1.0, 2.0], &mut out, &mut ends)
            .unwrap();
        assert_eq!(k, 1);
        // Hann(3) = [0, 1, 0] (up to rounding).
        for (o, e) in out.iter().zip([0.0, 0.0, 1.0, 2.0, 0.0, 0.0]) {
            assert!((o - e).abs() < 1e-15, "{o} vs {e}");
        }
    }

    #[test]
    fn short_output_is_an_error_and_consumes_nothing() {
        let mut sw = SlidingWindow::new(2, 1, 1, WindowFunction::None).unwrap();
        let mut out = [0.0; 2];
        let mut ends = [0; 1];
        assert!(sw.process(&[1.0, 2.0, 3.0], &mut out, &mut ends).is_err());
        let k = sw.process(&[1.0, 2.0], &mut out, &mut ends).unwrap();
        assert_eq!((k, out), (1, [1.0, 2.0]));
    }

    #[test]
    fn windows_in_the_ring_equal_copied_windows() {
        // Batches of 1..=9 events, the ring grown twice on the way (the
        // history must survive), against the copying path.
        let (length, step, c) = (7, 3, 3);
        let x: Vec<f64> = (0..200 * c).map(|i| ((i * 31) % 17) as f64 - 8.0).collect();
        let mut copied = SlidingWindow::new(length, step, c, WindowFunction::None).unwrap();
        let mut inring = copied.clone();
        inring.reserve(4);
        let (mut at, mut batch) = (0, 1);
        while at < 200 {
            let n = batch.min(200 - at);
            if n > inring.reach() {
                inring.reserve(n);
            }
            let input = &x[at * c..(at + n) * c];
            let most = copied.windows_for(n);
            let mut out = vec![0.0; most * length * c];
            let (mut ends_a, mut ends_b, mut starts) =
                (vec![0; most], vec![0; most], vec![0; most]);
            let ka = copied.process(input, &mut out, &mut ends_a).unwrap();
            let kb = inring
                .process_in_ring(input, &mut starts, &mut ends_b)
                .unwrap();
            assert_eq!((ka, &ends_a), (kb, &ends_b));
            for (k, &start) in starts.iter().enumerate().take(kb) {
                let w = &inring.ring()[start..][..length * c];
                assert_eq!(w, &out[k * length * c..][..length * c], "batch at {at}");
            }
            at += n;
            batch = batch % 9 + 1;
        }
        let mut starts = [0; 4];
        assert!(inring
            .process_in_ring(&x[..(inring.reach() + 1) * c], &mut starts, &mut [0; 4])
            .is_err());
    }

    #[test]
    fn windowed_features_equal_window_then_features() {
        let specs = [
            FeatureSpec::new(Feature::Mav),
            FeatureSpec::with_threshold(Feature::Zc, 0.1),
        ];
        let c = 3;
        let x: Vec<f64> = (0..60 * c)
            .map(|i| ((i * 7919) % 23) as f64 - 11.0)
            .collect();
        let mut wf = WindowedFeatures::new(&specs, 8, 5, c).unwrap();
        let mut a = vec![0.0; 12 * wf.output_width()];
        let mut ends_a = [0; 12];
        let ka = wf.process(&x, &mut a, &mut ends_a).unwrap();

        let mut sw = SlidingWindow::new(8, 5, c, WindowFunction::None).unwrap();
        let mut fk = FeatureKernel::new(&specs, 8, c).unwrap();
        let mut w = vec![0.0; 12 * 8 * c];
        let mut ends_b = [0; 12];
        let kb = sw.process(&x, &mut w, &mut ends_b).unwrap();
        let mut b = vec![0.0; kb * fk.output_width()];
        fk.process(&w[..kb * 8 * c], &mut b).unwrap();
        assert_eq!(ka, kb);
        assert_eq!(&a[..ka * wf.output_width()], &b[..]);
        assert_eq!(ends_a, ends_b);
    }
}
