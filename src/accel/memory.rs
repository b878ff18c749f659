//! What a structure would take before it is built: each structure states a lower bound on its
//! bytes over a number of triangles ([`super::Registered::memory`]), and a build that would not
//! fit in the memory this machine has free is refused with the estimate, instead of running the
//! machine out of memory halfway.

use super::{registered, AccelSettings};

/// Bytes a build may take: what the system says is available to a new process (`MemAvailable`
/// in /proc/meminfo), or less where the environment's `PENUMBRA_MEMORY_BYTES` says so (a share of
/// a shared machine); `None` where neither says.
pub fn available_bytes() -> Option<u64> {
    let system = std::fs::read_to_string("/proc/meminfo").ok().and_then(|info| {
        let line = info.lines().find(|l| l.starts_with("MemAvailable:"))?;
        line.split_whitespace().nth(1)?.parse::<u64>().ok().map(|kb| kb * 1024)
    });
    let share = std::env::var("PENUMBRA_MEMORY_BYTES")
        .ok()
        .and_then(|v| v.trim().parse::<u64>().ok());
    match (system, share) {
        (Some(a), Some(b)) => Some(a.min(b)),
        (a, b) => a.or(b),
    }
}

/// The lower bound on the bytes of `settings`' structure over `triangles` triangles.
pub fn estimate(settings: &AccelSettings, triangles: usize) -> u64 {
    let r = registered(settings.name).expect("settings name a registered structure");
    (r.memory)(triangles, settings)
}

/// Refuses to build `settings`' structure over `triangles` triangles when its lower-bound
/// estimate exceeds `available` bytes; the message gives both.
pub fn check(settings: &AccelSettings, triangles: usize, available: Option<u64>) -> Result<(), String> {
    let need = estimate(settings, triangles);
    match available {
        Some(free) if need > free => Err(format!(
            "`{}` ({}) over {triangles} triangles needs at least {:.1} GB, more than the {:.1} GB this machine has available",
            settings.name,
            settings.describe(),
            need as f64 / 1e9,
            free as f64 / 1e9
        )),
        _ => Ok(()),
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn a_field_too_large_for_the_machine_is_refused_before_it_is_built() {
        let huge = AccelSettings::with(
            "vlf",
            &toml::toml! {
                level = 64
                tiles = 512
            },
        )
        .unwrap();
        // 8193 directions x 512^2 tile offsets of 4 bytes, held twice while building, and
        // 1000 x 8193 entries of 4 bytes, twice: 17.25 GB.
        let e = check(&huge, 1000, Some(15 << 30)).unwrap_err();
        assert!(e.contains("needs at least 17.2 GB") && e.contains("the 16.1 GB"), "{e}");
        assert!(
            check(&huge, 1000, Some(32 << 30)).is_ok(),
            "a machine with room builds it"
        );
        let small = AccelSettings::named("vlf").unwrap();
        assert!(check(&small, 1000, Some(1 << 30)).is_ok());
        assert!(
            check(&huge, 1000, None).is_ok(),
            "no figure from the system: no refusal"
        );
        // Every structure's estimate grows with the triangles.
        for r in super::super::REGISTRY {
            let s = AccelSettings::default_for(r);
            assert!((r.memory)(2_000_000, &s) > (r.memory)(1000, &s), "{}", r.name);
        }
    }
}
