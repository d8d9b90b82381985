//! Progress of long work on stderr: a bar when stderr is a terminal; otherwise plain
//! lines (done of total, rate, time left) every few seconds, also while no unit
//! finishes (a thread of their own writes them), and one at the end, so that a campaign
//! whose stderr goes to a file (a Slurm shard's log, `2> log`) shows how far it is.

use std::io::Write;
use std::sync::mpsc::{self, RecvTimeoutError};
use std::sync::{Arc, Mutex, MutexGuard};
use std::thread::JoinHandle;
use std::time::{Duration, Instant};

/// How often a plain line is written while work goes on.
const LINE_EVERY: Duration = Duration::from_secs(5);

/// Progress of `total` units of work, safe to advance from worker threads.
pub(crate) enum Progress {
    Bar(indicatif::ProgressBar),
    Lines(Ticker),
    Hidden,
}

impl Progress {
    /// A bar on a terminal ("`message` pos/len `unit` [bar] eta"), plain lines on
    /// stderr otherwise.
    pub(crate) fn new(total: u64, unit: &str, message: String) -> Self {
        if !std::io::IsTerminal::is_terminal(&std::io::stderr()) {
            let lines = Lines::new(total, unit, message, Box::new(std::io::stderr()));
            return Self::Lines(Ticker::start(lines, LINE_EVERY));
        }
        let bar = indicatif::ProgressBar::new(total);
        let template = format!("{{msg}} {{pos}}/{{len}} {unit} [{{wide_bar}}] eta {{eta}}");
        bar.set_style(
            indicatif::ProgressStyle::with_template(&template).expect("a valid template").progress_chars("=> "),
        );
        bar.set_message(message);
        Self::Bar(bar)
    }

    /// `n` more units done.
    pub(crate) fn inc(&self, n: u64) {
        match self {
            Self::Bar(b) => b.inc(n),
            Self::Lines(t) => t.lines().done += n,
            Self::Hidden => {}
        }
    }

    /// What is being done now (the lines' prefix, the bar's message).
    pub(crate) fn set_message(&self, message: String) {
        match self {
            Self::Bar(b) => b.set_message(message),
            Self::Lines(t) => t.lines().message = message,
            Self::Hidden => {}
        }
    }

    /// The work is over: the bar is cleared, the lines end with the total time.
    pub(crate) fn finish(&self) {
        match self {
            Self::Bar(b) => b.finish_and_clear(),
            Self::Lines(t) => {
                t.stop();
                t.lines().finish(Instant::now());
            }
            Self::Hidden => {}
        }
    }
}

/// A thread that writes a line every interval until stopped (by `finish`, or when
/// dropped: work that ends in an error writes no total).
pub(crate) struct Ticker {
    lines: Arc<Mutex<Lines>>,
    /// The thread and the sender whose drop stops it, until stopped.
    running: Mutex<Option<(mpsc::Sender<()>, JoinHandle<()>)>>,
}

impl Ticker {
    fn start(lines: Lines, every: Duration) -> Self {
        let lines = Arc::new(Mutex::new(lines));
        let (stop, stopped) = mpsc::channel::<()>();
        let shared = Arc::clone(&lines);
        let thread = std::thread::spawn(move || {
            while let Err(RecvTimeoutError::Timeout) = stopped.recv_timeout(every) {
                lock(&shared).line(Instant::now());
            }
        });
        Self { lines, running: Mutex::new(Some((stop, thread))) }
    }

    fn lines(&self) -> MutexGuard<'_, Lines> {
        lock(&self.lines)
    }

    /// Stops the thread and waits for it (a line it is writing is written whole).
    fn stop(&self) {
        if let Some((stop, thread)) = lock(&self.running).take() {
            drop(stop);
            let _ = thread.join();
        }
    }
}

impl Drop for Ticker {
    fn drop(&mut self) {
        self.stop();
    }
}

/// A lock that a panicked holder does not poison for the others.
fn lock<T>(m: &Mutex<T>) -> MutexGuard<'_, T> {
    m.lock().unwrap_or_else(|e| e.into_inner())
}

/// The plain-line reporter.
pub(crate) struct Lines {
    message: String,
    unit: String,
    total: u64,
    done: u64,
    start: Instant,
    out: Box<dyn Write + Send>,
}

impl Lines {
    fn new(total: u64, unit: &str, message: String, out: Box<dyn Write + Send>) -> Self {
        Self { message, unit: unit.to_string(), total, done: 0, start: Instant::now(), out }
    }

    /// A line of how far the work is at `now`: before the first unit the time so far,
    /// then the rate and the time left at that rate.
    fn line(&mut self, now: Instant) {
        let elapsed = now.duration_since(self.start).as_secs_f64();
        let (done, total, unit) = (self.done, self.total, &self.unit);
        let percent = 100.0 * done as f64 / total.max(1) as f64;
        let head = format!("{}: {done}/{total} {unit} ({percent:.0} %)", self.message);
        if done == 0 {
            let _ = writeln!(self.out, "{head}, {} so far", duration(elapsed));
            return;
        }
        let rate = done as f64 / elapsed.max(1e-9);
        let left = total.saturating_sub(done) as f64 / rate.max(1e-12);
        // the rate as units a second when they are quicker than a second each
        let pace = if rate > 1.0 {
            format!("{rate:.1} {unit}/s")
        } else {
            format!("{} per {}", duration(1.0 / rate), unit.trim_end_matches('s'))
        };
        let _ = writeln!(self.out, "{head}, {pace}, {} left", duration(left));
    }

    fn finish(&mut self, now: Instant) {
        let elapsed = now.duration_since(self.start).as_secs_f64();
        let _ =
            writeln!(self.out, "{}: {}/{} {} in {}", self.message, self.done, self.total, self.unit, duration(elapsed));
    }
}

/// A duration for people: "0.42 s", "12 s", "4 min 12 s", "1 h 02 min".
fn duration(s: f64) -> String {
    if !s.is_finite() {
        return "?".into();
    }
    let whole = s.round() as u64;
    match whole {
        _ if s < 10.0 => format!("{s:.2} s"),
        0..60 => format!("{whole} s"),
        60..3600 => format!("{} min {:02} s", whole / 60, whole % 60),
        _ => format!("{} h {:02} min", whole / 3600, whole % 3600 / 60),
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use std::sync::Arc;

    /// A writer the test reads back.
    #[derive(Clone, Default)]
    struct Shared(Arc<Mutex<Vec<u8>>>);

    impl Write for Shared {
        fn write(&mut self, b: &[u8]) -> std::io::Result<usize> {
            self.0.lock().unwrap().extend_from_slice(b);
            Ok(b.len())
        }
        fn flush(&mut self) -> std::io::Result<()> {
            Ok(())
        }
    }

    /// 10 runs, one every 2 s, lines at 1, 5, 11 and 15 s: the time so far before the
    /// first run, then the runs done, the rate and the time left at that rate; then the
    /// total.
    #[test]
    fn lines_give_the_rate_and_time_left_then_the_total() {
        let out = Shared::default();
        let mut lines = Lines::new(10, "runs", "mc x".into(), Box::new(out.clone()));
        let t0 = lines.start;
        let at = |s: f64| t0 + Duration::from_secs_f64(s);
        lines.line(at(1.0));
        for k in 1..=10 {
            lines.done += 1;
            if k == 2 || k == 5 || k == 7 {
                lines.line(at(f64::from(2 * k + 1)));
            }
        }
        lines.finish(at(20.0));
        let text = String::from_utf8(out.0.lock().unwrap().clone()).unwrap();
        let expected = "mc x: 0/10 runs (0 %), 1.00 s so far\n\
                        mc x: 2/10 runs (20 %), 2.50 s per run, 20 s left\n\
                        mc x: 5/10 runs (50 %), 2.20 s per run, 11 s left\n\
                        mc x: 7/10 runs (70 %), 2.14 s per run, 6.43 s left\n\
                        mc x: 10/10 runs in 20 s\n";
        assert_eq!(text, expected);
    }

    /// The thread writes lines while no unit is done, and stops on `finish` (no line
    /// after the total, while the progress lives on) and on drop (no total).
    #[test]
    fn the_ticker_writes_while_no_unit_finishes_and_stops() {
        let read = |s: &Shared| String::from_utf8(s.0.lock().unwrap().clone()).unwrap();
        let out = Shared::default();
        let every = Duration::from_millis(20);
        let progress =
            Progress::Lines(Ticker::start(Lines::new(3, "runs", "mc y".into(), Box::new(out.clone())), every));
        std::thread::sleep(Duration::from_millis(150));
        progress.finish();
        let text = read(&out);
        let lines: Vec<&str> = text.lines().collect();
        assert!(lines.len() >= 3, "{text}");
        let (total, ticks) = lines.split_last().unwrap();
        assert!(ticks.iter().all(|l| l.starts_with("mc y: 0/3 runs (0 %), ") && l.ends_with(" so far")), "{text}");
        assert!(total.starts_with("mc y: 0/3 runs in "), "{text}");
        std::thread::sleep(Duration::from_millis(100));
        assert_eq!(read(&out), text, "a line after the total");
        drop(progress);

        let dropped = Shared::default();
        drop(Ticker::start(Lines::new(3, "runs", "mc z".into(), Box::new(dropped.clone())), Duration::from_secs(60)));
        assert_eq!(read(&dropped), "", "a dropped ticker wrote");
    }

    #[test]
    fn durations_read_as_people_write_them() {
        let cases = [(0.42, "0.42 s"), (12.4, "12 s"), (252.0, "4 min 12 s"), (3720.0, "1 h 02 min")];
        for (s, text) in cases {
            assert_eq!(duration(s), text);
        }
        assert_eq!(duration(f64::INFINITY), "?");
    }
}
