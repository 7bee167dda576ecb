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
//! of `P` entries and a statistics table of `N` entries. They differ for `auto`: its
//! labels are `u8`, so a parent table of all 256 `u8` values needs no bounds check,
//! while its statistics table holds only the labels it hands out.

/// A component label: an index into the tables.
pub(crate) trait Label: Copy + Eq + Ord {
    /// The label as a table index.
    fn index(self) -> usize;
}

impl Label for u8 {
    fn index(self) -> usize {
        usize::from(self)
    }
}

impl Label for u16 {
    fn index(self) -> usize {
        usize::from(self)
    }
}

/// Statistics of one component, merged when two components join.
pub(crate) trait Stats: Copy {
    /// Adds `other`'s statistics to `self`'s.
    fn merge(&mut self, other: &Self);
}

/// A union-find forest of at most `N` components (labels `0..N`) with statistics `S`,
/// and a parent table of `P ≥ N` entries.
#[derive(Debug, Clone)]
pub(crate) struct Components<L, S, const P: usize, const N: usize> {
    /// Parent of each label; a root is its own parent. Entries the user marks free hold
    /// a value outside `0..P`.
    parent: [L; P],
    /// Statistics of each label (meaningful at roots).
    stats: [S; N],
}

impl<L: Label, S: Stats, const P: usize, const N: usize> Components<L, S, P, N> {
    /// A table with every parent `parent` and every statistic `stats`.
    pub const fn new(parent: L, stats: S) -> Self {
        Components {
            parent: [parent; P],
            stats: [stats; N],
        }
    }

    /// The parent of `l` (`None` outside the table).
    pub fn parent(&self, l: usize) -> Option<L> {
        self.parent.get(l).copied()
    }

    /// The parent table.
    pub fn parents(&self) -> &[L; P] {
        &self.parent
    }

    /// Sets the parent of `l` (ignored outside the table).
    pub fn set_parent(&mut self, l: usize, p: L) {
        if let Some(e) = self.parent.get_mut(l) {
            *e = p;
        }
    }

    /// The statistics of `l` (`None` outside the table).
    pub fn stats(&self, l: usize) -> Option<&S> {
        self.stats.get(l)
    }

    /// The statistics of `l`, to update (`None` outside the table).
    pub fn stats_mut(&mut self, l: usize) -> Option<&mut S> {
        self.stats.get_mut(l)
    }

    /// Makes `l` a new root with statistics `stats`.
    pub fn make_set(&mut self, l: L, stats: S) {
        self.set_parent(l.index(), l);
        if let Some(s) = self.stats.get_mut(l.index()) {
            *s = stats;
        }
    }

    /// The root of `l`, halving the path on the way (every label on it then points to
    /// its grandparent). A label whose parent lies outside the table (a free entry) is
    /// its own root.
    pub fn find(&mut self, mut l: L) -> L {
        loop {
            let Some(&p) = self.parent.get(l.index()) else {
                return l;
            };
            if p == l {
                return l;
            }
            let Some(&g) = self.parent.get(p.index()) else {
                return l;
            };
            self.parent[l.index()] = g;
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
        if let (Some(&g), true) = (self.stats.get(gone.index()), keep.index() < N) {
            self.stats[keep.index()].merge(&g);
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
