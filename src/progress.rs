//! The progress bar of the long commands (`tradeoff`, `scaling`): on stderr
//! when it is a terminal, hidden in pipes and tests, where it would only add
//! noise to what is read. A named thread ticks it (spinner and clock) four
//! times a second, so a single run of seconds to minutes never looks frozen.
use indicatif::{ProgressBar, ProgressStyle};
use std::io::IsTerminal;
use std::thread::JoinHandle;
use std::time::Duration;

pub struct Progress {
    bar: ProgressBar,
    ticker: Option<JoinHandle<()>>,
}

impl Progress {
    /// A bar of `len` runs, or a hidden one off a terminal.
    pub fn new(len: usize) -> Progress {
        if !std::io::stderr().is_terminal() {
            return Progress {
                bar: ProgressBar::hidden(),
                ticker: None,
            };
        }
        let bar = ProgressBar::new(len as u64);
        // The template is a constant: it either parses or fails here alike.
        if let Ok(style) =
            ProgressStyle::with_template("{spinner} {bar:20} {pos}/{len} runs, {elapsed}: {msg}")
        {
            bar.set_style(style);
        }
        let ticking = bar.clone();
        let ticker = std::thread::Builder::new()
            .name("progress".into())
            .spawn(move || {
                while !ticking.is_finished() {
                    ticking.tick();
                    std::thread::park_timeout(Duration::from_millis(250));
                }
            })
            .ok();
        Progress { bar, ticker }
    }

    /// `done` runs finished; `next` is under way.
    pub fn set(&self, done: usize, next: &str) {
        self.bar.set_position(done as u64);
        self.bar.set_message(next.to_string());
    }

    /// Clear the bar and stop its thread.
    pub fn finish(mut self) {
        self.bar.finish_and_clear();
        if let Some(t) = self.ticker.take() {
            t.thread().unpark();
            let _ = t.join();
        }
    }
}
