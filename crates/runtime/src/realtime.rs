//! Real-time deployment of one process: SCHED_FIFO at a given priority, CPU affinity, memory
//! locked against paging, and a pre-faulted stack, asked of the system at the process's start.
//! Each setting the system refuses (no CAP_SYS_NICE and no RLIMIT_RTPRIO, a low RLIMIT_MEMLOCK, a
//! CPU that is not there) is returned as a [`Refusal`] for the caller to log once; the process
//! runs on without it, as it would have without real-time settings.

use std::io;

/// What one process asks for.
#[derive(Debug, Clone, Default, PartialEq, Eq)]
pub struct RealtimePlan {
    /// SCHED_FIFO priority (1..=99); `None` keeps normal scheduling.
    pub priority: Option<u8>,
    /// CPUs the process may run on; empty: all.
    pub cpus: Vec<usize>,
    /// `mlockall(MCL_CURRENT | MCL_FUTURE)`: no page of the process is ever paged out, nor
    /// faulted in later from disk.
    pub lock_memory: bool,
    /// Stack touched at the start, KiB, so that its pages are resident (and locked) before the
    /// first sample rather than faulted in on the hot path.
    pub prefault_stack_kib: usize,
}

/// A setting the system refused.
#[derive(Debug)]
pub struct Refusal {
    /// Which setting: `priority`, `cpus` or `lock_memory`.
    pub setting: &'static str,
    /// What was asked, as the configuration says it.
    pub asked: String,
    /// The system's answer.
    pub error: io::Error,
}

/// Largest CPU index an affinity mask can hold.
pub const MAX_CPU: usize = libc::CPU_SETSIZE as usize - 1;

/// Applies `plan` to this process (its calling thread, and the threads it starts later); returns
/// what the system refused, in the order tried.
pub fn apply(plan: &RealtimePlan) -> Vec<Refusal> {
    let mut refused = Vec::new();
    if plan.lock_memory
        && let Err(error) = lock_memory()
    {
        refused.push(Refusal {
            setting: "lock_memory",
            asked: "true".into(),
            error,
        });
    }
    if plan.prefault_stack_kib > 0 {
        prefault_stack(plan.prefault_stack_kib);
    }
    if !plan.cpus.is_empty()
        && let Err(error) = set_affinity(&plan.cpus)
    {
        refused.push(Refusal {
            setting: "cpus",
            asked: format!("{:?}", plan.cpus),
            error,
        });
    }
    if let Some(priority) = plan.priority
        && let Err(error) = set_fifo(priority)
    {
        refused.push(Refusal {
            setting: "priority",
            asked: format!("SCHED_FIFO {priority}"),
            error,
        });
    }
    refused
}

fn lock_memory() -> io::Result<()> {
    // SAFETY: mlockall takes flags only.
    if unsafe { libc::mlockall(libc::MCL_CURRENT | libc::MCL_FUTURE) } == 0 {
        Ok(())
    } else {
        Err(io::Error::last_os_error())
    }
}

fn set_affinity(cpus: &[usize]) -> io::Result<()> {
    if let Some(cpu) = cpus.iter().find(|c| **c > MAX_CPU) {
        return Err(io::Error::new(
            io::ErrorKind::InvalidInput,
            format!("CPU {cpu} is beyond the largest an affinity mask holds ({MAX_CPU})"),
        ));
    }
    // SAFETY: an all-zero cpu_set_t is the empty set; CPU_SET writes inside it for an index
    // below CPU_SETSIZE (checked above); sched_setaffinity reads `size_of` bytes of it.
    unsafe {
        let mut set: libc::cpu_set_t = std::mem::zeroed();
        for &cpu in cpus {
            libc::CPU_SET(cpu, &mut set);
        }
        if libc::sched_setaffinity(0, std::mem::size_of::<libc::cpu_set_t>(), &set) == 0 {
            Ok(())
        } else {
            Err(io::Error::last_os_error())
        }
    }
}

fn set_fifo(priority: u8) -> io::Result<()> {
    let param = libc::sched_param {
        sched_priority: i32::from(priority),
    };
    // SAFETY: sched_setscheduler reads the parameter struct passed by reference.
    if unsafe { libc::sched_setscheduler(0, libc::SCHED_FIFO, &param) } == 0 {
        Ok(())
    } else {
        Err(io::Error::last_os_error())
    }
}

/// Touches `kib` KiB of stack below this frame, 16 KiB a frame.
fn prefault_stack(kib: usize) {
    const CHUNK: usize = 16 * 1024;
    #[inline(never)]
    fn touch(chunks: usize) {
        let mut page = [0u8; CHUNK];
        std::hint::black_box(&mut page);
        if chunks > 1 {
            touch(chunks - 1);
        }
        // Used after the call, so the frame is not reused by it.
        std::hint::black_box(&page);
    }
    touch(kib.div_ceil(CHUNK / 1024).max(1));
}

/// This thread's scheduling policy and real-time priority.
pub fn current_policy() -> io::Result<(i32, i32)> {
    // SAFETY: sched_getscheduler takes a pid; sched_getparam writes the struct passed.
    unsafe {
        let policy = libc::sched_getscheduler(0);
        if policy < 0 {
            return Err(io::Error::last_os_error());
        }
        let mut param: libc::sched_param = std::mem::zeroed();
        if libc::sched_getparam(0, &mut param) != 0 {
            return Err(io::Error::last_os_error());
        }
        Ok((policy, param.sched_priority))
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn an_empty_plan_asks_for_nothing_and_is_refused_nothing() {
        let before = current_policy().unwrap();
        assert!(apply(&RealtimePlan::default()).is_empty());
        assert_eq!(current_policy().unwrap(), before);
    }

    #[test]
    fn a_cpu_that_is_not_there_is_refused_and_the_thread_runs_on() {
        // In a thread of its own: the affinity of the test harness's threads is left alone.
        let refused = std::thread::spawn(|| {
            apply(&RealtimePlan {
                cpus: vec![MAX_CPU + 1],
                prefault_stack_kib: 64,
                ..RealtimePlan::default()
            })
        })
        .join()
        .unwrap();
        assert_eq!(refused.len(), 1);
        assert_eq!(refused[0].setting, "cpus");
        assert!(
            refused[0].error.to_string().contains("beyond"),
            "{:?}",
            refused[0]
        );
    }

    #[test]
    fn fifo_is_granted_or_refused_with_the_systems_reason() {
        let (refused, policy) = std::thread::spawn(|| {
            let refused = apply(&RealtimePlan {
                priority: Some(10),
                ..RealtimePlan::default()
            });
            (refused, current_policy().unwrap())
        })
        .join()
        .unwrap();
        match refused.as_slice() {
            [] => assert_eq!(policy, (libc::SCHED_FIFO, 10)),
            [r] => {
                assert_eq!(r.setting, "priority");
                assert_eq!(r.error.raw_os_error(), Some(libc::EPERM), "{r:?}");
                assert_eq!(policy.0, libc::SCHED_OTHER);
            }
            more => panic!("{more:?}"),
        }
    }
}
