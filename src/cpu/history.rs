//! A minute of one-second samples for the sparklines and the chart. Time
//! comes in as `Instant`s, so tests drive it with a fake clock.
use std::collections::VecDeque;
use std::time::{Duration, Instant};

/// One sample per this much time...
pub const STEP: Duration = Duration::from_secs(1);
/// ...over this long: the sparkline's and the chart's "last minute".
pub const SPAN: Duration = Duration::from_mins(1);
/// Samples in a full history.
pub const LEN: usize = (SPAN.as_secs() / STEP.as_secs()) as usize;

/// Values in one-second slots counted from a shared origin, newest last.
/// Several readings in one slot keep the latest; slots skipped (a late
/// sampler) take the next reading, which averages over them anyway.
#[derive(Clone, Debug)]
pub struct History {
    origin: Instant,
    /// The slot of the newest value.
    last: Option<u64>,
    values: VecDeque<f64>,
}

impl History {
    pub fn new(origin: Instant) -> History {
        History {
            origin,
            last: None,
            values: VecDeque::with_capacity(LEN),
        }
    }

    pub fn push(&mut self, at: Instant, value: f64) {
        let slot = (at.saturating_duration_since(self.origin).as_nanos() / STEP.as_nanos()) as u64;
        match self.last {
            Some(last) if slot <= last => {
                if let Some(v) = self.values.back_mut() {
                    *v = value;
                }
                return;
            }
            Some(last) => {
                let fill = (slot - last).min(LEN as u64);
                for _ in 0..fill {
                    self.values.push_back(value);
                }
            }
            None => self.values.push_back(value),
        }
        self.last = Some(slot);
        while self.values.len() > LEN {
            self.values.pop_front();
        }
    }

    /// The values, oldest first, one per second up to the newest.
    pub fn values(&self) -> Vec<f64> {
        self.values.iter().copied().collect()
    }

    #[cfg(test)]
    pub fn len(&self) -> usize {
        self.values.len()
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn holds_the_last_sixty_seconds_of_one_second_samples() {
        let t0 = Instant::now();
        let mut h = History::new(t0);
        // A sampler a little late every time, for two minutes.
        for k in 0..120u64 {
            h.push(t0 + Duration::from_millis(k * 1000 + 7), k as f64);
        }
        assert_eq!(h.len(), 60);
        let v = h.values();
        assert_eq!(v[0], 60.0);
        assert_eq!(v[59], 119.0);
    }

    #[test]
    fn readings_in_one_second_keep_the_latest_and_gaps_are_filled() {
        let t0 = Instant::now();
        let mut h = History::new(t0);
        for ms in [0, 250, 500, 750] {
            h.push(t0 + Duration::from_millis(ms), ms as f64);
        }
        assert_eq!(h.values(), [750.0]);
        // Three seconds without a reading: the next one stands for them.
        h.push(t0 + Duration::from_millis(4100), 5.0);
        assert_eq!(h.values(), [750.0, 5.0, 5.0, 5.0, 5.0]);
        // A gap longer than the span leaves one span of the new value.
        h.push(t0 + Duration::from_secs(1000), 9.0);
        assert_eq!(h.values(), vec![9.0; LEN]);
    }
}
