//! The process graph of a deployment: which services the watchdog starts and in which order.

use ipc_types::ServiceKind;

/// The optional processes a deployment runs.
#[derive(Debug, Clone, Copy, Default, PartialEq, Eq)]
pub struct Optional {
    /// The MAVLink output.
    pub mavlink: bool,
    /// The gnss service (a receiver is fitted).
    pub gnss: bool,
    /// The Zenoh bridge.
    pub bridge: bool,
}

/// The pipeline's services in start order: consumers first, so that no sample is published before
/// its subscriber exists. The hot-standby navigator lane runs when the deployment asks for two
/// navigator lanes, the MAVLink output and the Zenoh bridge when they are enabled, the gnss service
/// when a receiver is fitted (after the navigators that read it). The simulator is not here: it
/// replaces the serial devices, and starts last, once acquisition waits for its terminal.
pub fn pipeline_services(navigator_lanes: u8, optional: Optional) -> Vec<ServiceKind> {
    let Optional {
        mavlink,
        gnss,
        bridge,
    } = optional;
    let mut kinds = Vec::new();
    if bridge {
        kinds.push(ServiceKind::Bridge);
    }
    if mavlink {
        kinds.push(ServiceKind::Mavlink);
    }
    kinds.push(ServiceKind::Navigator);
    if navigator_lanes == 2 {
        kinds.push(ServiceKind::NavigatorStandby);
    }
    if gnss {
        kinds.push(ServiceKind::Gnss);
    }
    kinds.extend([
        ServiceKind::Altimeter,
        ServiceKind::Fusion,
        ServiceKind::Acquisition,
    ]);
    kinds
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn consumers_start_before_their_producers() {
        let names = |lanes| -> Vec<&str> {
            pipeline_services(lanes, Optional::default())
                .into_iter()
                .map(ServiceKind::name)
                .collect()
        };
        assert_eq!(
            names(1),
            ["navigator", "altimeter", "fusion", "acquisition"]
        );
        assert_eq!(
            names(2),
            [
                "navigator",
                "navigator-standby",
                "altimeter",
                "fusion",
                "acquisition"
            ]
        );
        assert_eq!(
            pipeline_services(
                1,
                Optional {
                    mavlink: true,
                    bridge: true,
                    ..Optional::default()
                }
            )
            .into_iter()
            .map(ServiceKind::name)
            .collect::<Vec<_>>(),
            [
                "bridge",
                "mavlink",
                "navigator",
                "altimeter",
                "fusion",
                "acquisition"
            ]
        );
        // The receiver's fixes have their reader before the first one is published.
        assert_eq!(
            pipeline_services(
                1,
                Optional {
                    gnss: true,
                    ..Optional::default()
                }
            )
            .into_iter()
            .map(ServiceKind::name)
            .collect::<Vec<_>>(),
            ["navigator", "gnss", "altimeter", "fusion", "acquisition"]
        );
    }
}
