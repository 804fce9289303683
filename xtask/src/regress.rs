//! `cargo xtask regress [--bless] [FILTER]`: scenario files in `fixtures/regress/*.json`, golden results in
//! `fixtures/regress/golden/<scenario>.json`.
//!
//! A scenario is `{"kind": "...", ...kind-specific inputs..., "tolerances": {"field": {"rel": r, "abs": a}}}`.
//! Running it yields a flat map of named result fields (numbers, integers, strings, booleans, arrays of them).
//! With `"expect_error": true` the scenario's request must fail, and its error message (field `error`) is compared
//! with the golden's. Numbers are compared with `|actual - golden| <= max(abs, rel * |golden|)` (default rel 1e-9, abs 1e-12; a field
//! named in `tolerances` uses its own); everything else must be equal. Fields prefixed with `info_` are recorded
//! (e.g. timings) but never compared. `--slow` adds the scenarios of `fixtures/regress/slow/` when that directory
//! exists (scenarios too slow for CI in the dev profile; goldens in `fixtures/regress/slow/golden/`): the 15-part plan
//! of the real part `bendfm_0`, whose last seven parts each go to the floor after thousands of perched candidates
//! fail. The seed's full 121-cube Fig. 2 and 15-part Complex Fig. 20 run in the default set.

use anyhow::Context;
use serde_json::{Map, Value};
use std::collections::BTreeMap;
use std::path::Path;

/// Result fields of one scenario, by name.
pub type Fields = BTreeMap<String, Value>;

#[derive(Debug, Clone, Copy)]
struct Tol {
    rel: f64,
    abs: f64,
}

const DEFAULT_TOL: Tol = Tol { rel: 1e-9, abs: 1e-12 };

fn tolerances(scenario: &Value) -> BTreeMap<String, Tol> {
    let mut out = BTreeMap::new();
    if let Some(Value::Object(m)) = scenario.get("tolerances") {
        for (k, v) in m {
            let rel = v.get("rel").and_then(Value::as_f64).unwrap_or(0.0);
            let abs = v.get("abs").and_then(Value::as_f64).unwrap_or(0.0);
            out.insert(k.clone(), Tol { rel, abs });
        }
    }
    out
}

fn same(golden: &Value, actual: &Value, tol: Tol) -> bool {
    match (golden, actual) {
        (Value::Number(g), Value::Number(a)) => {
            if let (Some(g), Some(a)) = (g.as_i64(), a.as_i64())
                && tol.rel == DEFAULT_TOL.rel
                && tol.abs == DEFAULT_TOL.abs
            {
                return g == a;
            }
            match (g.as_f64(), a.as_f64()) {
                (Some(g), Some(a)) => (g - a).abs() <= tol.abs.max(tol.rel * g.abs()),
                _ => false,
            }
        }
        (Value::Array(g), Value::Array(a)) => g.len() == a.len() && g.iter().zip(a).all(|(g, a)| same(g, a, tol)),
        (Value::Object(g), Value::Object(a)) => {
            g.len() == a.len() && g.iter().all(|(k, gv)| a.get(k).is_some_and(|av| same(gv, av, tol)))
        }
        _ => golden == actual,
    }
}

fn short(v: &Value) -> String {
    let s = v.to_string();
    if s.len() > 38 { format!("{}...", &s[..35]) } else { s }
}

/// Runs the scenarios of `fixtures/regress/` (and, with `slow`, of `fixtures/regress/slow/`, each directory with
/// its own `golden/`); returns false when any result differs from its golden (or a golden is missing).
pub fn run(root: &Path, bless: bool, filter: Option<&str>, slow: bool) -> anyhow::Result<bool> {
    let dir = root.join("fixtures").join("regress");
    println!("{:<34} {:<28} {:<40} {:<40} status", "scenario", "field", "golden", "actual");
    let mut all_ok = run_dir(&dir, bless, filter)?;
    if slow && dir.join("slow").is_dir() {
        all_ok &= run_dir(&dir.join("slow"), bless, filter)?;
    }
    if !bless {
        println!(
            "{}",
            if all_ok { "regress: all scenarios match their goldens" } else { "regress: DIFFERENCES FOUND" }
        );
    }
    Ok(all_ok)
}

/// The scenarios of one directory.
fn run_dir(dir: &Path, bless: bool, filter: Option<&str>) -> anyhow::Result<bool> {
    let golden_dir = dir.join("golden");
    std::fs::create_dir_all(&golden_dir)?;
    let mut files: Vec<_> = std::fs::read_dir(dir)
        .with_context(|| format!("cannot read {}", dir.display()))?
        .filter_map(Result::ok)
        .map(|e| e.path())
        .filter(|p| p.extension().is_some_and(|x| x == "json"))
        .collect();
    files.sort();
    let mut all_ok = true;
    for path in files {
        let name = path.file_stem().map(|s| s.to_string_lossy().into_owned()).unwrap_or_default();
        if filter.is_some_and(|f| !name.contains(f)) {
            continue;
        }
        let text = std::fs::read_to_string(&path).with_context(|| format!("cannot read {}", path.display()))?;
        let scenario: Value =
            serde_json::from_str(&text).with_context(|| format!("{} is not valid JSON", path.display()))?;
        let started = std::time::Instant::now();
        let mut fields = match crate::scenarios::run(&scenario, dir) {
            Ok(f) => f,
            // a scenario of a request that must fail: its error text is the golden
            Err(e) if scenario.get("expect_error").and_then(Value::as_bool) == Some(true) => {
                std::iter::once(("error".to_string(), Value::from(format!("{e:#}")))).collect()
            }
            Err(e) => {
                println!("{name:<34} {:<28} {:<40} {:<40} ERROR", "-", "-", format!("{e:#}"));
                all_ok = false;
                continue;
            }
        };
        fields.insert("info_seconds".into(), Value::from((started.elapsed().as_secs_f64() * 1e3).round() / 1e3));
        let golden_path = golden_dir.join(format!("{name}.json"));
        if bless {
            let obj: Map<String, Value> = fields.into_iter().collect();
            let mut text = serde_json::to_string_pretty(&Value::Object(obj))?;
            text.push('\n');
            stackplan_geom::io::write_atomic(&golden_path, text.as_bytes())
                .with_context(|| format!("cannot write {}", golden_path.display()))?;
            println!("{name:<34} blessed");
            continue;
        }
        let golden: Map<String, Value> = match std::fs::read_to_string(&golden_path) {
            Ok(t) => {
                serde_json::from_str(&t).with_context(|| format!("{} is not valid JSON", golden_path.display()))?
            }
            Err(_) => {
                println!("{name:<34} {:<28} {:<40} {:<40} NO GOLDEN (run with --bless)", "-", "-", "-");
                all_ok = false;
                continue;
            }
        };
        let tols = tolerances(&scenario);
        let mut keys: Vec<&String> = golden.keys().chain(fields.keys()).collect();
        keys.sort();
        keys.dedup();
        for key in keys {
            let (g, a) = (golden.get(key), fields.get(key));
            let status = if key.starts_with("info_") {
                "info"
            } else {
                match (g, a) {
                    (Some(g), Some(a)) if same(g, a, *tols.get(key).unwrap_or(&DEFAULT_TOL)) => "ok",
                    _ => {
                        all_ok = false;
                        "DIFFERS"
                    }
                }
            };
            let show = |v: Option<&Value>| v.map_or_else(|| "(missing)".to_string(), short);
            println!("{name:<34} {key:<28} {:<40} {:<40} {status}", show(g), show(a));
        }
    }
    Ok(all_ok)
}

#[cfg(test)]
mod tests {
    use super::*;
    use serde_json::json;

    #[test]
    fn tolerant_comparison() {
        let t = Tol { rel: 1e-6, abs: 0.0 };
        assert!(same(&json!(1.0), &json!(1.0000001), t));
        assert!(!same(&json!(1.0), &json!(1.01), t));
        assert!(same(&json!(3), &json!(3), DEFAULT_TOL));
        assert!(!same(&json!(3), &json!(4), DEFAULT_TOL));
        assert!(same(&json!([1.0, "a"]), &json!([1.0000001, "a"]), t));
        assert!(!same(&json!([1.0, "a"]), &json!([1.0, "b"]), t));
    }
}
