//! How much memory a world will take, and whether the machine has it: a count
//! that would not fit is refused up front with the figure, never left to the
//! kernel's OOM killer.
use crate::physics::ModelKind;

/// Peak bytes a sphere costs while a model steps headless (`bench`), with a
/// quarter for margin (peak RSS at a million spheres less the empty process,
/// the largest of packing 0.005, 0.1 and the dense preset: for `exact` 185,
/// 184 and 248 B; docs/figures.md#memory has the runs).
pub fn sphere_bytes(model: ModelKind) -> u64 {
    match model {
        ModelKind::Discrete => 243,
        // `auto` may run any: the hungriest.
        ModelKind::Swept | ModelKind::Auto(_) => 342,
        ModelKind::Exact => 310,
    }
}

/// What the app holds a sphere on top of the model's run, with the same
/// margin: the start kept for Reset (64 bytes; only for a scene from a
/// file, a preset is made again) and the front and back screen views (20
/// bytes each).
const SCREEN_BYTES: u64 = 130;

/// What the run still takes after the check whatever the count: threads'
/// stacks, the screen's buffers. Counted once, and not halved with the
/// share: a run of no sphere needs only this.
const FIXED_BYTES: u64 = 16 << 20;

/// The share of the memory left, once the fixed cost is paid, that the
/// spheres may plan on.
const SHARE: f64 = 0.5;

/// Bytes a world of `count` spheres needs headless under `model`, or in the
/// app (`None`): under whichever model needs most, since the app can switch
/// at any time, plus what the screen keeps.
pub fn need(count: usize, model: Option<ModelKind>) -> u64 {
    let per = model.map_or_else(
        || {
            ModelKind::ALL
                .map(sphere_bytes)
                .into_iter()
                .max()
                .unwrap_or(0)
                + SCREEN_BYTES
        },
        sphere_bytes,
    );
    FIXED_BYTES.saturating_add((count as u64).saturating_mul(per))
}

/// `MemAvailable` of `/proc/meminfo`, or what the address-space limit
/// (`ulimit -v`) leaves beyond what the process already maps, if that is
/// lower, in bytes (`None` when neither is known).
pub fn available() -> Option<u64> {
    let free = crate::procfs::meminfo_kib("MemAvailable").map(|kib| kib.saturating_mul(1024));
    let mapped = crate::procfs::status_kib("VmSize").map_or(0, |kib| kib.saturating_mul(1024));
    let limit = rustix::process::getrlimit(rustix::process::Resource::As)
        .current
        .map(|l| l.saturating_sub(mapped));
    match (free, limit) {
        (Some(f), Some(l)) => Some(f.min(l)),
        (f, l) => f.or(l),
    }
}

/// Whether `count` spheres fit in `budget` bytes free; the message says how
/// much they would need.
pub fn check(count: usize, model: Option<ModelKind>, free: Option<u64>) -> Result<(), String> {
    let Some((need, allowed, free)) = refusal(count, model, free) else {
        return Ok(());
    };
    Err(format!(
        "{count} spheres would need about {} of memory{}, more than the {} a run may plan on: {} for the process and half of the rest of the {} available (free memory, or what ulimit -v leaves if lower)",
        mib(need),
        model.map_or(String::new(), |m| format!(" with {m}")),
        mib(allowed),
        mib(FIXED_BYTES),
        mib(free)
    ))
}

/// The screen's notice for a count [`check`] refuses, short enough for two
/// rows of the readouts panel (the command line gives the whole story).
pub fn count_notice(count: usize, free: Option<u64>) -> Option<String> {
    let (need, allowed, _) = refusal(count, None, free)?;
    Some(format!(
        "count limit: {count} spheres need {}, over the {} a run may use",
        mib(need),
        mib(allowed)
    ))
}

/// What `count` spheres need, what a run may plan on and what is free,
/// when the first is more than the second.
fn refusal(count: usize, model: Option<ModelKind>, free: Option<u64>) -> Option<(u64, u64, u64)> {
    let free = free?;
    let need = need(count, model);
    // The fixed cost once, then a share of the rest for the spheres.
    let allowed = if free < FIXED_BYTES {
        0
    } else {
        FIXED_BYTES + ((free - FIXED_BYTES) as f64 * SHARE) as u64
    };
    (need > allowed).then_some((need, allowed, free))
}

/// What `count` spheres would take and what the machine has, for a message
/// that refuses them for another reason (e.g. more than ballpit supports).
pub fn need_text(count: usize, model: Option<ModelKind>) -> String {
    let with = model.map_or(String::new(), |m| format!(" with {m}"));
    let have = available().map_or(String::new(), |f| format!("; {} is available", mib(f)));
    format!(
        "they would need about {} of memory{with}{have}",
        mib(need(count, model))
    )
}

fn mib(bytes: u64) -> String {
    if bytes >= 10 << 30 {
        format!("{} GiB", bytes >> 30)
    } else {
        format!("{} MiB", bytes >> 20)
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn refuses_what_exceeds_half_of_what_is_free() {
        let free = Some(4u64 << 30);
        assert!(check(1_000_000, Some(ModelKind::Swept), free).is_ok());
        let err = check(10_000_000, Some(ModelKind::Exact), free).unwrap_err();
        assert!(
            err.starts_with("10000000 spheres would need about 2972 MiB"),
            "{err}"
        );
        assert!(
            err.contains("with exact") && err.contains("4096 MiB"),
            "{err}"
        );
        // The app: the hungriest model counts, and the screen's copies.
        let hungriest = ModelKind::ALL.map(|m| need(1000, Some(m)));
        assert_eq!(
            need(1000, None),
            hungriest.into_iter().max().unwrap() + 1000 * SCREEN_BYTES
        );
        // No figure from the system: nothing to check against.
        assert!(check(usize::MAX, None, None).is_ok());
        // The fixed cost is counted once: a run of no sphere or one needs
        // only it (issue 27: 64 MiB claimed under `ulimit -v 60000`).
        let tight = Some(40u64 << 20);
        assert!(check(0, Some(ModelKind::Swept), tight).is_ok());
        assert!(check(1, Some(ModelKind::Swept), tight).is_ok());
        // Half of the 24 MiB beyond it: 36 792 spheres at 342 bytes.
        assert!(check(36_700, Some(ModelKind::Swept), tight).is_ok());
        assert!(check(36_800, Some(ModelKind::Swept), tight).is_err());
        assert!(check(0, Some(ModelKind::Swept), Some(8 << 20)).is_err());
        assert_eq!(need(usize::MAX, None), u64::MAX);
        // The screen's short form refuses the same counts.
        // The screen's short form: the app's count (hungriest model and the
        // screen's copies, 472 bytes a sphere) against the same share.
        assert!(count_notice(20_000, tight).is_none());
        assert_eq!(
            count_notice(1_000_000, tight).unwrap(),
            "count limit: 1000000 spheres need 466 MiB, over the 28 MiB a run may use"
        );
    }
}
