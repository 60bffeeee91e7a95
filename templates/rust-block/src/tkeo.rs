//! The Teager–Kaiser energy operator (Kaiser 1990), per channel:
//! ψ[n] = x[n]² − x[n−1]·x[n+1].
//!
//! ψ[n] needs the next sample, so the output is one sample late: the output for input sample k
//! is ψ[k−1] = x[k−1]² − x[k−2]·x[k], with x before the first sample taken as 0 (so the first
//! output is 0 and the second x[0]²). The last two samples of every channel are kept between
//! calls, so splitting the signal into frames differently gives the same output.
//!
//! Params (in order): `Rectify` (0 or 1): 1 outputs |ψ| (TKEO is negative where the signal's
//! curvature exceeds its energy, e.g. right after a sharp peak).

use crate::abi::Kernel;

/// Teager–Kaiser energy of every channel, one sample late.
#[derive(Debug, Clone)]
pub struct Tkeo {
    rectify: bool,
    /// x[k−1] of each channel.
    previous: Vec<f64>,
    /// x[k−2] of each channel.
    before_previous: Vec<f64>,
}

impl Kernel for Tkeo {
    fn new(params: &[f64], channels: usize) -> Result<Self, String> {
        let rectify = match params {
            [] => false,
            [r] if *r == 0.0 => false,
            [r] if *r == 1.0 => true,
            [r] => return Err(format!("Rectify must be 0 or 1, got {r}")),
            _ => return Err(format!("expected 1 param (Rectify), got {}", params.len())),
        };
        Ok(Tkeo {
            rectify,
            previous: vec![0.0; channels],
            before_previous: vec![0.0; channels],
        })
    }

    fn output_channels(&self) -> usize {
        self.previous.len()
    }

    fn process(&mut self, input: &[f64], output: &mut [f64]) {
        let channels = self.previous.len();
        for (x, y) in input
            .chunks_exact(channels)
            .zip(output.chunks_exact_mut(channels))
        {
            for c in 0..channels {
                let (x1, x2) = (self.previous[c], self.before_previous[c]);
                let psi = x1 * x1 - x2 * x[c];
                y[c] = if self.rectify { psi.abs() } else { psi };
                self.before_previous[c] = x1;
                self.previous[c] = x[c];
            }
        }
    }

    fn reset(&mut self) {
        self.previous.fill(0.0);
        self.before_previous.fill(0.0);
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    fn run(kernel: &mut Tkeo, input: &[f64]) -> Vec<f64> {
        let mut out = vec![f64::NAN; input.len()];
        kernel.process(input, &mut out);
        out
    }

    #[test]
    fn a_sine_has_constant_energy_a_squared_sin_squared_omega() {
        // ψ of A·sin(ωn + φ) is A²·sin²(ω) for every n (Kaiser 1990).
        let (a, w) = (2.5, 0.3_f64);
        let x: Vec<f64> = (0..64).map(|n| a * (w * n as f64 + 0.7).sin()).collect();
        let mut k = Tkeo::new(&[0.0], 1).unwrap();
        let y = run(&mut k, &x);
        let expected = a * a * w.sin() * w.sin();
        for (n, v) in y.iter().enumerate().skip(2) {
            assert!(
                (v - expected).abs() < 1e-12,
                "ψ[{n}] = {v}, expected {expected}"
            );
        }
    }

    #[test]
    fn first_outputs_use_zeros_before_the_signal() {
        let mut k = Tkeo::new(&[], 1).unwrap();
        assert_eq!(run(&mut k, &[3.0, 5.0, 7.0]), vec![0.0, 9.0, 25.0 - 21.0]);
    }

    #[test]
    fn channels_are_independent_and_rectify_takes_the_magnitude() {
        // Channel 0: 1, 4, 1 → ψ[1] = 16 − 1 = 15; channel 1: 4, 1, 4 → ψ[1] = 1 − 16 = −15.
        let mut plain = Tkeo::new(&[0.0], 2).unwrap();
        let mut rect = Tkeo::new(&[1.0], 2).unwrap();
        let x = [1.0, 4.0, 4.0, 1.0, 1.0, 4.0];
        assert_eq!(run(&mut plain, &x), vec![0.0, 0.0, 1.0, 16.0, 15.0, -15.0]);
        assert_eq!(run(&mut rect, &x), vec![0.0, 0.0, 1.0, 16.0, 15.0, 15.0]);
    }

    #[test]
    fn wrong_params_say_what_is_wrong() {
        assert_eq!(
            Tkeo::new(&[0.5], 1).unwrap_err(),
            "Rectify must be 0 or 1, got 0.5"
        );
        assert_eq!(
            Tkeo::new(&[0.0, 1.0], 1).unwrap_err(),
            "expected 1 param (Rectify), got 2"
        );
    }
}
