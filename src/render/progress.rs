//! A render's progress as a bar with the time left, for a person at a terminal: hidden for the
//! first half second (a short render shows nothing), then drawn on stderr a few times a second.

use indicatif::{ProgressBar, ProgressDrawTarget, ProgressStyle};
use std::sync::atomic::{AtomicBool, Ordering};
use std::time::{Duration, Instant};

/// How long a render runs before its bar appears.
const SHOW_AFTER: Duration = Duration::from_millis(500);

/// Pixels done of a render.
pub(crate) struct Progress {
    bar: ProgressBar,
    start: Instant,
    shown: AtomicBool,
}

impl Progress {
    /// Progress over `pixels` pixels, drawn on stderr once the render has run half a second.
    pub fn new(pixels: u64) -> Progress {
        let bar = ProgressBar::with_draw_target(Some(pixels), ProgressDrawTarget::hidden());
        bar.set_style(
            ProgressStyle::with_template(
                "rendering [{wide_bar}] {percent:>3}%, {elapsed} elapsed, about {eta} left",
            )
            .expect("a valid template")
            .progress_chars("=> "),
        );
        Progress {
            bar,
            start: Instant::now(),
            shown: AtomicBool::new(false),
        }
    }

    /// Progress counted but never drawn (the viewer shows its own bar).
    pub fn silent(pixels: u64) -> Progress {
        let p = Progress::new(pixels);
        p.shown.store(true, Ordering::Relaxed);
        p
    }

    /// Progress over rounds of samples (`--max-time`, `--target-rms`): each round's pixels
    /// as the bar, and what the rounds have done so far as its message.
    pub fn rounds(pixels: u64) -> Progress {
        let p = Progress::new(pixels);
        p.bar.set_style(
            ProgressStyle::with_template(
                "rendering {msg} [{wide_bar}] {percent:>3}%, {elapsed} elapsed",
            )
            .expect("a valid template")
            .progress_chars("=> "),
        );
        p
    }

    /// A new round: the bar starts again, `message` says where the rounds are.
    pub fn next_round(&self, message: String) {
        self.bar.set_position(0);
        self.bar.set_message(message);
    }

    /// The share of the pixels done, 0 to 1.
    pub fn fraction(&self) -> f64 {
        let total = self.bar.length().unwrap_or(0).max(1);
        self.bar.position() as f64 / total as f64
    }

    /// `pixels` more are done.
    pub fn add(&self, pixels: u64) {
        self.bar.inc(pixels);
        if self.start.elapsed() > SHOW_AFTER
            && self
                .shown
                .compare_exchange(false, true, Ordering::Relaxed, Ordering::Relaxed)
                .is_ok()
        {
            self.bar
                .set_draw_target(ProgressDrawTarget::stderr_with_hz(4));
        }
    }

    /// The render is done: the bar goes, leaving the terminal as it was.
    pub fn finish(&self) {
        self.bar.finish_and_clear();
    }
}
