//! What each thread of the process is for. The engine names its threads
//! from their role, and the sampler reads the role back once, from the name
//! the kernel reports, so the rest of the app (order, the pool's group and
//! total, the chart) works with roles and never parses names.
use std::borrow::Cow;

#[derive(Clone, Copy, Debug, PartialEq, Eq, Hash, PartialOrd, Ord)]
pub enum ThreadRole {
    /// The process's first thread: the frame loop (and the physics in `off`).
    Main,
    /// The worker that drives the physics in `worker` and `split`.
    Physics,
    /// Lane thread `n` of the pool.
    Pool(u32),
    /// `split`'s sphere–sphere thread.
    SplitPair,
    /// `split`'s sphere–wall thread.
    SplitWall,
    /// Anything else (`input`, `signals`, `output`, …), known by its name.
    Other,
}

impl ThreadRole {
    const POOL: &'static str = "pool-";

    /// The thread's name for this role (`Other` has none of its own).
    #[must_use]
    pub fn name(self) -> Cow<'static, str> {
        match self {
            ThreadRole::Main => "main".into(),
            ThreadRole::Physics => "physics".into(),
            ThreadRole::Pool(n) => format!("{}{n}", Self::POOL).into(),
            ThreadRole::SplitPair => "split-pair".into(),
            ThreadRole::SplitWall => "split-wall".into(),
            ThreadRole::Other => "".into(),
        }
    }

    /// The role of a thread called `name`.
    #[must_use]
    pub fn of(name: &str) -> ThreadRole {
        match name {
            "main" => ThreadRole::Main,
            "physics" => ThreadRole::Physics,
            "split-pair" => ThreadRole::SplitPair,
            "split-wall" => ThreadRole::SplitWall,
            _ => name
                .strip_prefix(Self::POOL)
                .filter(|n| !n.starts_with('+'))
                .and_then(|n| n.parse().ok())
                .map_or(ThreadRole::Other, ThreadRole::Pool),
        }
    }

    /// The pool lane's number, for pool threads.
    #[must_use]
    pub fn lane(self) -> Option<u32> {
        match self {
            ThreadRole::Pool(n) => Some(n),
            _ => None,
        }
    }

    /// The label of the pool's group in the panel and the chart (`pool`).
    pub const POOL_GROUP: &'static str = "pool";
}

#[cfg(test)]
mod tests {
    use super::ThreadRole;

    #[test]
    fn every_role_reads_back_from_its_name() {
        for role in [
            ThreadRole::Main,
            ThreadRole::Physics,
            ThreadRole::Pool(0),
            ThreadRole::Pool(255),
            ThreadRole::SplitPair,
            ThreadRole::SplitWall,
        ] {
            assert_eq!(ThreadRole::of(&role.name()), role);
        }
        for other in [
            "input", "pool-", "pool-x", "pool-+1", "pools-1", "output", "",
        ] {
            assert_eq!(ThreadRole::of(other), ThreadRole::Other, "{other}");
        }
        // Main, physics, the pool by number, the split: the panel's order.
        assert!(ThreadRole::Physics < ThreadRole::Pool(0));
        assert!(ThreadRole::Pool(2) < ThreadRole::Pool(10));
        assert!(ThreadRole::Pool(255) < ThreadRole::SplitPair);
    }
}
