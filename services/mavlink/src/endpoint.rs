//! Where the MAVLink stream goes, in the address form ground stations and autopilot companions use:
//! `udpout:HOST:PORT` (send to a listener), `udpin:ADDR:PORT` (listen, answer whoever spoke
//! last) and `serial:PATH:BAUD` (a serial port wired to the autopilot's telemetry port).

use std::fmt;
use std::net::{SocketAddr, ToSocketAddrs};

/// The line rates a serial endpoint may name: the standard rates of the serial drivers (termios),
/// from 1200 up. A rate outside the list is most often a typing error (`92160`), which the driver
/// would refuse only when the port is opened, or silently round.
pub const STANDARD_BAUD_RATES: [u32; 21] = [
    1_200, 2_400, 4_800, 9_600, 19_200, 38_400, 57_600, 115_200, 230_400, 460_800, 500_000,
    576_000, 921_600, 1_000_000, 1_152_000, 1_500_000, 2_000_000, 2_500_000, 3_000_000, 3_500_000,
    4_000_000,
];

/// One endpoint of the MAVLink output.
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
    /// A serial port: the stream is written to it, and what comes back is read from it.
    Serial {
        /// The device path (`/dev/ttyAMA0`, `/dev/serial/by-id/...`).
        path: String,
        /// The line rate, one of [`STANDARD_BAUD_RATES`].
        baud: u32,
    },
}

impl Endpoint {
    /// Parses `udpout:HOST:PORT`, `udpin:ADDR:PORT` (an IPv6 address in brackets) or
    /// `serial:PATH:BAUD`; the error says what is wrong, for the caller to prefix with the field.
    pub fn parse(text: &str) -> Result<Self, String> {
        let (scheme, rest) = text
            .split_once(':')
            .ok_or("expected udpout:HOST:PORT, udpin:ADDR:PORT or serial:PATH:BAUD")?;
        if scheme == "serial" {
            return Self::parse_serial(rest);
        }
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
                "transport {other:?} is not offered: udpout, udpin (MAVLink over UDP) or serial"
            )),
        }
    }

    /// Parses what follows `serial:`: an absolute device path, `:`, a standard baud rate.
    fn parse_serial(rest: &str) -> Result<Self, String> {
        let (path, baud) = rest
            .rsplit_once(':')
            .ok_or("missing :BAUD after the device path (serial:/dev/ttyS1:921600)")?;
        if !path.starts_with('/') {
            return Err(format!(
                "device path {path:?} is not absolute (serial:/dev/ttyS1:921600)"
            ));
        }
        let baud: u32 = baud
            .parse()
            .map_err(|_| format!("baud rate {baud:?} is not a number"))?;
        if !STANDARD_BAUD_RATES.contains(&baud) {
            return Err(format!(
                "baud rate {baud} is not a standard rate: one of {STANDARD_BAUD_RATES:?}"
            ));
        }
        Ok(Self::Serial {
            path: path.to_string(),
            baud,
        })
    }

    /// The socket address this endpoint names, resolved (a host name through the system's
    /// resolver); the first address found.
    pub fn socket_addr(&self) -> std::io::Result<SocketAddr> {
        let (host, port) = match self {
            Self::UdpOut { host, port } => (host, *port),
            Self::UdpIn { addr, port } => (addr, *port),
            Self::Serial { .. } => {
                return Err(std::io::Error::new(
                    std::io::ErrorKind::InvalidInput,
                    format!("{self}: a serial port has no socket address"),
                ));
            }
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
            Self::Serial { path, baud } => return write!(f, "serial:{path}:{baud}"),
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
            ("tcp:127.0.0.1:5760", "not offered"),
            ("serial:/dev/ttyS0", "missing :BAUD"),
            ("serial:/dev/ttyS0:fast", "not a number"),
            ("serial:/dev/ttyS0:92160", "92160 is not a standard rate"),
            ("serial:/dev/ttyS0:0", "0 is not a standard rate"),
            ("serial:ttyS0:57600", "not absolute"),
            ("serial::57600", "not absolute"),
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

    #[test]
    fn parses_a_serial_port_at_each_standard_rate() {
        let telem = Endpoint::parse("serial:/dev/ttyAMA0:921600").unwrap();
        assert_eq!(
            telem,
            Endpoint::Serial {
                path: "/dev/ttyAMA0".into(),
                baud: 921_600
            }
        );
        assert_eq!(telem.to_string(), "serial:/dev/ttyAMA0:921600");
        assert!(telem.socket_addr().is_err());
        // A path with colons of its own (by-id names) keeps them: the rate is after the last.
        let by_id = "serial:/dev/serial/by-id/usb-FTDI:if00:57600";
        assert_eq!(Endpoint::parse(by_id).unwrap().to_string(), by_id);
        for baud in STANDARD_BAUD_RATES {
            assert!(Endpoint::parse(&format!("serial:/dev/ttyS1:{baud}")).is_ok());
        }
    }
}
