//! What an experiment costs: the CPU time of this process and wall-clock
//! timestamps that other processes (the shards of a Slurm array) can be
//! compared with.

/// CPU time (user + system) this process has used so far, in seconds, or
/// `None` where the system does not say (`getrusage(RUSAGE_SELF)` on Unix);
/// 0 when wall times are fixed ([`crate::output::timing::timing_fixed`]).
pub fn process_cpu_seconds() -> Option<f64> {
    process_cpu_seconds_measured().map(crate::output::timing::wall)
}

fn process_cpu_seconds_measured() -> Option<f64> {
    #[cfg(unix)]
    {
        // SAFETY: `usage` is a plain C struct that getrusage fills in.
        let mut usage: libc::rusage = unsafe { std::mem::zeroed() };
        // SAFETY: a valid pointer to a rusage struct.
        let r = unsafe { libc::getrusage(libc::RUSAGE_SELF, &mut usage) };
        if r != 0 {
            return None;
        }
        let secs = |t: libc::timeval| t.tv_sec as f64 + t.tv_usec as f64 * 1e-6;
        Some(secs(usage.ru_utime) + secs(usage.ru_stime))
    }
    #[cfg(not(unix))]
    {
        None
    }
}

/// Seconds since the Unix epoch (0 if the clock is before it, and when
/// wall times are fixed: [`crate::output::timing::timing_fixed`]).
pub fn unix_seconds() -> f64 {
    crate::output::timing::wall(
        std::time::SystemTime::now()
            .duration_since(std::time::UNIX_EPOCH)
            .map(|d| d.as_secs_f64())
            .unwrap_or(0.0),
    )
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn cpu_time_grows_with_work() {
        let Some(before) = process_cpu_seconds() else {
            return;
        };
        // Spin until the process clock moves (at most a few ticks of it).
        let mut x = 0u64;
        let mut after = before;
        while after <= before {
            for i in 0..1_000_000u64 {
                x = x.wrapping_mul(6364136223846793005).wrapping_add(i);
            }
            after = process_cpu_seconds().unwrap();
        }
        assert!(x != 1 && after > before);
        assert!(unix_seconds() > 1.6e9);
    }
}
