//! Progress bars and summaries, silenced by `--quiet`.

use indicatif::{ProgressBar, ProgressStyle};

/// Where the program reports progress: bars on a terminal's standard error, nothing when quiet.
pub struct Progress {
    quiet: bool,
}

impl Progress {
    /// A reporter; `quiet` silences everything but errors.
    pub fn new(quiet: bool) -> Progress {
        Progress { quiet }
    }

    /// A bar counting `len` steps of `what` (hidden when quiet or not on a terminal).
    pub fn bar(&self, len: u64, what: &str) -> ProgressBar {
        if self.quiet {
            return ProgressBar::hidden();
        }
        let bar = ProgressBar::new(len);
        let style = ProgressStyle::with_template("{msg:>12} [{bar:30}] {pos}/{len} {elapsed}")
            .map(|s| s.progress_chars("=> "))
            .unwrap_or_else(|_| ProgressStyle::default_bar());
        bar.set_style(style);
        bar.set_message(what.to_owned());
        bar
    }

    /// A spinner for one long step.
    pub fn spinner(&self, what: &str) -> ProgressBar {
        if self.quiet {
            return ProgressBar::hidden();
        }
        let s = ProgressBar::new_spinner();
        s.set_message(what.to_owned());
        s.enable_steady_tick(std::time::Duration::from_millis(120));
        s
    }

    /// Prints the result a command exists to print (an experiment's tables): unlike
    /// [`Progress::say`], `--quiet` does not silence it.
    pub fn report(&self, text: impl AsRef<str>) {
        print_line(text.as_ref());
    }

    /// Prints a summary line on standard output unless quiet.
    pub fn say(&self, line: impl AsRef<str>) {
        if !self.quiet {
            print_line(line.as_ref());
        }
    }
}

/// Prints a line on standard output. A closed pipe (`patchnav ... | head`) ends the program
/// quietly, as other command-line tools do, instead of panicking in `println!`.
pub fn print_line(text: &str) {
    use std::io::Write as _;
    let mut out = std::io::stdout().lock();
    match writeln!(out, "{text}").and_then(|()| out.flush()) {
        Ok(()) => {}
        Err(e) if e.kind() == std::io::ErrorKind::BrokenPipe => std::process::exit(0),
        Err(e) => {
            eprintln!("error: writing to standard output: {e}");
            std::process::exit(1);
        }
    }
}

/// A bar as the library sees it.
struct Bar(ProgressBar);

impl patch_pipeline::Ticker for Bar {
    fn inc(&self, n: u64) {
        self.0.inc(n);
    }
    fn finish_and_clear(&self) {
        self.0.finish_and_clear();
    }
}

/// The library's steps report through the same bars and lines as the program's.
impl patch_pipeline::Progress for Progress {
    fn bar(&self, len: u64, what: &str) -> Box<dyn patch_pipeline::Ticker> {
        Box::new(Bar(Progress::bar(self, len, what)))
    }
    fn spinner(&self, what: &str) -> Box<dyn patch_pipeline::Ticker> {
        Box::new(Bar(Progress::spinner(self, what)))
    }
    fn say(&self, line: &str) {
        Progress::say(self, line);
    }
    fn report(&self, text: &str) {
        Progress::report(self, text);
    }
}
