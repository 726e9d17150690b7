//! The terminal itself: set up and put back (`guard`), the gate every write
//! passes (`latch`), the `output` thread (`writer`), the drawing backend
//! that turns cells into bytes (`backend`), the escapes written by hand
//! (`escapes`), frames paced by the terminal's answers (`pacing`) and what
//! the terminal can show (`caps`). Nothing here knows what is drawn.
pub mod backend;
pub(super) mod caps;
pub(super) mod escapes;
pub(super) mod guard;
pub(super) mod latch;
pub(super) mod pacing;
pub(super) mod writer;
