//! The names of the app's threads in a threading mode, for the CPU reports
//! the panel tests draw.
use ballpit::engine::Threading;

/// `base` (the app's own threads), then the pool's `pool` threads or the
/// two split threads.
pub fn thread_names(base: &[&str], mode: Threading, pool: usize) -> Vec<String> {
    let mut names: Vec<String> = base.iter().map(|s| (*s).to_string()).collect();
    match mode {
        Threading::Pool => names.extend((0..pool).map(|i| format!("pool-{i}"))),
        Threading::Split => names.extend(["split-pair".to_string(), "split-wall".to_string()]),
        _ => {}
    }
    names
}
