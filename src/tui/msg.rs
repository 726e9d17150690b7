//! What wakes the frame loop: every thread of the app talks to it in one
//! message type over one channel.
use super::input::keys::Action;

/// What wakes the frame loop besides its own clock.
#[derive(Clone, Debug, PartialEq)]
pub enum Msg {
    /// What a key press means (the input thread reads the key table).
    Action(Action),
    /// The terminal answered a status request (read at that instant).
    Status(std::time::Instant),
    /// The `output` thread finished writing a chunk.
    Written,
    /// The physics finished a frame.
    PhysicsDone,
    Resize,
    /// A termination signal (its number): the `signals` thread is ending
    /// the process.
    Signal(i32),
    /// The process is being stopped (job control): the terminal is the
    /// shell's until `Resumed`.
    Held,
    /// Back in the foreground after a stop: everything must be repainted.
    Resumed,
    /// The terminal is gone or unreadable.
    Fatal(String),
    /// Some thread panicked (the hook has restored the terminal already).
    Panic,
}
