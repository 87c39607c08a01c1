//! A Zenoh endpoint as `[zenoh]` and `rins up --zenoh` take it: `tcp/HOST:PORT` or
//! `tls/HOST:PORT`, HOST an IPv4 address, a bracketed IPv6 address or a DNS name. Anything else is
//! refused at start with the reason, rather than by Zenoh later in a child's restart loop. Link
//! settings (certificates) belong in Zenoh's own configuration file (`[zenoh] config_file`), not in
//! the endpoint.

use std::net::IpAddr;

/// The transports this build of rins carries.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum Transport {
    /// Plain TCP.
    Tcp,
    /// TCP under TLS (certificates from Zenoh's configuration file).
    Tls,
}

/// A checked endpoint.
#[derive(Debug, Clone, PartialEq, Eq)]
pub struct Endpoint {
    /// Its transport.
    pub transport: Transport,
    /// The host as written (an address without its brackets, or a name).
    pub host: String,
    /// The TCP port.
    pub port: u16,
}

impl Endpoint {
    /// Parses `text`; the error says what is wrong with it.
    pub fn parse(text: &str) -> Result<Self, String> {
        let (proto, address) = text
            .split_once('/')
            .ok_or("expected PROTOCOL/HOST:PORT, e.g. tcp/10.0.0.2:7447")?;
        let transport = match proto {
            "tcp" => Transport::Tcp,
            "tls" => Transport::Tls,
            other => {
                return Err(format!("protocol {other:?} is not carried: use tcp or tls"));
            }
        };
        if address.contains(['#', '?', '/']) {
            return Err(
                "an endpoint takes no options or path: put link settings in zenoh.config_file"
                    .into(),
            );
        }
        let (host, port) = address
            .rsplit_once(':')
            .ok_or("no port: expected HOST:PORT")?;
        let port: u16 = port
            .parse()
            .map_err(|_| format!("port {port:?} is not a number from 1 to 65535"))?;
        if port == 0 {
            return Err("port 0 is not a port to connect to or listen on".into());
        }
        let host = match host.strip_prefix('[').and_then(|h| h.strip_suffix(']')) {
            Some(v6) => {
                v6.parse::<std::net::Ipv6Addr>()
                    .map_err(|_| format!("{v6:?} is not an IPv6 address"))?;
                v6
            }
            None if host.contains(':') => {
                return Err(format!(
                    "IPv6 address {host:?} must be in brackets: [{host}]"
                ));
            }
            None if valid_host_name(host) || host.parse::<IpAddr>().is_ok() => host,
            None => return Err(format!("{host:?} is neither an address nor a host name")),
        };
        Ok(Self {
            transport,
            host: host.to_string(),
            port,
        })
    }

    /// The host as an address, when it is one (not a name).
    pub fn address(&self) -> Option<IpAddr> {
        self.host.parse().ok()
    }
}

/// A DNS name: labels of letters, digits and hyphens, 1 to 63 characters, not starting or ending
/// with a hyphen; 253 characters at most.
fn valid_host_name(host: &str) -> bool {
    !host.is_empty()
        && host.len() <= 253
        && host.split('.').all(|label| {
            !label.is_empty()
                && label.len() <= 63
                && !label.starts_with('-')
                && !label.ends_with('-')
                && label.chars().all(|c| c.is_ascii_alphanumeric() || c == '-')
        })
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn good_endpoints_are_taken_apart() {
        let e = Endpoint::parse("tcp/10.0.0.2:7447").unwrap();
        assert_eq!(
            (e.transport, e.host.as_str(), e.port),
            (Transport::Tcp, "10.0.0.2", 7447)
        );
        assert_eq!(e.address(), Some("10.0.0.2".parse().unwrap()));
        let e = Endpoint::parse("tls/[fe80::1]:7448").unwrap();
        assert_eq!((e.transport, e.host.as_str()), (Transport::Tls, "fe80::1"));
        let e = Endpoint::parse("tcp/router.local:7447").unwrap();
        assert_eq!(e.address(), None);
    }

    #[test]
    fn bad_endpoints_are_refused_with_the_reason() {
        for (text, why) in [
            ("10.0.0.2:7447", "PROTOCOL/HOST:PORT"),
            ("udp/10.0.0.2:7447", "\"udp\" is not carried"),
            ("tcp/10.0.0.2", "no port"),
            ("tcp/10.0.0.2:70000", "not a number"),
            ("tcp/10.0.0.2:0", "port 0"),
            ("tcp/fe80::1:7447", "must be in brackets"),
            ("tcp/[zz::1]:7447", "not an IPv6 address"),
            ("tcp/bad_host!:7447", "neither an address"),
            ("tls/h:7447#root_ca_certificate=/x", "zenoh.config_file"),
            ("tcp/:7447", "neither an address"),
        ] {
            let err = Endpoint::parse(text).unwrap_err();
            assert!(err.contains(why), "{text}: {err}");
        }
    }
}
