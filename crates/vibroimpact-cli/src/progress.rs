//! Progress on standard error (indicatif), drawn only when standard error
//! is a terminal: piped or redirected runs stay quiet.

use std::io::IsTerminal;

use indicatif::{ProgressBar, ProgressDrawTarget, ProgressStyle};

fn target() -> ProgressDrawTarget {
    if std::io::stderr().is_terminal() {
        ProgressDrawTarget::stderr()
    } else {
        ProgressDrawTarget::hidden()
    }
}

/// A bar over `total` units of `what` (e.g. "values").
pub fn bar(total: usize, what: &str) -> ProgressBar {
    let style = ProgressStyle::with_template(&format!(
        "{{prefix}} [{{bar:30}}] {{pos}}/{{len}} {what} ({{eta}} left)"
    ))
    .unwrap_or_else(|_| ProgressStyle::default_bar())
    .progress_chars("=> ");
    ProgressBar::with_draw_target(Some(total as u64), target()).with_style(style)
}

/// A line of status messages without a known end (e.g. a branch's points).
pub fn status() -> ProgressBar {
    let style = ProgressStyle::with_template("{spinner} {pos} points  {msg}")
        .unwrap_or_else(|_| ProgressStyle::default_spinner());
    ProgressBar::with_draw_target(None, target()).with_style(style)
}

/// Says up front, on standard error, that a run will take long (its
/// estimated steps and time), if it will; the run goes on.
pub fn announce_long(work: Option<vibroimpact::simulate::WorkEstimate>) {
    announce_long_as(work, "Ctrl-C stops it and keeps what is complete");
}

/// [`announce_long`] with what Ctrl-C does to this command's results.
pub fn announce_long_as(work: Option<vibroimpact::simulate::WorkEstimate>, on_stop: &str) {
    if let Some(work) = work.filter(|w| w.is_long()) {
        eprintln!("note: {}; {on_stop}", work.describe());
    }
}
