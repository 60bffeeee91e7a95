//! `normalize`: the incremental models are exactly the plain models on
//! inputs standardised with the statistics they record (see `Model`).

use mosaic_learn::{Model, ModelConfig, PredictingMachine, Ridge, RidgeParams};

fn samples(n: usize) -> (Vec<f64>, Vec<f64>) {
    // Inputs of very different scales and offsets, whose spread changes over time.
    let (mut x, mut y) = (Vec::new(), Vec::new());
    for i in 0..n {
        let t = i as f64;
        let grow = 1.0 + t / 50.0;
        let xi = [
            1e-3 * (0.3 * t).sin() * grow,
            500.0 + 40.0 * (0.07 * t).cos(),
            7.0,
            (0.5 * t).sin() * (0.05 * t).cos() * grow,
        ];
        x.extend_from_slice(&xi);
        y.extend_from_slice(&[1e3 * xi[0] + 0.01 * xi[1] + xi[3], (xi[3] * 2.0).tanh()]);
    }
    (x, y)
}

/// Section `name` of the model's flat state.
fn section(m: &Model, name: &str) -> Vec<f64> {
    let mut s = vec![0.0; m.state_len()];
    m.save_state(&mut s).unwrap();
    let mut at = 0;
    for (n, len) in m.state_sections() {
        if n == name {
            return s[at..at + len].to_vec();
        }
        at += len;
    }
    panic!("no section {name}");
}

fn rel(a: &[f64], b: &[f64]) -> f64 {
    let s = b.iter().fold(0.0f64, |s, x| s.max(x.abs())).max(1e-300);
    a.iter()
        .zip(b)
        .fold(0.0f64, |m, (x, y)| m.max((x - y).abs()))
        / s
}

#[test]
fn ridge_is_exact_for_its_recorded_scales() {
    let (x, y) = samples(400);
    for beta in [1.0, 0.995] {
        let mut m = ModelConfig::ridge(4, 2)
            .lambda(0.5)
            .forgetting(beta)
            .normalize(true)
            .build()
            .unwrap();
        m.partial_fit(&x, &y).unwrap();
        let pen = m.ridge().unwrap().penalty().to_vec();
        // The recorded scales are within 10 % of the final sds.
        let norm = section(&m, "normalizer");
        for i in 0..4 {
            let sd = (norm[2 + 4 + i] / norm[0]).sqrt();
            let s2 = if sd > 1e-12 * norm[2 + i].abs() {
                sd * sd
            } else {
                1.0
            };
            let r = s2 / pen[i];
            assert!(
                r > 1.0 / 1.21 && r < 1.21,
                "input {i}: sd² {s2} vs penalty {}",
                pen[i]
            );
        }
        // The same raw samples, batch, with that penalty and the model's λ_eff.
        let mut batch = Ridge::new(
            4,
            2,
            RidgeParams {
                lambda: m.effective_lambda(),
                forgetting: beta,
                ..RidgeParams::default()
            },
        )
        .unwrap();
        batch.set_penalty(&pen).unwrap();
        batch.fit(&x, &y).unwrap();
        let e = rel(m.ridge().unwrap().weights(), batch.weights());
        assert!(e < 1e-8, "β {beta}: weights differ by {e:e}");
    }
}

#[test]
fn rff_is_exact_after_the_warm_up() {
    let (x, y) = samples(300);
    let k = 120;
    let cfg = ModelConfig::rff(4, 2)
        .features(40)
        .gamma(0.4)
        .seed(9)
        .lambda(0.1)
        .normalize(true)
        .normalize_samples(k);
    let mut m = cfg.build().unwrap();
    m.partial_fit(&x, &y).unwrap();
    let norm = section(&m, "normalizer");
    assert_eq!((norm[0], norm[1]), (k as f64, 1.0), "count, frozen");
    // Standardise every sample with the frozen statistics; learn without normalize.
    let z: Vec<f64> = x
        .iter()
        .enumerate()
        .map(|(j, v)| {
            let i = j % 4;
            let (mean, sd) = (norm[2 + i], (norm[6 + i] / norm[0]).sqrt());
            let s = if sd > 1e-12 * mean.abs() { sd } else { 1.0 };
            (v - mean) / s
        })
        .collect();
    let mut plain = cfg.clone().normalize(false).build().unwrap();
    plain.partial_fit(&z, &y).unwrap();
    let e = rel(
        m.ridge().unwrap().weights(),
        plain.ridge().unwrap().weights(),
    );
    assert!(e < 1e-10, "weights differ by {e:e}");
    assert_eq!(m.samples_seen(), 300);
}

#[test]
fn rff_loaded_mid_warm_up_freezes_without_replay() {
    let (x, y) = samples(60);
    let cfg = ModelConfig::rff(4, 2)
        .features(16)
        .normalize(true)
        .normalize_samples(40);
    let mut a = cfg.build().unwrap();
    a.partial_fit(&x[..80], &y[..40]).unwrap(); // 20 samples
    let mut s = vec![0.0; a.state_len()];
    a.save_state(&mut s).unwrap();
    let mut b = cfg.build().unwrap();
    b.load_state(&s).unwrap();
    b.partial_fit(&x[80..], &y[40..]).unwrap();
    assert_eq!(b.samples_seen(), 60);
    assert_eq!(section(&b, "normalizer")[..2], [40.0, 1.0]);
}
