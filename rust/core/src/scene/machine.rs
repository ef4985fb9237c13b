//! What the machine offers a bake (the default memory budget, `max_memory`) and what this
//! process uses of it (for the watchdog in `progress`).

/// Used when the machine's memory cannot be read.
const FALLBACK_MEMORY: u64 = 16 << 30;

/// Half of the machine's memory (or of the container's limit, when lower): a bake leaves
/// room for Blender and the rest of the desktop.
pub fn default_max_memory() -> u64 {
    physical_memory().unwrap_or(FALLBACK_MEMORY) / 2
}

/// Physical memory in bytes (Linux: /proc/meminfo, capped by a cgroup v2 limit).
fn physical_memory() -> Option<u64> {
    let total = proc_kib("/proc/meminfo", "MemTotal:")?.checked_mul(1024)?;
    let limit = std::fs::read_to_string("/sys/fs/cgroup/memory.max")
        .ok()
        .and_then(|s| s.trim().parse::<u64>().ok());
    Some(limit.map_or(total, |l| l.min(total)))
}

/// This process's resident memory in bytes (Linux; `None` elsewhere), for the watchdog.
pub fn resident_bytes() -> Option<u64> {
    proc_kib("/proc/self/status", "VmRSS:")?.checked_mul(1024)
}

/// The kiB figure on the line of `file` that starts with `key` (`/proc` format).
fn proc_kib(file: &str, key: &str) -> Option<u64> {
    std::fs::read_to_string(file)
        .ok()?
        .lines()
        .find(|l| l.starts_with(key))?
        .split_whitespace()
        .nth(1)?
        .parse()
        .ok()
}

#[cfg(test)]
mod test {
    use super::*;

    #[test]
    fn default_is_half_the_machine() {
        let m = default_max_memory();
        assert!(m >= 1 << 28, "{m}");
        if let Some(p) = physical_memory() {
            assert_eq!(m, p / 2);
        }
    }
}
