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

/// How long the start-up probe waits for an answer.
pub const PROBE: Duration = Duration::from_millis(200);
/// A frame unanswered this long, plus its crossing at [`SLOWEST_LINK`],
/// means the terminal stopped answering.
const ANSWER_TIMEOUT: Duration = Duration::from_secs(3);
/// Bytes per second of the slowest link the timeout allows for (a first
/// frame in colour, 10 KB, then has 13 s).
const SLOWEST_LINK: f64 = 1000.0;
/// Frames a key's update may be queued behind (a full one and one update).
const MAX_IN_FLIGHT: usize = 2;
/// Below this the link is treated as fast: no idle gap, no frozen canvas.
const FAST: Duration = Duration::from_millis(3);
/// Frames in flight on a fast link: a long round trip then does not cap
/// the frame rate (30 fps over a 100 ms round trip needs three).
const FAST_IN_FLIGHT: usize = 4;
/// Below this rate frames drop their colours (docs/terminal-io.md): 30
/// coloured frames a second take 130-180 KB/s at 120x40.
const CHEAP_RATE: f64 = 100_000.0;
/// On a slow link a second frame may follow the one in flight only if both
/// cross in this time: a key's update then waits behind at most this much
/// (or one frame), and a long round trip does not cap the frame rate.
const QUEUE_BUDGET: f64 = 0.1;

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

impl Sent {
    /// When its answer is overdue.
    fn deadline(&self) -> Instant {
        self.at + ANSWER_TIMEOUT + Duration::from_secs_f64(self.bytes as f64 / SLOWEST_LINK)
    }
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
    /// The size of the last frames answered (a slowly forgetting maximum).
    last_bytes: usize,
    /// Seconds the last answered frame took to cross the link.
    last_transfer: f64,
    /// When the question before the frame now crossing was answered.
    started: Option<Instant>,
    /// A frame's crossing has been timed.
    measured: bool,
}

impl Pacer {
    /// Start probing; the caller writes [`super::escapes::STATUS_QUERY`] now.
    pub fn new(now: Instant) -> Pacer {
        let mut p = Pacer {
            mode: Mode::Probing,
            probe_deadline: now + PROBE,
            in_flight: VecDeque::new(),
            unwritten: 0,
            rtt: None,
            rate: None,
            last_bytes: 0,
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

    #[cfg(test)]
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

    /// Whether frames should be cheaper (no colours): the link is measured
    /// slow. The rate is the link's, not the frames', so this does not flip
    /// back and forth as the frames shrink.
    pub fn cheap(&self) -> bool {
        self.slow() && self.rate.is_some_and(|r| r < CHEAP_RATE)
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

    /// Bytes of the frames not yet on screen.
    fn bytes_in_flight(&self) -> usize {
        self.in_flight.iter().map(|s| s.bytes).sum()
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
        if s.bytes >= 512 {
            self.last_bytes = s.bytes.max(self.last_bytes / 2);
        }
    }

    /// Time passes: the probe or an answer may be overdue.
    pub fn tick(&mut self, now: Instant) {
        match self.mode {
            Mode::Probing if now >= self.probe_deadline => {
                self.mode = Mode::Unpaced;
                self.in_flight.clear();
            }
            Mode::Paced if self.in_flight.front().is_some_and(|s| now > s.deadline()) => {
                self.mode = Mode::Unpaced;
                self.in_flight.clear();
            }
            _ => {}
        }
    }

    /// Whether a full frame may go out now.
    pub fn may_send(&self) -> bool {
        match self.mode {
            Mode::Probing => false,
            Mode::Paced => {
                let frames = self.frames_in_flight();
                frames == 0
                    || frames < self.fast_limit()
                    || self.rate.is_some_and(|r| {
                        let queued = self.bytes_in_flight() + self.last_bytes;
                        self.slow() && queued as f64 <= r * QUEUE_BUDGET
                    })
            }
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
            Mode::Paced => self.in_flight.front().map(Sent::deadline),
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
                // One frame per round trip and crossing, or per crossing
                // when two fit the budget.
                let pipelined = self
                    .rate
                    .is_some_and(|r| 2.0 * self.last_bytes as f64 <= r * QUEUE_BUDGET);
                let frame = self.last_transfer + if pipelined { 0.0 } else { rtt };
                match self.rate {
                    Some(r) if self.last_transfer > FAST.as_secs_f64() => format!(
                        "{:.0}ms {:.0}KB/s {:.0}fps{}",
                        rtt * 1e3,
                        r / 1e3,
                        1.0 / frame.max(1e-3),
                        if self.cheap() { " mono" } else { "" }
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

    /// Send a frame and have both of its questions answered.
    fn frame(p: &mut Pacer, at: Instant, bytes: usize, rtt: u64, transfer: u64) {
        p.sent(at, bytes, true);
        p.answered(at + ms(rtt));
        p.answered(at + ms(rtt + transfer));
    }

    #[test]
    fn a_slow_link_is_measured_and_gets_one_frame_at_a_time() {
        let t0 = Instant::now();
        let mut p = Pacer::new(t0);
        assert!(!p.may_send(), "probing");
        p.written();
        p.answered(t0 + ms(100));
        assert_eq!(p.mode(), Mode::Paced);
        assert!(p.asks());
        assert!(p.may_send());
        // A 6 KB frame at 16 KB/s on a 100 ms round trip: the question
        // before it is answered after 100 ms, the one after it 375 ms later.
        let t = t0 + ms(100);
        frame(&mut p, t, 6000, 100, 375);
        assert!((p.rtt.unwrap() - 0.1).abs() < 1e-9, "{:?}", p.rtt);
        let rate = p.rate.unwrap();
        assert!((rate - 16_000.0).abs() < 100.0, "{rate}");
        assert!(p.slow());
        assert!(p.cheap(), "16 KB/s is too slow for colours");
        assert!(p.describe().contains("16KB/s"), "{}", p.describe());
        // One frame in flight: two would not cross in the budget.
        let t = t + ms(500);
        assert!(p.may_send());
        p.sent(t, 6000, true);
        assert!(!p.may_send());
        // A key's update may follow it, and nothing more.
        assert!(p.may_send_update());
        p.sent(t + ms(10), 100, true);
        assert!(!p.may_send_update(), "at most two frames in flight");
        p.answered(t + ms(100));
        p.answered(t + ms(475));
        assert!(!p.may_send(), "the update is still unanswered");
        // The update's round trip waited behind the frame: not a sample.
        p.answered(t + ms(476));
        p.answered(t + ms(480));
        assert!((p.rtt.unwrap() - 0.1).abs() < 1e-9, "{:?}", p.rtt);
        assert!(p.may_send());
    }

    #[test]
    fn a_moderate_link_takes_a_second_frame_when_both_fit_the_budget() {
        let t0 = Instant::now();
        let mut p = Pacer::new(t0);
        p.answered(t0 + ms(100));
        // 2 KB frames at 64 KB/s: 31 ms each; two fit in 100 ms.
        let t = t0 + ms(100);
        frame(&mut p, t, 2000, 100, 31);
        assert!(p.slow() && p.cheap());
        p.sent(t + ms(200), 2000, true);
        assert!(p.may_send(), "a second frame fits");
        p.sent(t + ms(233), 2000, true);
        assert!(p.may_send(), "a third still fits in 6.4 KB");
        p.sent(t + ms(266), 2000, true);
        assert!(!p.may_send(), "a fourth would not");
    }

    #[test]
    fn a_fast_link_keeps_several_frames_in_flight_and_full_colour() {
        let t0 = Instant::now();
        let mut p = Pacer::new(t0);
        p.answered(t0 + ms(1));
        // Until a frame has been timed, one at a time.
        p.sent(t0 + ms(1), 5000, true);
        assert!(!p.may_send());
        p.answered(t0 + ms(2));
        p.answered(t0 + ms(2));
        // A long round trip on a fast link: several frames in flight.
        let mut t = t0 + ms(10);
        for i in 0..FAST_IN_FLIGHT {
            assert!(p.may_send(), "frame {i}");
            p.sent(t, 5000, true);
            t += ms(33);
        }
        assert!(!p.may_send());
        assert!(!p.slow() && !p.cheap());
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
        assert!(!p.may_send(), "the probe is not written yet");
        p.written();
        assert!(p.may_send());
        p.sent(t0 + ms(201), 5000, false);
        assert!(!p.may_send());
        assert!(p.may_send_update());
        p.written();
        assert!(p.may_send());
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
        // 5000 bytes may take 5 s on the slowest link allowed for.
        p.tick(t0 + ms(10) + ANSWER_TIMEOUT + ms(5000));
        assert_eq!(p.mode(), Mode::Paced);
        p.tick(t0 + ms(11) + ANSWER_TIMEOUT + ms(5000));
        assert_eq!(p.mode(), Mode::Unpaced);
        assert!(p.may_send());
    }
}
