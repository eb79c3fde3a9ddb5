//! A progress bar on stderr for runs longer than about a second (indicatif hides it when stderr is not a
//! terminal).

use std::sync::atomic::{AtomicBool, Ordering};
use std::time::Duration;

use indicatif::{ProgressBar, ProgressStyle};
use scene_complexity::run::RunControl;

/// How long a run goes before its progress bar appears.
const QUIET_FOR: Duration = Duration::from_millis(800);

/// Runs `work` while a thread draws its progress from `control` (of `total` lines, when known).
pub fn while_running<T>(control: &RunControl, total: Option<u64>, work: impl FnOnce() -> T) -> T {
    let done = AtomicBool::new(false);
    std::thread::scope(|s| {
        s.spawn(|| draw(control, total, &done));
        let result = work();
        done.store(true, Ordering::Relaxed);
        result
    })
}

fn draw(control: &RunControl, total: Option<u64>, done: &AtomicBool) {
    let start = std::time::Instant::now();
    while start.elapsed() < QUIET_FOR {
        if done.load(Ordering::Relaxed) {
            return;
        }
        std::thread::sleep(Duration::from_millis(20));
    }
    let bar = match total {
        Some(n) => ProgressBar::new(n).with_style(
            ProgressStyle::with_template(
                "{elapsed_precise} [{bar:40}] {human_pos}/{human_len} lines, eta {eta}",
            )
            .expect("a valid template")
            .progress_chars("=> "),
        ),
        None => ProgressBar::new_spinner().with_style(
            ProgressStyle::with_template(
                "{elapsed_precise} {spinner} {human_pos} lines ({per_sec})",
            )
            .expect("a valid template"),
        ),
    };
    while !done.load(Ordering::Relaxed) {
        bar.set_position(control.lines_started());
        std::thread::sleep(Duration::from_millis(100));
    }
    bar.finish_and_clear();
}
