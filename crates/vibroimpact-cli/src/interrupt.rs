//! Ctrl-C: a long command stops computing, keeps what it has computed
//! (written atomically like any output) and exits non-zero saying so.

use vibroimpact::integrate::Interrupt;

/// A stop token that Ctrl-C requests.
pub fn on_ctrl_c() -> Interrupt {
    let token = Interrupt::new();
    let handler = token.clone();
    // A second registration in one process is refused by `ctrlc`; the
    // command then simply runs without its own handler.
    let _ = ctrlc::set_handler(move || handler.request());
    token
}
