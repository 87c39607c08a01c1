//! The supervisor with real child processes: a child that keeps exiting is restarted exactly
//! `max_restarts` times, then given up (no further restart, reported as given up), while a healthy
//! sibling is left alone.

use std::path::PathBuf;
use std::time::{Duration, Instant};

use rins_watchdog::restart_policy::{GiveUp, RestartPolicy};
use rins_watchdog::supervisor::{ChildEvent, ChildSpec, Supervisor};

fn shell(name: &str, script: &str, policy: RestartPolicy) -> ChildSpec {
    ChildSpec {
        name: name.to_string(),
        program: PathBuf::from("/bin/sh"),
        args: vec!["-c".to_string(), script.to_string()],
        policy,
        stops_last: false,
    }
}

/// Polls until `done` holds for the events seen so far (at most 10 s).
fn poll_until(
    supervisor: &mut Supervisor,
    done: impl Fn(&[ChildEvent]) -> bool,
) -> Vec<ChildEvent> {
    let start = Instant::now();
    let mut events = Vec::new();
    while !done(&events) {
        assert!(start.elapsed() < Duration::from_secs(10), "{events:?}");
        supervisor.poll(&mut events);
        std::thread::sleep(Duration::from_millis(1));
    }
    events
}

fn gave_up(events: &[ChildEvent]) -> bool {
    events
        .iter()
        .any(|e| matches!(e, ChildEvent::GaveUp { .. }))
}

#[test]
fn a_crashing_child_is_restarted_up_to_its_limit_then_given_up() {
    let policy = RestartPolicy {
        initial_backoff: Duration::from_millis(1),
        max_backoff: Duration::from_millis(4),
        max_restarts: 2,
        window: Duration::from_secs(60),
        give_up: GiveUp::LeaveDown,
        ..RestartPolicy::default()
    };
    let mut supervisor = Supervisor::new();
    supervisor
        .start(shell("altimeter", "exit 3", policy))
        .expect("start the crashing child");
    supervisor
        .start(shell("fusion", "exec sleep 30", RestartPolicy::default()))
        .expect("start the healthy child");
    let events = poll_until(&mut supervisor, gave_up);

    let exited = events
        .iter()
        .filter(|e| matches!(e, ChildEvent::Exited { .. }))
        .count();
    let restarted = events
        .iter()
        .filter(|e| matches!(e, ChildEvent::Restarted { .. }))
        .count();
    assert_eq!((exited, restarted), (2, 2), "{events:?}");
    match events.last() {
        Some(ChildEvent::GaveUp {
            name,
            status,
            exits,
            window,
            action,
            failed_starts,
        }) => {
            assert_eq!(name, "altimeter");
            assert!(status.contains('3'), "{status}");
            assert_eq!(
                (*exits, *window, *action),
                (3, Duration::from_secs(60), GiveUp::LeaveDown)
            );
            // Three failed starts are fewer than the limit: the restart limit gave it up.
            assert_eq!(*failed_starts, 3);
        }
        other => panic!("the last event should be the give-up: {other:?}"),
    }

    // Given up stays given up: no restart however long it is polled.
    let mut later = Vec::new();
    for _ in 0..50 {
        supervisor.poll(&mut later);
        std::thread::sleep(Duration::from_millis(1));
    }
    assert!(later.is_empty(), "{later:?}");
    let children = supervisor.children();
    let altimeter = &children[0];
    assert_eq!(
        (altimeter.pid, altimeter.restarts, altimeter.given_up),
        (None, 2, true)
    );
    let fusion = &children[1];
    assert!(fusion.pid.is_some() && !fusion.given_up, "{fusion:?}");
    assert_eq!(supervisor.running().len(), 1);
    supervisor.stop_all(Duration::from_secs(2));
    assert!(supervisor.running().is_empty());
}

/// A child whose every start fails (it exits with an error at once) is given up after
/// `FAILED_STARTS_LIMIT` starts, well within a restart limit that its growing backoff would take
/// minutes to reach, if ever; one killed by signals as often is restarted on.
#[test]
fn a_child_failing_every_start_is_given_up_but_one_killed_by_signals_is_not() {
    use rins_watchdog::supervisor::FAILED_STARTS_LIMIT;
    let mut supervisor = Supervisor::new();
    supervisor
        .start(shell("fusion", "exit 1", RestartPolicy::default()))
        .expect("start the failing child");
    supervisor
        .start(shell("altimeter", "kill -9 $$", RestartPolicy::default()))
        .expect("start the killed child");
    let started = Instant::now();
    let events = poll_until(&mut supervisor, gave_up);
    assert!(started.elapsed() < Duration::from_secs(5), "{events:?}");
    let given_up: Vec<_> = events
        .iter()
        .filter_map(|e| match e {
            ChildEvent::GaveUp {
                name,
                status,
                exits,
                failed_starts,
                action,
                ..
            } => Some((
                name.as_str(),
                status.as_str(),
                *exits,
                *failed_starts,
                *action,
            )),
            _ => None,
        })
        .collect();
    assert_eq!(
        given_up,
        vec![(
            "fusion",
            "exit status: 1",
            FAILED_STARTS_LIMIT as usize,
            FAILED_STARTS_LIMIT,
            GiveUp::Shutdown
        )],
        "{events:?}"
    );
    // The other goes on being restarted after as many deaths by SIGKILL.
    let events = poll_until(&mut supervisor, |events| {
        events
            .iter()
            .filter(|e| matches!(e, ChildEvent::Restarted { name, .. } if name == "altimeter"))
            .count()
            > FAILED_STARTS_LIMIT as usize
    });
    assert!(!gave_up(&events), "{events:?}");
    assert_eq!(supervisor.given_up(), vec!["fusion".to_string()]);
    supervisor.stop_all(Duration::from_secs(2));
}

#[test]
fn a_zero_limit_gives_up_at_the_first_exit() {
    let policy = RestartPolicy {
        max_restarts: 0,
        ..RestartPolicy::default()
    };
    let mut supervisor = Supervisor::new();
    supervisor
        .start(shell("sim", "exit 0", policy))
        .expect("start the child");
    let events = poll_until(&mut supervisor, gave_up);
    assert!(
        matches!(
            events.as_slice(),
            [ChildEvent::GaveUp {
                exits: 1,
                action: GiveUp::Shutdown,
                ..
            }]
        ),
        "{events:?}"
    );
    assert_eq!(supervisor.restarts(), 0);
}

#[test]
fn the_device_stand_in_stops_after_the_services_reading_it() {
    let dir = std::env::temp_dir().join(format!("rins-stop-order-{}", std::process::id()));
    std::fs::create_dir_all(&dir).expect("temp dir");
    let order = dir.join("order");
    // Each child notes its name when SIGTERM reaches it, then exits.
    let noting = |name: &str| {
        format!(
            "trap 'echo {name} >> {}; exit 0' TERM; while :; do sleep 0.01; done",
            order.display()
        )
    };
    let mut supervisor = Supervisor::new();
    for name in ["acquisition", "fusion"] {
        supervisor
            .start(shell(name, &noting(name), RestartPolicy::default()))
            .expect("start a service");
    }
    // Started last, as `rins up` starts the simulator: without `stops_last` it would be signalled first.
    supervisor
        .start(ChildSpec {
            stops_last: true,
            ..shell("sim", &noting("sim"), RestartPolicy::default())
        })
        .expect("start the simulator");
    std::thread::sleep(Duration::from_millis(100));
    supervisor.stop_all(Duration::from_secs(5));
    let noted = std::fs::read_to_string(&order).expect("the children noted their stop");
    let _ = std::fs::remove_dir_all(&dir);
    let noted: Vec<&str> = noted.lines().collect();
    assert_eq!(noted.len(), 3, "{noted:?}");
    assert_eq!(noted.last(), Some(&"sim"), "{noted:?}");
    assert!(supervisor.running().is_empty());
}
