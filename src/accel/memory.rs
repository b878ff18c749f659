//! What a structure would take before it is built: each structure states a lower bound on its
//! bytes over a number of triangles ([`super::Registered::memory`]), and a build that would not
//! fit in the memory this machine has free is refused with the estimate, instead of running the
//! machine out of memory halfway.

use super::{registered, AccelSettings};

/// `n` bytes in words that tell apart the sizes a refusal compares: "1.5 GB", "16.0 MB",
/// "900 bytes" (a budget of 16 MB is not "0.0 GB").
pub fn bytes(n: u64) -> String {
    match n {
        // Bounds at what rounds to 1.0 MB and 1.0 GB, so no size reads "1000.0 MB".
        0..999_950 => format!("{n} bytes"),
        999_950..999_950_000 => format!("{:.1} MB", n as f64 / 1e6),
        _ => format!("{:.1} GB", n as f64 / 1e9),
    }
}

/// The memory a process may still take, and the limit that says so.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub struct Budget {
    /// Bytes a build may take.
    pub bytes: u64,
    /// Which limit is the smallest, in words (for refusals).
    pub limit: &'static str,
}

impl Budget {
    /// `bytes` under `limit`.
    pub fn new(bytes: u64, limit: &'static str) -> Budget {
        Budget { bytes, limit }
    }

    /// "the 4.0 GB that LIMIT leaves", for refusals.
    pub fn describe(&self) -> String {
        format!("the {} that {} leaves", bytes(self.bytes), self.limit)
    }
}

/// The smallest of the limits a build runs into: the memory the system has free
/// (`MemAvailable` in /proc/meminfo), what the process's address-space limit (`RLIMIT_AS`, as
/// `ulimit -v` sets it) leaves above what it already maps, what its control group's memory
/// limit leaves above its usage (a container's or a batch job's share), and the environment's
/// `PENUMBRA_MEMORY_BYTES` (a share stated by hand); `None` where none says. A build past any of them aborts the process, so each is checked before one starts.
pub fn available() -> Option<Budget> {
    smallest([
        mem_available().map(|b| Budget::new(b, "the memory the system has available (MemAvailable)")),
        address_space_left().map(|b| Budget::new(b, "the address-space limit (RLIMIT_AS, ulimit -v)")),
        cgroup_left().map(|b| Budget::new(b, "the control group's memory limit")),
        std::env::var("PENUMBRA_MEMORY_BYTES")
            .ok()
            .and_then(|v| v.trim().parse::<u64>().ok())
            .map(|b| Budget::new(b, "PENUMBRA_MEMORY_BYTES")),
    ])
}

/// The smallest of the limits that say something.
fn smallest(limits: [Option<Budget>; 4]) -> Option<Budget> {
    limits.into_iter().flatten().min_by_key(|b| b.bytes)
}

/// `MemAvailable` in /proc/meminfo, in bytes.
fn mem_available() -> Option<u64> {
    let info = std::fs::read_to_string("/proc/meminfo").ok()?;
    kilobytes(&info, "MemAvailable:")
}

/// The address-space limit less the process's current virtual size (`VmSize`).
fn address_space_left() -> Option<u64> {
    let mut limit = libc::rlimit {
        rlim_cur: 0,
        rlim_max: 0,
    };
    // SAFETY: getrlimit writes the limit into the struct it is given.
    if unsafe { libc::getrlimit(libc::RLIMIT_AS, &mut limit) } != 0 || limit.rlim_cur == libc::RLIM_INFINITY {
        return None;
    }
    let status = std::fs::read_to_string("/proc/self/status").ok()?;
    let mapped = kilobytes(&status, "VmSize:").unwrap_or(0);
    Some(limit.rlim_cur.saturating_sub(mapped))
}

/// The process's control-group memory limit less its usage: cgroup v2's `memory.max` and
/// `memory.current`, or v1's `memory.limit_in_bytes` and `memory.usage_in_bytes`; `None` where
/// there is no limit ("max") or no such file.
fn cgroup_left() -> Option<u64> {
    let own = std::fs::read_to_string("/proc/self/cgroup").ok()?;
    let number = |p: std::path::PathBuf| std::fs::read_to_string(p).ok()?.trim().parse::<u64>().ok();
    let left = |dir: std::path::PathBuf, max: &str, used: &str| {
        let limit = number(dir.join(max))?;
        Some(limit.saturating_sub(number(dir.join(used)).unwrap_or(0)))
    };
    let root = std::path::Path::new("/sys/fs/cgroup");
    own.lines().find_map(|l| {
        let (_, rest) = l.split_once(':')?;
        let (controllers, path) = rest.split_once(':')?;
        let path = path.trim_start_matches('/');
        if controllers.is_empty() {
            left(root.join(path), "memory.max", "memory.current")
        } else if controllers.split(',').any(|c| c == "memory") {
            left(
                root.join("memory").join(path),
                "memory.limit_in_bytes",
                "memory.usage_in_bytes",
            )
        } else {
            None
        }
    })
}

/// The number of kilobytes on the line of `text` starting with `key`, in bytes.
fn kilobytes(text: &str, key: &str) -> Option<u64> {
    let line = text.lines().find(|l| l.starts_with(key))?;
    line.split_whitespace().nth(1)?.parse::<u64>().ok().map(|kb| kb * 1024)
}

/// The lower bound on the bytes of `settings`' structure over `triangles` triangles.
pub fn estimate(settings: &AccelSettings, triangles: usize) -> u64 {
    let r = registered(settings.name).expect("settings name a registered structure");
    (r.memory)(triangles, settings)
}

/// Refuses to build `settings`' structure over `triangles` triangles when its lower-bound
/// estimate exceeds what `available` leaves; the message gives both and names the limit.
pub fn check(settings: &AccelSettings, triangles: usize, available: Option<Budget>) -> Result<(), String> {
    let need = estimate(settings, triangles);
    match available {
        Some(budget) if need > budget.bytes => Err(format!(
            "`{}` ({}) over {triangles} triangles needs at least {}, more than {}",
            settings.name,
            settings.describe(),
            bytes(need),
            budget.describe()
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
        let e = check(&huge, 1000, Some(Budget::new(15 << 30, "a test's limit"))).unwrap_err();
        assert!(
            e.contains("needs at least 17.2 GB") && e.contains("the 16.1 GB that a test's limit leaves"),
            "{e}"
        );
        assert!(
            check(&huge, 1000, Some(Budget::new(32 << 30, "room"))).is_ok(),
            "a machine with room builds it"
        );
        let small = AccelSettings::named("vlf").unwrap();
        assert!(check(&small, 1000, Some(Budget::new(1 << 30, "a GiB"))).is_ok());
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

    #[test]
    fn the_smallest_limit_is_the_budget_and_is_named() {
        let status = "Name:\tsweep\nVmPeak:\t  200 kB\nVmSize:\t  123 kB\n";
        assert_eq!(kilobytes(status, "VmSize:"), Some(123 * 1024));
        assert_eq!(kilobytes(status, "VmRSS:"), None);
        let (a, b) = (Budget::new(5, "a"), Budget::new(3, "b"));
        assert_eq!(smallest([Some(a), None, Some(b), None]), Some(b));
        assert_eq!(smallest([None; 4]), None);
        // This machine's budget is at most what the system has free.
        if let (Some(all), Some(free)) = (available(), mem_available()) {
            assert!(all.bytes <= free);
        }
    }
}
