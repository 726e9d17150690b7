//! What the rounds of a step did, kept apart so the rounds and the
//! conflicts they check both report into it without importing each other.

/// How a step's events were cut, for benches and tests (for a step cut
/// into parts, summed over them; `rounds` the most any part took).
#[derive(Clone, Copy, Debug, Default, PartialEq, Eq)]
pub struct RoundStats {
    /// Clusters of the first round.
    pub clusters: usize,
    pub rounds: usize,
    /// Cluster runs after the first round.
    pub reruns: usize,
    /// Spheres with events.
    pub involved: usize,
    /// Pairs in different clusters whose paths were compared, and how many
    /// of those were found apart (no rerun needed).
    pub compared: usize,
    pub apart: usize,
}

impl RoundStats {
    /// Takes in the stats of another part of the same step.
    pub fn add(&mut self, o: &RoundStats) {
        self.clusters += o.clusters;
        self.rounds = self.rounds.max(o.rounds);
        self.reruns += o.reruns;
        self.involved += o.involved;
        self.compared += o.compared;
        self.apart += o.apart;
    }
}
