//! `rins latency`: per-hop latency from the header stamps of the navigation and altitude topics.

use std::time::{Duration, Instant};

use anyhow::{Result, bail};
use hdrhistogram::Histogram;
use ipc_types::{Altitude, Header, Stage, names};
use rins_runtime::clock::monotonic_ns;
use rins_runtime::ipc::TopicSubscriber;
use rins_runtime::nav_subscriber::NavSubscriber;
use rins_runtime::shutdown::Shutdown;
use rins_runtime::tool_node::ToolNode;
use serde::Serialize;

/// One measured hop: from one stamp to another, in nanoseconds.
struct Hop {
    name: &'static str,
    histogram: Histogram<u64>,
}

impl Hop {
    fn new(name: &'static str) -> Result<Self> {
        // 1 ns .. 10 s at 3 significant digits.
        Ok(Self {
            name,
            histogram: Histogram::new_with_bounds(1, 10_000_000_000, 3)?,
        })
    }

    fn record(&mut self, from_ns: u64, to_ns: u64) {
        if from_ns != 0 && to_ns >= from_ns {
            // Saturate rather than fail on an absurd value: it still shows up as the max.
            self.histogram.saturating_record((to_ns - from_ns).max(1));
        }
    }
}

#[derive(Serialize)]
struct HopReport {
    hop: &'static str,
    samples: u64,
    p50_us: f64,
    p99_us: f64,
    p999_us: f64,
    max_us: f64,
}

fn report(hop: &Hop) -> HopReport {
    let h = &hop.histogram;
    let us = |ns: u64| ns as f64 / 1000.0;
    HopReport {
        hop: hop.name,
        samples: h.len(),
        p50_us: us(h.value_at_quantile(0.5)),
        p99_us: us(h.value_at_quantile(0.99)),
        p999_us: us(h.value_at_quantile(0.999)),
        max_us: us(h.max()),
    }
}

fn stage(h: &Header, s: Stage) -> u64 {
    h.stage_ns(s)
}

pub fn run(seconds: f64, json: bool) -> Result<()> {
    if !(seconds.is_finite() && seconds > 0.0) {
        bail!("--seconds {seconds}: must be a positive number");
    }
    let shutdown = Shutdown::install()?;
    // Ports are made after the tool node, so they are dropped before it cleans up.
    let tool = ToolNode::join("latency")?;
    let (node, settings) = (tool.node(), tool.settings());
    // The stream consumers see: both navigator lanes through the lane selector.
    let mut nav = NavSubscriber::new(node)?;
    let alt = TopicSubscriber::<Altitude>::new(node, names::ALTITUDE)?;
    let mut hops = [
        Hop::new("serial rx -> acquisition published")?,
        Hop::new("acquisition -> fusion published")?,
        Hop::new("fusion -> navigator published")?,
        Hop::new("serial rx -> nav state published")?,
        Hop::new("navigator published -> consumer received")?,
        Hop::new("acquisition -> altimeter published")?,
    ];
    let end = Instant::now() + Duration::from_secs_f64(seconds);
    while Instant::now() < end && !shutdown.requested() {
        nav.wait(Duration::from_millis(50))?;
        while let Some(s) = nav.receive()? {
            let now = monotonic_ns();
            let h = &s.header;
            let (rx, acq, fus, navp) = (
                h.origin_rx_ns,
                stage(h, Stage::Acquisition),
                stage(h, Stage::Fusion),
                stage(h, Stage::Navigator),
            );
            hops[0].record(rx, acq);
            hops[1].record(acq, fus);
            hops[2].record(fus, navp);
            hops[3].record(rx, navp);
            hops[4].record(navp, now);
        }
        while let Some(a) = alt.receive()? {
            hops[5].record(
                stage(&a.header, Stage::Acquisition),
                stage(&a.header, Stage::Altimeter),
            );
        }
    }
    if hops[3].histogram.is_empty() {
        bail!(
            "no navigation state received in {seconds} s on prefix {:?}: is the pipeline running (rins up)?",
            settings.prefix
        );
    }
    let reports: Vec<HopReport> = hops.iter().map(report).collect();
    if json {
        println!("{}", serde_json::to_string(&reports)?);
    } else {
        println!(
            "{:<42} {:>8} {:>9} {:>9} {:>9} {:>9}",
            "hop", "samples", "p50 µs", "p99 µs", "p99.9 µs", "max µs"
        );
        for r in &reports {
            println!(
                "{:<42} {:>8} {:>9.1} {:>9.1} {:>9.1} {:>9.1}",
                r.hop, r.samples, r.p50_us, r.p99_us, r.p999_us, r.max_us
            );
        }
    }
    Ok(())
}
