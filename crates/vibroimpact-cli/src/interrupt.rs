//! Ctrl-C: a long command stops computing, keeps what it has computed
//! (written atomically like any output) and exits non-zero saying so. A
//! second Ctrl-C quits at once, removing the temporary files of writes in
//! progress (see [`crate::output::Pending`]).

use std::sync::OnceLock;

use vibroimpact::integrate::Interrupt;

/// The process's stop token.
static TOKEN: OnceLock<Interrupt> = OnceLock::new();

/// The stop token that Ctrl-C requests; the first call installs the
/// handler (the first Ctrl-C requests the stop, the second quits with exit
/// status 130 after removing pending temporary files).
pub fn on_ctrl_c() -> Interrupt {
    let mut installed = false;
    let token = TOKEN
        .get_or_init(|| {
            installed = true;
            Interrupt::new()
        })
        .clone();
    if installed {
        let handler = token.clone();
        // A refused registration (another handler in the process) leaves the
        // default action: Ctrl-C then ends the process.
        let _ = ctrlc::set_handler(move || {
            if handler.requested() {
                crate::output::remove_pending();
                std::process::exit(130);
            }
            handler.request();
            eprintln!("stopping at the next step (Ctrl-C again to quit at once)");
        });
    }
    token
}
