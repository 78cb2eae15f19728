//! The runs of a sweep (or of one shard of it), as a sequence: [`Runs`]. A sweep's runs are
//! made on demand from their index (the sweep axes are a mixed-radix product, so run `i`'s
//! values are its digits: O(axes) work and no memory per run); a list made by other means
//! (`settle tune`'s candidates) is kept as it is.

use std::borrow::Cow;

use crate::spec::backend::Backend;
use crate::spec::run_spec::RunSpec;

/// What makes a sweep's run from its id (`crate::expand` implements it for a scenario's
/// sweep).
pub trait MakeRun: std::fmt::Debug + Send + Sync {
    /// The number of runs of the whole sweep.
    fn total(&self) -> usize;
    /// Run `id` (`id < total()`), fully resolved, with the backend of every run.
    fn make(&self, id: usize) -> RunSpec;
    /// Set the backend of every run.
    fn set_backend(&mut self, backend: Backend);
}

/// A sequence of runs: a list, or a sweep's runs made on demand ([`Runs`]).
pub trait RunList: std::fmt::Debug + Sync {
    /// The number of runs.
    fn len(&self) -> usize;
    /// Run `i` (in order; `None` past the last).
    fn get(&self, i: usize) -> Option<Cow<'_, RunSpec>>;
    /// The id of run `i` (in order).
    fn id(&self, i: usize) -> Option<usize> {
        self.get(i).map(|r| r.id)
    }
    /// Whether there are none.
    fn is_empty(&self) -> bool {
        self.len() == 0
    }
}

impl dyn RunList + '_ {
    /// The run at `i` (in order), which must exist.
    ///
    /// # Panics
    /// When `i >= len()`.
    pub fn at(&self, i: usize) -> Cow<'_, RunSpec> {
        match self.get(i) {
            Some(r) => r,
            None => panic!("run {i} of {}", self.len()),
        }
    }

    /// The first run.
    pub fn first(&self) -> Option<Cow<'_, RunSpec>> {
        self.get(0)
    }

    /// The runs in order.
    pub fn iter(&self) -> impl Iterator<Item = Cow<'_, RunSpec>> + '_ {
        (0..self.len()).map(|i| self.at(i))
    }
}

impl RunList for Vec<RunSpec> {
    fn len(&self) -> usize {
        self.as_slice().len()
    }

    fn get(&self, i: usize) -> Option<Cow<'_, RunSpec>> {
        self.as_slice().get(i).map(Cow::Borrowed)
    }
}

/// The runs of a sweep or of one shard of it, made on demand.
#[derive(Debug)]
pub struct Runs {
    maker: Box<dyn MakeRun>,
    /// Runs `first`, `first + step`, ... of the sweep, `len` of them.
    first: usize,
    step: usize,
    len: usize,
}

impl RunList for Runs {
    fn len(&self) -> usize {
        self.len
    }

    fn get(&self, i: usize) -> Option<Cow<'_, RunSpec>> {
        (i < self.len).then(|| Cow::Owned(self.maker.make(self.first + i * self.step)))
    }

    fn id(&self, i: usize) -> Option<usize> {
        (i < self.len).then_some(self.first + i * self.step)
    }
}

impl Runs {
    /// Every run of the sweep `maker` makes.
    pub fn new(maker: Box<dyn MakeRun>) -> Self {
        let len = maker.total();
        Self {
            maker,
            first: 0,
            step: 1,
            len,
        }
    }

    /// The runs of the sweep whose ids are `first`, `first + step`, ... (a shard).
    pub fn every(self, first: usize, step: usize) -> Self {
        let step = step.max(1);
        let len = self.maker.total().saturating_sub(first).div_ceil(step);
        Self {
            first,
            step,
            len,
            ..self
        }
    }

    /// The position of the run with id `id`, if it is one of these.
    pub fn position(&self, id: usize) -> Option<usize> {
        (id >= self.first && (id - self.first).is_multiple_of(self.step))
            .then(|| (id - self.first) / self.step)
            .filter(|&i| i < self.len)
    }

    /// Set the backend of every run.
    pub fn set_backend(&mut self, backend: Backend) {
        self.maker.set_backend(backend);
    }
}
