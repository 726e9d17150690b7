//! What a level sorts: each sphere's ball, id and cell key, and where they
//! come from. Apart from the level and its placing, which both use them.
use glam::DVec3;

/// A sphere's ball for the step: it stays within `reach` of `pos`.
#[derive(Clone, Copy, Debug, Default)]
pub(super) struct Ball {
    pub(super) pos: DVec3,
    pub(super) reach: f64,
}

/// A sphere in a level: its ball, id and padded cell key (on its way into
/// the first level, `level::WIDE` when too wide for it). One record, so that
/// sorting it into place writes one place in memory, not three.
#[derive(Clone, Copy, Debug, Default)]
pub(super) struct Entry {
    pub(super) ball: Ball,
    pub(super) id: u32,
    pub(super) key: u32,
}

/// Where the first level's records come from while it sorts them.
pub(super) trait Source: Sync {
    /// Each sphere's (cell key, reach), in id order.
    fn keys(&self) -> impl DoubleEndedIterator<Item = (u32, f64)> + ExactSizeIterator;
    /// The (cell key, reach) of spheres `ids` alone, as `keys` gives them.
    fn keys_of(&self, ids: std::ops::Range<usize>) -> impl Iterator<Item = (u32, f64)>;
    /// Sphere `i`'s record.
    fn entry(&self, i: usize) -> Entry;
    /// The records themselves, when they lie in memory in id order.
    fn records(&self) -> Option<&[Entry]>;
}

impl Source for [Entry] {
    #[inline(always)]
    fn keys(&self) -> impl DoubleEndedIterator<Item = (u32, f64)> + ExactSizeIterator {
        self.iter().map(|e| (e.key, e.ball.reach))
    }
    #[inline(always)]
    fn keys_of(&self, ids: std::ops::Range<usize>) -> impl Iterator<Item = (u32, f64)> {
        self[ids].iter().map(|e| (e.key, e.ball.reach))
    }
    #[inline(always)]
    fn entry(&self, i: usize) -> Entry {
        self[i]
    }
    fn records(&self) -> Option<&[Entry]> {
        Some(self)
    }
}
