"""The rins topics from Python: the payloads as `ctypes` structures, the topic names, and helpers
to join a running deployment over iceoryx2 and subscribe to a topic.

The structures have the layout of the Rust `#[repr(C)]` payloads (the section between the markers
below is generated from the Rust layouts and checked against them by `tests/python_ctypes.rs`), and
each names its Rust type in `type_name()`, which iceoryx2 compares when a subscriber opens a topic.

A deployment is found the way rins processes find it: `RINS_IPC_PREFIX` and `RINS_IPC_ROOT`, with
per-user defaults (`rins_<uid>_`; `$XDG_RUNTIME_DIR/rins/`, `/run/rins/` for root, else
`/tmp/rins-<uid>/`). `rins up` writes the deployment's iceoryx2 configuration to
`<root>/<prefix>run/iceoryx2.toml` and removes it at stop; `open_node()` loads it.

    import rins_topics as rt
    node = rt.open_node()
    nav = rt.subscribe_nav(node, timeout_s=5)   # both navigator lanes, one stream
    state = nav.receive(timeout_s=1.0)          # a NavState copy; None when none came
    imu = rt.subscribe(node, rt.FUSED_IMU, rt.FusedImu)
    sample = imu.receive()          # None when nothing is queued
    if sample is not None:
        fused = rt.FusedImu.from_buffer_copy(sample.payload().contents)
        sample.delete()

The navigation solution comes from two navigator lanes (`NAV_LANES`); `subscribe_nav` follows
them as rins's own consumers do, through the lane selector of `lane_selector.py`: every sequence
number once, in order, switching lanes when the one delivering dies.

The structures alone need no iceoryx2: `NavState.from_buffer_copy(raw_bytes)` reads a payload from
a recording.
"""

import ctypes
import enum
import os
import time
from pathlib import Path

from lane_selector import LaneSelector, SelectorConfig

#: Environment variables naming a deployment, as rins reads them.
PREFIX_ENV = "RINS_IPC_PREFIX"
ROOT_ENV = "RINS_IPC_ROOT"
#: The deployment's iceoryx2 configuration, in its run directory.
CONFIG_FILE_NAME = "iceoryx2.toml"


class NoDeployment(RuntimeError):
    """No running deployment on the prefix and root: its configuration file is missing."""


class TopicNotFound(RuntimeError):
    """The deployment does not publish the topic (yet)."""


def default_prefix(uid: int) -> str:
    """The prefix of user `uid` when `RINS_IPC_PREFIX` is unset."""
    return f"rins_{uid}_"


def default_root(uid: int, xdg_runtime_dir: "str | None") -> str:
    """The root of user `uid` when `RINS_IPC_ROOT` is unset."""
    if xdg_runtime_dir:
        return xdg_runtime_dir.rstrip("/") + "/rins/"
    if uid == 0:
        return "/run/rins/"
    return f"/tmp/rins-{uid}/"


def deployment() -> "tuple[str, str]":
    """(prefix, root) of the deployment this process joins, from the environment."""
    uid = os.geteuid()
    prefix = os.environ.get(PREFIX_ENV, default_prefix(uid))
    root = os.environ.get(ROOT_ENV) or default_root(uid, os.environ.get("XDG_RUNTIME_DIR"))
    if not root.endswith("/"):
        root += "/"
    return prefix, root


def config_file() -> Path:
    """Where `rins up` wrote the iceoryx2 configuration of the deployment."""
    prefix, root = deployment()
    return Path(root) / f"{prefix}run" / CONFIG_FILE_NAME


def open_node(name: str = "python"):
    """An iceoryx2 node in the deployment from the environment; raises `NoDeployment` when its
    configuration file is missing (no `rins up` running there)."""
    import iceoryx2 as iox2

    path = config_file()
    if not path.is_file():
        prefix, root = deployment()
        raise NoDeployment(
            f"no rins deployment on prefix {prefix!r}, root {root!r}: {path} is missing "
            f"(is `rins up` running with the same {PREFIX_ENV} and {ROOT_ENV}?)"
        )
    config = iox2.config.from_file(iox2.FilePath.new(str(path)))
    return (
        iox2.NodeBuilder.new()
        .name(iox2.NodeName.new(name))
        .config(config)
        .create(iox2.ServiceType.Ipc)
    )


def subscribe(node, topic: str, payload: type, timeout_s: float = 0.0):
    """A subscriber on `topic` carrying `payload` (a structure of this module), opened with the
    limits rins creates topics with. Waits up to `timeout_s` for the topic to appear (a service
    starting); raises `TopicNotFound` after that."""
    import iceoryx2 as iox2

    deadline = time.monotonic() + timeout_s
    while True:
        try:
            service = (
                node.service_builder(iox2.ServiceName.new(topic))
                .publish_subscribe(payload)
                .max_publishers(MAX_PUBLISHERS)
                .max_subscribers(MAX_SUBSCRIBERS)
                .max_nodes(MAX_NODES)
                .subscriber_max_buffer_size(SUBSCRIBER_BUFFER)
                .history_size(HISTORY_SIZE.get(topic, 0))
                .enable_safe_overflow(True)
                .open()
            )
            return service.subscriber_builder().create()
        except iox2.PublishSubscribeOpenError as e:
            # The binding's error carries iceoryx2's variant name as its text.
            if str(e) != "DoesNotExist":
                raise
            if time.monotonic() >= deadline:
                raise TopicNotFound(f"topic {topic!r} does not exist in the deployment") from e
            time.sleep(0.05)


def wire_name(enum_type: type, value: int) -> str:
    """The name tools print for `value` of `enum_type` (e.g. `NavMode`), `unknown(N)` otherwise."""
    return WIRE_NAMES.get(enum_type, {}).get(value, f"unknown({value})")


def bit_names(bits: int, table: "dict[int, str]") -> "list[str]":
    """The names of the bits of `bits` that `table` lists (`INTEGRITY_REASONS`, `FUSED_FLAGS`...)."""
    return [name for bit, name in table.items() if bits & bit]


class NavSubscription:
    """The navigation stream as rins's own consumers see it: both navigator lanes' topics
    (`NAV_LANES`) merged by a `LaneSelector` into one contiguous sequence, each sequence number once
    and in order, from the lane the selector has chosen. Killing a navigator lane loses no sample:
    the other lane's samples continue the stream at the next sequence number. With a single lane
    the standby topic does not exist and the stream is the primary's.

    Made by `subscribe_nav`."""

    #: How often a standby topic that does not exist (yet) is looked for again, s.
    STANDBY_RETRY_S = 0.5
    #: Sleep between polls while `receive` waits, ms.
    POLL_MS = 2

    def __init__(self, node, timeout_s: float = 0.0, config: "SelectorConfig | None" = None):
        import iceoryx2 as iox2

        self._node = node
        self._pause = iox2.Duration.from_millis(self.POLL_MS)
        self.selector = LaneSelector(config or SelectorConfig())
        self._lanes = [subscribe(node, NAV_LANES[0], NavState, timeout_s), None]
        self._standby_due = 0.0
        #: Samples received from each lane.
        self.lane_totals = [0] * len(NAV_LANES)
        # Sequence number of the newest sample received from each lane.
        self._lane_newest = [None] * len(NAV_LANES)
        #: Sequence numbers the output stepped over: missing in both lanes (a hole in the input),
        #: or dropped from a full subscriber queue while this process did not receive.
        self.skipped = 0
        self._last_seq = None

    @property
    def selected_lane(self) -> int:
        """The lane delivering now."""
        return self.selector.selected

    def receive(self, timeout_s: float = 0.0) -> "NavState | None":
        """The next sample of the stream (a copy, out of shared memory), or None when none is due
        within `timeout_s`. While waiting, iceoryx2 raises `NodeWaitFailure` when the process is
        asked to stop (SIGINT, SIGTERM: the node handles them)."""
        deadline = time.monotonic() + timeout_s
        while True:
            state = self._next()
            if state is not None:
                if self._last_seq is not None:
                    self.skipped += max(state.header.origin_seq - self._last_seq - 1, 0)
                self._last_seq = state.header.origin_seq
                return state
            if time.monotonic() >= deadline:
                return None
            self._node.wait(self._pause)

    def _next(self) -> "NavState | None":
        """Takes one sample of each lane at a time, so that a backlog waits in the subscribers'
        queues, which are deep, and not in the selector, which keeps only what a switch needs; a
        lane whose ring is full stays in its queue until the selected lane delivers or is found
        dead (on this process's clock, CLOCK_MONOTONIC as the navigators stamp)."""
        self._open_standby()
        now_ns = time.monotonic_ns()
        while True:
            state = self.selector.pop(now_ns)
            if state is not None:
                return state
            pulled = False
            for lane in range(len(self._lanes)):
                if self.selector.has_room(lane) and self._pull(lane):
                    pulled = True
            if not pulled:
                return None
            self._catch_up()

    def _pull(self, lane: int) -> bool:
        """One sample of `lane` into the selector; whether there was one."""
        subscriber = self._lanes[lane]
        if subscriber is None:
            return False
        sample = subscriber.receive()
        if sample is None:
            return False
        state = NavState.from_buffer_copy(sample.payload().contents)
        sample.delete()
        self.lane_totals[lane] += 1
        self._lane_newest[lane] = state.header.origin_seq
        self.selector.push(lane, state)
        return True

    def _catch_up(self) -> None:
        """Pulls the other lane up to the selected lane's next sample: a hole in the selected lane
        is filled only from what the selector holds, and the standby publishes in batches while
        the primary serves."""
        other = 1 - self.selector.selected
        nxt = self.selector.next_seq(self.selector.selected)
        if nxt is None:
            return
        while (
            (self._lane_newest[other] is None or self._lane_newest[other] + 1 < nxt)
            and self.selector.has_room(other)
            and self._pull(other)
        ):
            pass

    def _open_standby(self) -> None:
        """Opens the standby lane's topic once it exists (it starts with its navigator)."""
        if self._lanes[1] is not None or time.monotonic() < self._standby_due:
            return
        try:
            self._lanes[1] = subscribe(self._node, NAV_LANES[1], NavState)
        except TopicNotFound:
            self._standby_due = time.monotonic() + self.STANDBY_RETRY_S


def subscribe_nav(node, timeout_s: float = 0.0, config: "SelectorConfig | None" = None):
    """The navigation stream of both navigator lanes, one sample per sequence number (see
    `NavSubscription`). Waits up to `timeout_s` for the primary lane's topic; raises
    `TopicNotFound` after that."""
    return NavSubscription(node, timeout_s, config)


# --- generated from the Rust layouts: do not edit ---

#: Layout version every payload carries in `version`.
PAYLOAD_VERSION = 10

# Topic names.
RAW_IMU = "rins/raw/imu"
RAW_BARO = "rins/raw/baro"
RAW_MAG = "rins/raw/mag"
RAW_AUX = "rins/raw/aux"
GNSS = "rins/gnss"
GNSS_LINK = "rins/gnss/link"
FUSED_IMU = "rins/fused/imu"
ALTITUDE = "rins/altitude"
NAV_STATE = "rins/nav/state"
NAV_STATE_STANDBY = "rins/nav/state/standby"
TRUTH = "rins/sim/truth"
HEARTBEAT = "rins/heartbeat"
HEALTH = "rins/health"
SIM_CONTROL = "rins/control/sim"
SIM_FAULT_APPLIED = "rins/sim/fault"
FUSION_CONTROL = "rins/control/fusion"
FUSION_REPLY = "rins/control/fusion/reply"
RAW_AIRSPEED = "rins/raw/airspeed"
#: Both navigator lanes: primary, hot standby.
NAV_LANES = (NAV_STATE, NAV_STATE_STANDBY)
#: The short names `rins echo` accepts.
SHORT_NAMES = {
    "raw-imu": "rins/raw/imu",
    "raw-baro": "rins/raw/baro",
    "raw-mag": "rins/raw/mag",
    "raw-aux": "rins/raw/aux",
    "gnss": "rins/gnss",
    "gnss-link": "rins/gnss/link",
    "fused-imu": "rins/fused/imu",
    "altitude": "rins/altitude",
    "nav": "rins/nav/state",
    "truth": "rins/sim/truth",
    "heartbeat": "rins/heartbeat",
    "health": "rins/health",
    "raw-airspeed": "rins/raw/airspeed",
}

# Limits every rins process opens a topic with; a subscriber asks for the same, since
# iceoryx2 refuses to open a service with more than it was created for.
MAX_PUBLISHERS = 16
MAX_SUBSCRIBERS = 16
MAX_NODES = 64
SUBSCRIBER_BUFFER = 512
#: History kept for late subscribers, by topic (none for a topic not listed).
HISTORY_SIZE = {
    "rins/raw/imu": 256,
}


class NavMode(enum.IntEnum):
    """`ipc_types::NavMode`, carried as a `u8` field."""

    ALIGNING = 0
    NAVIGATING = 1
    COASTING = 2
    INVALID = 3


class Integrity(enum.IntEnum):
    """`ipc_types::Integrity`, carried as a `u8` field."""

    OK = 0
    DEGRADED = 1
    INVALID = 2


class ChannelState(enum.IntEnum):
    """`ipc_types::ChannelState`, carried as a `u8` field."""

    OK = 0
    SUSPECT = 1
    EXCLUDED = 2
    ABSENT = 3


class FaultReason(enum.IntEnum):
    """`ipc_types::FaultReason`, carried as a `u8` field."""

    NONE = 0
    MISSING = 1
    DEVICE_ERROR = 2
    SATURATED = 3
    STUCK = 4
    NOISY = 5
    PARITY = 6
    STATIONARY_REFERENCE = 7
    TEMPERATURE = 8


class SensorType(enum.IntEnum):
    """`ipc_types::SensorType`, carried as a `u8` field."""

    GYRO = 0
    ACCEL = 1


class SimFault(enum.IntEnum):
    """`ipc_types::SimFault`, carried as a `u8` field."""

    CLEAR = 0
    DEAD = 1
    STUCK = 2
    BIAS_STEP = 3
    RAMP = 4
    NOISE = 5
    SATURATE = 6
    INTERMITTENT = 7
    DISCONNECT = 8
    GNSS_OUTAGE = 9
    GNSS_JUMP = 10
    GNSS_FREEZE = 11
    GNSS_DRIFT = 12


class FaultOutcome(enum.IntEnum):
    """`ipc_types::FaultOutcome`, carried as a `u8` field."""

    APPLIED = 0
    UNKNOWN_COMMAND = 1
    NO_SUCH_CHANNEL = 2
    INVALID_PARAMETER = 3


class ReadmitOutcome(enum.IntEnum):
    """`ipc_types::ReadmitOutcome`, carried as a `u8` field."""

    READMITTED = 0
    NOT_EXCLUDED = 1
    NO_SUCH_CHANNEL = 2
    BAD_REQUEST = 3
    FAULT_STILL_PRESENT = 4
    BUSY = 5


class ServiceKind(enum.IntEnum):
    """`ipc_types::ServiceKind`, carried as a `u8` field."""

    SIMULATOR = 0
    ACQUISITION = 1
    FUSION = 2
    ALTIMETER = 3
    NAVIGATOR = 4
    WATCHDOG = 5
    NAVIGATOR_STANDBY = 6
    MAVLINK = 7
    GNSS = 8
    BRIDGE = 9


class ServiceState(enum.IntEnum):
    """`ipc_types::ServiceState`, carried as a `u8` field."""

    STARTING = 0
    RUNNING = 1
    RESTARTING = 2
    SILENT = 3
    GIVEN_UP = 4


class LinkError(enum.IntEnum):
    """`ipc_types::LinkError`, carried as a `u8` field."""

    NONE = 0
    NO_SYNC = 1
    UNKNOWN_FRAME_TYPE = 2
    BAD_LENGTH = 3
    CRC_MISMATCH = 4
    BAD_CONTENT = 5


#: The name tools print for each enum value (`rins echo`, `rins status`).
WIRE_NAMES = {
    NavMode: {
        0: "aligning",
        1: "navigating",
        2: "coasting",
        3: "invalid",
    },
    Integrity: {
        0: "ok",
        1: "degraded",
        2: "invalid",
    },
    ChannelState: {
        0: "ok",
        1: "suspect",
        2: "excluded",
        3: "absent",
    },
    FaultReason: {
        0: "none",
        1: "missing",
        2: "device-error",
        3: "saturated",
        4: "stuck",
        5: "noisy",
        6: "parity",
        7: "stationary-reference",
        8: "temperature",
    },
    SensorType: {
        0: "gyro",
        1: "accel",
    },
    SimFault: {
        0: "clear",
        1: "dead",
        2: "stuck",
        3: "bias",
        4: "ramp",
        5: "noise",
        6: "saturate",
        7: "intermittent",
        8: "disconnect",
        9: "gnss-outage",
        10: "gnss-jump",
        11: "gnss-freeze",
        12: "gnss-drift",
    },
    FaultOutcome: {
        0: "applied",
        1: "unknown-command",
        2: "no-such-channel",
        3: "invalid-parameter",
    },
    ReadmitOutcome: {
        0: "readmitted",
        1: "not-excluded",
        2: "no-such-channel",
        3: "bad-request",
        4: "fault-still-present",
        5: "busy",
    },
    ServiceKind: {
        0: "sim",
        1: "acquisition",
        2: "fusion",
        3: "altimeter",
        4: "navigator",
        5: "watchdog",
        6: "navigator-standby",
        7: "mavlink",
        8: "gnss",
        9: "bridge",
    },
    ServiceState: {
        0: "starting",
        1: "running",
        2: "restarting",
        3: "silent",
        4: "given-up",
    },
    LinkError: {
        0: "none",
        1: "no-sync",
        2: "unknown-frame-type",
        3: "bad-length",
        4: "crc-mismatch",
        5: "bad-content",
    },
}

#: Bits of NavState.integrity_reasons, with their names.
INTEGRITY_REASONS = {
    0x1: "imu-unusable",
    0x2: "time-not-advancing",
    0x4: "all-aiding-rejected",
    0x8: "baro-inconsistent",
    0x10: "mag-inconsistent",
    0x20: "zupt-inconsistent",
    0x40: "covariance",
    0x80: "recovering",
    0x100: "non-finite",
    0x200: "aiding-stale",
    0x400: "gnss-inconsistent",
    0x800: "sensor-fault-unisolated",
    0x1000: "position-unknown",
    0x2000: "airspeed-inconsistent",
}

#: Bits of NavState.aiding (accepted sources), with their names.
AIDING_SOURCES = {
    0x1: "baro",
    0x2: "mag",
    0x4: "zupt",
    0x8: "hupt",
    0x10: "gravity",
    0x20: "gnss",
    0x40: "airspeed",
}

#: Bits of NavState.aiding (stale sources), with their names.
AIDING_STALE = {
    0x100: "baro",
    0x200: "mag",
    0x400: "gnss",
}

#: Bits of NavState.aiding (rejected sources), with their names.
AIDING_REJECTED = {
    0x800: "gnss",
}

#: Bits of FusedImu.flags, with their names.
FUSED_FLAGS = {
    0x1: "gyro-fault-not-isolated",
    0x2: "accel-fault-not-isolated",
    0x4: "gyro-insufficient",
    0x8: "accel-insufficient",
    0x10: "gyro-rest-bias-pending",
    0x20: "gyro-saturated",
    0x40: "accel-saturated",
    0x80: "input-rejected",
}

#: Bits of RawImu.status, with their names.
RAW_IMU_STATUS = {
    0x1: "device-error",
    0x2: "saturation",
}


class Header(ctypes.Structure):
    """`rins::Header`: 56 bytes, aligned to 8."""

    _fields_ = [
        ("origin_seq", ctypes.c_uint64),
        ("origin_device_time_us", ctypes.c_uint64),
        ("origin_rx_ns", ctypes.c_uint64),
        ("stage_pub_ns", ctypes.c_uint64 * 4),
    ]

    @staticmethod
    def type_name() -> str:
        """The iceoryx2 type name of the Rust payload."""
        return "rins::Header"


class RawImu(ctypes.Structure):
    """`rins::RawImu`: 152 bytes, aligned to 8."""

    _fields_ = [
        ("version", ctypes.c_uint16),
        ("n_gyro", ctypes.c_uint8),
        ("n_accel", ctypes.c_uint8),
        ("n_temperature", ctypes.c_uint8),
        ("_pad", ctypes.c_uint8 * 3),
        ("status", ctypes.c_uint32),
        ("valid_mask", ctypes.c_uint32),
        ("header", Header),
        ("gyro_counts", ctypes.c_int16 * 16),
        ("accel_counts", ctypes.c_int16 * 16),
        ("temperature_c", ctypes.c_float * 4),
    ]

    @staticmethod
    def type_name() -> str:
        """The iceoryx2 type name of the Rust payload."""
        return "rins::RawImu"


class RawBaro(ctypes.Structure):
    """`rins::RawBaro`: 80 bytes, aligned to 8."""

    _fields_ = [
        ("version", ctypes.c_uint16),
        ("_pad", ctypes.c_uint8 * 6),
        ("header", Header),
        ("pressure_pa", ctypes.c_double),
        ("temperature_c", ctypes.c_float),
        ("_pad2", ctypes.c_uint32),
    ]

    @staticmethod
    def type_name() -> str:
        """The iceoryx2 type name of the Rust payload."""
        return "rins::RawBaro"


class RawMag(ctypes.Structure):
    """`rins::RawMag`: 80 bytes, aligned to 8."""

    _fields_ = [
        ("version", ctypes.c_uint16),
        ("_pad", ctypes.c_uint8 * 6),
        ("header", Header),
        ("field_ut", ctypes.c_float * 3),
        ("_pad2", ctypes.c_uint32),
    ]

    @staticmethod
    def type_name() -> str:
        """The iceoryx2 type name of the Rust payload."""
        return "rins::RawMag"


class RawAux(ctypes.Structure):
    """`rins::RawAux`: 72 bytes, aligned to 8."""

    _fields_ = [
        ("version", ctypes.c_uint16),
        ("_pad", ctypes.c_uint8 * 6),
        ("header", Header),
        ("foot_pressure", ctypes.c_float),
        ("_pad2", ctypes.c_uint32),
    ]

    @staticmethod
    def type_name() -> str:
        """The iceoryx2 type name of the Rust payload."""
        return "rins::RawAux"


class GnssFix(ctypes.Structure):
    """`rins::GnssFix`: 152 bytes, aligned to 8."""

    _fields_ = [
        ("version", ctypes.c_uint16),
        ("fix_type", ctypes.c_uint8),
        ("satellites", ctypes.c_uint8),
        ("protocol", ctypes.c_uint8),
        ("velocity_valid", ctypes.c_uint8),
        ("accuracy_reported", ctypes.c_uint8),
        ("_pad", ctypes.c_uint8 * 1),
        ("header", Header),
        ("receiver_time_us", ctypes.c_uint64),
        ("latitude_rad", ctypes.c_double),
        ("longitude_rad", ctypes.c_double),
        ("altitude_m", ctypes.c_double),
        ("velocity_ned_mps", ctypes.c_double * 3),
        ("horizontal_accuracy_m", ctypes.c_double),
        ("vertical_accuracy_m", ctypes.c_double),
        ("speed_accuracy_mps", ctypes.c_double),
        ("hdop", ctypes.c_double),
    ]

    @staticmethod
    def type_name() -> str:
        """The iceoryx2 type name of the Rust payload."""
        return "rins::GnssFix"


class GnssLinkReport(ctypes.Structure):
    """`rins::GnssLinkReport`: 248 bytes, aligned to 8."""

    _fields_ = [
        ("version", ctypes.c_uint16),
        ("heard", ctypes.c_uint8),
        ("silent", ctypes.c_uint8),
        ("quiet", ctypes.c_uint8),
        ("_pad", ctypes.c_uint8 * 3),
        ("now_ns", ctypes.c_uint64),
        ("bytes", ctypes.c_uint64),
        ("reconnects", ctypes.c_uint64),
        ("sentences_used", ctypes.c_uint64),
        ("ubx_frames_used", ctypes.c_uint64),
        ("unused_gsv", ctypes.c_uint64),
        ("unused_gsa", ctypes.c_uint64),
        ("unused_zda", ctypes.c_uint64),
        ("unused_txt", ctypes.c_uint64),
        ("unused_gbs", ctypes.c_uint64),
        ("unused_other_nmea", ctypes.c_uint64),
        ("unused_proprietary", ctypes.c_uint64),
        ("unused_other_messages", ctypes.c_uint64),
        ("nothing_to_use", ctypes.c_uint64),
        ("checksum_errors", ctypes.c_uint64),
        ("without_checksum", ctypes.c_uint64),
        ("malformed", ctypes.c_uint64),
        ("oversized", ctypes.c_uint64),
        ("wrong_length", ctypes.c_uint64),
        ("resyncs", ctypes.c_uint64),
        ("unframed_bytes", ctypes.c_uint64),
        ("lines_crlf", ctypes.c_uint64),
        ("lines_lf", ctypes.c_uint64),
        ("epochs", ctypes.c_uint64),
        ("epochs_without_fix", ctypes.c_uint64),
        ("published", ctypes.c_uint64),
        ("publish_failures", ctypes.c_uint64),
        ("ubx_late", ctypes.c_uint64),
        ("nmea_epochs_superseded", ctypes.c_uint64),
        ("silent_episodes", ctypes.c_uint64),
    ]

    @staticmethod
    def type_name() -> str:
        """The iceoryx2 type name of the Rust payload."""
        return "rins::GnssLinkReport"


class FusedImu(ctypes.Structure):
    """`rins::FusedImu`: 232 bytes, aligned to 8."""

    _fields_ = [
        ("version", ctypes.c_uint16),
        ("n_gyro", ctypes.c_uint8),
        ("n_accel", ctypes.c_uint8),
        ("flags", ctypes.c_uint32),
        ("header", Header),
        ("rate_rps", ctypes.c_double * 3),
        ("specific_force_mps2", ctypes.c_double * 3),
        ("rate_var", ctypes.c_double * 3),
        ("specific_force_var", ctypes.c_double * 3),
        ("gyro_state", ctypes.c_uint8 * 16),
        ("accel_state", ctypes.c_uint8 * 16),
        ("gyro_reason", ctypes.c_uint8 * 16),
        ("accel_reason", ctypes.c_uint8 * 16),
        ("gyro_test_statistic", ctypes.c_float),
        ("accel_test_statistic", ctypes.c_float),
    ]

    @staticmethod
    def type_name() -> str:
        """The iceoryx2 type name of the Rust payload."""
        return "rins::FusedImu"


class Altitude(ctypes.Structure):
    """`rins::Altitude`: 88 bytes, aligned to 8."""

    _fields_ = [
        ("version", ctypes.c_uint16),
        ("valid", ctypes.c_uint8),
        ("_pad", ctypes.c_uint8 * 5),
        ("header", Header),
        ("height_m", ctypes.c_double),
        ("vertical_speed_mps", ctypes.c_double),
        ("height_var", ctypes.c_double),
    ]

    @staticmethod
    def type_name() -> str:
        """The iceoryx2 type name of the Rust payload."""
        return "rins::Altitude"


class NavState(ctypes.Structure):
    """`rins::NavState`: 384 bytes, aligned to 8."""

    _fields_ = [
        ("version", ctypes.c_uint16),
        ("mode", ctypes.c_uint8),
        ("lane", ctypes.c_uint8),
        ("aiding", ctypes.c_uint32),
        ("header", Header),
        ("quaternion", ctypes.c_double * 4),
        ("velocity_ned_mps", ctypes.c_double * 3),
        ("latitude_rad", ctypes.c_double),
        ("longitude_rad", ctypes.c_double),
        ("altitude_m", ctypes.c_double),
        ("covariance_diag", ctypes.c_double * 15),
        ("aiding_accepted", ctypes.c_uint32 * 7),
        ("aiding_rejected", ctypes.c_uint32 * 7),
        ("solution_start_seq", ctypes.c_uint64),
        ("gyro_bias_rps", ctypes.c_double * 3),
        ("accel_bias_mps2", ctypes.c_double * 3),
        ("integrity", ctypes.c_uint8),
        ("_pad", ctypes.c_uint8 * 3),
        ("integrity_reasons", ctypes.c_uint32),
    ]

    @staticmethod
    def type_name() -> str:
        """The iceoryx2 type name of the Rust payload."""
        return "rins::NavState"


class Truth(ctypes.Structure):
    """`rins::Truth`: 144 bytes, aligned to 8."""

    _fields_ = [
        ("version", ctypes.c_uint16),
        ("_pad", ctypes.c_uint8 * 6),
        ("header", Header),
        ("quaternion", ctypes.c_double * 4),
        ("velocity_ned_mps", ctypes.c_double * 3),
        ("latitude_rad", ctypes.c_double),
        ("longitude_rad", ctypes.c_double),
        ("altitude_m", ctypes.c_double),
    ]

    @staticmethod
    def type_name() -> str:
        """The iceoryx2 type name of the Rust payload."""
        return "rins::Truth"


class Health(ctypes.Structure):
    """`rins::Health`: 144 bytes, aligned to 8."""

    _fields_ = [
        ("version", ctypes.c_uint16),
        ("service", ctypes.c_uint8),
        ("_pad", ctypes.c_uint8 * 1),
        ("pid", ctypes.c_uint32),
        ("now_ns", ctypes.c_uint64),
        ("received", ctypes.c_uint64),
        ("published", ctypes.c_uint64),
        ("crc_errors", ctypes.c_uint64),
        ("lost", ctypes.c_uint64),
        ("malformed", ctypes.c_uint64),
        ("duplicates", ctypes.c_uint64),
        ("late", ctypes.c_uint64),
        ("seq_jumps", ctypes.c_uint64),
        ("time_rebases", ctypes.c_uint64),
        ("resync_bytes", ctypes.c_uint64),
        ("reconnects", ctypes.c_uint64),
        ("rejected", ctypes.c_uint64),
        ("stale_input_episodes", ctypes.c_uint64),
        ("bytes_received", ctypes.c_uint64),
        ("valid_frames", ctypes.c_uint64),
        ("input_stale", ctypes.c_uint8),
        ("last_decode_error", ctypes.c_uint8),
        ("_pad2", ctypes.c_uint8 * 6),
    ]

    @staticmethod
    def type_name() -> str:
        """The iceoryx2 type name of the Rust payload."""
        return "rins::Health"


class ServiceHealth(ctypes.Structure):
    """`rins::ServiceHealth`: 24 bytes, aligned to 4."""

    _fields_ = [
        ("service", ctypes.c_uint8),
        ("state", ctypes.c_uint8),
        ("input_stale", ctypes.c_uint8),
        ("_pad", ctypes.c_uint8 * 1),
        ("pid", ctypes.c_uint32),
        ("restarts", ctypes.c_uint32),
        ("heartbeat_age_ms", ctypes.c_uint32),
        ("output_rate_hz", ctypes.c_float),
        ("_pad2", ctypes.c_uint8 * 4),
    ]

    @staticmethod
    def type_name() -> str:
        """The iceoryx2 type name of the Rust payload."""
        return "rins::ServiceHealth"


class LinkReport(ctypes.Structure):
    """`rins::LinkReport`: 56 bytes, aligned to 8."""

    _fields_ = [
        ("heard", ctypes.c_uint8),
        ("last_decode_error", ctypes.c_uint8),
        ("_pad", ctypes.c_uint8 * 6),
        ("bytes_received", ctypes.c_uint64),
        ("valid_frames", ctypes.c_uint64),
        ("discarded_bytes", ctypes.c_uint64),
        ("crc_errors", ctypes.c_uint64),
        ("malformed", ctypes.c_uint64),
        ("reconnects", ctypes.c_uint64),
    ]

    @staticmethod
    def type_name() -> str:
        """The iceoryx2 type name of the Rust payload."""
        return "rins::LinkReport"


class RedundancyReport(ctypes.Structure):
    """`rins::RedundancyReport`: 88 bytes, aligned to 4."""

    _fields_ = [
        ("heard", ctypes.c_uint8),
        ("n_gyro", ctypes.c_uint8),
        ("n_accel", ctypes.c_uint8),
        ("_pad", ctypes.c_uint8 * 1),
        ("flags", ctypes.c_uint32),
        ("gyro_state", ctypes.c_uint8 * 16),
        ("accel_state", ctypes.c_uint8 * 16),
        ("gyro_reason", ctypes.c_uint8 * 16),
        ("accel_reason", ctypes.c_uint8 * 16),
        ("gyro_test_statistic", ctypes.c_float),
        ("accel_test_statistic", ctypes.c_float),
        ("age_ms", ctypes.c_uint32),
        ("_pad2", ctypes.c_uint8 * 4),
    ]

    @staticmethod
    def type_name() -> str:
        """The iceoryx2 type name of the Rust payload."""
        return "rins::RedundancyReport"


class NavReport(ctypes.Structure):
    """`rins::NavReport`: 16 bytes, aligned to 4."""

    _fields_ = [
        ("heard", ctypes.c_uint8),
        ("mode", ctypes.c_uint8),
        ("lane", ctypes.c_uint8),
        ("integrity", ctypes.c_uint8),
        ("aiding", ctypes.c_uint32),
        ("integrity_reasons", ctypes.c_uint32),
        ("age_ms", ctypes.c_uint32),
    ]

    @staticmethod
    def type_name() -> str:
        """The iceoryx2 type name of the Rust payload."""
        return "rins::NavReport"


class HealthReport(ctypes.Structure):
    """`rins::HealthReport`: 672 bytes, aligned to 8."""

    _fields_ = [
        ("version", ctypes.c_uint16),
        ("count", ctypes.c_uint8),
        ("_pad", ctypes.c_uint8 * 5),
        ("now_ns", ctypes.c_uint64),
        ("uptime_ms", ctypes.c_uint64),
        ("services", ServiceHealth * 10),
        ("link", LinkReport),
        ("redundancy", RedundancyReport),
        ("nav", NavReport),
        ("gnss", GnssLinkReport),
    ]

    @staticmethod
    def type_name() -> str:
        """The iceoryx2 type name of the Rust payload."""
        return "rins::HealthReport"


class FaultApplied(ctypes.Structure):
    """`rins::FaultApplied`: 24 bytes, aligned to 8."""

    _fields_ = [
        ("version", ctypes.c_uint16),
        ("sensor", ctypes.c_uint8),
        ("channel", ctypes.c_uint8),
        ("fault", ctypes.c_uint8),
        ("outcome", ctypes.c_uint8),
        ("_pad", ctypes.c_uint8 * 2),
        ("device_time_us", ctypes.c_uint64),
        ("param", ctypes.c_double),
    ]

    @staticmethod
    def type_name() -> str:
        """The iceoryx2 type name of the Rust payload."""
        return "rins::FaultApplied"


class SimControl(ctypes.Structure):
    """`rins::SimControl`: 16 bytes, aligned to 8."""

    _fields_ = [
        ("version", ctypes.c_uint16),
        ("sensor", ctypes.c_uint8),
        ("channel", ctypes.c_uint8),
        ("fault", ctypes.c_uint8),
        ("_pad", ctypes.c_uint8 * 3),
        ("param", ctypes.c_double),
    ]

    @staticmethod
    def type_name() -> str:
        """The iceoryx2 type name of the Rust payload."""
        return "rins::SimControl"


class FusionControl(ctypes.Structure):
    """`rins::FusionControl`: 8 bytes, aligned to 4."""

    _fields_ = [
        ("version", ctypes.c_uint16),
        ("sensor", ctypes.c_uint8),
        ("channel", ctypes.c_uint8),
        ("request_id", ctypes.c_uint32),
    ]

    @staticmethod
    def type_name() -> str:
        """The iceoryx2 type name of the Rust payload."""
        return "rins::FusionControl"


class FusionReply(ctypes.Structure):
    """`rins::FusionReply`: 16 bytes, aligned to 4."""

    _fields_ = [
        ("version", ctypes.c_uint16),
        ("sensor", ctypes.c_uint8),
        ("channel", ctypes.c_uint8),
        ("request_id", ctypes.c_uint32),
        ("outcome", ctypes.c_uint8),
        ("reason", ctypes.c_uint8),
        ("_pad", ctypes.c_uint8 * 2),
        ("pid", ctypes.c_uint32),
    ]

    @staticmethod
    def type_name() -> str:
        """The iceoryx2 type name of the Rust payload."""
        return "rins::FusionReply"


class RawAirspeed(ctypes.Structure):
    """`rins::RawAirspeed`: 72 bytes, aligned to 8."""

    _fields_ = [
        ("version", ctypes.c_uint16),
        ("_pad", ctypes.c_uint8 * 6),
        ("header", Header),
        ("diff_pressure_pa", ctypes.c_float),
        ("temperature_c", ctypes.c_float),
    ]

    @staticmethod
    def type_name() -> str:
        """The iceoryx2 type name of the Rust payload."""
        return "rins::RawAirspeed"


#: The payload each topic carries.
TOPIC_PAYLOADS = {
    RAW_IMU: RawImu,
    RAW_BARO: RawBaro,
    RAW_MAG: RawMag,
    RAW_AUX: RawAux,
    GNSS: GnssFix,
    GNSS_LINK: GnssLinkReport,
    FUSED_IMU: FusedImu,
    ALTITUDE: Altitude,
    NAV_STATE: NavState,
    NAV_STATE_STANDBY: NavState,
    TRUTH: Truth,
    HEARTBEAT: Health,
    HEALTH: HealthReport,
    SIM_FAULT_APPLIED: FaultApplied,
    SIM_CONTROL: SimControl,
    FUSION_CONTROL: FusionControl,
    FUSION_REPLY: FusionReply,
    RAW_AIRSPEED: RawAirspeed,
}
# --- end of generated section ---
