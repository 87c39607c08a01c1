//! Where the MAVLink stream goes, in the address form ground stations and autopilot companions use:
//! `udpout:HOST:PORT` (send to a listener) and `udpin:ADDR:PORT` (listen, answer whoever spoke
//! last).

use std::fmt;
use std::net::{SocketAddr, ToSocketAddrs};

/// One UDP endpoint of the MAVLink output.
#[derive(Debug, Clone, PartialEq, Eq)]
pub enum Endpoint {
    /// Send to `host:port`; answers come back to the local port the stream leaves from.
    UdpOut {
        /// Host name or address of the listener.
        host: String,
        /// Its UDP port.
        port: u16,
    },
    /// Listen on `addr:port`; the stream goes to whoever sent the last datagram.
    UdpIn {
        /// Local address to bind (`0.0.0.0` for every interface).
        addr: String,
        /// Local UDP port.
        port: u16,
    },
}

impl Endpoint {
    /// Parses `udpout:HOST:PORT` or `udpin:ADDR:PORT` (an IPv6 address in brackets); the error says
    /// what is wrong, for the caller to prefix with the field.
    pub fn parse(text: &str) -> Result<Self, String> {
        let (scheme, rest) = text
            .split_once(':')
            .ok_or("expected udpout:HOST:PORT or udpin:ADDR:PORT")?;
        let (host, port) = rest
            .rsplit_once(':')
            .ok_or("missing :PORT after the host")?;
        let host = host.trim_start_matches('[').trim_end_matches(']');
        if host.is_empty() {
            return Err("empty host".into());
        }
        let port: u16 = port
            .parse()
            .map_err(|_| format!("port {port:?} is not a number 1..=65535"))?;
        if port == 0 {
            return Err("port 0: use 1..=65535".into());
        }
        let host = host.to_string();
        match scheme {
            "udpout" => Ok(Self::UdpOut { host, port }),
            "udpin" => Ok(Self::UdpIn { addr: host, port }),
            other => Err(format!(
                "transport {other:?} is not offered: udpout or udpin (MAVLink over UDP)"
            )),
        }
    }

    /// The socket address this endpoint names, resolved (a host name through the system's
    /// resolver); the first address found.
    pub fn socket_addr(&self) -> std::io::Result<SocketAddr> {
        let (host, port) = match self {
            Self::UdpOut { host, port } => (host, *port),
            Self::UdpIn { addr, port } => (addr, *port),
        };
        (host.as_str(), port)
            .to_socket_addrs()?
            .next()
            .ok_or_else(|| {
                std::io::Error::new(
                    std::io::ErrorKind::AddrNotAvailable,
                    format!("{self}: the name resolves to no address"),
                )
            })
    }
}

impl fmt::Display for Endpoint {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        let (scheme, host, port) = match self {
            Self::UdpOut { host, port } => ("udpout", host, port),
            Self::UdpIn { addr, port } => ("udpin", addr, port),
        };
        if host.contains(':') {
            write!(f, "{scheme}:[{host}]:{port}")
        } else {
            write!(f, "{scheme}:{host}:{port}")
        }
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn parses_both_directions_and_ipv6() {
        assert_eq!(
            Endpoint::parse("udpout:127.0.0.1:14550"),
            Ok(Endpoint::UdpOut {
                host: "127.0.0.1".into(),
                port: 14550
            })
        );
        let v6 = Endpoint::parse("udpin:[::1]:14540").unwrap();
        assert_eq!(
            v6,
            Endpoint::UdpIn {
                addr: "::1".into(),
                port: 14540
            }
        );
        assert_eq!(v6.to_string(), "udpin:[::1]:14540");
        assert_eq!(
            v6.socket_addr().unwrap(),
            "[::1]:14540".parse::<SocketAddr>().unwrap()
        );
    }

    #[test]
    fn refuses_what_it_cannot_open() {
        for (text, why) in [
            ("serial:/dev/ttyS0:57600", "not offered"),
            ("udpout:127.0.0.1", "missing :PORT"),
            ("udpout:host:0", "port 0"),
            ("udpout::14550", "empty host"),
            ("14550", "expected udpout"),
            ("udpout:127.0.0.1:70000", "not a number"),
        ] {
            let err = Endpoint::parse(text).unwrap_err();
            assert!(err.contains(why), "{text}: {err}");
        }
    }
}
