//! A command's options given as a JSON object instead of a command line: the jobs of `stackplan batch` and the
//! keyword arguments of the Python package. The object is turned into the command's own arguments and parsed by its
//! own parser, so the defaults, the checks and the messages are the command line's.

use clap::FromArgMatches;
use serde_json::{Map, Value};

/// Parses `options` (keys: the command's long options without `--`, `_` for `-`; values: numbers, strings,
/// `true`/`false` for flags, arrays of numbers for comma-separated lists, `null` for the default) as the arguments of
/// `A`, after the `positional` arguments. `hidden`: options that cannot be given this way; `positional_keys`: the
/// keys that name the positional arguments (listed in the message of an unknown key). The error is one line and
/// names the key.
pub fn command_args<A: clap::Args + FromArgMatches>(
    options: &Map<String, Value>,
    positional: &[String],
    hidden: &[&str],
    positional_keys: &[&str],
) -> Result<A, String> {
    let command = crate::with_negatives(A::augment_args(clap::Command::new("options")).no_binary_name(true));
    let keys: Vec<String> = command
        .get_arguments()
        .filter_map(|a| a.get_long())
        .filter(|l| !hidden.contains(l) && !matches!(*l, "help" | "json"))
        .map(|l| l.replace('-', "_"))
        .collect();
    let mut argv: Vec<String> = positional.to_vec();
    for (key, value) in options {
        if !keys.contains(key) {
            let mut all: Vec<&str> = positional_keys.to_vec();
            all.extend(keys.iter().map(String::as_str));
            return Err(format!("unknown key `{key}` (the keys are {})", all.join(", ")));
        }
        let flag = key.replace('_', "-");
        let text = match value {
            Value::Null | Value::Bool(false) => continue,
            Value::Bool(true) => {
                argv.push(format!("--{flag}"));
                continue;
            }
            Value::Number(n) => n.to_string(),
            Value::String(s) => s.clone(),
            Value::Array(items) if items.iter().all(Value::is_number) => {
                items.iter().map(Value::to_string).collect::<Vec<_>>().join(",")
            }
            other => {
                return Err(format!(
                    "key `{key}`: expected a number, a string, true/false or a list of numbers, got {other}"
                ));
            }
        };
        argv.push(format!("--{flag}={text}"));
    }
    let key_names = |text: &str| {
        // clap's message names the option (`'--dtheta-deg <DEG>'`): name the key instead
        let mut text = text.to_string();
        for key in &keys {
            let flag = key.replace('_', "-");
            text = text.replace(&format!("'--{flag}"), &format!("'{key}"));
        }
        text
    };
    let first_line = |e: clap::Error| {
        let text = e.to_string();
        key_names(text.lines().next().unwrap_or("invalid options").trim_start_matches("error: "))
    };
    let matches = command.try_get_matches_from(argv).map_err(first_line)?;
    A::from_arg_matches(&matches).map_err(first_line)
}
