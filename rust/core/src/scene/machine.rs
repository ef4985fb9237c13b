//! What the machine offers a bake: the default memory budget (`max_memory`).

/// Used when the machine's memory cannot be read.
const FALLBACK_MEMORY: u64 = 16 << 30;

/// Half of the machine's memory (or of the container's limit, when lower): a bake leaves
/// room for Blender and the rest of the desktop.
pub fn default_max_memory() -> u64 {
    physical_memory().unwrap_or(FALLBACK_MEMORY) / 2
}

/// Physical memory in bytes (Linux: /proc/meminfo, capped by a cgroup v2 limit).
fn physical_memory() -> Option<u64> {
    let meminfo = std::fs::read_to_string("/proc/meminfo").ok()?;
    let kb: u64 = meminfo
        .lines()
        .find(|l| l.starts_with("MemTotal:"))?
        .split_whitespace()
        .nth(1)?
        .parse()
        .ok()?;
    let total = kb.checked_mul(1024)?;
    let limit = std::fs::read_to_string("/sys/fs/cgroup/memory.max")
        .ok()
        .and_then(|s| s.trim().parse::<u64>().ok());
    Some(limit.map_or(total, |l| l.min(total)))
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
