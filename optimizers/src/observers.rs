//! Observers: a terminal progress bar, a history CSV, and a fan-out to several observers.

use czid_core::{CzError, Observer, Progress, Result, Snapshot};
use std::path::Path;

/// Sends every call to each of its observers; stops when any of them asks to.
#[derive(Default)]
pub struct Observers<'a>(pub Vec<&'a mut dyn Observer>);

impl Observer for Observers<'_> {
    fn observe(&mut self, progress: &Progress<'_>) -> bool {
        // Every observer sees every iteration, even after one asked to stop.
        let mut go = true;
        for o in self.0.iter_mut() {
            go &= o.observe(progress);
        }
        go
    }

    fn checkpoint(&mut self, progress: &Progress<'_>, state: &dyn Snapshot) -> Result<()> {
        self.0.iter_mut().try_for_each(|o| o.checkpoint(progress, state))
    }
}

/// `seconds` for a person reading a log: tenths of a second below ten, minutes from two on.
fn about(seconds: f64) -> String {
    if seconds < 10.0 {
        format!("{seconds:.1} s")
    } else if seconds < 120.0 {
        format!("{seconds:.0} s")
    } else {
        format!("{:.0} min", seconds / 60.0)
    }
}

/// A terminal progress bar over the evaluation budget, showing the best value.
pub struct ProgressBar {
    bar: indicatif::ProgressBar,
    /// Plain progress lines for a log (standard error is not a terminal, so no bar is drawn).
    lines: Option<LogLines>,
}

/// When the next plain progress line is due.
struct LogLines {
    every: usize,
    next: usize,
    start: std::time::Instant,
    /// The last progress observed (evaluations, best value, failures) when its line was not
    /// printed: the run may end before the next tenth of the budget.
    unprinted: Option<(usize, f64, usize)>,
}

impl LogLines {
    /// Prints a line; `pace` adds when the budget will be used up at the pace so far (a run
    /// still going; a method that converges stops earlier, so it is the most the run can take).
    fn print(&self, total: u64, evaluations: usize, best: f64, failures: usize, pace: bool) {
        let elapsed = self.start.elapsed().as_secs_f64();
        let left = (total as f64 - evaluations as f64).max(0.0) * elapsed / evaluations.max(1) as f64;
        let pace = if pace && evaluations > 0 && left > 0.0 {
            format!(", budget used up in about {}", about(left))
        } else {
            String::new()
        };
        eprintln!(
            "progress: {evaluations}/{total} evaluations, best {best:.6e}, {failures} failed, {elapsed:.1} s{pace}"
        );
    }
}

impl ProgressBar {
    /// A bar for a budget of `evaluations`, with when the budget will be used up at the pace so
    /// far. When standard error is not a terminal (a batch job's log) no bar can be drawn; a plain
    /// line is printed instead at every tenth of the budget.
    pub fn new(evaluations: usize) -> Self {
        use std::io::IsTerminal;
        let bar = indicatif::ProgressBar::new(evaluations as u64);
        if let Ok(style) = indicatif::ProgressStyle::with_template(
            "{elapsed_precise} [{bar:40}] {pos}/{len} evals, budget used up in {eta}  {msg}",
        ) {
            bar.set_style(style.progress_chars("=> "));
        }
        let every = evaluations.div_ceil(10).max(1);
        let lines = (!std::io::stderr().is_terminal()).then(|| LogLines {
            every,
            next: every,
            start: std::time::Instant::now(),
            unprinted: None,
        });
        ProgressBar { bar, lines }
    }

    /// A bar drawing nowhere and printing nothing (for tests and quiet runs).
    pub fn hidden(evaluations: usize) -> Self {
        let mut bar = Self::new(evaluations);
        bar.bar.set_draw_target(indicatif::ProgressDrawTarget::hidden());
        bar.lines = None;
        bar
    }

    /// Ends the bar where the run ended: at the evaluations observed last, which a run that
    /// converged or was stopped leaves short of the budget (the bar does not jump to the end).
    /// In a log, the last progress is printed if its line was not (the run ended between two
    /// tenths of the budget), so the log ends where the run did.
    pub fn finish(&mut self) {
        self.bar.abandon();
        let total = self.bar.length().unwrap_or(0);
        if let Some(l) = &mut self.lines {
            if let Some((evaluations, best, failures)) = l.unprinted.take() {
                l.print(total, evaluations, best, failures, false);
            }
        }
    }

    /// Evaluations the bar shows.
    pub fn position(&self) -> usize {
        self.bar.position() as usize
    }
}

impl Observer for ProgressBar {
    fn observe(&mut self, p: &Progress<'_>) -> bool {
        self.bar.set_position(p.evaluations as u64);
        self.bar.set_message(format!("best {:.6e}  failed {}", p.best_value, p.failures));
        if let Some(l) = &mut self.lines {
            l.unprinted = Some((p.evaluations, p.best_value, p.failures));
            if p.evaluations >= l.next {
                l.print(self.bar.length().unwrap_or(0), p.evaluations, p.best_value, p.failures, true);
                l.next = (p.evaluations / l.every + 1) * l.every;
                l.unprinted = None;
            }
        }
        true
    }
}

/// Writes one CSV row per iteration: `iteration, evaluations, failures, best_value, x0, x1, …`.
/// A write error stops the run and is returned by [`CsvHistory::finish`].
pub struct CsvHistory {
    writer: csv::Writer<std::fs::File>,
    header: bool,
    error: Option<CzError>,
    path: String,
}

impl CsvHistory {
    /// Creates (or truncates) `path`.
    pub fn create(path: &Path) -> Result<Self> {
        let writer = csv::Writer::from_path(path)
            .map_err(|e| CzError::Io { path: path.display().to_string(), message: e.to_string() })?;
        Ok(CsvHistory { writer, header: false, error: None, path: path.display().to_string() })
    }

    /// Flushes the file; returns the first write error, if any.
    pub fn finish(mut self) -> Result<()> {
        if let Some(e) = self.error.take() {
            return Err(e);
        }
        self.writer.flush().map_err(|e| CzError::Io { path: self.path.clone(), message: e.to_string() })
    }

    fn write(&mut self, p: &Progress<'_>) -> std::result::Result<(), csv::Error> {
        if !self.header {
            let mut h = vec!["iteration".to_string(), "evaluations".into(), "failures".into(), "best_value".into()];
            h.extend((0..p.best_x.len()).map(|i| format!("x{i}")));
            self.writer.write_record(&h)?;
            self.header = true;
        }
        let mut row = vec![p.iteration.to_string(), p.evaluations.to_string(), p.failures.to_string()];
        row.push(p.best_value.to_string());
        row.extend(p.best_x.iter().map(|v| v.to_string()));
        self.writer.write_record(&row)
    }
}

impl Observer for CsvHistory {
    fn observe(&mut self, p: &Progress<'_>) -> bool {
        if self.error.is_some() {
            return false;
        }
        // Each row reaches the file at once, so a killed run keeps every row it wrote.
        if let Err(e) = self.write(p).and_then(|_| self.writer.flush().map_err(csv::Error::from)) {
            self.error = Some(CzError::Io { path: self.path.clone(), message: e.to_string() });
            return false;
        }
        true
    }
}
