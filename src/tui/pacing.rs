//! Frames paced by the terminal (issue 16). Before and after each frame the
//! app asks the terminal for a device status report (`ESC[5n`); the
//! terminal answers only once it has consumed everything before the
//! question, so the second answer says "the frame is on screen", whatever the
//! buffers on the way, the first one times the round trip, and the time
//! between them is how long the frame took to cross the link. A full
//! frame goes out only when the previous one has been answered and the link
//! has had an idle gap as long as that frame took to cross it, so a key's
//! answer finds the link free about half of the time and never queues behind
//! more than one frame. A terminal that does not answer the start-up probe
//! within [`PROBE`] is driven as before (a frame when the last one has been
//! written). Pure logic on instants, so it is tested without a terminal.
use std::collections::VecDeque;
use std::time::{Duration, Instant};

/// The question appended to every paced frame.
pub const QUERY: &[u8] = b"\x1b[5n";
/// How long the start-up probe waits for an answer.
pub const PROBE: Duration = Duration::from_millis(200);
/// A frame unanswered this long means the terminal stopped answering.
const ANSWER_TIMEOUT: Duration = Duration::from_secs(3);
/// Frames a key's update may be queued behind (a full one and one update).
const MAX_IN_FLIGHT: usize = 2;
/// Below this the link is treated as fast: no idle gap, no frozen canvas.
const FAST: Duration = Duration::from_millis(3);
/// Frames in flight on a fast link: a long round trip then does not cap
/// the frame rate (30 fps over a 100 ms round trip needs three).
const FAST_IN_FLIGHT: usize = 4;
/// The idle gap after a frame, as a fraction of the time it took to cross
/// the link: a key's update finds the link free about half of the time, and
/// waits for at most one frame otherwise.
const GAP: f64 = 1.0;

#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum Mode {
    /// Waiting for the answer to the start-up probe.
    Probing,
    /// The terminal answers: frames wait for answers.
    Paced,
    /// No answers: a frame when the last one has been written.
    Unpaced,
}

#[derive(Clone, Copy, Debug)]
struct Sent {
    at: Instant,
    bytes: usize,
    /// The question before a frame (its answer times the round trip).
    before: bool,
    /// Sent while another question was unanswered: its round trip includes
    /// waiting behind that one.
    queued: bool,
}

/// What the app knows of the link to the terminal.
#[derive(Debug)]
pub struct Pacer {
    mode: Mode,
    probe_deadline: Instant,
    /// Questions asked and not yet answered, oldest first.
    in_flight: VecDeque<Sent>,
    /// Chunks handed to the writer and not yet written.
    unwritten: usize,
    /// Round trip of an empty message, seconds (smallest recent).
    rtt: Option<f64>,
    /// Bytes per second the link carries, when it is slow enough to tell.
    rate: Option<f64>,
    /// No full frame before this: the link's idle gap.
    idle_until: Instant,
    /// Seconds the last answered frame took to cross the link.
    last_transfer: f64,
    /// When the question before the frame now crossing was answered.
    started: Option<Instant>,
    /// A frame's crossing has been timed.
    measured: bool,
}

impl Pacer {
    /// Start probing; the caller writes [`QUERY`] now.
    pub fn new(now: Instant) -> Pacer {
        let mut p = Pacer {
            mode: Mode::Probing,
            probe_deadline: now + PROBE,
            in_flight: VecDeque::new(),
            unwritten: 0,
            rtt: None,
            rate: None,
            idle_until: now,
            last_transfer: 0.0,
            started: None,
            measured: false,
        };
        p.in_flight.push_back(Sent {
            at: now,
            bytes: 0,
            before: true,
            queued: false,
        });
        p.unwritten = 1;
        p
    }

    pub fn mode(&self) -> Mode {
        self.mode
    }

    /// Whether frames should carry the question.
    pub fn asks(&self) -> bool {
        self.mode == Mode::Paced
    }

    /// Whether the link is slow enough that a key's update should leave the
    /// canvas as it is (only the changed readouts cross the link).
    pub fn slow(&self) -> bool {
        self.mode == Mode::Paced
            && (self.last_transfer > FAST.as_secs_f64()
                || self.rtt.is_some_and(|r| r > 4.0 * FAST.as_secs_f64()))
    }

    /// A chunk of `bytes` was handed to the writer, between two questions
    /// or without any.
    pub fn sent(&mut self, now: Instant, bytes: usize, asked: bool) {
        self.unwritten += 1;
        if asked {
            let queued = !self.in_flight.is_empty();
            self.in_flight.push_back(Sent {
                at: now,
                bytes: 0,
                before: true,
                queued,
            });
            self.in_flight.push_back(Sent {
                at: now,
                bytes,
                before: false,
                queued: true,
            });
        }
    }

    /// Frames that may be in flight on this link: one until a frame has
    /// shown the link is fast.
    fn fast_limit(&self) -> usize {
        if self.measured && self.last_transfer < FAST.as_secs_f64() {
            FAST_IN_FLIGHT
        } else {
            1
        }
    }

    /// Frames sent and not yet on screen.
    fn frames_in_flight(&self) -> usize {
        self.in_flight.iter().filter(|s| !s.before).count()
    }

    /// The writer finished a chunk.
    pub fn written(&mut self) {
        self.unwritten = self.unwritten.saturating_sub(1);
    }

    /// The terminal answered the oldest question.
    pub fn answered(&mut self, now: Instant) {
        let Some(s) = self.in_flight.pop_front() else {
            // An answer after a timeout: the terminal does answer after all.
            if self.mode == Mode::Unpaced {
                self.mode = Mode::Paced;
            }
            return;
        };
        self.mode = Mode::Paced;
        let took = now.saturating_duration_since(s.at).as_secs_f64();
        if s.before {
            if !s.queued {
                // The smallest recent round trip, forgetting it slowly.
                self.rtt = Some(match self.rtt {
                    Some(r) if took >= r => r + 0.1 * (took - r),
                    _ => took,
                });
            }
            self.started = Some(now);
            return;
        }
        let transfer = self
            .started
            .take()
            .map_or(0.0, |t| now.saturating_duration_since(t).as_secs_f64());
        if s.bytes >= 512 {
            self.measured = true;
            self.last_transfer = transfer;
            if transfer > 0.002 {
                let sample = s.bytes as f64 / transfer;
                self.rate = Some(self.rate.map_or(sample, |r| r + 0.3 * (sample - r)));
            }
        }
        // Leave the link idle for a while after a frame.
        let gap = Duration::from_secs_f64(GAP * self.last_transfer);
        self.idle_until = now + if gap < FAST { Duration::ZERO } else { gap };
    }

    /// Time passes: the probe or an answer may be overdue.
    pub fn tick(&mut self, now: Instant) {
        match self.mode {
            Mode::Probing if now >= self.probe_deadline => {
                self.mode = Mode::Unpaced;
                self.in_flight.clear();
            }
            Mode::Paced
                if self
                    .in_flight
                    .front()
                    .is_some_and(|s| now.saturating_duration_since(s.at) > ANSWER_TIMEOUT) =>
            {
                self.mode = Mode::Unpaced;
                self.in_flight.clear();
            }
            _ => {}
        }
    }

    /// Whether a full frame may go out now.
    pub fn may_send(&self, now: Instant) -> bool {
        match self.mode {
            Mode::Probing => false,
            Mode::Paced => self.frames_in_flight() < self.fast_limit() && now >= self.idle_until,
            Mode::Unpaced => self.unwritten == 0,
        }
    }

    /// Whether a key's small update may go out now.
    pub fn may_send_update(&self) -> bool {
        match self.mode {
            Mode::Probing => false,
            Mode::Paced => self.frames_in_flight() < MAX_IN_FLIGHT.max(self.fast_limit()),
            Mode::Unpaced => self.unwritten <= 1,
        }
    }

    /// When [`may_send`](Self::may_send) or the mode may change by time
    /// alone.
    pub fn next_change(&self) -> Option<Instant> {
        match self.mode {
            Mode::Probing => Some(self.probe_deadline),
            Mode::Paced => match self.in_flight.front() {
                Some(s) => Some(s.at + ANSWER_TIMEOUT),
                None => Some(self.idle_until),
            },
            Mode::Unpaced => None,
        }
    }

    /// The link as the app sees it, for the readouts.
    pub fn describe(&self) -> String {
        match self.mode {
            Mode::Probing => "link: probing".into(),
            Mode::Unpaced => "link: no answers".into(),
            Mode::Paced => {
                let rtt = self.rtt.unwrap_or(0.0);
                let frame = rtt + 2.0 * self.last_transfer;
                match self.rate {
                    Some(r) if self.last_transfer > FAST.as_secs_f64() => format!(
                        "{:.0}ms {:.0}KB/s ≤{:.1}fps",
                        rtt * 1e3,
                        r / 1e3,
                        1.0 / frame.max(1e-3)
                    ),
                    _ => format!("link fast, rtt {:.0}ms", rtt * 1e3),
                }
            }
        }
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    fn ms(n: u64) -> Duration {
        Duration::from_millis(n)
    }

    #[test]
    fn a_terminal_that_answers_is_paced_one_frame_at_a_time() {
        let t0 = Instant::now();
        let mut p = Pacer::new(t0);
        assert!(!p.may_send(t0));
        p.written();
        p.answered(t0 + ms(100));
        assert_eq!(p.mode(), Mode::Paced);
        let t = t0 + ms(100);
        assert!(p.may_send(t));
        // A 6 KB frame at 16 KB/s on a 100 ms round trip: the question
        // before it is answered after 100 ms, the one after it 375 ms later.
        p.sent(t, 6000, true);
        assert!(!p.may_send(t + ms(10)));
        assert!(p.may_send_update());
        p.sent(t + ms(10), 100, true);
        assert!(!p.may_send_update(), "at most two frames in flight");
        p.answered(t + ms(100));
        p.answered(t + ms(475));
        assert!(!p.may_send(t + ms(476)), "the update is still unanswered");
        // The update's round trip waited behind the frame: not a sample.
        p.answered(t + ms(476));
        p.answered(t + ms(480));
        assert!((p.rtt.unwrap() - 0.1).abs() < 1e-9, "{:?}", p.rtt);
        // The link stays idle as long as the frame took to cross it.
        assert!(!p.may_send(t + ms(480 + 374)));
        assert!(p.may_send(t + ms(480 + 375)));
        assert!(p.slow());
        let rate = p.rate.unwrap();
        assert!((rate - 16_000.0).abs() < 200.0, "{rate}");
        assert!(p.describe().contains("16KB/s"), "{}", p.describe());
    }

    #[test]
    fn a_fast_link_has_no_gap() {
        let t0 = Instant::now();
        let mut p = Pacer::new(t0);
        p.answered(t0 + ms(1));
        let mut t = t0 + ms(1);
        for _ in 0..10 {
            p.sent(t, 5000, true);
            p.answered(t + Duration::from_micros(500));
            p.answered(t + Duration::from_micros(800));
            t += ms(33);
            assert!(p.may_send(t - ms(32)));
        }
        // A long round trip on a fast link: several frames in flight.
        for i in 0..FAST_IN_FLIGHT {
            assert!(p.may_send(t), "frame {i}");
            p.sent(t, 5000, true);
            t += ms(33);
        }
        assert!(!p.may_send(t));
        assert!(!p.slow());
        assert!(p.describe().contains("fast"), "{}", p.describe());
    }

    #[test]
    fn no_answer_to_the_probe_means_unpaced_and_a_late_answer_paces_again() {
        let t0 = Instant::now();
        let mut p = Pacer::new(t0);
        p.tick(t0 + ms(199));
        assert_eq!(p.mode(), Mode::Probing);
        assert_eq!(p.next_change(), Some(t0 + PROBE));
        p.tick(t0 + ms(200));
        assert_eq!(p.mode(), Mode::Unpaced);
        assert!(!p.asks());
        // Unpaced: a frame once the writer has written the last one.
        assert!(!p.may_send(t0 + ms(200)), "the probe is not written yet");
        p.written();
        assert!(p.may_send(t0 + ms(200)));
        p.sent(t0 + ms(201), 5000, false);
        assert!(!p.may_send(t0 + ms(210)));
        p.written();
        assert!(p.may_send(t0 + ms(210)));
        // The probe's answer arrives late (a long round trip): paced now.
        p.answered(t0 + ms(350));
        assert_eq!(p.mode(), Mode::Paced);
    }

    #[test]
    fn a_terminal_that_stops_answering_is_unpaced_after_a_timeout() {
        let t0 = Instant::now();
        let mut p = Pacer::new(t0);
        p.written();
        p.answered(t0 + ms(5));
        p.sent(t0 + ms(10), 5000, true);
        p.answered(t0 + ms(10));
        p.written();
        p.tick(t0 + ms(10) + ANSWER_TIMEOUT);
        assert_eq!(p.mode(), Mode::Paced);
        p.tick(t0 + ms(11) + ANSWER_TIMEOUT);
        assert_eq!(p.mode(), Mode::Unpaced);
        assert!(p.may_send(t0 + ms(11) + ANSWER_TIMEOUT));
    }
}
