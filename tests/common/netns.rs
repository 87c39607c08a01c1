//! A second network namespace joined to this one by a veth pair, so that bytes between a process
//! here and one there cross a network interface. Needs root (CAP_NET_ADMIN and the `ip` tool);
//! where that is missing, [`Link::new`] falls back to the loopback and says so.

use std::process::Command;

/// Where a test's far side runs: a namespace behind a veth pair, or the loopback.
pub struct Link {
    /// The far side's namespace (`None`: the loopback, in this namespace).
    pub namespace: Option<String>,
    /// The far side's address.
    pub far_ip: String,
    host_veth: Option<String>,
}

fn ip(args: &[&str]) -> bool {
    Command::new("ip")
        .args(args)
        .output()
        .is_ok_and(|o| o.status.success())
}

impl Link {
    /// A namespace `rz<pid><tag>` at 10.231.`subnet`.2, this side at .1 (a /30 of its own).
    pub fn new(tag: &str, subnet: u8) -> Self {
        let pid = std::process::id() % 100_000;
        let ns = format!("rz{pid}{tag}");
        let (host, far) = (format!("vh{pid}{tag}"), format!("vf{pid}{tag}"));
        let (host_ip, far_ip) = (format!("10.231.{subnet}.1"), format!("10.231.{subnet}.2"));
        let made = ip(&["netns", "add", &ns]);
        let steps: [&[&str]; 7] = [
            &["link", "add", &host, "type", "veth", "peer", "name", &far],
            &["link", "set", &far, "netns", &ns],
            &["addr", "add", &format!("{host_ip}/30"), "dev", &host],
            &["link", "set", &host, "up"],
            &[
                "netns",
                "exec",
                &ns,
                "ip",
                "addr",
                "add",
                &format!("{far_ip}/30"),
                "dev",
                &far,
            ],
            &["netns", "exec", &ns, "ip", "link", "set", &far, "up"],
            &["netns", "exec", &ns, "ip", "link", "set", "lo", "up"],
        ];
        if made && steps.iter().all(|s| ip(s)) {
            return Self {
                namespace: Some(ns),
                far_ip,
                host_veth: Some(host),
            };
        }
        if made {
            let _ = ip(&["netns", "del", &ns]);
        }
        let _ = ip(&["link", "del", &host]);
        eprintln!(
            "no network namespace could be made here (needs root and `ip`): the far side runs on \
             the loopback instead, and the bytes cross no network interface"
        );
        Self {
            namespace: None,
            far_ip: "127.0.0.1".into(),
            host_veth: None,
        }
    }

    /// A command running `program` on the far side.
    pub fn command(&self, program: impl AsRef<std::ffi::OsStr>) -> Command {
        match &self.namespace {
            Some(ns) => {
                let mut c = Command::new("ip");
                c.args(["netns", "exec", ns]).arg(program);
                c
            }
            None => Command::new(program),
        }
    }
}

impl Drop for Link {
    fn drop(&mut self) {
        if let Some(ns) = &self.namespace {
            let _ = ip(&["netns", "del", ns]);
        }
        if let Some(h) = &self.host_veth {
            let _ = ip(&["link", "del", h]);
        }
    }
}
