//! The numbers the event loop passes around, each its own type so one can
//! never stand for another: a body's [`Label`] (its place in the model's
//! spatial order, what every per-body array is indexed with), the
//! [`WorldId`] of the sphere it is in `world.spheres`, a [`SpeciesId`] and
//! a neighbour-list grid [`Cell`]. Each is 4 bytes, as the plain `u32`s were.

/// Defines a 4-byte index type: `at`/`index` to and from `usize`, and for a
/// `packed` one `raw` and `from_raw` where the number sits in a packed word.
macro_rules! index_type {
    ($(#[$doc:meta])* $name:ident, packed) => {
        index_type!($(#[$doc])* $name);

        impl $name {
            /// From the word a packed record keeps it in.
            #[inline(always)]
            pub fn from_raw(raw: u32) -> Self {
                Self(raw)
            }

            /// The word to keep it in a packed record.
            #[inline(always)]
            pub fn raw(self) -> u32 {
                self.0
            }
        }
    };
    ($(#[$doc:meta])* $name:ident) => {
        $(#[$doc])*
        #[derive(Clone, Copy, Debug, Default, PartialEq, Eq, PartialOrd, Ord, Hash)]
        pub struct $name(u32);

        impl $name {
            /// The one at `index` (below `u32::MAX`: a world holds at most 10^7 spheres).
            #[inline(always)]
            pub fn at(index: usize) -> Self {
                debug_assert!(index < u32::MAX as usize);
                Self(index as u32)
            }

            #[inline(always)]
            pub fn index(self) -> usize {
                self.0 as usize
            }
        }
    };
}

index_type!(
    /// A body's place in the model's own order (sorted in space at load):
    /// never a world id.
    Label, packed
);

index_type!(
    /// A sphere's index in `world.spheres`: what the world, observers and
    /// the CSV see. The model maps its labels to these through its `order`.
    WorldId
);

index_type!(
    /// A radius–mass pair's place in the model's species table.
    SpeciesId
);

index_type!(
    /// A cell of the neighbour lists' grid.
    Cell
);

impl Label {
    /// No body: the end of a chain.
    pub const NONE: Label = Label(u32::MAX);
}
