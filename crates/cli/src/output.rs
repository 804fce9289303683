//! Writing results: JSON to stdout or to a file, always atomically for files (temp file + rename), so an
//! interrupted or failed run never leaves a half-written output behind.

use serde::Serialize;
use std::io::Write;
use std::path::Path;
use std::sync::atomic::{AtomicBool, Ordering};

/// `-q`: leave out the summaries of [`print_summary`].
static QUIET: AtomicBool = AtomicBool::new(false);

/// Sets `-q` for [`print_summary`] (once, from `main`).
pub fn set_quiet(quiet: bool) {
    QUIET.store(quiet, Ordering::Relaxed);
}

/// Says which files a command wrote (`wrote F`), unless `-q` was given: on stdout, or on stderr when stdout carries
/// the command's JSON (`json`), so that stdout stays one JSON document.
pub fn print_wrote(paths: &[&Path], json: bool) -> anyhow::Result<()> {
    if QUIET.load(Ordering::Relaxed) || paths.is_empty() {
        return Ok(());
    }
    let names: Vec<String> = paths.iter().map(|p| p.display().to_string()).collect();
    let line = format!("wrote {}\n", names.join(", "));
    if json {
        let mut err = std::io::stderr().lock();
        err.write_all(line.as_bytes())?;
        return Ok(err.flush()?);
    }
    print_text(&line)
}

/// Writes `bytes` to `path` atomically (a temporary file in the same directory, synced, then renamed): the
/// writer of `stackplan_geom::io`, so the library and the program share one implementation.
pub fn write_atomic(path: &Path, bytes: &[u8]) -> anyhow::Result<()> {
    Ok(stackplan_geom::io::atomic::write_atomic(path, bytes)?)
}

/// Writes every `(path, bytes)` or none (`stackplan_geom::io::write_all_atomic`): the outputs of one command are
/// complete together or not written.
pub fn write_all_atomic<P: AsRef<Path>, B: AsRef<[u8]>>(files: impl IntoIterator<Item = (P, B)>) -> anyhow::Result<()> {
    let files: Vec<(P, B)> = files.into_iter().collect();
    Ok(stackplan_geom::io::write_all_atomic(files.iter().map(|(p, b)| (p.as_ref(), b.as_ref())))?)
}

/// Pretty JSON text of `value` with a trailing newline.
pub fn json_text(value: &impl Serialize) -> anyhow::Result<String> {
    let mut s = serde_json::to_string_pretty(value)?;
    s.push('\n');
    Ok(s)
}

/// Prints `value` as JSON on stdout.
pub fn print_json(value: &impl Serialize) -> anyhow::Result<()> {
    print_text(&json_text(value)?)
}

/// Prints text on stdout (the one place the CLI writes results to the terminal).
pub fn print_text(text: &str) -> anyhow::Result<()> {
    let mut out = std::io::stdout().lock();
    out.write_all(text.as_bytes())?;
    out.flush()?;
    Ok(())
}

/// Prints a summary for people on stdout unless `-q` was given: the result line of `plan`, the lines of `sweep`, the
/// table of `check` without `--json`, whose outcome the files written and the exit status carry. What a command is
/// asked to show (JSON, `part info`, `place`, ...) goes through [`print_text`] / [`print_json`] whatever `-q` says.
pub fn print_summary(text: &str) -> anyhow::Result<()> {
    if QUIET.load(Ordering::Relaxed) {
        return Ok(());
    }
    print_text(text)
}

/// Renames the key at the end of `path` in `value` to `to`: `path` is the keys from the top, `*` standing for every
/// element of an array (`["placements", "*", "theta"]`). Missing keys are left alone. The JSON outputs name an angle
/// in radians with the suffix `_rad` this way where the libraries' own names carry no unit (docs/formats.md,
/// "Conventions").
pub fn rename_key(value: &mut serde_json::Value, path: &[&str], to: &str) {
    use serde_json::Value;
    match path {
        [] => {}
        ["*", rest @ ..] => {
            if let Value::Array(items) = value {
                for item in items {
                    rename_key(item, rest, to);
                }
            }
        }
        [last] => {
            if let Value::Object(map) = value
                && let Some(v) = map.remove(*last)
            {
                map.insert(to.to_string(), v);
            }
        }
        [key, rest @ ..] => {
            if let Some(inner) = value.get_mut(*key) {
                rename_key(inner, rest, to);
            }
        }
    }
}

#[cfg(test)]
mod tests {
    use super::rename_key;

    #[test]
    fn keys_are_renamed_along_a_path() {
        let mut v = serde_json::json!({"placements": [{"theta": 1.0, "cost": 2}, {"theta": 0.5}], "theta": 3});
        rename_key(&mut v, &["placements", "*", "theta"], "theta_rad");
        assert_eq!(
            v,
            serde_json::json!({"placements": [{"theta_rad": 1.0, "cost": 2}, {"theta_rad": 0.5}], "theta": 3})
        );
        rename_key(&mut v, &["missing", "theta"], "x");
        assert_eq!(v["theta"], 3);
    }
}
