//! Progress of long work on stderr: a bar when stderr is a terminal; otherwise plain
//! lines (done of total, rate, time left) every few seconds and one at the end, so that
//! a campaign whose stderr goes to a file (a Slurm shard's log, `2> log`) shows how far
//! it is.

use std::io::Write;
use std::sync::Mutex;
use std::time::{Duration, Instant};

/// How often a plain line is written while work goes on.
const LINE_EVERY: Duration = Duration::from_secs(5);

/// Progress of `total` units of work, safe to advance from worker threads.
pub(crate) enum Progress {
    Bar(indicatif::ProgressBar),
    Lines(Mutex<Lines>),
    Hidden,
}

impl Progress {
    /// A bar on a terminal ("`message` pos/len `unit` [bar] eta"), plain lines on
    /// stderr otherwise.
    pub(crate) fn new(total: u64, unit: &str, message: String) -> Self {
        if !std::io::IsTerminal::is_terminal(&std::io::stderr()) {
            let lines = Lines::new(total, unit, message, LINE_EVERY, Box::new(std::io::stderr()));
            return Self::Lines(Mutex::new(lines));
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
            Self::Lines(l) => l.lock().unwrap_or_else(|e| e.into_inner()).advance(n, Instant::now()),
            Self::Hidden => {}
        }
    }

    /// What is being done now (the lines' prefix, the bar's message).
    pub(crate) fn set_message(&self, message: String) {
        match self {
            Self::Bar(b) => b.set_message(message),
            Self::Lines(l) => l.lock().unwrap_or_else(|e| e.into_inner()).message = message,
            Self::Hidden => {}
        }
    }

    /// The work is over: the bar is cleared, the lines end with the total time.
    pub(crate) fn finish(&self) {
        match self {
            Self::Bar(b) => b.finish_and_clear(),
            Self::Lines(l) => l.lock().unwrap_or_else(|e| e.into_inner()).finish(Instant::now()),
            Self::Hidden => {}
        }
    }
}

/// The plain-line reporter.
pub(crate) struct Lines {
    message: String,
    unit: String,
    total: u64,
    done: u64,
    start: Instant,
    last: Instant,
    every: Duration,
    out: Box<dyn Write + Send>,
}

impl Lines {
    /// Starts with a line of the work to do, so that a log shows the work began before
    /// its first unit is done (a campaign's first runs can take minutes).
    fn new(total: u64, unit: &str, message: String, every: Duration, mut out: Box<dyn Write + Send>) -> Self {
        let now = Instant::now();
        let _ = writeln!(out, "{message}: 0/{total} {unit}, started");
        Self { message, unit: unit.to_string(), total, done: 0, start: now, last: now, every, out }
    }

    fn advance(&mut self, n: u64, now: Instant) {
        self.done += n;
        if now.duration_since(self.last) < self.every || self.done >= self.total {
            return;
        }
        self.last = now;
        let elapsed = now.duration_since(self.start).as_secs_f64();
        let rate = self.done as f64 / elapsed.max(1e-9);
        let left = (self.total - self.done) as f64 / rate.max(1e-12);
        // the rate as units a second when they are quicker than a second each
        let pace = if rate > 1.0 {
            format!("{rate:.1} {}/s", self.unit)
        } else {
            format!("{} per {}", duration(1.0 / rate), self.unit.trim_end_matches('s'))
        };
        let _ = writeln!(
            self.out,
            "{}: {}/{} {} ({:.0} %), {pace}, {} left",
            self.message,
            self.done,
            self.total,
            self.unit,
            100.0 * self.done as f64 / self.total.max(1) as f64,
            duration(left)
        );
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

    /// 10 runs, one every 2 s, a line every 5 s: a line at the start, lines after runs
    /// 3, 6 and 9 (at 6, 12 and 18 s: the first run at or past 5 s since the last line),
    /// none at the last run, then the total; the rate and time left from the runs done
    /// so far.
    #[test]
    fn lines_come_every_interval_with_rate_and_time_left_then_the_total() {
        let out = Shared::default();
        let mut lines = Lines::new(10, "runs", "mc x".into(), Duration::from_secs(5), Box::new(out.clone()));
        let t0 = lines.start;
        for k in 1..=10 {
            lines.advance(1, t0 + Duration::from_secs(2 * k));
        }
        lines.finish(t0 + Duration::from_secs(20));
        let text = String::from_utf8(out.0.lock().unwrap().clone()).unwrap();
        let expected = "mc x: 0/10 runs, started\n\
                        mc x: 3/10 runs (30 %), 2.00 s per run, 14 s left\n\
                        mc x: 6/10 runs (60 %), 2.00 s per run, 8.00 s left\n\
                        mc x: 9/10 runs (90 %), 2.00 s per run, 2.00 s left\n\
                        mc x: 10/10 runs in 20 s\n";
        assert_eq!(text, expected);
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
