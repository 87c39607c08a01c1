//! The smallest Rust consumer of the navigation stream: joins the deployment of the environment
//! (`RINS_IPC_PREFIX`, `RINS_IPC_ROOT`, per-user defaults) and prints N samples of the stream both
//! navigator lanes make through the lane selector, as `rins echo nav` sees it.
//!
//! ```text
//! cargo run --example consume_nav -- 10     # with `rins up` running
//! ```

use std::time::{Duration, Instant};

use anyhow::{Context, Result, bail};
use ipc_types::{NavMode, PAYLOAD_VERSION};
use rins_navigator::lanes::NavSubscriber;
use rins_runtime::tool_node::ToolNode;

/// How long to wait for a sample before giving up: no pipeline is navigating.
const TIMEOUT: Duration = Duration::from_secs(10);

fn main() -> Result<()> {
    let count: u64 = match std::env::args().nth(1) {
        Some(arg) => arg
            .parse()
            .with_context(|| format!("count {arg:?}: not a number of samples"))?,
        None => 10,
    };
    // The node before its ports: a ToolNode cleans up after the ports are gone.
    let tool = ToolNode::join("consume-nav")?;
    let mut nav = NavSubscriber::new(tool.node())?;
    let mut received = 0;
    let mut last = Instant::now();
    while received < count {
        let Some(s) = nav.receive()? else {
            if last.elapsed() > TIMEOUT {
                bail!("no navigation sample for {TIMEOUT:?}: is `rins up` running?");
            }
            nav.wait(Duration::from_millis(100))?;
            continue;
        };
        last = Instant::now();
        if s.version != PAYLOAD_VERSION {
            bail!(
                "payload version {} where {PAYLOAD_VERSION} was expected",
                s.version
            );
        }
        let mode = NavMode::from_u8(s.mode).map_or("unknown", NavMode::name);
        println!(
            "seq {} lane {} {mode} q [{:.6}, {:.6}, {:.6}, {:.6}] lat {:.7} lon {:.7} alt {:.3}",
            s.header.origin_seq,
            s.lane,
            s.quaternion[0],
            s.quaternion[1],
            s.quaternion[2],
            s.quaternion[3],
            s.latitude_rad.to_degrees(),
            s.longitude_rad.to_degrees(),
            s.altitude_m,
        );
        received += 1;
    }
    Ok(())
}
