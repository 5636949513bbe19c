//! Counters of a traversal's work: the BVH nodes it tests and the primitives it tests, for the
//! per-pixel statistics of an inspected render (`render --aov`).
//!
//! The queries take a [`Tally`]; a render passes `()`, whose counters are empty functions the
//! compiler removes, so that counting costs a render nothing unless it asks for it.

use std::cell::Cell;

/// What a traversal tells about its work.
pub trait Tally {
    /// `n` BVH nodes were tested (a node test is one wide node's boxes, all its children).
    fn nodes(&self, n: u64);
    /// `n` primitives were tested (a leaf block's primitives, a packet's shapes).
    fn prims(&self, n: u64);
}

impl Tally for () {
    #[inline(always)]
    fn nodes(&self, _: u64) {}
    #[inline(always)]
    fn prims(&self, _: u64) {}
}

/// Counts of nodes and primitives tested, kept in cells so that the traversal's closures can
/// share them.
#[derive(Clone, Debug, Default)]
pub struct Traversal {
    /// BVH node tests.
    pub nodes: Cell<u64>,
    /// Primitive tests.
    pub prims: Cell<u64>,
}

impl Tally for Traversal {
    #[inline]
    fn nodes(&self, n: u64) {
        self.nodes.set(self.nodes.get() + n);
    }
    #[inline]
    fn prims(&self, n: u64) {
        self.prims.set(self.prims.get() + n);
    }
}

/// A traversal counted or not: for code that runs once per ray batch, where one branch per
/// count costs nothing worth a second copy.
impl Tally for Option<&Traversal> {
    #[inline]
    fn nodes(&self, n: u64) {
        if let Some(t) = self {
            t.nodes(n);
        }
    }
    #[inline]
    fn prims(&self, n: u64) {
        if let Some(t) = self {
            t.prims(n);
        }
    }
}
