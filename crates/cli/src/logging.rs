//! What the program writes on stderr besides errors: warnings, each printed once with a count, and (with `-v`) the
//! libraries' progress messages.
//!
//! The libraries log through `tracing` (and tiny-skia through `log`), often once per call: a warning raised for
//! every face of a part or every candidate of a plan would fill the terminal with copies. [`WarningTally`] keeps
//! each distinct warning (its message, without the fields that vary from call to call) with the number of times it
//! was raised and the fields of its first occurrence, and [`flush_warnings`] prints them once, at the end of the
//! command: `warning: a free-space cell could not be solved: skipped (37 times; first: orientation=3 ...)`.
//!
//! Escape codes (colour) are written only when stderr is a terminal and `NO_COLOR` is unset or empty
//! (<https://no-color.org>); the warnings and errors themselves are plain text.

use std::collections::HashMap;
use std::fmt::Write as _;
use std::io::IsTerminal;
use std::sync::Mutex;
use tracing::field::{Field, Visit};
use tracing::{Event, Level, Subscriber};
use tracing_subscriber::layer::{Context, Layer};

/// One distinct warning: its text, the fields of its first occurrence, and how often it was raised.
#[derive(Debug, Clone, PartialEq, Eq)]
pub struct Warning {
    /// The message (for a `log` record, its text).
    pub message: String,
    /// `key=value` of the first occurrence's other fields, space-separated (empty when it had none).
    pub first_fields: String,
    /// How many times it was raised.
    pub count: usize,
}

impl Warning {
    /// The line printed for it: `warning: MESSAGE`, then ` (N times; first: FIELDS)` as they apply.
    pub fn line(&self) -> String {
        let mut line = format!("warning: {}", self.message);
        match (self.count > 1, self.first_fields.is_empty()) {
            (true, true) => {
                let _ = write!(line, " ({} times)", self.count);
            }
            (true, false) => {
                let _ = write!(line, " ({} times; first: {})", self.count, self.first_fields);
            }
            (false, false) => {
                let _ = write!(line, " ({})", self.first_fields);
            }
            (false, true) => {}
        }
        line
    }
}

/// Distinct warnings in the order they were first raised.
#[derive(Debug, Default)]
struct Tally {
    order: Vec<Warning>,
    index: HashMap<String, usize>,
}

impl Tally {
    fn add(&mut self, message: String, fields: String) {
        match self.index.get(&message) {
            Some(&k) => self.order[k].count += 1,
            None => {
                self.index.insert(message.clone(), self.order.len());
                self.order.push(Warning { message, first_fields: fields, count: 1 });
            }
        }
    }
}

/// The warnings of this process (shared by every [`WarningTally`] installed in it).
static WARNINGS: Mutex<Option<Tally>> = Mutex::new(None);

/// A `tracing` layer that counts warnings and errors instead of printing them (see the module documentation).
#[derive(Debug, Default, Clone, Copy)]
pub struct WarningTally;

/// Collects an event's message and its other fields.
#[derive(Default)]
struct Fields {
    message: String,
    others: String,
}

impl Visit for Fields {
    fn record_str(&mut self, field: &Field, value: &str) {
        if field.name() == "message" {
            self.message = value.to_string();
        } else {
            self.record_debug(field, &value);
        }
    }

    fn record_debug(&mut self, field: &Field, value: &dyn std::fmt::Debug) {
        let name = field.name();
        if name == "message" {
            self.message = format!("{value:?}");
        } else if !name.starts_with("log.") {
            // (the `log` bridge's own fields: target, module, file and line)
            if !self.others.is_empty() {
                self.others.push(' ');
            }
            let _ = write!(self.others, "{name}={value:?}");
        }
    }
}

impl<S: Subscriber> Layer<S> for WarningTally {
    fn on_event(&self, event: &Event<'_>, _ctx: Context<'_, S>) {
        if *event.metadata().level() > Level::WARN {
            return;
        }
        let mut fields = Fields::default();
        event.record(&mut fields);
        if let Ok(mut tally) = WARNINGS.lock() {
            tally.get_or_insert_with(Tally::default).add(fields.message, fields.others);
        }
    }
}

/// Takes the warnings raised so far, each once with its count, in the order they were first raised.
pub fn take_warnings() -> Vec<Warning> {
    match WARNINGS.lock() {
        Ok(mut tally) => tally.take().map(|t| t.order).unwrap_or_default(),
        Err(_) => Vec::new(),
    }
}

/// Prints the warnings raised so far on stderr, one line each ([`Warning::line`]).
pub fn flush_warnings() {
    let warnings = take_warnings();
    if warnings.is_empty() {
        return;
    }
    let mut text = String::new();
    for w in &warnings {
        text.push_str(&w.line());
        text.push('\n');
    }
    // the one place besides errors where the program writes to stderr itself
    #[allow(clippy::print_stderr)]
    {
        eprint!("{text}");
    }
}

/// Whether escape codes may be written to stderr: it is a terminal and `NO_COLOR` is unset or empty.
pub fn stderr_colour() -> bool {
    std::io::stderr().is_terminal() && std::env::var_os("NO_COLOR").is_none_or(|v| v.is_empty())
}

/// Installs the logging of the program: warnings and errors tallied ([`WarningTally`]), the libraries' messages at
/// the level `-v` asks for written as they come (through the progress bars' writer, so they do not tear a bar), and
/// `log` records (tiny-skia's) taken in as `tracing` events. `STACKPLAN_LOG` overrides the level filter.
pub fn init(verbose: u8, quiet: bool) {
    use tracing_subscriber::prelude::*;
    let level = if quiet {
        "error"
    } else {
        match verbose {
            0 => "warn",
            1 => "info",
            2 => "debug",
            _ => "trace",
        }
    };
    let filter = tracing_subscriber::EnvFilter::try_from_env("STACKPLAN_LOG")
        .unwrap_or_else(|_| tracing_subscriber::EnvFilter::new(level));
    let indicatif_layer = tracing_indicatif::IndicatifLayer::new();
    let messages = tracing_subscriber::fmt::layer()
        .with_writer(indicatif_layer.get_stderr_writer())
        .with_target(false)
        .with_ansi(stderr_colour())
        .with_filter(tracing_subscriber::filter::filter_fn(|meta| *meta.level() > Level::WARN));
    let _ =
        tracing_subscriber::registry().with(filter).with(messages).with(WarningTally).with(indicatif_layer).try_init();
}

#[cfg(test)]
mod tests {
    use super::*;
    use tracing_subscriber::prelude::*;

    /// A hundred identical warnings whose fields differ are one line with the count and the first one's fields; a
    /// warning raised once is a line of its own; info messages are not tallied.
    #[test]
    fn identical_warnings_are_counted_once() {
        let subscriber = tracing_subscriber::registry().with(WarningTally);
        tracing::subscriber::with_default(subscriber, || {
            for k in 0..100 {
                tracing::warn!(orientation = k, "a free-space cell could not be solved: skipped");
            }
            tracing::warn!("the part is only 5 mm across");
            tracing::info!("not a warning");
            tracing::error!("an error");
        });
        let warnings = take_warnings();
        let lines: Vec<String> = warnings.iter().map(Warning::line).collect();
        assert_eq!(
            lines,
            [
                "warning: a free-space cell could not be solved: skipped (100 times; first: orientation=0)",
                "warning: the part is only 5 mm across",
                "warning: an error",
            ]
        );
        assert!(take_warnings().is_empty(), "taken once");
    }
}
