//! The table of every topic: its name, the payload it carries and how tools reach it. Everything
//! that lists topics is generated from it: the names in [`crate::names`], the payload layouts and
//! topic list of a recording, the runtime's payload traits, `rins record`'s choices and help,
//! `rins echo`'s topics, their readable forms and help, and the Python mirror. Adding a topic is
//! one entry here (plus its payload struct and that struct's layout).
//!
//! The table is grouped by payload, in the order payloads are listed everywhere (a payload
//! carried on several topics, the navigator lanes, appears once):
//!
//! ```text
//! Payload (stamped | unstamped) {
//!     /// Doc of the topic's constant.
//!     CONSTANT = "topic/name" [, echo "short"] [, record "short" at RANK];
//! }
//! ```
//!
//! - `stamped`: the payload has the common [`crate::Header`]; `unstamped`: it has none. Every
//!   payload carries its `version`.
//! - `echo "short"`: `rins echo` (and the Python `SHORT_NAMES`) accept the topic by that name.
//! - `record "short" at RANK`: `rins record --topics` accepts it by that name; RANK is its place
//!   in the order a recording's channels are written, which keeps recordings as they have always
//!   been laid out.
//!
//! Readers do not match this grammar: [`for_each_topic!`](crate::for_each_topic) hands a
//! reader's macro one flat projection of the table, entries ending in `;`, in table order:
//!
//! - `payloads`, for each payload: `Payload stamped;` or `Payload unstamped;`
//! - `topics`, for each topic: its doc, then `CONSTANT "topic/name" Payload kind;`
//! - `echo`, for each topic with `echo`: `"short" CONSTANT Payload kind;`
//! - `record`, for each topic with `record`: `RANK "short" CONSTANT Payload kind;` (in table
//!   order, not in rank order)
//!
//! `kind` is `stamped` or `unstamped`, `CONSTANT` the topic's constant in [`crate::names`].

/// Calls `$callback! { entries }` with one projection of the topic table (see the module
/// documentation for each projection's entries): `for_each_topic!(payloads => callback)`. The
/// callback is a `macro_rules!` macro in scope where this is invoked. `for_each_topic!(callback)`
/// hands over the table as written, in its own grammar.
#[macro_export]
macro_rules! for_each_topic {
    ($callback:ident) => {
        $crate::for_each_topic!(table => $callback)
    };
    ($projection:ident => $callback:ident) => {
        $crate::__project_topic_table! {
            $projection $callback
            RawImu (stamped) {
                /// Raw IMU frames ([`crate::RawImu`]), from acquisition.
                RAW_IMU = "rins/raw/imu", echo "raw-imu", record "raw-imu" at 0;
            }
            RawBaro (stamped) {
                /// Raw barometer samples ([`crate::RawBaro`]), from acquisition.
                RAW_BARO = "rins/raw/baro", echo "raw-baro", record "raw-baro" at 1;
            }
            RawMag (stamped) {
                /// Raw magnetometer samples ([`crate::RawMag`]), from acquisition.
                RAW_MAG = "rins/raw/mag", echo "raw-mag", record "raw-mag" at 2;
            }
            RawAux (stamped) {
                /// Raw auxiliary (foot-pressure) samples ([`crate::RawAux`]), from acquisition.
                RAW_AUX = "rins/raw/aux", echo "raw-aux", record "raw-aux" at 3;
            }
            GnssFix (stamped) {
                /// GNSS receiver epochs ([`crate::GnssFix`]), from the `gnss` service.
                GNSS = "rins/gnss", echo "gnss", record "gnss" at 17;
            }
            GnssLinkReport (unstamped) {
                /// The `gnss` service's once-a-second line counters ([`crate::GnssLinkReport`]).
                GNSS_LINK = "rins/gnss/link", echo "gnss-link", record "gnss-link" at 16;
            }
            FusedImu (stamped) {
                /// Fused body rate and specific force ([`crate::FusedImu`]), from fusion.
                FUSED_IMU = "rins/fused/imu", echo "fused-imu", record "fused-imu" at 4;
            }
            Altitude (stamped) {
                /// Barometric altitude ([`crate::Altitude`]), from the altimeter.
                ALTITUDE = "rins/altitude", echo "altitude", record "altitude" at 5;
            }
            NavState (stamped) {
                /// The navigation solution ([`crate::NavState`]) of navigator lane 0, the primary.
                NAV_STATE = "rins/nav/state", echo "nav", record "nav" at 6;
                /// The navigation solution ([`crate::NavState`]) of navigator lane 1, the hot
                /// standby.
                NAV_STATE_STANDBY = "rins/nav/state/standby", record "nav-standby" at 7;
            }
            Truth (stamped) {
                /// The simulator's ground truth ([`crate::Truth`]).
                TRUTH = "rins/sim/truth", echo "truth", record "truth" at 8;
            }
            Health (unstamped) {
                /// Each process's once-a-second heartbeat with its counters ([`crate::Health`]).
                HEARTBEAT = "rins/heartbeat", echo "heartbeat", record "heartbeat" at 10;
            }
            HealthReport (unstamped) {
                /// The watchdog's report on every process ([`crate::HealthReport`]).
                HEALTH = "rins/health", echo "health", record "health" at 9;
            }
            FaultApplied (unstamped) {
                /// Fault commands the simulator handled, with the device time they took effect
                /// ([`crate::FaultApplied`]).
                SIM_FAULT_APPLIED = "rins/sim/fault", record "fault" at 11;
            }
            SimControl (unstamped) {
                /// Commands to the simulator (fault injection, [`crate::SimControl`]).
                SIM_CONTROL = "rins/control/sim", record "sim-control" at 12;
            }
            FusionControl (unstamped) {
                /// Commands to fusion (re-admission of excluded channels,
                /// [`crate::FusionControl`]).
                FUSION_CONTROL = "rins/control/fusion", record "fusion-control" at 13;
            }
            FusionReply (unstamped) {
                /// Fusion's answers to [`FUSION_CONTROL`] requests ([`crate::FusionReply`]).
                FUSION_REPLY = "rins/control/fusion/reply", record "fusion-reply" at 14;
            }
            RawAirspeed (stamped) {
                /// Raw airspeed (pitot differential pressure) samples ([`crate::RawAirspeed`]),
                /// from acquisition.
                RAW_AIRSPEED = "rins/raw/airspeed", echo "raw-airspeed",
                    record "raw-airspeed" at 15;
            }
        }
    };
}

/// Projects the topic table for [`for_each_topic!`]: the table's grammar is matched here, and
/// only here. Every projection is built in one pass, then the one asked for is handed over.
#[doc(hidden)]
#[macro_export]
macro_rules! __project_topic_table {
    (@pick payloads $callback:ident [$($payloads:tt)*] $topics:tt $echo:tt $record:tt) => {
        $callback! { $($payloads)* }
    };
    (@pick topics $callback:ident $payloads:tt [$($topics:tt)*] $echo:tt $record:tt) => {
        $callback! { $($topics)* }
    };
    (@pick echo $callback:ident $payloads:tt $topics:tt [$($echo:tt)*] $record:tt) => {
        $callback! { $($echo)* }
    };
    (@pick record $callback:ident $payloads:tt $topics:tt $echo:tt [$($record:tt)*]) => {
        $callback! { $($record)* }
    };
    (@pick $other:ident $($rest:tt)*) => {
        compile_error!(concat!(
            "for_each_topic!: unknown projection `",
            stringify!($other),
            "` (payloads, topics, echo, record)"
        ));
    };
    (table $callback:ident $($table:tt)*) => {
        $callback! { $($table)* }
    };
    ($projection:ident $callback:ident $(
        $payload:ident ($kind:ident) {
            $(
                $(#[$meta:meta])*
                $constant:ident = $topic:literal
                    $(, echo $echo:literal)?
                    $(, record $short:literal at $rank:literal)?;
            )+
        }
    )+) => {
        $crate::__project_topic_table! {
            @pick $projection $callback
            [$($payload $kind;)+]
            [$($($(#[$meta])* $constant $topic $payload $kind;)+)+]
            [$($($($echo $constant $payload $kind;)?)+)+]
            [$($($($rank $short $constant $payload $kind;)?)+)+]
        }
    };
}
