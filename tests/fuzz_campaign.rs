//! The campaign fuzzer: random `--set` overrides of every scalar key of every shipped campaign
//! (huge, tiny, negative, zero, non-finite, wrong-typed values), shrunk by proptest to a minimal
//! failing case. Properties: loading never panics; a refusal names a key; an accepted campaign
//! describes itself and integrates (when short enough) without a panic and without a NaN in a
//! quantity of interest unless the instance is flagged diverged.

mod common;
use common::campaign_path;
use cryoslosh::campaign::Campaign;
use proptest::prelude::*;
use proptest::test_runner::{Config, RngAlgorithm, TestRng, TestRunner};
use std::panic::{catch_unwind, AssertUnwindSafe};

/// A scalar key path and its numeric value, if it has one.
type Key = (String, Option<f64>);

/// Every scalar key path of a TOML table (arrays by index) with its numeric value, if any.
fn scalar_keys(prefix: &str, v: &toml::Value, out: &mut Vec<Key>) {
    let join = |k: &str| {
        if prefix.is_empty() {
            k.to_string()
        } else {
            format!("{prefix}.{k}")
        }
    };
    match v {
        toml::Value::Table(t) => {
            for (k, x) in t {
                scalar_keys(&join(k), x, out);
            }
        }
        toml::Value::Array(a) if a.iter().all(|x| x.is_table()) => {
            for (i, x) in a.iter().enumerate() {
                scalar_keys(&join(&i.to_string()), x, out);
            }
        }
        toml::Value::Float(x) => out.push((prefix.to_string(), Some(*x))),
        toml::Value::Integer(i) => out.push((prefix.to_string(), Some(*i as f64))),
        _ => out.push((prefix.to_string(), None)),
    }
}

/// The shipped campaigns with their scalar keys.
fn campaigns() -> Vec<(std::path::PathBuf, Vec<Key>)> {
    let mut names: Vec<&str> = common::CAMPAIGNS.to_vec();
    names.push("template");
    names
        .into_iter()
        .map(|n| {
            let path = campaign_path(n);
            let doc: toml::Value =
                toml::from_str(&std::fs::read_to_string(&path).unwrap()).unwrap();
            let mut keys = Vec::new();
            scalar_keys("", &doc, &mut keys);
            (path, keys)
        })
        .collect()
}

/// A value to set: literal text, or the key's current value times a factor (plausible values,
/// so that accepted campaigns are fuzzed too).
#[derive(Clone, Debug)]
enum Val {
    Text(String),
    Scale(f64),
}

/// Values a user (or a typo) might give.
fn value() -> impl Strategy<Value = Val> {
    prop_oneof![
        3 => (0.3f64..3.0).prop_map(Val::Scale),
        1 => text().prop_map(Val::Text),
    ]
}

fn text() -> impl Strategy<Value = String> {
    prop_oneof![
        (-300i32..300).prop_map(|e| format!("1e{e}")),
        (-300i32..300).prop_map(|e| format!("-3.7e{e}")),
        (-1000.0f64..1000.0).prop_map(|x| format!("{x}")),
        (0u64..100).prop_map(|x| x.to_string()),
        Just("0".to_string()),
        Just("nan".to_string()),
        Just("inf".to_string()),
        Just("-inf".to_string()),
        Just("true".to_string()),
        Just("abc".to_string()),
    ]
}

#[test]
fn fuzzed_overrides_never_panic_and_refusals_name_a_key() {
    let all = campaigns();
    let n_campaigns = all.len();
    let strategy = (
        0..n_campaigns,
        proptest::collection::vec((any::<prop::sample::Index>(), value()), 1..4),
    );
    let config = Config {
        cases: 400,
        failure_persistence: None,
        ..Config::default()
    };
    let mut runner =
        TestRunner::new_with_rng(config, TestRng::deterministic_rng(RngAlgorithm::ChaCha));
    let (refused, accepted, integrated) = (
        std::cell::Cell::new(0u32),
        std::cell::Cell::new(0u32),
        std::cell::Cell::new(0u32),
    );
    let result = runner.run(&strategy, |(ci, sets)| {
        let (path, keys) = &all[ci];
        let overrides: Vec<String> = sets
            .iter()
            .map(|(ix, v)| {
                let (key, current) = ix.get(keys);
                let v = match (v, current) {
                    (Val::Scale(f), Some(x)) => {
                        let y = x * f;
                        // Integer keys (counts, seeds) stay integers.
                        if x.fract() == 0.0 {
                            format!("{}", y.round())
                        } else {
                            format!("{y}")
                        }
                    }
                    (Val::Scale(f), None) => format!("{f}"),
                    (Val::Text(t), _) => t.clone(),
                };
                format!("{key}={v}")
            })
            .collect();
        let loaded = catch_unwind(AssertUnwindSafe(|| Campaign::load(path, &overrides)));
        let Ok(loaded) = loaded else {
            return Err(TestCaseError::fail(format!("load panicked: {overrides:?}")));
        };
        let c = match loaded {
            Err(e) => {
                let text = e.to_string();
                let named = e.key().is_some()
                    || overrides
                        .iter()
                        .any(|o| text.contains(o.split('=').next().unwrap_or("")));
                prop_assert!(named, "a refusal must name a key: {text} ({overrides:?})");
                refused.set(refused.get() + 1);
                return Ok(());
            }
            Ok(c) => c,
        };
        accepted.set(accepted.get() + 1);
        let described = catch_unwind(AssertUnwindSafe(|| cryoslosh::campaign::describe(&c)));
        prop_assert!(described.is_ok(), "describe panicked: {overrides:?}");
        let steps: u64 = c.phases.iter().map(|p| p.steps().0).sum();
        if steps > 200_000 {
            return Ok(()); // too long for a fuzz case; check limits the count anyway
        }
        let q = catch_unwind(AssertUnwindSafe(|| {
            cryoslosh::simulate::simulate(&c, &c.params, None)
        }));
        let Ok(q) = q else {
            return Err(TestCaseError::fail(format!(
                "simulate panicked: {overrides:?}"
            )));
        };
        integrated.set(integrated.get() + 1);
        if !q.diverged {
            for (name, v) in [
                ("peak_pressure_pa", q.peak_pressure_pa),
                ("boiloff_kg", q.boiloff_kg),
                ("vented_kg", q.vented_kg),
                ("max_slosh_angle_rad", q.max_slosh_angle_rad),
                ("final_time_s", q.final_time_s),
            ] {
                prop_assert!(
                    v.is_finite(),
                    "{name} = {v} without divergence: {overrides:?}"
                );
            }
        }
        Ok(())
    });
    if let Err(e) = result {
        panic!("{e}");
    }
    eprintln!(
        "fuzz: {} refused, {} accepted, {} integrated",
        refused.get(),
        accepted.get(),
        integrated.get()
    );
    // The fuzzer must exercise both sides, or it proves nothing.
    assert!(refused.get() > 10 && accepted.get() > 10 && integrated.get() > 5);
}
