//! Chrome Trace Event JSON from the header stamps: what `rins latency --trace FILE` writes.
//!
//! Every stage stamps its publish time (CLOCK_MONOTONIC, the same clock in every process) into
//! the header it passes on, so one navigation sample carries the whole path of its serial frame.
//! Each sample becomes one slice on each process's track — acquisition from serial receive to its
//! publish, fusion from acquisition's publish to its own, the navigator lane from fusion's publish
//! to its own, the consumer from the navigator's publish to the moment it had the sample — and one
//! flow arrow through the four slices, so the Perfetto UI (or chrome://tracing) draws each
//! sample's path from serial receive to the consumer. A slice spans the hop into the process as
//! well as the work in it: the stamps say when a stage published, not when it woke.

use serde::Serialize;

/// The stamps of one navigation sample as a consumer received it, CLOCK_MONOTONIC ns.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub struct TracedSample {
    /// Sequence number of the originating serial frame.
    pub seq: u64,
    /// Navigator lane that computed the solution.
    pub lane: u8,
    /// Acquisition had the whole serial frame.
    pub rx_ns: u64,
    /// Acquisition published the raw sample.
    pub acquisition_ns: u64,
    /// Fusion published the fused sample.
    pub fusion_ns: u64,
    /// The navigator lane published the solution.
    pub navigator_ns: u64,
    /// The consumer had the solution.
    pub consumer_ns: u64,
}

impl TracedSample {
    /// Whether the stamps are all there and in path order (a sample from a stage that did not
    /// stamp, or a clock that ran backwards, has no drawable path).
    fn is_complete(&self) -> bool {
        let t = [
            self.rx_ns,
            self.acquisition_ns,
            self.fusion_ns,
            self.navigator_ns,
            self.consumer_ns,
        ];
        t[0] != 0 && t.windows(2).all(|w| w[0] <= w[1])
    }
}

/// The processes' tracks (Chrome trace "pid"s), in path order.
const TRACKS: [(u32, &str); 4] = [
    (1, "acquisition"),
    (2, "fusion"),
    (3, "navigator"),
    (4, "consumer (rins latency)"),
];

/// Slice names along the path, one per track.
const SLICES: [&str; 4] = [
    "serial rx -> published",
    "acquisition published -> fused published",
    "fused published -> solution published",
    "solution published -> received",
];

/// The flow arrows' category and name (a flow is matched by category, name and id).
const FLOW: &str = "sample";

/// One event of the Chrome Trace Event format.
#[derive(Debug, Clone, PartialEq, Serialize)]
pub struct TraceEvent {
    /// Event name.
    pub name: String,
    /// Category.
    #[serde(skip_serializing_if = "Option::is_none")]
    pub cat: Option<&'static str>,
    /// Phase: "X" complete slice, "s"/"t"/"f" flow start/step/end, "M" metadata.
    pub ph: &'static str,
    /// Start, µs.
    #[serde(skip_serializing_if = "Option::is_none")]
    pub ts: Option<f64>,
    /// Duration of a slice, µs.
    #[serde(skip_serializing_if = "Option::is_none")]
    pub dur: Option<f64>,
    /// Track (process).
    pub pid: u32,
    /// Thread within the track (the navigator's lane).
    pub tid: u32,
    /// Flow id: the sample's sequence number.
    #[serde(skip_serializing_if = "Option::is_none")]
    pub id: Option<u64>,
    /// Flow end binding: "e" binds to the enclosing slice.
    #[serde(skip_serializing_if = "Option::is_none")]
    pub bp: Option<&'static str>,
    /// Arguments shown with the event.
    #[serde(skip_serializing_if = "Option::is_none")]
    pub args: Option<serde_json::Value>,
}

impl TraceEvent {
    fn new(name: impl Into<String>, ph: &'static str, pid: u32, tid: u32) -> Self {
        Self {
            name: name.into(),
            cat: None,
            ph,
            ts: None,
            dur: None,
            pid,
            tid,
            id: None,
            bp: None,
            args: None,
        }
    }
}

/// The whole trace file.
#[derive(Debug, Serialize)]
pub struct Trace {
    /// Every event, metadata first.
    #[serde(rename = "traceEvents")]
    pub trace_events: Vec<TraceEvent>,
    /// How the viewer shows times.
    #[serde(rename = "displayTimeUnit")]
    pub display_time_unit: &'static str,
    /// Samples left out of the trace because a stamp was missing or out of order.
    #[serde(rename = "otherData")]
    pub other_data: serde_json::Value,
}

fn us(ns: u64) -> f64 {
    ns as f64 / 1000.0
}

/// The trace of `samples`: the tracks named, then per complete sample four slices and one flow
/// through them. Incomplete samples are left out and counted in `otherData.samples_incomplete`.
pub fn build(samples: &[TracedSample]) -> Trace {
    let mut events = Vec::with_capacity(TRACKS.len() + 3 + samples.len() * 8);
    for (pid, name) in TRACKS {
        let mut meta = TraceEvent::new("process_name", "M", pid, 0);
        meta.args = Some(serde_json::json!({ "name": name }));
        events.push(meta);
    }
    for lane in 0..2 {
        let mut meta = TraceEvent::new("thread_name", "M", TRACKS[2].0, lane);
        meta.args = Some(serde_json::json!({ "name": format!("lane {lane}") }));
        events.push(meta);
    }
    let mut incomplete = 0u64;
    for s in samples {
        if !s.is_complete() {
            incomplete += 1;
            continue;
        }
        let stamps = [
            s.rx_ns,
            s.acquisition_ns,
            s.fusion_ns,
            s.navigator_ns,
            s.consumer_ns,
        ];
        for (k, ((pid, _), slice)) in TRACKS.iter().zip(SLICES).enumerate() {
            let tid = if k == 2 { u32::from(s.lane) } else { 0 };
            let mut x = TraceEvent::new(slice, "X", *pid, tid);
            x.ts = Some(us(stamps[k]));
            x.dur = Some(us(stamps[k + 1] - stamps[k]));
            x.args = Some(serde_json::json!({ "seq": s.seq }));
            // The flow enters each slice where it starts: the next slice begins at this
            // slice's end, so every arrow runs from one publish to the stage that took it.
            let ph = match k {
                0 => "s",
                k if k == TRACKS.len() - 1 => "f",
                _ => "t",
            };
            let mut flow = TraceEvent::new(FLOW, ph, *pid, tid);
            flow.cat = Some(FLOW);
            flow.ts = Some(us(stamps[k]));
            flow.id = Some(s.seq);
            if ph == "f" {
                flow.bp = Some("e");
            }
            events.push(x);
            events.push(flow);
        }
    }
    Trace {
        trace_events: events,
        display_time_unit: "ns",
        other_data: serde_json::json!({
            "clock": "CLOCK_MONOTONIC",
            "samples": samples.len() as u64 - incomplete,
            "samples_incomplete": incomplete,
        }),
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    fn sample(seq: u64, t0: u64) -> TracedSample {
        TracedSample {
            seq,
            lane: (seq % 2) as u8,
            rx_ns: t0,
            acquisition_ns: t0 + 10_000,
            fusion_ns: t0 + 25_000,
            navigator_ns: t0 + 45_000,
            consumer_ns: t0 + 52_500,
        }
    }

    #[test]
    fn each_sample_is_four_slices_and_one_flow_through_them() {
        let samples = [sample(7, 1_000_000), sample(8, 2_000_000)];
        let trace = build(&samples);
        let flows: Vec<&TraceEvent> = trace
            .trace_events
            .iter()
            .filter(|e| e.cat == Some(FLOW))
            .collect();
        for s in &samples {
            let path: Vec<(&str, u32, f64)> = flows
                .iter()
                .filter(|e| e.id == Some(s.seq))
                .map(|e| (e.ph, e.pid, e.ts.unwrap()))
                .collect();
            let t0 = us(s.rx_ns);
            assert_eq!(
                path,
                [
                    ("s", 1, t0),
                    ("t", 2, t0 + 10.0),
                    ("t", 3, t0 + 25.0),
                    ("f", 4, t0 + 45.0)
                ]
            );
        }
        let slices: Vec<(u32, u32, f64)> = trace
            .trace_events
            .iter()
            .filter(|e| e.ph == "X" && e.args.as_ref().unwrap()["seq"] == 8)
            .map(|e| (e.pid, e.tid, e.dur.unwrap()))
            .collect();
        // Durations are the hops: 10, 15, 20 and 7.5 µs; lane 0 on the navigator's track.
        assert_eq!(
            slices,
            [(1, 0, 10.0), (2, 0, 15.0), (3, 0, 20.0), (4, 0, 7.5)]
        );
        assert_eq!(trace.other_data["samples"], 2);
    }

    #[test]
    fn a_sample_with_a_missing_or_backward_stamp_is_counted_not_drawn() {
        let mut missing = sample(1, 1_000_000);
        missing.fusion_ns = 0;
        let mut backward = sample(2, 2_000_000);
        backward.consumer_ns = backward.navigator_ns - 1;
        let trace = build(&[missing, backward, sample(3, 3_000_000)]);
        assert_eq!(trace.other_data["samples"], 1);
        assert_eq!(trace.other_data["samples_incomplete"], 2);
        let ids: Vec<u64> = trace.trace_events.iter().filter_map(|e| e.id).collect();
        assert_eq!(ids, [3, 3, 3, 3]);
    }

    #[test]
    fn the_tracks_are_named_and_the_file_is_the_object_form() {
        let json = serde_json::to_value(build(&[sample(1, 5_000)])).unwrap();
        assert_eq!(json["displayTimeUnit"], "ns");
        let names: Vec<&str> = json["traceEvents"]
            .as_array()
            .unwrap()
            .iter()
            .filter(|e| e["name"] == "process_name")
            .map(|e| e["args"]["name"].as_str().unwrap())
            .collect();
        assert_eq!(names, TRACKS.map(|(_, n)| n));
    }
}
