//! Progress of a long run: a bar on a terminal; elsewhere (cluster logs, CI) a timestamped log
//! line at most every [`LINE_SECONDS`] seconds and at the end, so a log shows how far a run got
//! and how fast.

use std::sync::Mutex;
use std::time::{Duration, Instant};

/// Seconds between progress lines off a terminal.
pub const LINE_SECONDS: u64 = 30;

/// Where progress goes.
#[derive(Debug, Default)]
pub struct Progress {
    terminal: bool,
}

impl Progress {
    /// Bars when stderr is a terminal, lines otherwise.
    pub fn new() -> Progress {
        Progress {
            terminal: std::io::IsTerminal::is_terminal(&std::io::stderr()),
        }
    }

    /// A bar over `total` steps of `what`.
    pub fn bar(&self, what: &str, total: u64) -> Bar {
        let bar = self.terminal.then(|| {
            indicatif::ProgressBar::new(total).with_style(
                indicatif::ProgressStyle::with_template(
                    "{prefix} {bar:40} {pos}/{len} {msg}, {elapsed} elapsed, ~{eta} left",
                )
                .expect("valid template"),
            )
        });
        if let Some(b) = &bar {
            b.set_prefix(what.to_string());
        }
        Bar {
            bar,
            what: what.to_string(),
            total,
            state: Mutex::new(LineState {
                done: 0,
                started: Instant::now(),
                last: Instant::now(),
                message: String::new(),
            }),
        }
    }
}

#[derive(Debug)]
struct LineState {
    done: u64,
    started: Instant,
    last: Instant,
    message: String,
}

/// One phase's progress.
#[derive(Debug)]
pub struct Bar {
    bar: Option<indicatif::ProgressBar>,
    what: String,
    total: u64,
    state: Mutex<LineState>,
}

impl Bar {
    /// `n` more steps done.
    pub fn inc(&self, n: u64) {
        if let Some(b) = &self.bar {
            b.inc(n);
            return;
        }
        let mut s = self.state.lock().unwrap_or_else(|p| p.into_inner());
        s.done += n;
        if s.last.elapsed() >= Duration::from_secs(LINE_SECONDS) || s.done >= self.total {
            s.last = Instant::now();
            let elapsed = s.started.elapsed().as_secs_f64();
            let left = elapsed / s.done.max(1) as f64 * self.total.saturating_sub(s.done) as f64;
            tracing::info!(
                "{}: {}/{} ({:.0} %){}, {:.0} s elapsed, ~{:.0} s left",
                self.what,
                s.done,
                self.total,
                100.0 * s.done as f64 / self.total.max(1) as f64,
                if s.message.is_empty() {
                    String::new()
                } else {
                    format!(", {}", s.message)
                },
                elapsed,
                left
            );
        }
    }

    /// What the phase is doing now.
    pub fn message(&self, text: impl Into<String>) {
        let text = text.into();
        match &self.bar {
            Some(b) => b.set_message(text),
            None => self.state.lock().unwrap_or_else(|p| p.into_inner()).message = text,
        }
    }

    /// Logs `f`'s output without tearing the bar.
    pub fn suspend<R>(&self, f: impl FnOnce() -> R) -> R {
        match &self.bar {
            Some(b) => b.suspend(f),
            None => f(),
        }
    }

    /// Ends the bar.
    pub fn finish(&self) {
        if let Some(b) = &self.bar {
            b.finish_and_clear();
        }
    }
}
