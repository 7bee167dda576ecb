//! Progress bars for long host work (dataset renders, evaluations, tuning): drawn on
//! stderr when it is a terminal, hidden otherwise so that logs and pipes stay clean.

use indicatif::{ProgressBar, ProgressStyle};

/// A bar of `len` steps counting `what` (e.g. "images"), with rate and ETA; hidden when
/// stderr is not a terminal.
pub fn bar(len: usize, what: &str) -> ProgressBar {
    if !std::io::IsTerminal::is_terminal(&std::io::stderr()) {
        return ProgressBar::hidden();
    }
    let bar = ProgressBar::new(len as u64);
    let template = format!(
        "{{spinner}} [{{elapsed_precise}}] {{bar:40}} {{pos}}/{{len}} {what} ({{per_sec}}, eta {{eta}})"
    );
    bar.set_style(
        ProgressStyle::with_template(&template).unwrap_or_else(|_| ProgressStyle::default_bar()),
    );
    bar
}
