//! A progress bar on stderr for runs longer than about a second (hidden when stderr is not a terminal,
//! and with `--quiet`). The rate and the time left are computed here from the lines cast since the run
//! began, so the first reading is not a burst of the batches already started.

use std::sync::atomic::{AtomicBool, Ordering};
use std::time::{Duration, Instant};

use indicatif::{ProgressBar, ProgressStyle};
use scene_complexity::RunControl;

use super::output::quiet;

/// How long a run goes before its progress bar appears.
const QUIET_FOR: Duration = Duration::from_millis(800);

/// Runs `work` while a thread draws its progress from `control` (of `total` lines, when known); `label`
/// says which run this is (in `convergence`), or is empty.
pub fn while_running<T>(
    control: &RunControl,
    total: Option<u64>,
    label: &str,
    work: impl FnOnce() -> T,
) -> T {
    let done = AtomicBool::new(false);
    // The control may have served earlier runs: count from here.
    let base = control.lines_started();
    std::thread::scope(|s| {
        if !quiet() {
            s.spawn(|| draw(control, base, total, label, &done));
        }
        // Set however `work` ends: a panic in it must not leave the scope waiting for the bar forever.
        let _finished = Finished(&done);
        work()
    })
}

/// Sets its flag when dropped, also while a panic unwinds.
struct Finished<'a>(&'a AtomicBool);

impl Drop for Finished<'_> {
    fn drop(&mut self) {
        self.0.store(true, Ordering::Relaxed);
    }
}

/// `1.23 M lines/s, 12 s left`.
fn rate_and_time_left(lines: u64, total: Option<u64>, elapsed: Duration) -> String {
    let rate = lines as f64 / elapsed.as_secs_f64().max(1e-9);
    let left = total
        .filter(|_| rate > 0.0)
        .map(|t| (t.saturating_sub(lines)) as f64 / rate)
        .map(|s| format!(", {} left", human_seconds(s)))
        .unwrap_or_default();
    format!("{:.2} M lines/s{left}", rate / 1e6)
}

fn human_seconds(s: f64) -> String {
    if s < 60.0 {
        format!("{s:.0} s")
    } else if s < 3600.0 {
        format!("{:.0} min {:.0} s", (s / 60.0).floor(), s % 60.0)
    } else {
        format!(
            "{:.0} h {:.0} min",
            (s / 3600.0).floor(),
            (s % 3600.0) / 60.0
        )
    }
}

fn draw(control: &RunControl, base: u64, total: Option<u64>, label: &str, done: &AtomicBool) {
    let start = Instant::now();
    while start.elapsed() < QUIET_FOR {
        if done.load(Ordering::Relaxed) {
            return;
        }
        std::thread::sleep(Duration::from_millis(20));
    }
    let prefix = if label.is_empty() {
        String::new()
    } else {
        format!("{label}  ")
    };
    let bar = match total {
        Some(n) => ProgressBar::new(n).with_style(
            ProgressStyle::with_template(
                "{prefix}{elapsed_precise} [{bar:36}] {human_pos}/{human_len} lines, {msg}",
            )
            .expect("a valid template")
            .progress_chars("=> "),
        ),
        None => ProgressBar::new_spinner().with_style(
            ProgressStyle::with_template(
                "{prefix}{elapsed_precise} {spinner} {human_pos} lines, {msg}",
            )
            .expect("a valid template"),
        ),
    };
    bar.set_prefix(prefix);
    while !done.load(Ordering::Relaxed) {
        let lines = control.lines_started() - base;
        let shown = total.map_or(lines, |t| lines.min(t));
        bar.set_position(shown);
        bar.set_message(rate_and_time_left(shown, total, start.elapsed()));
        std::thread::sleep(Duration::from_millis(100));
    }
    bar.finish_and_clear();
}

#[cfg(test)]
mod tests {
    use super::*;

    /// A panic in the work (a worker's, carried over by the pool) comes out of `while_running` instead
    /// of leaving it waiting for the progress bar's thread.
    #[test]
    fn a_panic_in_the_work_does_not_leave_the_bar_waiting() {
        let control = RunControl::default();
        let result = std::panic::catch_unwind(std::panic::AssertUnwindSafe(|| {
            while_running(&control, Some(10), "", || -> u32 { panic!("in the work") })
        }));
        assert!(result.is_err());
    }

    #[test]
    fn rate_and_time_left_read_sensibly() {
        let t = rate_and_time_left(5_000_000, Some(20_000_000), Duration::from_secs(2));
        assert_eq!(t, "2.50 M lines/s, 6 s left");
        assert_eq!(human_seconds(125.0), "2 min 5 s");
    }
}
