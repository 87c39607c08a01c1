//! The paced loop over real iceoryx2 shared memory: every tick runs once, in order, after the
//! commands between ticks, on a schedule fixed to the start; the counters the source keeps come
//! back and go out on the heartbeat; a stop ends an endless loop; the ticks between two
//! heartbeats do not touch the heap.

use std::alloc::{GlobalAlloc, Layout, System};
use std::cell::Cell;
use std::time::{Duration, Instant};

use ipc_types::{Health, ServiceKind, names};
use rins_runtime::clock::monotonic_ns;
use rins_runtime::ipc::{IpcError, IpcSettings, TopicSubscriber, create_node};
use rins_runtime::paced_loop::{PacedLoop, PacedSource, Pacing};
use rins_runtime::shm_cleanup;
use rins_runtime::shutdown::Shutdown;

/// Counts the allocations of each thread, readable at any moment (between two ticks).
struct CountingAllocator;

thread_local! {
    static ALLOCATIONS: Cell<usize> = const { Cell::new(0) };
}

fn allocations() -> usize {
    ALLOCATIONS.with(Cell::get)
}

// SAFETY: every call is handed to the system allocator unchanged; the count is a thread-local
// integer without a destructor (touching it never allocates).
unsafe impl GlobalAlloc for CountingAllocator {
    unsafe fn alloc(&self, layout: Layout) -> *mut u8 {
        ALLOCATIONS.with(|a| a.set(a.get() + 1));
        unsafe { System.alloc(layout) }
    }

    unsafe fn dealloc(&self, ptr: *mut u8, layout: Layout) {
        unsafe { System.dealloc(ptr, layout) }
    }

    unsafe fn realloc(&self, ptr: *mut u8, layout: Layout, new_size: usize) -> *mut u8 {
        ALLOCATIONS.with(|a| a.set(a.get() + 1));
        unsafe { System.realloc(ptr, layout, new_size) }
    }
}

#[global_allocator]
static ALLOCATOR: CountingAllocator = CountingAllocator;

const PERIOD_NS: u64 = 2_000_000;

/// Records what the loop asked of it, and when.
#[derive(Default)]
struct Recorder {
    /// ("between" or "tick", tick number, CLOCK_MONOTONIC ns).
    calls: Vec<(&'static str, u64, u64)>,
    /// Requested after this many ticks.
    stop_after: Option<(u64, Shutdown)>,
    /// The heartbeat topic, read between ticks while the loop's publisher is there.
    heartbeats: Option<TopicSubscriber<Health>>,
    beats: Vec<Health>,
}

impl PacedSource for Recorder {
    fn between_ticks(&mut self, tick: u64, _: &mut Health) -> Result<(), IpcError> {
        self.calls.push(("between", tick, monotonic_ns()));
        if let Some(heartbeats) = &self.heartbeats {
            while let Some(beat) = heartbeats.receive()? {
                self.beats.push(beat);
            }
        }
        Ok(())
    }

    fn tick(&mut self, tick: u64, counters: &mut Health) -> Result<(), IpcError> {
        self.calls.push(("tick", tick, monotonic_ns()));
        counters.published += 1;
        if let Some((after, shutdown)) = &self.stop_after
            && tick + 1 == *after
        {
            shutdown.request();
        }
        Ok(())
    }
}

fn settings(name: &str) -> IpcSettings {
    IpcSettings::new(
        format!("rtpace{name}{}_", std::process::id()),
        std::env::temp_dir()
            .join(format!("rtpace{name}{}root/", std::process::id()))
            .to_string_lossy()
            .into_owned(),
    )
}

fn clean_up(settings: &IpcSettings) {
    shm_cleanup::remove_all(settings, true);
    let _ = std::fs::remove_dir_all(&settings.root);
}

#[test]
fn every_tick_runs_once_in_order_on_the_schedule_and_is_counted() {
    let settings = settings("a");
    {
        let node = create_node("paced", &settings).expect("node");
        let pacing = Pacing {
            kind: ServiceKind::Simulator,
            period_ns: PERIOD_NS,
            ticks: Some(25),
        };
        let mut source = Recorder {
            heartbeats: Some(TopicSubscriber::new(&node, names::HEARTBEAT).expect("subscriber")),
            ..Recorder::default()
        };
        let started = monotonic_ns();
        let counters = PacedLoop::new(&node, pacing, &Shutdown::manual())
            .expect("loop")
            .run(&mut source)
            .expect("run");

        // Each tick once, in order, its commands first.
        let expected: Vec<(&str, u64)> = (0..25)
            .flat_map(|k| [("between", k), ("tick", k)])
            .collect();
        let got: Vec<(&str, u64)> = source.calls.iter().map(|&(w, k, _)| (w, k)).collect();
        assert_eq!(got, expected);
        // Tick k never runs before its time: k periods after the loop started, which was after
        // `started`.
        for &(what, k, at) in &source.calls {
            if what == "tick" {
                assert!(at >= started + k * PERIOD_NS, "tick {k} ran early");
            }
        }
        assert_eq!(counters.published, 25);
        // The first beat goes out with the first tick (a heartbeat is due at once).
        // (The run is shorter than a heartbeat period: no second one.)
        let beat = source.beats.first().expect("a heartbeat");
        assert_eq!(source.beats.len(), 1);
        assert_eq!(beat.service, ServiceKind::Simulator as u8);
        assert_eq!(beat.pid, std::process::id());
        assert_eq!(beat.published, 1);
    }
    clean_up(&settings);
}

#[test]
fn a_stop_ends_an_endless_loop_after_the_tick_that_asked() {
    let settings = settings("b");
    {
        let node = create_node("paced", &settings).expect("node");
        let shutdown = Shutdown::manual();
        let pacing = Pacing {
            kind: ServiceKind::Simulator,
            period_ns: PERIOD_NS,
            ticks: None,
        };
        let mut source = Recorder {
            stop_after: Some((10, shutdown.clone())),
            ..Recorder::default()
        };
        let t0 = Instant::now();
        let counters = PacedLoop::new(&node, pacing, &shutdown)
            .expect("loop")
            .run(&mut source)
            .expect("run");
        assert_eq!(counters.published, 10);
        assert_eq!(source.calls.last().map(|c| (c.0, c.1)), Some(("tick", 9)));
        // Generous for a loaded machine: ten ticks of 2 ms, not an endless run.
        assert!(t0.elapsed() < Duration::from_secs(10));
    }
    clean_up(&settings);
}

/// Notes the thread's allocation count at two ticks.
struct Counter {
    at: [(u64, usize); 2],
}

impl PacedSource for Counter {
    fn between_ticks(&mut self, tick: u64, _: &mut Health) -> Result<(), IpcError> {
        for (at, count) in &mut self.at {
            if *at == tick {
                *count = allocations();
            }
        }
        Ok(())
    }

    fn tick(&mut self, _: u64, counters: &mut Health) -> Result<(), IpcError> {
        counters.published += 1;
        Ok(())
    }
}

#[test]
fn ticks_do_not_allocate() {
    let before = allocations();
    drop(std::hint::black_box(vec![1u8; 8]));
    assert!(
        allocations() > before,
        "the counting allocator is installed"
    );
    let settings = settings("c");
    {
        let node = create_node("paced", &settings).expect("node");
        // 0.1 s of ticks, well inside the second between the first heartbeat (with tick 0) and
        // the next: what is counted is the loop and its ticks alone.
        let pacing = Pacing {
            kind: ServiceKind::Simulator,
            period_ns: 20_000,
            ticks: Some(5_000),
        };
        let mut source = Counter {
            at: [(100, usize::MAX), (4_999, 0)],
        };
        let counters = PacedLoop::new(&node, pacing, &Shutdown::manual())
            .expect("loop")
            .run(&mut source)
            .expect("run");
        assert_eq!(counters.published, 5_000);
        let [(_, first), (_, last)] = source.at;
        assert_eq!(
            last - first,
            0,
            "allocations between tick 100 and tick 4999"
        );
    }
    clean_up(&settings);
}
