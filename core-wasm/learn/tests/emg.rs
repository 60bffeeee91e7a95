//! A regression on the real recording pipelines/data/emg_bursts_1000hz.csv
//! (biceps brachii, cyclic contractions; fixture fixtures/emg_regression.json
//! from fixtures/gen_emg_regression.py, which defines the target).
//!
//! Inputs: MAV, RMS, WL, ZC, SSC of 200 ms windows every 50 ms, computed here
//! with mosaic-dsp's `WindowedFeatures` exactly as a pipeline would, and
//! checked against the fixture's NumPy features. Target: the normalised
//! zero-phase 1 Hz envelope of the EMG at each window's centre. The models
//! learn **incrementally**, one window at a time, on the first 70 % of the
//! recording and are scored (R²) on the last 30 %.
//!
//! Results (printed by `cargo test -p mosaic-learn --test emg -- --nocapture`):
//! * with features standardised by the training split's statistics, the
//!   incremental ridge (λ = 1) and RFF (given Ω, b) models equal
//!   scikit-learn's batch models: held-out R² 0.9534 and 0.9547;
//! * online, on raw features with the model's own normalisation (what an
//!   IncrementalPredictor with `Normalize: true` does): held-out R² 0.9533
//!   (ridge, λ = 1) and 0.9554 (RFF, D = 100, γ = 0.05, our own seed-0 draws,
//!   statistics frozen after the first 200 training samples).

#[path = "../../dsp/tests/common/mod.rs"]
mod common;

use common::fixture;
use mosaic_dsp::{Feature, FeatureSpec, WindowedFeatures};
use mosaic_learn::{ModelConfig, PredictingMachine, RandomFourierFeatures, RidgeParams};
use std::path::PathBuf;

fn recording() -> Vec<f64> {
    let path = PathBuf::from(env!("CARGO_MANIFEST_DIR"))
        .join("../../pipelines/data/emg_bursts_1000hz.csv");
    let text = std::fs::read_to_string(&path).unwrap_or_else(|e| panic!("{}: {e}", path.display()));
    text.lines()
        .skip(1)
        .map(|l| l.split(',').nth(1).unwrap().parse().unwrap())
        .collect()
}

fn r2(pred: &[f64], y: &[f64]) -> f64 {
    let mean = y.iter().sum::<f64>() / y.len() as f64;
    let sst: f64 = y.iter().map(|v| (v - mean).powi(2)).sum();
    let sse: f64 = pred.iter().zip(y).map(|(p, v)| (p - v).powi(2)).sum();
    1.0 - sse / sst
}

struct Task {
    x: Vec<f64>,
    y: Vec<f64>,
    n: usize,
    train: usize,
}

fn task() -> (Task, common::Json) {
    let fx = fixture("emg_regression.json");
    let rec = fx.get("recording");
    let (len, step) = (
        rec.get("length").num() as usize,
        rec.get("step").num() as usize,
    );
    let th = rec.get("thresholds");
    let specs = [
        FeatureSpec::new(Feature::Mav),
        FeatureSpec::new(Feature::Rms),
        FeatureSpec::new(Feature::Wl),
        FeatureSpec::with_threshold(Feature::Zc, th.get("ZC").num()),
        FeatureSpec::with_threshold(Feature::Ssc, th.get("SSC").num()),
    ];
    let emg = recording();
    let mut wf = WindowedFeatures::new(&specs, len, step, 1).unwrap();
    let most = wf.windows_for(emg.len());
    let mut x = vec![0.0; most * 5];
    let mut ends = vec![0usize; most];
    let n = wf.process(&emg, &mut x, &mut ends).unwrap();
    x.truncate(n * 5);
    // Our features are the fixture's NumPy features.
    let reference = fx.get("x").nums();
    assert_eq!(x.len(), reference.len());
    for (i, (a, b)) in x.iter().zip(&reference).enumerate() {
        assert!((a - b).abs() <= 1e-12 * b.abs(), "feature {i}: {a} vs {b}");
    }
    let ends_ref: Vec<usize> = fx.get("ends").nums().iter().map(|&e| e as usize).collect();
    assert_eq!(&ends[..n], &ends_ref[..]);
    let t = Task {
        x,
        y: fx.get("y").nums(),
        n,
        train: fx.get("train").num() as usize,
    };
    (t, fx)
}

#[test]
fn standardised_features_reproduce_sklearn() {
    let (t, fx) = task();
    let mean = fx.get("train_mean").nums();
    let sd = fx.get("train_sd").nums();
    let z: Vec<f64> =
        t.x.iter()
            .enumerate()
            .map(|(i, v)| (v - mean[i % 5]) / sd[i % 5])
            .collect();
    let (ztr, zte) = z.split_at(t.train * 5);
    let (ytr, yte) = t.y.split_at(t.train);

    let mut ridge = ModelConfig::ridge(5, 1).lambda(1.0).build().unwrap();
    for (x, y) in ztr.chunks(5).zip(ytr.chunks(1)) {
        ridge.partial_fit(x, y).unwrap();
    }
    let mut p = vec![0.0; t.n - t.train];
    ridge.predict(zte, &mut p).unwrap();
    let reference = fx.get("ridge");
    let e = p
        .iter()
        .zip(reference.get("predictions").nums())
        .fold(0.0f64, |m, (a, b)| m.max((a - b).abs()));
    assert!(e < 1e-8, "ridge predictions {e:e}");
    let score = r2(&p, yte);
    println!("EMG, ridge (λ 1), train-split standardisation: held-out R² {score:.4}");
    assert!((score - reference.get("r2").num()).abs() < 1e-8);

    let rf = fx.get("rff");
    let params = RidgeParams {
        lambda: 1.0,
        ..RidgeParams::default()
    };
    let mut rff = RandomFourierFeatures::with_weights(
        5,
        1,
        rf.get("gamma").num(),
        &rf.get("omega").nums(),
        &rf.get("offset").nums(),
        params,
    )
    .unwrap();
    for (x, y) in ztr.chunks(5).zip(ytr.chunks(1)) {
        rff.partial_fit(x, y).unwrap();
    }
    rff.predict(zte, &mut p).unwrap();
    let e = p
        .iter()
        .zip(rf.get("predictions").nums())
        .fold(0.0f64, |m, (a, b)| m.max((a - b).abs()));
    assert!(e < 1e-8, "rff predictions {e:e}");
    let score = r2(&p, yte);
    println!("EMG, RFF (D 100, γ 0.05, λ 1), train-split standardisation: held-out R² {score:.4}");
    assert!((score - rf.get("r2").num()).abs() < 1e-8);
}

#[test]
fn online_learning_with_running_normalisation() {
    let (t, _) = task();
    let (xtr, xte) = t.x.split_at(t.train * 5);
    let (ytr, yte) = t.y.split_at(t.train);
    for (name, cfg, floor) in [
        ("ridge (λ 1)", ModelConfig::ridge(5, 1), 0.95),
        (
            "RFF (D 100, γ 0.05, λ 1, seed 0)",
            ModelConfig::rff(5, 1).features(100).gamma(0.05),
            0.95,
        ),
    ] {
        let mut m = cfg.normalize(true).build().unwrap();
        for (x, y) in xtr.chunks(5).zip(ytr.chunks(1)) {
            m.partial_fit(x, y).unwrap();
        }
        let mut p = vec![0.0; t.n - t.train];
        m.predict(xte, &mut p).unwrap();
        let score = r2(&p, yte);
        let mut running = [0.0];
        m.r2(&mut running);
        println!(
            "EMG, {name}, own normalisation: held-out R² {score:.4} \
             (prequential R² on the training samples {:.4})",
            running[0]
        );
        assert!(score > floor, "{name}: held-out R² {score}");
    }
}
