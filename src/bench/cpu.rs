//! What the processors did during a run, as the kernel accounts it: the CPU time of
//! this process's threads (ended ones included) and the time the hypervisor took from the machine's processors
//! ("steal"). Beside the wall-clock speed-up of more threads, they tell a slow parallel
//! run that emray serialised (its threads off the processors, no steal) from one the
//! virtual machine was not given processors for (steal).

/// The CPU time of this process so far, user and system, every thread's (those that
/// ended too), in nanoseconds (`getrusage`, microsecond resolution); `None` where it is
/// not available.
pub fn process_cpu_ns() -> Option<u64> {
    #[cfg(unix)]
    {
        use nix::sys::resource::{UsageWho, getrusage};
        use nix::sys::time::TimeValLike;
        let usage = getrusage(UsageWho::RUSAGE_SELF).ok()?;
        let us = usage.user_time().num_microseconds() + usage.system_time().num_microseconds();
        u64::try_from(us).ok().map(|us| us * 1000)
    }
    #[cfg(not(unix))]
    None
}

/// The machine's stolen time so far over all its processors, in milliseconds (the
/// eighth number of the `cpu` line of `/proc/stat`, in 1/100 s); `None` off Linux or on
/// kernels without it.
pub fn machine_steal_ms() -> Option<f64> {
    let stat = std::fs::read_to_string("/proc/stat").ok()?;
    let cpu = stat.lines().find(|l| l.starts_with("cpu "))?;
    let steal: u64 = cpu.split_whitespace().nth(8)?.parse().ok()?;
    Some(steal as f64 * 10.0)
}

/// Readings at the start of a measured stretch.
#[derive(Clone, Copy, Debug)]
pub struct Mark {
    cpu_ns: Option<u64>,
    steal_ms: Option<f64>,
}

impl Mark {
    /// Read both now.
    pub fn now() -> Mark {
        Mark {
            cpu_ns: process_cpu_ns(),
            steal_ms: machine_steal_ms(),
        }
    }

    /// The process's CPU time and the machine's steal since this mark, ms.
    pub fn elapsed(&self) -> (Option<f64>, Option<f64>) {
        let end = Mark::now();
        let cpu = match (self.cpu_ns, end.cpu_ns) {
            (Some(a), Some(b)) => Some(b.saturating_sub(a) as f64 / 1e6),
            _ => None,
        };
        let steal = match (self.steal_ms, end.steal_ms) {
            (Some(a), Some(b)) => Some((b - a).max(0.0)),
            _ => None,
        };
        (cpu, steal)
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    /// Busy work on this thread shows as CPU time: spinning until the process has used
    /// 30 ms of it ends (however many other threads share the cores, which a bound on
    /// the share of the wall time would not survive), and the process's CPU time is at
    /// most the wall time on every core.
    #[test]
    fn busy_work_is_cpu_time() {
        if process_cpu_ns().is_none() {
            return; // not Linux
        }
        let mark = Mark::now();
        let t0 = std::time::Instant::now();
        let mut x = 1u64;
        let cpu = loop {
            for _ in 0..100_000 {
                x = x.wrapping_mul(6364136223846793005).wrapping_add(1);
            }
            let cpu = mark.elapsed().0.unwrap();
            if cpu >= 30.0 || t0.elapsed().as_secs() >= 20 {
                break cpu;
            }
        };
        std::hint::black_box(x);
        let wall = t0.elapsed().as_secs_f64() * 1e3;
        let cores = std::thread::available_parallelism().map_or(1, |n| n.get()) as f64;
        assert!(cpu >= 30.0, "cpu {cpu} ms after {wall} ms of busy work");
        assert!(cpu <= wall * cores + 10.0, "cpu {cpu} ms, wall {wall} ms");
        let (_, steal) = mark.elapsed();
        assert!(steal.is_none_or(|s| s >= 0.0));
    }
}
