//! How a long pipeline step says how far it got. The programs draw bars on a terminal
//! (`patchnav`'s `Progress`); a library caller passes [`Silent`] or its own.

/// A bar or spinner of one step.
pub trait Ticker: Send + Sync {
    /// `n` more units done.
    fn inc(&self, n: u64);
    /// The step is over: the bar goes away.
    fn finish_and_clear(&self);
}

/// Where pipeline steps report progress, summaries and results.
pub trait Progress: Sync {
    /// A bar counting `len` units of `what`.
    fn bar(&self, len: u64, what: &str) -> Box<dyn Ticker>;
    /// A spinner for one long step.
    fn spinner(&self, what: &str) -> Box<dyn Ticker>;
    /// A summary line (silenced by the programs' `--quiet`).
    fn say(&self, line: &str);
    /// The result a step exists to produce, as text (an experiment's table): a program prints
    /// it even when quiet.
    fn report(&self, text: &str);
}

/// Reports nothing, not even results.
#[derive(Copy, Clone, Debug, Default)]
pub struct Silent;

impl Ticker for Silent {
    fn inc(&self, _: u64) {}
    fn finish_and_clear(&self) {}
}

impl Progress for Silent {
    fn bar(&self, _: u64, _: &str) -> Box<dyn Ticker> {
        Box::new(Silent)
    }
    fn spinner(&self, _: &str) -> Box<dyn Ticker> {
        Box::new(Silent)
    }
    fn say(&self, _: &str) {}
    fn report(&self, _: &str) {}
}
