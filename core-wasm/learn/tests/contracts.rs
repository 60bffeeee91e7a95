//! Contract tests over every kind of model:
//! * learning n samples in one call equals n calls of one sample, and any
//!   other split (bit-exact state and predictions); the same for
//!   `train_predict`;
//! * after `reset()` the same samples give a bit-identical model;
//! * a saved state loads into a fresh model that predicts the same;
//! * `fit` forgets what was learnt before.

use mosaic_learn::{Model, ModelConfig, PredictingMachine};

fn configs() -> Vec<(&'static str, ModelConfig)> {
    vec![
        ("ridge", ModelConfig::ridge(4, 3)),
        (
            "ridge, no intercept",
            ModelConfig::ridge(4, 3).intercept(false),
        ),
        (
            "ridge, forgetting 0.97, normalize",
            ModelConfig::ridge(4, 3).forgetting(0.97).normalize(true),
        ),
        (
            "ridge, refactor every 7",
            ModelConfig::ridge(4, 3).lambda(1e-3).refactor_every(7),
        ),
        (
            "rff",
            ModelConfig::rff(4, 3).features(24).gamma(0.3).seed(5),
        ),
        (
            "rff, forgetting 0.9, normalize, no intercept",
            ModelConfig::rff(4, 3)
                .features(16)
                .forgetting(0.9)
                .normalize(true)
                .intercept(false),
        ),
    ]
}

fn samples(n: usize) -> (Vec<f64>, Vec<f64>) {
    let (mut x, mut y) = (Vec::new(), Vec::new());
    for i in 0..n {
        let t = i as f64;
        let xi = [
            (0.3 * t).sin(),
            (0.11 * t).cos() * 2.0,
            t.sqrt(),
            1.0 / (1.0 + t),
        ];
        x.extend_from_slice(&xi);
        y.extend_from_slice(&[xi[0] + xi[1] * xi[2], -xi[3], (0.7 * t).sin()]);
    }
    (x, y)
}

fn state(m: &Model) -> Vec<u64> {
    let mut s = vec![0.0; m.state_len()];
    m.save_state(&mut s).unwrap();
    s.iter().map(|v| v.to_bits()).collect()
}

#[test]
fn any_split_gives_the_same_model() {
    let (x, y) = samples(120);
    for (name, cfg) in configs() {
        let mut whole = cfg.build().unwrap();
        whole.partial_fit(&x, &y).unwrap();
        let reference = state(&whole);

        let mut one = cfg.build().unwrap();
        for (xi, yi) in x.chunks(4).zip(y.chunks(3)) {
            one.partial_fit(xi, yi).unwrap();
        }
        assert_eq!(state(&one), reference, "{name}: one by one");

        let mut split = cfg.build().unwrap();
        let mut at = 0;
        for k in [1, 5, 2, 30, 7, 75] {
            split
                .partial_fit(&x[at * 4..(at + k) * 4], &y[at * 3..(at + k) * 3])
                .unwrap();
            at += k;
        }
        assert_eq!(at, 120);
        assert_eq!(state(&split), reference, "{name}: uneven split");

        whole.reset();
        whole.partial_fit(&x, &y).unwrap();
        assert_eq!(state(&whole), reference, "{name}: after reset");
    }
}

#[test]
fn train_predict_is_split_invariant() {
    let (x, _) = samples(60);
    let target = [0.5, -1.0, 2.0];
    for (name, cfg) in configs() {
        let mut a = cfg.build().unwrap();
        let mut pa = vec![0.0; 60 * 3];
        assert_eq!(a.train_predict(&x, &target, &mut pa).unwrap(), 60);
        let mut b = cfg.build().unwrap();
        let mut pb = vec![0.0; 60 * 3];
        for i in 0..60 {
            b.train_predict(&x[i * 4..i * 4 + 4], &target, &mut pb[i * 3..i * 3 + 3])
                .unwrap();
        }
        let bits = |v: &[f64]| v.iter().map(|x| x.to_bits()).collect::<Vec<_>>();
        assert_eq!(bits(&pa), bits(&pb), "{name}");
        assert_eq!(state(&a), state(&b), "{name}");
        // Learn, then predict: the prediction of the sample just learnt.
        let mut p = vec![0.0; 3];
        b.predict(&x[59 * 4..], &mut p).unwrap();
        assert_eq!(bits(&p), bits(&pb[59 * 3..]), "{name}");
    }
}

#[test]
fn saved_state_round_trip() {
    let (x, y) = samples(80);
    let (xt, _) = samples(10);
    for (name, cfg) in configs() {
        let mut a = cfg.build().unwrap();
        a.partial_fit(&x, &y).unwrap();
        let mut s = vec![0.0; a.state_len()];
        a.save_state(&mut s).unwrap();
        let mut b = cfg.build().unwrap();
        b.load_state(&s).unwrap();
        assert_eq!(b.samples_seen(), 80);
        let (mut pa, mut pb) = (vec![0.0; 30], vec![0.0; 30]);
        a.predict(&xt, &mut pa).unwrap();
        b.predict(&xt, &mut pb).unwrap();
        // Bit for bit: the loaded model predicts with the saved weights.
        assert_eq!(pa, pb, "{name}: the loaded model predicts otherwise");
        // Both go on learning alike.
        a.partial_fit(&x[..40], &y[..30]).unwrap();
        b.partial_fit(&x[..40], &y[..30]).unwrap();
        a.predict(&xt, &mut pa).unwrap();
        b.predict(&xt, &mut pb).unwrap();
        let e = pa
            .iter()
            .zip(&pb)
            .fold(0.0f64, |m, (p, q)| m.max((p - q).abs()));
        assert!(e < 1e-9, "{name}: after more learning, {e:e} apart");
    }
}

#[test]
fn fit_forgets_what_came_before() {
    let (x, y) = samples(50);
    for (name, cfg) in configs() {
        let mut fresh = cfg.build().unwrap();
        fresh.fit(&x, &y).unwrap();
        let mut used = cfg.build().unwrap();
        used.partial_fit(&y[..12], &x[..9]).ok(); // shapes differ on purpose: an error
        used.partial_fit(&x[40..], &y[30..]).unwrap();
        used.fit(&x, &y).unwrap();
        assert_eq!(state(&used), state(&fresh), "{name}");
    }
}
