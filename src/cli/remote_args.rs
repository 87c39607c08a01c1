//! `--remote` of `rins echo` and `rins status`.

/// A deployment on another host, read through its Zenoh bridge's ROS 2 topics.
#[derive(Debug, Clone, clap::Args)]
pub struct RemoteArgs {
    /// Read the deployment behind this Zenoh endpoint (a router, or the bridge's own
    /// `--zenoh-listen` endpoint: `tcp/HOST:PORT`, `tls/HOST:PORT`) instead of this host's shared
    /// memory. Topics: nav (Odometry), imu, fix (NavSatFix), diagnostics; `rins status --remote`
    /// prints the diagnostics.
    #[arg(long, value_name = "ENDPOINT")]
    pub remote: Option<String>,
    /// The ROS domain id the remote bridge publishes in (its zenoh.domain_id).
    #[arg(long, default_value_t = 0, requires = "remote")]
    pub domain: u32,
    /// The remote bridge's ROS namespace (its zenoh.namespace).
    #[arg(long, default_value = "/rins", requires = "remote")]
    pub namespace: String,
}
