//! Connected-component labelling, shared by the mask-to-box rule ([`super::mask`]:
//! runs of foreground pixels, streamed row by row) and `auto` (edge cells of its step
//! plane): one union-find over small integer labels, with statistics per component
//! merged on union.
//!
//! - [`Components::find`]: the root of a label, halving the path on the way;
//! - [`Components::union`]: joins two roots; the lower label stays root and takes the
//!   other's statistics ([`Stats::merge`]), so a component's label is the first one it
//!   was given (raster order: the tie-breakers of both users rely on it);
//! - statistics are per use: [`super::mask`]'s box, pixel count and first pixel;
//!   `auto`'s cell box and summed steps.
//!
//! Capacities are the users' (fixed arrays, no heap): `L` labels index a parent table
//! `P` (an array of `L`) and a statistics table `N` (an array of `S`). They differ for `auto`: its
//! labels are `u8`, so a parent table of all 256 `u8` values needs no bounds check,
//! while its statistics table holds only the labels it hands out.

use core::marker::PhantomData;

/// The offsets (dx, dy) of a pixel's (or cell's) 8 neighbours, row by row: the
/// 8-connectivity both the spot search's refinement and the segment detector's region
/// growth walk.
pub(crate) const NEIGHBOURS_8: [(isize, isize); 8] = [
    (-1, -1),
    (0, -1),
    (1, -1),
    (-1, 0),
    (1, 0),
    (-1, 1),
    (0, 1),
    (1, 1),
];

use crate::capacity::{Buffer, ConstInit};

/// A component label: an index into the tables.
pub(crate) trait Label: Copy + Eq + Ord + core::fmt::Debug + ConstInit {
    /// The label as a table index.
    fn index(self) -> usize;
}

impl Label for u8 {
    fn index(self) -> usize {
        usize::from(self)
    }
}

/// Statistics of one component, merged when two components join.
pub(crate) trait Stats: Copy + core::fmt::Debug + ConstInit {
    /// Adds `other`'s statistics to `self`'s.
    fn merge(&mut self, other: &Self);
}

/// A union-find forest of at most `N` components (labels `0..N`, `N` the length of
/// the statistics table `T`) with statistics `S`, and a parent table `P` of at least
/// `N` entries.
#[derive(Debug, Clone)]
pub(crate) struct Components<L, S, P, T> {
    /// Parent of each label; a root is its own parent. Entries the user marks free hold
    /// a value outside the table.
    parent: P,
    /// Statistics of each label (meaningful at roots).
    stats: T,
    _types: PhantomData<(L, S)>,
}

impl<L, S, P: ConstInit, T: ConstInit> ConstInit for Components<L, S, P, T> {
    /// Every parent `L::INIT` (the user's "free" or "no label") and every statistic
    /// `S::INIT`.
    const INIT: Self = Components {
        parent: P::INIT,
        stats: T::INIT,
        _types: PhantomData,
    };
}

impl<L: Label, S: Stats, P: Buffer<L>, T: Buffer<S>> Components<L, S, P, T> {
    /// The parent of `l` (`None` outside the table).
    pub fn parent(&self, l: usize) -> Option<L> {
        self.parent.as_ref().get(l).copied()
    }

    /// The parent table.
    pub fn parents(&self) -> &P {
        &self.parent
    }

    /// Sets the parent of `l` (ignored outside the table).
    pub fn set_parent(&mut self, l: usize, p: L) {
        if let Some(e) = self.parent.as_mut().get_mut(l) {
            *e = p;
        }
    }

    /// The statistics of `l` (`None` outside the table).
    pub fn stats(&self, l: usize) -> Option<&S> {
        self.stats.as_ref().get(l)
    }

    /// The statistics of `l`, to update (`None` outside the table).
    pub fn stats_mut(&mut self, l: usize) -> Option<&mut S> {
        self.stats.as_mut().get_mut(l)
    }

    /// Makes `l` a new root with statistics `stats`.
    pub fn make_set(&mut self, l: L, stats: S) {
        self.set_parent(l.index(), l);
        if let Some(s) = self.stats.as_mut().get_mut(l.index()) {
            *s = stats;
        }
    }

    /// The root of `l`, halving the path on the way (every label on it then points to
    /// its grandparent). A label whose parent lies outside the table (a free entry) is
    /// its own root.
    pub fn find(&mut self, mut l: L) -> L {
        let parent = self.parent.as_mut();
        loop {
            let Some(&p) = parent.get(l.index()) else {
                return l;
            };
            if p == l {
                return l;
            }
            let Some(&g) = parent.get(p.index()) else {
                return l;
            };
            parent[l.index()] = g;
            l = p;
        }
    }

    /// Joins roots `a` and `b`: the lower label stays root and takes the other's
    /// statistics. Returns the root.
    pub fn union(&mut self, a: L, b: L) -> L {
        if a == b {
            return a;
        }
        let (keep, gone) = if a < b { (a, b) } else { (b, a) };
        self.set_parent(gone.index(), keep);
        let stats = self.stats.as_mut();
        if let (Some(&g), true) = (stats.get(gone.index()), keep.index() < stats.len()) {
            stats[keep.index()].merge(&g);
        }
        keep
    }

    /// Points every label of `labels` straight at its root, so later lookups are one
    /// read of [`Components::parents`].
    pub fn flatten(&mut self, labels: core::ops::Range<usize>, label: impl Fn(usize) -> L) {
        for l in labels {
            let root = self.find(label(l));
            self.set_parent(l, root);
        }
    }
}
