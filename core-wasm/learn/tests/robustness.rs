//! Ill-conditioned and hostile inputs: constant and duplicated channels,
//! tiny and huge λ, values near the limits, long runs with forgetting, NaN
//! and infinite samples, corrupt saved states. The model must never hold a
//! NaN, and must agree with the batch solution where one exists.

use mosaic_learn::{
    LearnError, Model, ModelConfig, PredictingMachine, RandomFourierFeatures, RffParams, Ridge,
    RidgeParams,
};

/// Deterministic pseudo-random numbers in [-1, 1) (xorshift).
struct Noise(u64);
impl Noise {
    fn next(&mut self) -> f64 {
        self.0 ^= self.0 << 13;
        self.0 ^= self.0 >> 7;
        self.0 ^= self.0 << 17;
        (self.0 >> 11) as f64 / (1u64 << 52) as f64 - 1.0
    }
}

fn all_finite(m: &dyn PredictingMachine) -> bool {
    let mut s = vec![0.0; m.state_len()];
    m.save_state(&mut s).unwrap();
    s.iter().all(|v| v.is_finite())
}

/// Rows with a constant channel (5.0) and a duplicate of channel 0.
fn degenerate(n: usize, scale: f64) -> (Vec<f64>, Vec<f64>) {
    let mut r = Noise(42);
    let (mut x, mut y) = (Vec::new(), Vec::new());
    for _ in 0..n {
        let a = r.next() * scale;
        let b = r.next() * scale;
        x.extend_from_slice(&[a, 5.0 * scale, a, b]);
        y.extend_from_slice(&[2.0 * a / scale - b / scale + 1.0, a / scale]);
    }
    (x, y)
}

fn rel(a: &[f64], b: &[f64]) -> f64 {
    let s = b.iter().fold(0.0f64, |s, x| s.max(x.abs())).max(1e-300);
    a.iter()
        .zip(b)
        .fold(0.0f64, |m, (x, y)| m.max((x - y).abs()))
        / s
}

#[test]
fn constant_and_duplicate_channels_with_tiny_lambda() {
    for &lambda in &[1e-12, 1e-6, 1.0] {
        for &scale in &[1e-6, 1.0, 1e6] {
            for &intercept in &[true, false] {
                let (x, y) = degenerate(500, scale);
                let p = RidgeParams {
                    lambda,
                    intercept,
                    ..RidgeParams::default()
                };
                let mut inc = Ridge::new(4, 2, p).unwrap();
                inc.partial_fit(&x, &y).unwrap();
                let mut batch = Ridge::new(4, 2, p).unwrap();
                batch.fit(&x, &y).unwrap();
                let what = format!("λ {lambda:e}, scale {scale:e}, intercept {intercept}");
                assert!(
                    all_finite(&inc) && all_finite(&batch),
                    "{what}: NaN in the state"
                );
                // The duplicated channels share their weight equally; how equally
                // depends on the conditioning ‖S‖/λ (their difference lies in the
                // null space of S, where only λ and rounding act).
                let w = inc.weights();
                let cond = 500.0 * scale * scale / lambda;
                let tol = 1e-9 + 1e-15 * cond;
                assert!(
                    (w[0] - w[4]).abs() <= tol * w[0].abs(),
                    "{what}: duplicate weights {} vs {}",
                    w[0],
                    w[4]
                );
                // Their sum is identifiable, to working precision: while ‖S‖/λ < 1/ε.
                if cond > 1e6 && cond < 1e15 {
                    let sum = (w[0] + w[4]) * scale;
                    assert!((sum - 2.0).abs() < 1e-3, "{what}: w0 + w2 = {sum} / scale");
                }
                let (mut pi, mut pb) = (vec![0.0; 200], vec![0.0; 200]);
                inc.predict(&x[..400], &mut pi).unwrap();
                batch.predict(&x[..400], &mut pb).unwrap();
                assert!(pi.iter().all(|v| v.is_finite()), "{what}");
                // Beyond a conditioning of 1/ε the normal equations are singular at
                // working precision: both solutions are then right to rounding only.
                let e = rel(&pi, &pb);
                let tol = (1e-14 * cond).clamp(1e-9, 1e-2);
                println!(
                    "{what}: ‖S‖/λ {cond:.0e}, incremental vs batch {e:.1e} (tolerance {tol:.0e})"
                );
                assert!(e < tol, "{what}: incremental vs batch {e:e}");
                if intercept || scale == 1.0 {
                    // An exact linear target is recovered (the constant column stands in
                    // for the intercept when there is none).
                    let ey = rel(&pi, &y[..200]);
                    let tol = if lambda * 1e6 < scale * scale {
                        1e-3
                    } else {
                        1.0
                    };
                    assert!(ey < tol, "{what}: fit error {ey:e}");
                }
            }
        }
    }
}

#[test]
fn refused_samples_leave_the_model_unchanged() {
    let mut m = ModelConfig::rff(2, 1)
        .features(20)
        .normalize(true)
        .build()
        .unwrap();
    m.partial_fit(&[0.1, 0.2, 0.3, 0.1, -0.2, 0.5], &[1.0, 2.0, 3.0])
        .unwrap();
    let mut before = vec![0.0; m.state_len()];
    m.save_state(&mut before).unwrap();
    for (x, y) in [
        ([f64::NAN, 0.0], 1.0),
        ([0.0, f64::INFINITY], 1.0),
        ([1e51, 0.0], 1.0),
        ([0.0, 0.0], f64::NAN),
        ([0.0, 0.0], -1e200),
    ] {
        assert_eq!(m.partial_fit(&x, &[y]).unwrap(), 0, "{x:?} {y}");
    }
    assert_eq!(m.rejected(), 5);
    let mut after = vec![0.0; m.state_len()];
    m.save_state(&mut after).unwrap();
    assert_eq!(before, after);
    // A batch with bad rows uses the others.
    let n = m
        .fit(&[0.0, 1.0, f64::NAN, 0.0, 1.0, 0.0], &[1.0, 2.0, 3.0])
        .unwrap();
    assert_eq!(n, 2);
    assert!(all_finite(&m));
}

#[test]
fn long_run_with_forgetting_stays_finite_and_exact() {
    // 100,000 samples; channel 1 is constant, channel 2 is zero for the second half.
    let beta = 0.99;
    let p = RidgeParams {
        lambda: 1e-3,
        forgetting: beta,
        ..RidgeParams::default()
    };
    let mut m = Ridge::new(3, 1, p).unwrap();
    let mut r = Noise(7);
    let mut recent = Vec::new();
    let mut targets = Vec::new();
    let n = 100_000;
    for i in 0..n {
        let a = r.next();
        let c = if i < n / 2 { r.next() } else { 0.0 };
        let x = [a, 3.0, c];
        let y = [a - c + 0.01 * r.next()];
        m.partial_fit(&x, &y).unwrap();
        if i >= n - 3000 {
            recent.extend_from_slice(&x);
            targets.extend_from_slice(&y);
        }
    }
    assert!(all_finite(&m));
    let le = m.effective_lambda();
    assert!(le > 0.5e-3 && le <= 1e-3, "λ_eff {le}");
    assert!(m.refactors() > 1000);
    // Exact: the weighted batch solution (weights β^(n−1−i), λ_eff) on the last
    // 3000 samples (older ones weigh less than 0.99^3000 ≈ 1e-13).
    let mut batch = Ridge::new(
        3,
        1,
        RidgeParams {
            lambda: le,
            forgetting: beta,
            ..RidgeParams::default()
        },
    )
    .unwrap();
    batch.fit(&recent, &targets).unwrap();
    let e = rel(m.weights(), batch.weights());
    assert!(e < 1e-8, "weights differ by {e:e}");
}

#[test]
fn near_the_limits_and_all_zero() {
    for &v in &[1e-45, 1e45] {
        let mut m = ModelConfig::ridge(2, 1).build().unwrap();
        for i in 0..100 {
            let t = i as f64;
            m.partial_fit(&[v * t.sin(), v], &[v * t.cos()]).unwrap();
        }
        assert!(all_finite(&m), "scale {v:e}");
        let mut y = [0.0];
        m.predict(&[v, v], &mut y).unwrap();
        assert!(y[0].is_finite());
    }
    // All-zero inputs: the model predicts the mean target.
    let mut m = ModelConfig::ridge(3, 2).normalize(true).build().unwrap();
    for i in 0..10 {
        m.partial_fit(&[0.0; 3], &[i as f64, 1.0]).unwrap();
    }
    let mut y = [0.0; 2];
    m.predict(&[0.0; 3], &mut y).unwrap();
    assert!((y[0] - 4.5).abs() < 1e-12 && (y[1] - 1.0).abs() < 1e-12);
    assert!(all_finite(&m));
}

#[test]
fn the_corners_of_the_domain_stay_finite() {
    // λ at both ends of its range, values up to ±1e50, constant and duplicated channels,
    // sudden jumps over 100 orders of magnitude, forgetting and normalisation.
    let mut r = Noise(3);
    for &lambda in &[1e-50, 1e-20, 1.0, 1e50] {
        for &beta in &[1.0, 0.9] {
            for &normalize in &[false, true] {
                let mut m = ModelConfig::ridge(4, 1)
                    .lambda(lambda)
                    .forgetting(beta)
                    .normalize(normalize)
                    .build()
                    .unwrap();
                for i in 0..300 {
                    let big = if i % 50 < 25 { 1e50 } else { 1e-50 };
                    let a = r.next() * big;
                    let x = [a, a, 7.0, r.next() * 1e-30];
                    m.partial_fit(&x, &[r.next() * big]).unwrap();
                }
                let what = format!("λ {lambda:e}, β {beta}, normalize {normalize}");
                assert!(all_finite(&m), "{what}: NaN in the state");
                let mut y = [0.0];
                m.predict(&[1.0, 1.0, 7.0, 0.0], &mut y).unwrap();
                assert!(y[0].is_finite(), "{what}: prediction {}", y[0]);
                assert_eq!(m.rejected(), 0, "{what}");
            }
        }
    }
    assert!(ModelConfig::ridge(2, 1).lambda(1e-51).build().is_err());
    assert!(ModelConfig::ridge(2, 1).lambda(1e51).build().is_err());
}

#[test]
fn rff_on_degenerate_inputs() {
    let (x, y) = degenerate(300, 1.0);
    let rff = RffParams {
        features: 64,
        gamma: 0.3,
        seed: 3,
    };
    let p = RidgeParams {
        lambda: 1e-12,
        ..RidgeParams::default()
    };
    let mut m = RandomFourierFeatures::new(4, 2, rff, p).unwrap();
    m.partial_fit(&x, &y).unwrap();
    assert!(all_finite(&m));
}

fn trained() -> Model {
    let mut m = ModelConfig::ridge(3, 2).normalize(true).build().unwrap();
    let mut r = Noise(1);
    for _ in 0..50 {
        let x = [r.next(), r.next(), r.next()];
        m.partial_fit(&x, &[x[0] + x[1], x[2]]).unwrap();
    }
    m
}

/// Index of section `name` in the flat state.
fn at(m: &Model, name: &str) -> usize {
    let mut i = 0;
    for (n, len) in m.state_sections() {
        if n == name {
            return i;
        }
        i += len;
    }
    panic!("no section {name}");
}

/// What the error must be.
type Expect = fn(&LearnError) -> bool;

#[test]
fn corrupt_states_are_refused_and_the_model_kept() {
    let m = trained();
    let mut good = vec![0.0; m.state_len()];
    m.save_state(&mut good).unwrap();
    let sc = at(&m, "scatter");
    let cases: Vec<(Vec<f64>, Expect)> = vec![
        (good[..good.len() - 1].to_vec(), |e| {
            matches!(e, LearnError::StateLength { .. })
        }),
        (
            {
                let mut s = good.clone();
                s[sc + 4] = f64::NAN;
                s
            },
            |e| {
                matches!(
                    e,
                    LearnError::StateValue {
                        section: "scatter",
                        index: 4,
                        ..
                    }
                )
            },
        ),
        (
            {
                let mut s = good.clone();
                s[sc + 1] += 1.0;
                s
            },
            |e| matches!(e, LearnError::NotSymmetric { row: 1, col: 0 }),
        ),
        (
            {
                let mut s = good.clone();
                s[sc + 1] = 1e3; // |S01| far above √(S00·S11): indefinite
                s[sc + 3] = 1e3;
                s
            },
            |e| matches!(e, LearnError::NotPositiveDefinite),
        ),
        (
            {
                let mut s = good.clone();
                s[at(&m, "weights") + 2] += 0.5;
                s
            },
            |e| {
                matches!(
                    e,
                    LearnError::Inconsistent {
                        section: "weights",
                        ..
                    }
                )
            },
        ),
        (
            {
                let mut s = good.clone();
                s[at(&m, "intercept")] += 0.5;
                s
            },
            |e| {
                matches!(
                    e,
                    LearnError::Inconsistent {
                        section: "intercept",
                        ..
                    }
                )
            },
        ),
        (
            {
                let mut s = good.clone();
                s[at(&m, "meta") + 2] = 0.0;
                s
            },
            |e| {
                matches!(
                    e,
                    LearnError::StateValue {
                        section: "meta",
                        index: 2,
                        ..
                    }
                )
            },
        ),
        (
            {
                let mut s = good.clone();
                s[at(&m, "normalizer")] = -1.0;
                s
            },
            |e| {
                matches!(
                    e,
                    LearnError::StateValue {
                        section: "normalizer",
                        ..
                    }
                )
            },
        ),
    ];
    for (i, (state, ok)) in cases.into_iter().enumerate() {
        let mut target = trained();
        let err = target.load_state(&state).unwrap_err();
        assert!(ok(&err), "case {i}: unexpected error {err:?}");
        assert!(!err.to_string().is_empty());
        let mut after = vec![0.0; target.state_len()];
        target.save_state(&mut after).unwrap();
        assert_eq!(after, good, "case {i}: the model changed");
    }
}

#[test]
fn invalid_configurations() {
    let bad = [
        ModelConfig::ridge(0, 1),
        ModelConfig::ridge(3000, 1),
        ModelConfig::ridge(2, 0),
        ModelConfig::ridge(2, 1).lambda(f64::NAN),
        ModelConfig::ridge(2, 1).lambda(-1.0),
        ModelConfig::ridge(2, 1).forgetting(0.0),
        ModelConfig::ridge(2, 1).forgetting(1.5),
        ModelConfig::rff(2, 1).gamma(0.0),
        ModelConfig::rff(2, 1).features(0),
        ModelConfig::rff(2, 1).features(5000),
        ModelConfig::rff(1 << 20, 1).features(8),
    ];
    for cfg in bad {
        let e = cfg.build().unwrap_err();
        assert!(!e.to_string().is_empty(), "{cfg:?}");
    }
    let e = ModelConfig::rff(2, 1).features(5000).build().unwrap_err();
    assert!(e.to_string().starts_with("Features is 5000"), "{e}");
}
