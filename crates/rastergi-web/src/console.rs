//! The log and panics go to the browser's console; warnings are also kept for the page to
//! show ([`take_warnings`]).

use std::cell::RefCell;

thread_local! {
    static WARNINGS: RefCell<Vec<String>> = const { RefCell::new(Vec::new()) };
}

struct Console;

impl log::Log for Console {
    fn enabled(&self, metadata: &log::Metadata) -> bool {
        metadata.level() <= log::Level::Info
    }

    fn log(&self, record: &log::Record) {
        if !self.enabled(record.metadata()) {
            return;
        }
        let line = format!("{}", record.args());
        match record.level() {
            log::Level::Error => web_sys::console::error_1(&line.clone().into()),
            log::Level::Warn => web_sys::console::warn_1(&line.clone().into()),
            _ => web_sys::console::log_1(&line.clone().into()),
        }
        if record.level() <= log::Level::Warn {
            WARNINGS.with(|w| w.borrow_mut().push(line));
        }
    }

    fn flush(&self) {}
}

static CONSOLE: Console = Console;

/// Installs the logger and the panic hook (once; later calls do nothing).
pub fn init() {
    if log::set_logger(&CONSOLE).is_ok() {
        log::set_max_level(log::LevelFilter::Info);
        std::panic::set_hook(Box::new(|info| web_sys::console::error_1(&format!("rastergi panicked: {info}").into())));
    }
}

/// The warnings logged since the last call.
pub fn take_warnings() -> Vec<String> {
    WARNINGS.with(|w| std::mem::take(&mut *w.borrow_mut()))
}
